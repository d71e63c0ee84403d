// trajectory_recorder.cpp — the sample band's pending walks (hybrid_simulation.hpp,
// TrajectoryRecorder::defer_last_outside; docs/design.md, "Design-space maps"): out of line, in
// their own translation unit, so that the closed-form event loop (hybrid_simulation.cpp), which
// the plain step response runs without a band, is compiled as without them (issue 19).
#include "backlash/numeric/hybrid_simulation.hpp"

#include <utility>

namespace backlash::numeric {

void TrajectoryRecorder::defer(long long first, double t0, const HybridState& last, std::function<HybridState(double)> at,
                               const BandTest& band, const double* turns, int turn_count) {
  if (pending_.size() >= 256) flush(band);  // memory stays bounded (the walks then as undeferred)
  Pending p{first, k_, t0, last, std::move(at), {}, turns && turn_count <= kMaxTurns ? turn_count : -1};
  for (int i = 0; i < p.turn_count; ++i) p.turns[static_cast<std::size_t>(i)] = turns[i];
  pending_.push_back(std::move(p));
}

void TrajectoryRecorder::flush(const BandTest& band) {
  kept_.clear();
  bool found = false;
  for (auto p = pending_.rbegin(); p != pending_.rend(); ++p) {
    const std::size_t before = kept_.size();
    if (!found) found = walk_back(*p, band);
    r_.samples_left_out += (p->end - p->first) - static_cast<long long>(kept_.size() - before);
  }
  pending_.clear();
  for (auto it = kept_.rbegin(); it != kept_.rend(); ++it) push(it->first, it->second);
}

// The samples that may be outside are kept, from the segment's last backwards, down to the first
// certainly outside (then true): those the sample-by-sample walk keeps.  Where θo is monotone —
// from the last turn at or before a sample inside by the margin (or from the segment's start) to
// that sample — the stretch holds no sample that may be outside when θo at its start is inside by
// the margin too (the band is an interval: the rule by which record() leaves out a whole
// segment); else θo leaves the inner band once on it, and its last sample that may be outside is
// found by bisection (the samples after it lie inside by the margin).
bool TrajectoryRecorder::walk_back(const Pending& p, const BandTest& band) {
  const double h = o_.sample_interval;
  const auto tau = [&](long long k) { return static_cast<double>(k) * h - p.t0; };
  const auto state = [&](long long k) { return k == p.end - 1 ? p.last : p.at(tau(k)); };
  const auto keep = [&](const HybridState& x) { return band.may_be_outside(measured(p_, x)); };
  for (long long k = p.end - 1; k >= p.first;) {
    const HybridState x = state(k);
    if (keep(x)) {
      kept_.push_back({static_cast<double>(k) * h, x});
      if (band.outside(measured(p_, x))) return true;
      --k;
      continue;
    }
    double a = 0;  // the stretch's start: the last turn at or before τ_k, else the segment's start
    for (int i = 0; i < p.turn_count; ++i)
      if (p.turns[static_cast<std::size_t>(i)] <= tau(k)) a = p.turns[static_cast<std::size_t>(i)];
    if (p.turn_count < 0 || !(a <= tau(k))) {
      --k;
      continue;
    }
    long long first = k;  // the stretch's first sample
    while (first > p.first && tau(first - 1) >= a) --first;
    if (!keep(p.at(a))) {
      k = first - 1;
      continue;
    }
    long long lo = first - 1, hi = k;  // may be outside at lo (or at a), inside by the margin at hi
    while (hi - lo > 1) {
      const long long mid = lo + (hi - lo) / 2;
      (keep(state(mid)) ? lo : hi) = mid;
    }
    k = lo;
  }
  return false;
}

}  // namespace backlash::numeric
