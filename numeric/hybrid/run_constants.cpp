// run_constants.cpp — a closed-form run's constants, once per thread and parameter set
// (run_constants.hpp).
#include "hybrid/run_constants.hpp"

#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/scales.hpp"
#include "hybrid/gap_events.hpp"

#include <array>
#include <atomic>
#include <cstring>

namespace backlash::numeric {

namespace {

std::atomic<long> built{0};

// The witness of one velocity (row of x) on a segment: its zeros are the extremes of the angle.
// The contact segment's is kept by its inputs' bits: a map's points share that segment
// (kept_witness_mode); the free segment's change with the split of J and F.
WitnessMode velocity_mode(const LinearSegment& segment, Eigen::Index row, double time_unit) {
  SmallRow e = SmallRow::Zero(segment.A.rows());
  e(row) = 1;
  if (segment.A.rows() == 2) return detail::kept_witness_mode(segment.A, segment.c, e, time_unit);
  return WitnessMode(segment.A, segment.c, e, time_unit);
}

// The same parameter set bit for bit (−0 and 0 differ; a NaN never matches: then rebuilt).
bool same(const Parameters& a, const Parameters& b) {
  const double x[] = {a.Jm, a.Fm, a.JL, a.FL, a.K, a.theta_R, a.backlash};
  const double y[] = {b.Jm, b.Fm, b.JL, b.FL, b.K, b.theta_R, b.backlash};
  for (std::size_t i = 0; i < std::size(x); ++i)
    if (std::memcmp(&x[i], &y[i], sizeof(double)) != 0 || x[i] != y[i]) return false;
  return a.measured_at == b.measured_at;
}

}  // namespace

long run_constants_built() { return built.load(std::memory_order_relaxed); }

namespace detail {

RunConstants::RunConstants(const Parameters& p)
    : parameters(p),
      contact_segment(contact_mode_segment(p)),
      free_segment(free_mode_segment(p)),
      torque(transmitted_torque(p)),
      time_unit(servo_time_unit(p)),
      contact_mode(contact_segment.A, contact_segment.c, torque.r, time_unit),
      gap_mode(gap_witness_mode(free_segment, time_unit)),
      gap_turns_once(gap_rate_turns_at_most_once(p)) {
  built.fetch_add(1, std::memory_order_relaxed);
}

const RunConstants::Velocities& RunConstants::velocities() const {
  if (!velocities_)
    velocities_.emplace(Velocities{velocity_mode(contact_segment, 1, time_unit),
                                   {velocity_mode(free_segment, 1, time_unit), velocity_mode(free_segment, 3, time_unit)}});
  return *velocities_;
}

namespace {

struct Kept {
  std::optional<RunConstants> constants;
  int users = 0;
};

}  // namespace

RunConstantsLease::RunConstantsLease(const Parameters& p) {
  thread_local std::array<Kept, 2> kept;
  Kept* slot = nullptr;
  for (Kept& k : kept)
    if (!slot && k.constants && same(k.constants->parameters, p)) slot = &k;
  for (Kept& k : kept)
    if (!slot && k.users == 0) (slot = &k)->constants.emplace(p);
  if (!slot) {
    own_ = std::make_unique<RunConstants>(p);
    constants_ = own_.get();
    return;
  }
  users_ = &slot->users;
  ++*users_;
  constants_ = &*slot->constants;
}

RunConstantsLease::~RunConstantsLease() {
  if (users_) --*users_;
}

}  // namespace detail

}  // namespace backlash::numeric
