#include "backlash/numeric/dividing_lines.hpp"

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/quiet_tail.hpp"
#include "hybrid/unit_gap_profile.hpp"

#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

namespace backlash::numeric {

const char* to_string(RecombinationStatus status) {
  switch (status) {
    case RecombinationStatus::Recombination: return "recombination";
    case RecombinationStatus::Recontact: return "recontact";
    case RecombinationStatus::NoRecombination: return "none";
    case RecombinationStatus::Unresolved: return "work_limit";
  }
  return "?";
}

namespace {

double horizon_of(const Parameters& p, const TraceOptions& options) {
  // In the system's own time (slowest_time_scale includes the contact period 2π√(J/K)), never a
  // floor in seconds (a 60 s floor never bound for the thesis's cases: 40 periods of 2π s exceed it).
  return options.horizon > 0 ? options.horizon : 40 * slowest_time_scale(p);
}

LinearWitness gap_witness(const ValidatedEvaluator& evaluator, double dtheta_m0, double level) {
  return detail::gap_change_witness(
      free_mode_segment(evaluator.parameters()),
      [&evaluator, dtheta_m0](double t) {
        const FreeState f = evaluator.free_state(t, dtheta_m0);
        SmallVector x(4);
        x << f.theta_m, f.dtheta_m, f.theta_L, f.dtheta_L;
        return x;
      },
      [&evaluator, dtheta_m0](double t) { return evaluator.free_state(t, dtheta_m0).gap; }, level,
      servo_time_unit(evaluator.parameters()));
}

// The states at the impact time point.t: motor and load before it, the recombined system after (eq. 24).
void fill_impact_states(const ValidatedEvaluator& evaluator, DividingLinePoint& point) {
  const Parameters& p = evaluator.parameters();
  const FreeState f = evaluator.free_state(point.t, point.dtheta_m0);
  point.theta_m = f.theta_m;
  point.dtheta_m = f.dtheta_m;
  point.theta_L = f.theta_L;
  point.dtheta_L = f.dtheta_L;
  point.theta_o = p.measured_at == model::MeasuredAt::Motor ? f.theta_m : f.theta_L;
  point.dtheta_o = recombined_velocity(p, f.dtheta_m, f.dtheta_L);
}

// Start of the search for a return to the face left.  On the separation line
// the gap starts as w'''(0) t^3/6 (value, slope and curvature vanish), far below
// rounding noise at first; the search starts at a certified departure time t0:
// the gap cannot return to 0 on (0, t0], and at t0 it is well above the noise.
std::optional<double> return_search_start(const ValidatedEvaluator& evaluator, double dtheta_m0) {
  const Parameters& p = evaluator.parameters();
  const double scale = std::max({1.0, std::fabs(p.theta_R), std::fabs(evaluator.cot_phi() * dtheta_m0)});
  return certified_departure(gap_witness(evaluator, dtheta_m0, 0), 1e-10 * scale);
}

}  // namespace

namespace {
DividingLinePoint point_by_profile(const ValidatedEvaluator& evaluator, double v0, const TraceOptions& options);
/// Above this |θ̇m0| the flight's angles are so large against its gap that the direct search's
/// noise floor (1e-10 of the position scale) no longer separates a departure from rounding:
/// the unit profile, exact by linearity (gap = θ̇m0·f(t)), answers instead.
constexpr double direct_search_velocity_limit = 1e3;
}  // namespace

namespace {

// A point found in error coordinates, back in the case's: its angles shifted by θR.
void shift_angles(DividingLinePoint& point, double theta_R) {
  if (!has_impact(point.status)) return;
  point.theta_m += theta_R;
  point.theta_L += theta_R;
  point.theta_o += theta_R;
}

std::string budget_reason(const SearchBudgetExhausted& budget, double horizon) {
  char where[120];
  std::snprintf(where, sizeof where, " at t = %.6g s of the flight from the separation line (horizon %.6g s)",
                budget.certified_until, horizon);
  return budget.what() + std::string(where);
}

}  // namespace

DividingLinePoint dividing_line_point(const ValidatedEvaluator& evaluator, double v0, const TraceOptions& options) {
  if (const std::optional<ValidatedEvaluator> centred = in_error_coordinates(evaluator)) {
    DividingLinePoint point = dividing_line_point(*centred, v0, options);
    shift_angles(point, evaluator.parameters().theta_R);
    return point;
  }
  const Parameters& p = evaluator.parameters();
  DividingLinePoint point;
  point.dtheta_m0 = v0;
  if (v0 == 0 || p.backlash <= 0) return point;
  if (std::fabs(v0) > direct_search_velocity_limit) return point_by_profile(evaluator, v0, options);
  const LinearWitness gap = gap_witness(evaluator, v0, 0);
  const double scale = std::max({1.0, std::fabs(p.theta_R), std::fabs(evaluator.cot_phi() * v0)});
  std::optional<detail::GapEvent> event;
  try {
    // From the separation line: both bodies at v0, Δx'(0) = 0 exactly (gap_events.hpp, turns_once).
    event = detail::first_gap_event(free_mode_segment(p), gap.state, gap.value, std::copysign(p.backlash, v0),
                                    horizon_of(p, options), scale, servo_time_unit(p),
                                    detail::gap_rate_turns_at_most_once(p));
  } catch (const SearchBudgetExhausted&) {
    point.status = RecombinationStatus::Unresolved;
    return point;
  }
  if (!event) return point;
  point.status = event->kind == detail::GapEventKind::FaceLeft ? RecombinationStatus::Recontact
                                                               : RecombinationStatus::Recombination;
  point.t = event->crossing.t;
  point.grazing = event->crossing.grazing;
  fill_impact_states(evaluator, point);
  return point;
}

namespace {

using detail::UnitGapProfile;

// A nearly frictionless load (FL → 0) stretches the horizon to 40·JL/FL while the motor settles
// within its own time scale: then, after a while, f and f' keep one sign to the horizon
// (quiet_tail.hpp).  The first such time certified, tried at the ends of the searches' windows 3,
// 5, 7, … from t0 (7, 31, 127, … first windows on), while short of an eighth of the horizon (a
// shorter horizon gains nothing); each try within kQuietTailBudget intervals.
constexpr long kQuietTailBudget = 400;

std::optional<double> quiet_start(const ValidatedEvaluator& evaluator, const std::function<SmallVector(double)>& state,
                                  double t0, double horizon) {
  const Parameters& p = evaluator.parameters();
  const LinearSegment free = free_mode_segment(p);
  const double window = detail::gap_witness_mode(free, servo_time_unit(p)).first_window;
  for (int k = 3; k < 60; k += 2) {
    const double from = t0 + window * (std::ldexp(1.0, k) - 1);
    if (!(from <= horizon / 8)) break;
    if (detail::gap_moves_away_from(free, state, evaluator.free_state(from, 1.0).gap, from, horizon, servo_time_unit(p),
                                    kQuietTailBudget))
      return from;
  }
  return std::nullopt;
}

// The first crossing of `w` in (lo, hi] as first_crossing(w, lo, hi) finds it, with w certified
// free of zeros from `quiet` to hi: searched on (lo, quiet] first, where none means none at all,
// and a crossing there found again by the whole search (which stops at it: the same bits).
std::optional<Crossing> crossing_before_quiet_tail(const LinearWitness& w, double lo, double hi,
                                                   const std::optional<double>& quiet) {
  if (quiet && *quiet > lo && *quiet < hi) {
    try {
      if (!first_crossing(w, lo, *quiet)) return std::nullopt;
    } catch (const SearchBudgetExhausted&) {
      // the whole search answers (or spends its own budget)
    }
  }
  return first_crossing(w, lo, hi);
}

}  // namespace

UnitGapProfile detail::unit_gap_profile(const ValidatedEvaluator& evaluator, double horizon, bool quiet_tail) {
  UnitGapProfile profile;
  const double unit = 1.0;
  const std::optional<double> t0 = return_search_start(evaluator, unit);
  if (!t0) return profile;
  const LinearWitness gap = gap_witness(evaluator, unit, 0);
  const std::optional<double> quiet = quiet_tail ? quiet_start(evaluator, gap.state, *t0, horizon) : std::nullopt;
  std::optional<Crossing> back;
  const auto stopped = [&profile, horizon](const SearchBudgetExhausted& budget, double from) {
    profile.complete = false;
    profile.work_limit = budget_reason(budget, horizon);
    profile.end = std::max(from, budget.certified_until);  // no zero of the witness on (from, end]
  };
  profile.valid = true;
  try {
    back = crossing_before_quiet_tail(gap, *t0, horizon, quiet);
    profile.end = back ? back->t : horizon;
  } catch (const SearchBudgetExhausted& budget) {
    stopped(budget, *t0);  // f ≠ 0 on (t0, end]: no return there
  }
  profile.returns = back.has_value();
  LinearWitness slope = gap;  // zeros of f' = θ̇L − θ̇m
  slope.e = SmallRow::Zero(4);
  slope.e(1) = -1;
  slope.e(3) = 1;
  slope.value = nullptr;
  auto add = [&](double t) {
    profile.knots.push_back(t);
    profile.values.push_back(t == profile.end && profile.returns ? 0.0 : evaluator.free_state(t, unit).gap);
  };
  // The separation point itself: f(0) = 0, and f is monotone on (0, t0] (its first non-vanishing
  // derivative keeps its sign there), so a level below f(t0) — a large θ̇m0, whose gap reaches
  // the face before the departure time — is found on [0, t0] instead of being missed.
  profile.knots.push_back(0.0);
  profile.values.push_back(0.0);
  add(*t0);
  double t = *t0;
  try {
    while (t < profile.end) {
      const auto critical = crossing_before_quiet_tail(slope, t, profile.end, quiet);
      if (!critical) break;
      add(critical->t);
      t = critical->t + 1e-12 * std::max(1.0, critical->t);
    }
  } catch (const SearchBudgetExhausted& budget) {
    stopped(budget, t);  // f' ≠ 0 on (t, end]: f monotone from the last knot to the new end
    profile.returns = false;
  }
  if (profile.complete || profile.end > profile.knots.back()) add(profile.end);
  return profile;
}

namespace {

// First t with f(t) = level on the profile (monotone pieces in order), or nothing.
std::optional<Crossing> first_level_crossing(const ValidatedEvaluator& evaluator, const UnitGapProfile& profile, double level) {
  const auto f = [&evaluator, level](double t) { return evaluator.free_state(t, 1.0).gap - level; };
  for (size_t i = 0; i + 1 < profile.knots.size(); ++i) {
    const double a = profile.knots[i], b = profile.knots[i + 1];
    const double fa = profile.values[i] - level, fb = profile.values[i + 1] - level;
    if (fa == 0 && i > 0) return Crossing{a, true, 0};  // touches the level at a maximum: grazing
    if ((fa > 0) == (fb > 0) && fb != 0) continue;
    if (fb == 0) return Crossing{b, i + 2 < profile.knots.size(), 0};
    boost::uintmax_t iterations = 200;
    const auto root = boost::math::tools::toms748_solve(
        f, a, b, fa, fb, [](double lo, double hi) { return hi - lo <= 1e-14 * std::max(1.0, std::fabs(hi)); }, iterations);
    return Crossing{0.5 * (root.first + root.second), false, 0};
  }
  return std::nullopt;
}

DividingLinePoint point_from_profile(const ValidatedEvaluator& evaluator, const UnitGapProfile& profile, double v0) {
  const Parameters& p = evaluator.parameters();
  DividingLinePoint point;
  point.dtheta_m0 = v0;
  if (v0 == 0 || p.backlash <= 0 || !profile.valid) return point;
  // gap = v0·f reaches the opposite face copysign(b, v0) where f = b/|v0|.
  if (const auto hit = first_level_crossing(evaluator, profile, p.backlash / std::fabs(v0))) {
    point.status = RecombinationStatus::Recombination;
    point.t = hit->t;
    point.grazing = hit->grazing;
  } else if (profile.returns) {
    point.status = RecombinationStatus::Recontact;
    point.t = profile.end;
  } else {
    if (!profile.complete) point.status = RecombinationStatus::Unresolved;
    return point;
  }
  fill_impact_states(evaluator, point);
  return point;
}

DividingLinePoint point_by_profile(const ValidatedEvaluator& evaluator, double v0, const TraceOptions& options) {
  return point_from_profile(evaluator, detail::unit_gap_profile(evaluator, horizon_of(evaluator.parameters(), options)), v0);
}

}  // namespace

DividingLines trace_dividing_lines(const ValidatedEvaluator& evaluator, const std::vector<double>& grid,
                                   const TraceOptions& options) {
  if (const std::optional<ValidatedEvaluator> centred = in_error_coordinates(evaluator)) {
    DividingLines lines = trace_dividing_lines(*centred, grid, options);
    for (DividingLinePoint& point : lines.points) shift_angles(point, evaluator.parameters().theta_R);
    return lines;
  }
  const Parameters& p = evaluator.parameters();
  DividingLines lines;
  lines.cot_phi = evaluator.cot_phi();
  lines.horizon = horizon_of(p, options);
  const UnitGapProfile profile = detail::unit_gap_profile(evaluator, lines.horizon);
  // Threshold: b / sup f before the return; none when f still rises at the horizon (it grows without bound).
  if (profile.valid && profile.complete && p.backlash > 0) {
    double sup = 0;
    for (double v : profile.values) sup = std::max(sup, v);
    const FreeState at_end = evaluator.free_state(profile.end, 1.0);
    const bool unbounded = !profile.returns && at_end.dtheta_L - at_end.dtheta_m > 1e-9;
    if (!unbounded && sup > 0) lines.threshold = p.backlash / sup;
  }
  lines.points.reserve(grid.size());
  for (double v0 : grid) lines.points.push_back(point_from_profile(evaluator, profile, v0));
  const auto unresolved = [](const DividingLinePoint& q) { return q.status == RecombinationStatus::Unresolved; };
  if (std::any_of(lines.points.begin(), lines.points.end(), unresolved)) lines.work_limit = profile.work_limit;
  return lines;
}

std::vector<double> default_dividing_line_grid() {
  std::vector<double> grid{1, 0.9, 0.8, 0.7, 0.6, 0.5, 0.45, 0.4, 0.35, 0.3, 0.25, 0.2, 0.15, 0.13, 0.12, 0.1,
                           0.09, 0.08, 0.075, 0.07, 0.065, 0.06, 0.05, 0.04, 0.035, 0.03, 0.025, 0.02};
  return grid;
}

}  // namespace backlash::numeric
