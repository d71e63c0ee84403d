// Placeholder: the closed-form simulator with effects (effects_simulation.hpp) is being written.
