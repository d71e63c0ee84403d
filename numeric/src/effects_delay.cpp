// The delayed model (docs/effects.md §delay): placeholder until the method-of-steps integrator lands.
#include "backlash/numeric/effects_simulation.hpp"

#include <stdexcept>

namespace backlash::numeric::detail {

SimulationResult simulate_delayed(const Parameters&, const Effects&, const HybridState&, const SimulationOptions&) {
  throw std::logic_error("delay: not implemented yet");
}

}  // namespace backlash::numeric::detail
