// backlash/numeric/effects_engine_options.hpp — what the effects engine (docs/effects.md) is
// told beside the SimulationOptions every simulator reads (hybrid_simulation.hpp), and the one
// threshold of its own that the documentation names.  The nominal simulators and the
// independent odeint ones never read these.
#pragma once

#include "backlash/numeric/hybrid_simulation.hpp"

#include <functional>
#include <vector>

namespace backlash::numeric {

/// The options only the effects engine reads, beside the SimulationOptions every simulator reads.
struct EffectsEngineOptions {
  bool general_engine = false;  ///< run the effects engine even when every effect is neutral
  /// stop_at_face = ±1: stop right after the first event of kind stop_at_kind whose face (the
  /// face left by a separation, hit by an impact) is stop_at_face, at t > 0.
  int stop_at_face = 0;
  EventKind stop_at_kind = EventKind::Recombination;
  /// With SimulationOptions::track_extremes: extremes only of segments starting at or after this time.
  double extremes_after = 0;
  /// The delayed model's work budget: integration steps per run (each no longer than the delay),
  /// then the status work_limit, exit 3 (docs/effects.md, "Delay").
  long max_delay_steps = 20'000'000;
  /// Asked after every event with the events so far: true ends the run there, completed (the
  /// delayed loop's limit-cycle search stops once its crossings repeat).
  std::function<bool(const std::vector<SimulationEvent>&)> stop_when = {};
};

/// The accumulation threshold of docs/effects.md: a bounce series whose remaining duration is
/// below this fraction of the servo period is summed, not simulated.
inline constexpr double accumulation_fraction = 1e-7;

}  // namespace backlash::numeric
