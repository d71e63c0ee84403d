// run_constants.hpp (private) — the constants of a closed-form run that depend on the parameter
// set alone (docs/design.md, "Design-space maps"): the contact and free segments, the transmitted
// torque's row, and the certified witnesses' constants (WitnessMode) of Tc in contact, of the gap
// in flight and, for runs that track extremes, of the velocities.  A point of a map runs ~5
// simulations (its limit cycle's half cycles, its settle run and the stop's check) on one
// parameter set; they share one set of constants, built once per thread and parameter set — the
// same bits as building them per run (the same function of the same parameters).
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/parameters.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <array>
#include <memory>
#include <optional>

namespace backlash::numeric::detail {

struct RunConstants {
  explicit RunConstants(const Parameters& p);
  /// The velocities' witnesses (θ̇o in contact; θ̇m and θ̇L in flight), built at the first run that
  /// tracks extremes.  Only the thread that owns the cache calls this (run_constants).
  const WitnessMode& contact_velocity() const { return velocities().contact; }
  const WitnessMode* free_velocities() const { return velocities().free.data(); }

  const Parameters parameters;  ///< the set these constants belong to (compared bit for bit)
  const LinearSegment contact_segment, free_segment;
  const TransmittedTorque torque;
  const double time_unit;  ///< servo_time_unit(parameters)
  const WitnessMode contact_mode, gap_mode;  ///< Tc in contact; the gap θL − θm in flight
  const bool gap_turns_once;  ///< gap_rate_turns_at_most_once(parameters) (gap_events.hpp)

 private:
  struct Velocities {
    WitnessMode contact;
    std::array<WitnessMode, 2> free;
  };
  const Velocities& velocities() const;
  mutable std::optional<Velocities> velocities_;
};

/// The constants of `p` for one run, without allocating: this thread's kept set when `p` is the
/// same parameter set bit for bit, else built in place of one no run is using (two kept per
/// thread: a run and one nested run of another set, e.g. settle.cpp's check inside its step
/// response; deeper nesting builds its own).  Held for the run's lifetime.
class RunConstantsLease {
 public:
  explicit RunConstantsLease(const Parameters& p);
  ~RunConstantsLease();
  RunConstantsLease(const RunConstantsLease&) = delete;
  RunConstantsLease& operator=(const RunConstantsLease&) = delete;
  const RunConstants* operator->() const { return constants_; }

 private:
  int* users_ = nullptr;  // the kept set's count of runs holding it
  std::unique_ptr<RunConstants> own_;
  const RunConstants* constants_ = nullptr;
};

}  // namespace backlash::numeric::detail
