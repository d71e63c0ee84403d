// Placeholder: the independent odeint simulator with effects is being written
// (see odeint_effects_simulation.hpp).
#include "backlash/numeric/odeint_effects_simulation.hpp"
