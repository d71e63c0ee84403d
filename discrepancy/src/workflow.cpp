// The discrepancy workflow (discrepancy.hpp): compare, localise, name, add.
#include "internal.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <thread>

namespace backlash::discrepancy {

const char* to_string(Status status) {
  switch (status) {
    case Status::EffectFound: return "effect_found";
    case Status::NoDiscrepancy: return "no_discrepancy";
    case Status::Unexplained: return "unexplained";
  }
  return "?";
}

// ------------------------------------------------------------------ noise and features

double estimate_noise(const std::vector<double>& y) {
  if (y.size() < 12) return 0;
  // Δ⁴ of white noise has variance C(8,4)σ² = 70σ²; the median of |Δ⁴y| is 0.6745 of its σ.
  std::vector<double> d;
  d.reserve(y.size() - 4);
  for (std::size_t i = 4; i < y.size(); ++i)
    d.push_back(std::fabs(y[i] - 4 * y[i - 1] + 6 * y[i - 2] - 4 * y[i - 3] + y[i - 4]));
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2] / (0.6745 * std::sqrt(70.0));
}

Features features_of(const std::vector<double>& t, const std::vector<double>& theta, double theta_R, double step) {
  Features f;
  const std::size_t n = theta.size();
  if (n < 10) return f;
  const double direction = step >= 0 ? 1 : -1;
  f.overshoot = -INFINITY;
  for (double y : theta) f.overshoot = std::max(f.overshoot, (y - theta_R) * direction);
  const std::size_t tail = n - n / 10;
  f.final_error = std::accumulate(theta.begin() + static_cast<std::ptrdiff_t>(tail), theta.end(), 0.0) / (n - tail) - theta_R;
  // Peaks of |θo − θR| (local maxima of the error's size) for the decay rate.
  std::vector<std::pair<double, double>> peaks;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double a = std::fabs(theta[i - 1] - theta_R), b = std::fabs(theta[i] - theta_R), c = std::fabs(theta[i + 1] - theta_R);
    if (b > a && b >= c) peaks.push_back({t[i], b});
  }
  if (peaks.size() >= 3) {
    const auto& first = peaks[1];
    const auto& last = peaks[std::min<std::size_t>(peaks.size() - 1, 6)];
    if (last.first > first.first && first.second > 0 && last.second > 0)
      f.decay_rate = std::log(last.second / first.second) / (last.first - first.first);
  }
  // The last third: half its peak-to-peak, and the period from crossings of its mean.
  const std::size_t third = n - n / 3;
  double lo = INFINITY, hi = -INFINITY, mean = 0;
  for (std::size_t i = third; i < n; ++i) {
    lo = std::min(lo, theta[i]);
    hi = std::max(hi, theta[i]);
    mean += theta[i];
  }
  mean /= (n - third);
  f.cycle_amplitude = 0.5 * (hi - lo);
  std::vector<double> crossings;
  for (std::size_t i = third + 1; i < n; ++i)
    if ((theta[i - 1] - mean) < 0 && (theta[i] - mean) >= 0)
      crossings.push_back(t[i - 1] + (t[i] - t[i - 1]) * (mean - theta[i - 1]) / (theta[i] - theta[i - 1]));
  if (crossings.size() >= 2) f.cycle_period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  return f;
}

namespace {

using detail::EffectCandidate;
using detail::ModelPoint;
using detail::Observations;
using detail::Simulator;

Observations observations_of(const measurements::MeasuredRecord& data, double holdout_fraction, double step) {
  Observations o;
  o.t = data.t;
  auto add = [&](const std::vector<double>& column, int which) {
    const double floor = 1e-7 * std::max(std::fabs(step), 1.0);  // a noise-free record still has a scale
    o.columns.push_back(column);
    o.which.push_back(which);
    o.sigma.push_back(std::max(estimate_noise(column), floor));
  };
  add(data.theta_out, 0);
  if (data.theta_motor) add(*data.theta_motor, 1);
  if (data.theta_load) add(*data.theta_load, 2);
  // Ten blocks; with the default 0.3 held out, the third, sixth and ninth (every k-th block,
  // k = round(1/fraction)), so the held-out samples see the transient and the end alike.
  const std::size_t n = data.size();
  const int every = holdout_fraction > 0 ? std::max(2, static_cast<int>(std::lround(1 / holdout_fraction))) : 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int block = static_cast<int>(10 * i / n);
    (every > 0 && block % every == every - 1 ? o.holdout_indices : o.fit_indices).push_back(i);
    o.all_indices.push_back(i);
  }
  if (o.holdout_indices.empty()) o.holdout_indices = o.fit_indices;
  return o;
}

// The scores of one model against the observations (weighted residuals).
struct Scores {
  double sse_fit = 0, sse_holdout = 0, sse = 0;
  std::size_t n_fit = 0, n_holdout = 0, n = 0;
  double rms_theta_out = 0;  ///< unweighted, whole record
  double rms_fit() const { return std::sqrt(sse_fit / std::max<std::size_t>(1, n_fit)); }
  double rms_holdout() const { return std::sqrt(sse_holdout / std::max<std::size_t>(1, n_holdout)); }
  double rms() const { return std::sqrt(sse / std::max<std::size_t>(1, n)); }
  double bic(int parameters) const {
    return n_fit * std::log(std::max(sse_fit, 1e-300) / n_fit) + parameters * std::log(static_cast<double>(n_fit));
  }
};

Scores score(const Observations& o, const std::vector<std::vector<double>>& traces) {
  Scores s;
  const std::vector<double> fit = detail::residuals(o, traces, o.fit_indices);
  const std::vector<double> held = detail::residuals(o, traces, o.holdout_indices);
  s.sse_fit = detail::sum_of_squares(fit);
  s.sse_holdout = detail::sum_of_squares(held);
  s.sse = s.sse_fit + s.sse_holdout;
  s.n_fit = fit.size();
  s.n_holdout = held.size();
  s.n = s.n_fit + s.n_holdout;
  double sum = 0;
  for (std::size_t i = 0; i < o.size(); ++i) sum += (o.columns[0][i] - traces[0][i]) * (o.columns[0][i] - traces[0][i]);
  s.rms_theta_out = std::sqrt(sum / o.size());
  return s;
}

// A named effect's parameters as reported (the compliance's damping from its ratio).
std::vector<Parameter> reported(const EffectCandidate& c, const detail::Fit& fit, const ModelPoint& point) {
  std::vector<Parameter> out;
  for (std::size_t i = 0; i < c.ranges.size(); ++i)
    out.push_back({c.ranges[i].name, fit.values[i], fit.uncertainty.empty() ? NAN : fit.uncertainty[i]});
  if (c.effect == "compliance") {
    const double ratio = fit.values[1], ratio_sigma = out[1].uncertainty;
    const double scale = point.e.mesh_damping / ratio;
    out[1] = {"damping", point.e.mesh_damping, ratio_sigma * scale};
  }
  return out;
}

double first_departure(const Observations& o, const std::vector<double>& model);

struct Trial {
  EffectCandidate candidate;
  detail::Fit fit;
  Candidate result;
  ModelPoint point;
};

// Every candidate of a round, fitted on the first part and scored (threads over candidates).
std::vector<Trial> round_of(Simulator& simulator, const Observations& o, const ModelPoint& current, int current_k,
                            const Scores& current_scores, double departure, const std::vector<std::string>& effects,
                            double step, const DiscrepancyOptions& options) {
  std::vector<Trial> trials(effects.size());
  std::atomic<std::size_t> next{0};
  std::mutex progress_mutex;
  long finished = 0;
  auto report = [&] {
    if (!options.progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    options.progress(++finished, static_cast<long>(trials.size()));
  };
  auto work = [&] {
    for (std::size_t i = next++; i < trials.size(); i = next++) {
      const auto started = std::chrono::steady_clock::now();
      Trial& t = trials[i];
      t.candidate = detail::candidate_for(effects[i], current, step);
      t.result.effect = effects[i];
      try {
        t.fit = detail::fit_candidate(simulator, o, current, t.candidate, false, nullptr, options.candidate_work, departure);
        if (t.fit.budget_exhausted)
          t.result.failure = "its fit reached the work budget of " + std::to_string(options.candidate_work) + " (1000 per simulation plus its events)";
      } catch (const std::exception& error) {  // a candidate that cannot be simulated is a failed candidate
        t.fit = detail::Fit{};
        t.result.failure = error.what();
      }
      t.result.simulations = t.fit.simulations;
      if (t.fit.ok) {
        t.point = t.candidate.apply(current, t.fit.values);
        const auto traces = simulator.traces(t.point, o.size());
        if (traces) {
          const Scores s = score(o, *traces);
          ++t.result.simulations;
          t.result.parameters = reported(t.candidate, t.fit, t.point);
          t.result.rms = s.rms_theta_out;
          t.result.rms_fit = s.rms_fit();
          t.result.rms_holdout = s.rms_holdout();
          const int k = current_k + static_cast<int>(t.candidate.ranges.size());
          t.result.bic = s.bic(k);
          t.result.delta_bic = t.result.bic - current_scores.bic(current_k);
          // Decisive on both: the BIC, and the held-out samples — they must shrink, or, when the
          // model already meets them at the noise level, at least not get worse.
          const double held = current_scores.rms_holdout();
          const bool confirmed = t.result.rms_holdout < options.decisive_holdout * held ||
                                 (held <= options.noise_level && t.result.rms_holdout <= 1.02 * held);
          // A parameter pinned at the edge of its range says the effect, as parameterised, cannot be
          // told from its limit (a mesh at the stiffest end is a rigid gear): not decisive.
          const bool at_edge = std::any_of(t.fit.u.begin(), t.fit.u.end(), [](double u) { return u < 1e-3 || u > 1 - 1e-3; });
          t.result.at_range_edge = at_edge;
          t.result.decisive = t.result.delta_bic < -options.decisive_bic && confirmed && !at_edge;
        } else {
          t.fit.ok = false;
        }
      }
      if (!t.fit.ok) t.result.bic = t.result.rms = t.result.rms_holdout = INFINITY;
      t.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      report();
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < std::max(1, options.threads); ++k) pool.emplace_back(work);
  work();
  for (std::thread& th : pool) th.join();
  std::stable_sort(trials.begin(), trials.end(), [](const Trial& a, const Trial& b) { return a.result.bic < b.result.bic; });
  return trials;
}

// All named effects refitted together on the whole record, from their current values.
ModelPoint joint_refit(Simulator& simulator, const Observations& o, const ModelPoint& nominal,
                       std::vector<Candidate>& named, std::vector<EffectCandidate>& candidates, double step) {
  EffectCandidate joint;
  joint.effect = "joint";
  std::vector<double> start;
  std::vector<std::size_t> sizes;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = 0; j < candidates[i].ranges.size(); ++j) {
      const detail::ParameterRange& r = candidates[i].ranges[j];
      joint.ranges.push_back(r);
      double value = named[i].parameters[j].value;
      if (candidates[i].effect == "compliance" && j == 1)  // the fit's coordinate is the damping ratio
        value = value / (2 * std::sqrt(named[i].parameters[0].value * nominal.p.Jm * nominal.p.JL / (nominal.p.Jm + nominal.p.JL)));
      const double u = r.logarithmic ? std::log(value / r.low) / std::log(r.high / r.low) : (value - r.low) / (r.high - r.low);
      start.push_back(std::min(1.0, std::max(0.0, u)));
    }
    sizes.push_back(candidates[i].ranges.size());
  }
  joint.apply = [&candidates, sizes](const ModelPoint& base, const std::vector<double>& values) {
    ModelPoint m = base;
    std::size_t at = 0;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      m = candidates[i].apply(m, std::vector<double>(values.begin() + at, values.begin() + at + sizes[i]));
      at += sizes[i];
    }
    return m;
  };
  const detail::Fit fit = detail::fit_candidate(simulator, o, nominal, joint, true, &start);
  if (!fit.ok) return joint.apply(nominal, [&] {
    std::vector<double> v;
    for (const Candidate& c : named)
      for (const Parameter& p : c.parameters) v.push_back(p.value);
    return v;
  }());
  const ModelPoint point = joint.apply(nominal, fit.values);
  std::size_t at = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    detail::Fit part;
    part.values.assign(fit.values.begin() + at, fit.values.begin() + at + sizes[i]);
    part.uncertainty.assign(fit.uncertainty.begin() + at, fit.uncertainty.begin() + at + sizes[i]);
    named[i].parameters = reported(candidates[i], part, point);
    named[i].simulations += fit.simulations;
    at += sizes[i];
  }
  (void)step;
  return point;
}

std::vector<Region> regions_of(const std::vector<numeric::SimulationEvent>& events, const Observations& o,
                               const std::vector<double>& nominal, const std::vector<double>& corrected,
                               const numeric::Effects& effects) {
  std::vector<Region> out;
  std::vector<std::pair<double, std::string>> starts{{-INFINITY, "contact"}};
  for (const numeric::SimulationEvent& e : events) {
    std::string kind = e.after.in_contact ? (effects.compliant() ? "mesh" : "contact") : "free";
    if (e.kind == numeric::EventKind::Rest) kind = "rest";
    if (e.after.motor_stuck && e.after.load_stuck) kind = "rest";
    if (kind != starts.back().second) starts.push_back({e.t, kind});
  }
  for (std::size_t k = 0; k < starts.size(); ++k) {
    Region r;
    r.kind = starts[k].second;
    const double from = starts[k].first, to = k + 1 < starts.size() ? starts[k + 1].first : INFINITY;
    double before = 0, after = 0;
    r.t_start = INFINITY;
    for (std::size_t i = 0; i < o.size(); ++i) {
      if (!(o.t[i] >= from && o.t[i] < to)) continue;
      r.t_start = std::min(r.t_start, o.t[i]);
      r.t_end = o.t[i];
      ++r.samples;
      before += (o.columns[0][i] - nominal[i]) * (o.columns[0][i] - nominal[i]);
      after += (o.columns[0][i] - corrected[i]) * (o.columns[0][i] - corrected[i]);
    }
    if (r.samples == 0) continue;
    r.rms_before = std::sqrt(before / r.samples);
    r.rms_after = std::sqrt(after / r.samples);
    out.push_back(r);
  }
  return out;
}

double first_departure(const Observations& o, const std::vector<double>& model) {
  int run = 0;
  for (std::size_t i = 0; i < o.size(); ++i) {
    run = std::fabs(o.columns[0][i] - model[i]) > 3 * o.sigma[0] ? run + 1 : 0;
    if (run == 5) return o.t[i - 4];
  }
  return NAN;
}

/// The shortest decimal that reads back as `value` (for messages).
std::string shortest_text(double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return error == std::errc() ? std::string(buffer, end) : "?";
}

/// A step record is sampled: no interval longer than `largest_gap_intervals` median intervals
/// (a gap the record does not see is motion the model would have to be simulated through
/// unobserved, and the event cap of a long simulation is not a statement about the data).
void require_sampled(const measurements::MeasuredRecord& data) {
  constexpr double largest_gap_intervals = 100;
  std::vector<double> intervals(data.size() - 1);
  for (std::size_t i = 1; i < data.size(); ++i) intervals[i - 1] = data.t[i] - data.t[i - 1];
  std::vector<double> sorted = intervals;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < intervals.size(); ++i)
    if (intervals[i] > largest_gap_intervals * median)
      throw measurements::sample_error(
          data, i + 1, "t",
          "a gap of " + shortest_text(intervals[i]) + " s after t = " + shortest_text(data.t[i]) +
              " s, more than 100 times the median sample interval " + shortest_text(median) +
              " s: a step record is sampled without gaps (docs/discrepancy.md)");
}

/// The step's time on the record's clock ([experiment] step_time, absent: 0), checked against
/// the record (at least 10 samples, no gap: require_sampled): it must start at most one
/// sample interval after the step (it sees the response from its start) and end after it.
double checked_step_time(const model::CaseSpec& spec, const measurements::MeasuredRecord& data) {
  if (data.size() < 10) throw std::invalid_argument("the record has fewer than 10 samples");
  require_sampled(data);
  const double step_time =
      spec.experiment && spec.experiment->step_time ? model::to_double(*spec.experiment->step_time) : 0.0;
  const double first = data.t.front(), interval = data.t[1] - data.t[0];
  const std::string where = "the step at t = " + shortest_text(step_time) + " s ([experiment] step_time" +
                            (spec.experiment && spec.experiment->step_time ? "" : ", absent: 0") + ")";
  if (first - step_time > interval)
    throw measurements::sample_error(data, 0, "t",
                                     "the record starts at t = " + shortest_text(first) + " s, after " + where +
                                         ": it does not cover the step (give the step's time as [experiment] step_time)");
  if (!(data.t.back() > step_time))
    throw measurements::sample_error(data, data.size() - 1, "t",
                                     "the record ends at t = " + shortest_text(data.t.back()) + " s, before " +
                                         where + ": it does not cover the step");
  return step_time;
}

}  // namespace

DiscrepancyResult find_discrepancy(const model::CaseSpec& spec, const measurements::MeasuredRecord& data, double step,
                                   const DiscrepancyOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (step == 0) throw std::invalid_argument("the step is 0: there is no experiment to compare with");
  const double step_time = checked_step_time(spec, data);
  DiscrepancyResult result;
  const Observations o = observations_of(data, options.holdout_fraction, step);
  ModelPoint nominal{numeric::parameters_of(spec), numeric::effects_of(spec)};
  Simulator simulator(o, step, data.t.back(), step_time);
  simulator.prepare({nominal});
  std::vector<numeric::SimulationEvent> nominal_events;
  const auto nominal_traces = simulator.traces(nominal, o.size(), &nominal_events);
  if (!nominal_traces) throw std::runtime_error("the nominal model could not be simulated over the record");
  result.noise = o.sigma[0];
  result.t = o.t;
  result.theta_measured = o.columns[0];
  result.theta_nominal = (*nominal_traces)[0];
  result.nominal_events = nominal_events;
  Scores current_scores = score(o, *nominal_traces);
  result.rms_before = current_scores.rms_theta_out;
  result.gap_before = current_scores.rms();
  result.first_departure = first_departure(o, result.theta_nominal);

  ModelPoint current = nominal;
  int current_k = 0;
  std::vector<EffectCandidate> named_candidates;
  std::vector<std::string> remaining = options.candidates;
  while (current_scores.rms() > options.noise_level && static_cast<int>(result.effects.size()) < options.max_effects &&
         !remaining.empty()) {
    const auto current_traces = simulator.traces(current, o.size());
    const double departure = current_traces ? first_departure(o, (*current_traces)[0]) : NAN;
    std::vector<Trial> trials =
        round_of(simulator, o, current, current_k, current_scores, departure, remaining, step, options);
    std::vector<Candidate> round;
    for (const Trial& t : trials) round.push_back(t.result);
    result.rounds.push_back(round);
    const auto winner = std::find_if(trials.begin(), trials.end(), [](const Trial& t) { return t.result.decisive; });
    if (winner == trials.end()) break;
    // Refit the winner on the whole record, from its fit on the first part: its uncertainty.
    const detail::Fit whole = detail::fit_candidate(simulator, o, current, winner->candidate, true, &winner->fit.u);
    Candidate named = winner->result;
    ModelPoint point = winner->point;
    if (whole.ok) {
      point = winner->candidate.apply(current, whole.values);
      named.parameters = reported(winner->candidate, whole, point);
      named.simulations += whole.simulations;
    }
    result.effects.push_back(named);
    named_candidates.push_back(winner->candidate);
    current = point;
    current_k += static_cast<int>(winner->candidate.ranges.size());
    remaining.erase(std::remove(remaining.begin(), remaining.end(), winner->result.effect), remaining.end());
    const auto traces = simulator.traces(current, o.size());
    if (!traces) break;
    current_scores = score(o, *traces);
  }
  if (result.effects.size() > 1) current = joint_refit(simulator, o, nominal, result.effects, named_candidates, step);

  std::vector<numeric::SimulationEvent> corrected_events;
  const auto corrected = simulator.traces(current, o.size(), &corrected_events);
  result.theta_corrected = corrected ? (*corrected)[0] : result.theta_nominal;
  result.corrected_events = corrected_events;
  result.rms_after = corrected ? score(o, *corrected).rms_theta_out : result.rms_before;
  result.gap_after = corrected ? score(o, *corrected).rms() : result.gap_before;
  result.parameters = current.p;
  result.corrected_effects = current.e;
  const double theta_R = nominal.p.theta_R;
  result.measured = features_of(o.t, result.theta_measured, theta_R, step);
  result.nominal = features_of(o.t, result.theta_nominal, theta_R, step);
  result.corrected = features_of(o.t, result.theta_corrected, theta_R, step);
  result.regions = regions_of(nominal_events, o, result.theta_nominal, result.theta_corrected, nominal.e);
  if (!result.effects.empty())
    result.status = Status::EffectFound;
  else if (score(o, *nominal_traces).rms() <= options.noise_level)
    result.status = Status::NoDiscrepancy;
  else
    result.status = Status::Unexplained;
  result.simulations = simulator.simulations();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace backlash::discrepancy
