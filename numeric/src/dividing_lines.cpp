#include "backlash/numeric/dividing_lines.hpp"

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "gap_events.hpp"

#include <boost/math/tools/minima.hpp>

#include <algorithm>
#include <cmath>

namespace backlash::numeric {

const char* to_string(RecombinationStatus status) {
  switch (status) {
    case RecombinationStatus::Recombination: return "recombination";
    case RecombinationStatus::Recontact: return "recontact";
    case RecombinationStatus::NoRecombination: return "none";
  }
  return "?";
}

namespace {

double horizon_of(const Parameters& p, const TraceOptions& options) {
  return options.horizon > 0 ? options.horizon : std::max(60.0, 40 * slowest_time_scale(p));
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
      [&evaluator, dtheta_m0](double t) { return evaluator.free_state(t, dtheta_m0).gap; }, level);
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

DividingLinePoint dividing_line_point(const ValidatedEvaluator& evaluator, double v0, const TraceOptions& options) {
  const Parameters& p = evaluator.parameters();
  DividingLinePoint point;
  point.dtheta_m0 = v0;
  if (v0 == 0 || p.backlash <= 0) return point;
  const LinearWitness gap = gap_witness(evaluator, v0, 0);
  const double scale = std::max({1.0, std::fabs(p.theta_R), std::fabs(evaluator.cot_phi() * v0)});
  const auto event = detail::first_gap_event(free_mode_segment(p), gap.state, gap.value, std::copysign(p.backlash, v0),
                                             horizon_of(p, options), scale);
  if (!event) return point;
  point.status = event->kind == detail::GapEventKind::FaceLeft ? RecombinationStatus::Recontact
                                                               : RecombinationStatus::Recombination;
  point.t = event->crossing.t;
  point.grazing = event->crossing.grazing;
  const FreeState f = evaluator.free_state(point.t, v0);
  point.theta_m = f.theta_m;
  point.dtheta_m = f.dtheta_m;
  point.theta_L = f.theta_L;
  point.dtheta_L = f.dtheta_L;
  point.theta_o = p.measured_at == model::MeasuredAt::Motor ? f.theta_m : f.theta_L;
  point.dtheta_o = recombined_velocity(p, f.dtheta_m, f.dtheta_L);
  return point;
}

namespace {

// sup over the free flight (until the gap returns to 0, or the horizon) of gap/θ̇m0.
// gap is linear in θ̇m0 (θR cancels), so the unit-velocity flight decides every θ̇m0 > 0.
std::optional<double> recombination_threshold(const ValidatedEvaluator& evaluator, double horizon) {
  const Parameters& p = evaluator.parameters();
  if (p.backlash <= 0) return std::nullopt;
  const double unit = 1.0;
  const std::optional<double> t0 = return_search_start(evaluator, unit);
  if (!t0) return std::nullopt;
  const auto back = first_crossing(gap_witness(evaluator, unit, 0), *t0, horizon);
  const double end = back ? back->t : horizon;
  // Maxima of the gap: zeros of its slope θ̇L − θ̇m, certified in turn.
  const LinearSegment s = free_mode_segment(p);
  LinearWitness slope;
  slope.A = s.A;
  slope.c = s.c;
  slope.e = SmallRow::Zero(4);
  slope.e(1) = -1;
  slope.e(3) = 1;
  slope.state = gap_witness(evaluator, unit, 0).state;
  double best = evaluator.free_state(end, unit).gap;
  double t = *t0;
  while (true) {
    const auto critical = first_crossing(slope, t, end);
    if (!critical) break;
    best = std::max(best, evaluator.free_state(critical->t, unit).gap);
    t = critical->t + 1e-9 * std::max(1.0, critical->t);
    if (t >= end) break;
  }
  // If the gap can grow without bound (it still rises at the horizon), every θ̇m0 recombines.
  const FreeState at_end = evaluator.free_state(end, unit);
  if (!back && at_end.dtheta_L - at_end.dtheta_m > 1e-9) return std::nullopt;
  if (best <= 0) return std::nullopt;
  return p.backlash / best;
}

}  // namespace

DividingLines trace_dividing_lines(const ValidatedEvaluator& evaluator, const std::vector<double>& grid,
                                   const TraceOptions& options) {
  DividingLines lines;
  lines.cot_phi = evaluator.cot_phi();
  lines.horizon = horizon_of(evaluator.parameters(), options);
  lines.threshold = recombination_threshold(evaluator, lines.horizon);
  lines.points.reserve(grid.size());
  for (double v0 : grid) lines.points.push_back(dividing_line_point(evaluator, v0, options));
  return lines;
}

std::vector<double> default_dividing_line_grid() {
  std::vector<double> grid{1, 0.9, 0.8, 0.7, 0.6, 0.5, 0.45, 0.4, 0.35, 0.3, 0.25, 0.2, 0.15, 0.13, 0.12, 0.1,
                           0.09, 0.08, 0.075, 0.07, 0.065, 0.06, 0.05, 0.04, 0.035, 0.03, 0.025, 0.02};
  return grid;
}

}  // namespace backlash::numeric
