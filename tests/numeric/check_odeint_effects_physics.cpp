// Placeholder: the physics tests of the odeint simulator with effects are being written.
#include <gtest/gtest.h>
