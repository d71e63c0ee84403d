#include "hybrid/gap_events.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::numeric::detail {

LinearWitness gap_change_witness(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                 std::function<double(double)> gap_change, double level, double time_unit) {
  LinearWitness w;
  w.time_unit = time_unit;
  w.A = free_segment.A;
  w.c = free_segment.c;
  w.e = SmallRow::Zero(4);
  w.e(0) = -1;
  w.e(2) = 1;
  w.state = std::move(state);
  w.value = std::move(gap_change);
  w.level = level;
  return w;
}

WitnessMode gap_witness_mode(const LinearSegment& free_segment, double time_unit) {
  SmallRow e = SmallRow::Zero(4);
  e(0) = -1;
  e(2) = 1;
  return WitnessMode(free_segment.A, free_segment.c, e, time_unit);
}

namespace {

// A flight's two gap levels, searched window by window together (docs/design.md, "The event loop").
// The reference is the two searches one after the other: the `first` level over (start, horizon],
// then the `second` up to the first's crossing, the earlier kept.  When the first level's crossing
// is far off or absent (a nearly frictionless load: horizons of 60·JL/FL) that certifies the whole
// horizon before the second level, which crosses in its first seconds, is even looked at.  Here
// each level is advanced over its own search's windows (WitnessMode::first_window from its start,
// each twice the one before: the windows first_crossing's whole search would use), the one behind
// first, each window a certified first_crossing of its own on that span; the searches stop at the
// first window in which a level crosses once the other is certified clear beyond it.  The crossing
// kept is then the one the level's whole search from its start finds (the same crossing; its time
// bit for bit the reference's, the windows of that search being the reference's up to it), so
// event times are those of the sequential searches.  Whatever the windows cannot settle — a
// grazing, two crossings closer than 1e-9 of their time, an exhausted budget — goes to the
// sequential searches themselves.

// The reference's answer from the first level's whole search: the second searched up to its crossing.
std::optional<LevelEvent> with_second(const std::optional<Crossing>& a, const Level& second, double horizon) {
  const std::optional<Crossing> b = second.search(second.start(), a ? a->t : horizon);
  if (b && (!a || b->t < a->t)) return LevelEvent{true, *b};
  if (a) return LevelEvent{false, *a};
  return std::nullopt;
}

std::optional<LevelEvent> sequential_search(const Level& first, const Level& second, double horizon) {
  return with_second(first.search(first.start(), horizon), second, horizon);
}

// The first stretch of each level, searched as its whole search searches it (windows 0, 1, 2 of
// first_crossing's search: 7 of the mode's time scales): a crossing there is the reference's at
// once, and most flights end there.
constexpr int kFirstStretchWindows = 3;

// One level advanced over its whole search's windows: none crosses on (start, end] unless found;
// (begin, end] is the window searched last, or the one holding the crossing found.  `limit`
// (≤ horizon): neither level crosses on [limit, horizon] (a quiet tail, quiet_gap_from), so the
// windows stop there, the last one cut at it.
struct Track {
  const Level& level;
  double horizon, limit, first_window, window, begin, end;
  bool started = false, exact = false;  ///< exact: found by the level's whole search (its reference time)
  std::optional<Crossing> found;

  Track(const Level& l, double horizon_, double limit_, double first_window_)
      : level(l), horizon(horizon_), limit(limit_), first_window(first_window_), window(first_window_),
        begin(l.start()), end(begin) {}
  bool exhausted() const { return found || end >= limit; }
  // No crossing of this level on (start, x] (x ≤ horizon, or the limit reached: the tail is quiet).
  bool clear_beyond(double x) const { return found ? found->t > x : (end >= x || end >= limit); }
  // The whole search's windows from the start, its ends computed as first_crossing's search does,
  // up to the first one that ends at or after `t`, `count` of them at least: (begin, end].
  void windows_to(double t, int count) {
    begin = end = level.start();
    window = first_window;
    for (int i = 0; end < horizon && (i < count || end < t); ++i) {
      begin = end;
      end = horizon - begin <= window ? horizon : begin + window;
      window *= 2;
    }
  }
  // The first call: the level's whole search over its first windows, to `reach` at least (its
  // crossing there is the reference's), or a search of its own when they pass the limit (cut
  // there).  Later calls: the next window, a certified search of its own.
  void advance(double reach, int windows = 1) {
    if (!started) {
      started = true;
      windows_to(reach, windows);
      exact = end <= limit;
      end = std::max(begin, std::min(end, limit));
      found = level.search(level.start(), end);
      if (found && exact) windows_to(found->t, 1);  // the window that holds it
      return;
    }
    exact = false;
    begin = end;
    end = limit - begin <= window ? limit : begin + window;
    window *= 2;
    found = level.search(begin, end);
  }
  // The crossing as the level's whole search finds it: found again by that search (which stops
  // there) when a window of its own found it; it must be the same crossing in the same window.
  std::optional<Crossing> whole() const {
    if (exact) return found;
    const std::optional<Crossing> w = level.search(level.start(), horizon);
    if (!w || w->grazing || w->t > end || !(std::fabs(w->t - found->t) <= 1e-9 * found->t)) return std::nullopt;
    return w;
  }
};

// What the windows settle (`settled`: the event, or none on the whole horizon); the rest goes to
// the sequential searches.
struct Windowed {
  bool settled = false;
  std::optional<LevelEvent> event;
};

// After the first level's first stretch found nothing: both levels window by window.
// `first_settles`: a crossing of the first level that is not grazing is the event (first_of_two_levels).
Windowed windowed_search(Track& a, Track& b, const long& samples, bool first_settles) {
  const long budget = CrossingOptions{}.max_intervals;
  try {
    for (;;) {
      if ((a.found && a.found->grazing) || (b.found && b.found->grazing) || samples > budget) break;
      // The second level's crossing stands when the first is clear past its window (the reference
      // searches the second level up to the first's crossing: its windows up to that one the same).
      if (b.found && a.clear_beyond(b.end + (b.end - b.begin) * 0x1p-20)) {
        if (const auto w = b.whole()) return {true, LevelEvent{true, *w}};
        break;
      }
      if (a.found && (first_settles || b.clear_beyond(a.found->t * (1 + 1e-9)))) {
        if (const auto w = a.whole()) return {true, LevelEvent{false, *w}};
        break;
      }
      if (a.found && b.found) break;  // both within one window of each other: the reference decides
      if (a.exhausted() && b.exhausted()) return {true, std::nullopt};
      const bool first_next = !a.found && (b.found || b.exhausted() || (!a.exhausted() && a.end <= b.end));
      (first_next ? a : b).advance((first_next ? b : a).end);
    }
  } catch (const SearchBudgetExhausted&) {
    // the sequential searches give the reference's answer or its own exhausted budget
  }
  return {};
}

// The first level's first stretch as the reference searches it — a crossing there (or none on the
// whole horizon) is the reference's, and the second level is then searched as the reference does
// —, else both levels window by window, and the sequential searches where they cannot settle.
// With a quiet tail from `limit` on, no window goes past it: a crossing found in a stretch cut at
// the limit is taken from the level's whole search (the reference's time), and a first level
// clear up to the limit leaves the second to its windows up to the limit, not to its whole search.
std::optional<LevelEvent> windowed_levels(const Level& first, const Level& second, double horizon, double first_window,
                                          const long& samples, bool first_settles, double limit) {
  Track a(first, horizon, limit, first_window);
  a.advance(-INFINITY, kFirstStretchWindows);
  if (a.found && !a.exact) {
    a.found = a.whole();
    if (!a.found) return sequential_search(first, second, horizon);
  }
  if (first_settles && a.found && !a.found->grazing) return LevelEvent{false, *a.found};
  if (a.found || a.end >= horizon) return with_second(a.found, second, horizon);
  Track b(second, horizon, limit, first_window);
  const Windowed windowed = windowed_search(a, b, samples, first_settles);
  if (windowed.settled) return windowed.event;
  return sequential_search(first, second, horizon);
}

}  // namespace

// The two levels, window by window when the mode has a time scale, else one after the other.
std::optional<LevelEvent> first_of_two_levels(const Level& first, const Level& second, double horizon,
                                              double first_window, const long& samples, bool first_settles,
                                              double quiet_from) {
  if (!(first_window > 0) || !std::isfinite(first_window)) return sequential_search(first, second, horizon);
  const double limit = quiet_from < horizon ? std::max(0.0, quiet_from) : horizon;
  return windowed_levels(first, second, horizon, first_window, samples, first_settles, limit);
}

// The gap rate of a free flight (free_mode_segment): θ̇L' = −(FL/JL) θ̇L, so (D + a) θ̇L = 0 with
// a = FL/JL.  Output at the load: Jm θ̈m = K(θR − θL) − Fm θ̇m, so (D + b) θ̇m = (K/Jm)(θR − θL),
// b = Fm/Jm; D(D + b) θ̇m = −(K/Jm) θ̇L and (D + a) D (D + b) θ̇m = 0.  Output at the motor:
// Jm θ̈m = K(θR − θm) − Fm θ̇m, so (D² + bD + K/Jm) θ̇m = 0.  Either way (D + a)·q(D) annihilates
// θ̇L − θ̇m with q of degree 2, and when all three roots are real a nonzero solution has at most
// two real zeros counted with multiplicity (an exponential polynomial Σ P_i(t) e^{λ_i t} with real
// λ_i has at most Σ (deg P_i + 1) − 1: divide by e^{λ_1 t} and apply Rolle's theorem deg P_1 + 1
// times).  The motor's roots are real when b² ≥ 4K/Jm, i.e. Fm² ≥ 4 K Jm, asked here with a
// margin far above the rounding of these products (near critical damping the answer is "no").
bool gap_rate_turns_at_most_once(const Parameters& p) {
  if (p.measured_at == model::MeasuredAt::Load) return true;
  return p.Fm * p.Fm > 4 * p.K * p.Jm * (1 + 1e-9);
}

std::optional<GapEvent> first_gap_event(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                        double opposite_face_change, double horizon, double position_scale,
                                        bool turns_once) {
  return first_gap_event_with(gap_mode, sample, opposite_face_change, horizon, position_scale, turns_once);
}

std::optional<GapEvent> first_gap_event_inside(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                               double start_gap, int face, double half, double horizon) {
  return first_gap_event_inside_with(gap_mode, sample, start_gap, face, half, horizon);
}

std::optional<GapEvent> first_gap_event(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                        std::function<double(double)> gap_change, double opposite_face_change,
                                        double horizon, double position_scale, double time_unit, bool turns_once) {
  const auto sample = [&state, &gap_change](double t) { return WitnessSample{state(t), gap_change(t)}; };
  return first_gap_event(gap_witness_mode(free_segment, time_unit), sample, opposite_face_change, horizon, position_scale,
                         turns_once);
}

}  // namespace backlash::numeric::detail
