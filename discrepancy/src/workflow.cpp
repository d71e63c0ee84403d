// The discrepancy workflow (discrepancy.hpp): compare, localise, name, add.
#include "internal.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
    case Status::ParametersCorrected: return "parameters_corrected";
    case Status::PartlyExplained: return "partly_explained";
    case Status::Ambiguous: return "ambiguous";
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

// The measured columns (their σ the white-noise rule on the record, until the residual's noise
// replaces it), an encoder's quantum per column.
Observations observations_of(const measurements::MeasuredRecord& data, double step) {
  Observations o;
  o.t = data.t;
  o.floor = 1e-7 * std::max(std::fabs(step), 1.0);  // a noise-free record still has a scale
  auto add = [&](const std::vector<double>& column, int which) {
    o.columns.push_back(column);
    o.which.push_back(which);
    o.quantum.push_back(detail::quantum_of(column));
    o.sigma.push_back(std::max({estimate_noise(column), o.floor, o.quantum.back() / std::sqrt(12.0)}));
  };
  add(data.theta_out, 0);
  if (data.theta_motor) add(*data.theta_motor, 1);
  if (data.theta_load) add(*data.theta_load, 2);
  o.skip.assign(data.size(), 0);
  return o;
}

// The samples fitted and held out: ten blocks; with the default 0.3 held out, the third, sixth
// and ninth (every k-th block, k = round(1/fraction)), so the held-out samples see the transient
// and the end alike.  Samples flagged as spikes are in neither.
void split_blocks(Observations& o, double holdout_fraction) {
  const std::size_t n = o.size();
  o.fit_indices.clear(), o.holdout_indices.clear(), o.all_indices.clear();
  const int every = holdout_fraction > 0 ? std::max(2, static_cast<int>(std::lround(1 / holdout_fraction))) : 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (o.skip[i]) continue;
    const int block = static_cast<int>(10 * i / n);
    (every > 0 && block % every == every - 1 ? o.holdout_indices : o.fit_indices).push_back(i);
    o.all_indices.push_back(i);
  }
  if (o.holdout_indices.empty()) o.holdout_indices = o.fit_indices;
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
/// the record (at least 10 samples, no gap: require_sampled): it must end after the step, and
/// start at most one sample interval after it — or, a record that started late, within a tenth
/// of its span after it (the model is simulated from the step and compared from the first
/// sample); later than that the clocks disagree.
double checked_step_time(const model::CaseSpec& spec, const measurements::MeasuredRecord& data) {
  if (data.size() < 10) throw std::invalid_argument("the record has fewer than 10 samples");
  require_sampled(data);
  const double step_time =
      spec.experiment && spec.experiment->step_time ? model::to_double(*spec.experiment->step_time) : 0.0;
  const double first = data.t.front(), interval = data.t[1] - data.t[0];
  const std::string where = "the step at t = " + shortest_text(step_time) + " s ([experiment] step_time" +
                            (spec.experiment && spec.experiment->step_time ? "" : ", absent: 0") + ")";
  if (first - step_time > interval && first - step_time > 0.1 * (data.t.back() - step_time))
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

namespace {

// The nominal model's residual read for its noise: spikes flagged (and left out of every index
// list), then every column's level and theta_out's correlation.
void read_noise(Observations& o, const std::vector<std::vector<double>>& nominal, double holdout_fraction) {
  for (std::size_t c = 0; c < o.columns.size(); ++c) {
    std::vector<double> r(o.size());
    for (std::size_t i = 0; i < o.size(); ++i) r[i] = o.columns[c][i] - nominal[c][i];
    const detail::NoiseFit white = detail::noise_of_residual(r, std::vector<char>(o.size(), 0), o.quantum[c], o.floor);
    detail::flag_spikes(r, white.white_sigma, o.skip);
  }
  split_blocks(o, holdout_fraction);
  detail::reestimate_noise(o, nominal);
}

// The outliers listed: every flagged sample, its distance from its nearest unflagged neighbours in σ.
std::vector<Outlier> outliers_of(const Observations& o, const std::vector<std::vector<double>>& model) {
  static const char* names[] = {"theta_out", "theta_motor", "theta_load"};
  std::vector<Outlier> out;
  for (std::size_t i = 1; i + 1 < o.size(); ++i) {
    if (!o.skip[i]) continue;
    for (std::size_t c = 0; c < o.columns.size(); ++c) {
      const auto r = [&](std::size_t k) { return o.columns[c][k] - model[c][k]; };
      std::size_t before = i - 1, after = i + 1;  // the nearest samples not flagged (a spike's twin is)
      while (before > 0 && o.skip[before]) --before;
      while (after + 1 < o.size() && o.skip[after]) ++after;
      const double size = (r(i) - 0.5 * (r(before) + r(after))) / o.sigma[c];
      if (c == 0 || std::fabs(size) > std::fabs(out.back().size)) {
        if (c > 0) out.pop_back();
        out.push_back({i, o.t[i], names[o.which[c]], size});
      }
    }
  }
  return out;
}

// The nominal parameters corrected, from the candidates named (backlash_size as "backlash").
std::vector<ParameterCorrection> corrections_of(const std::vector<detail::Named>& named, const numeric::Parameters& nominal,
                                                const model::CaseSpec& spec) {
  std::vector<ParameterCorrection> out;
  for (const detail::Named& n : named) {
    if (!is_parameter_correction(n.result.effect)) continue;
    ParameterCorrection c;
    c.key = n.result.effect == "backlash_size" ? "backlash" : n.result.effect;
    c.nominal = detail::nominal_value(c.key, nominal);
    c.fitted = n.result.parameters.front().value;
    c.uncertainty = n.result.parameters.front().uncertainty;
    c.ratio = c.nominal != 0 ? c.fitted / c.nominal : NAN;
    c.given_free = std::find(spec.fit_free.begin(), spec.fit_free.end(), c.key) != spec.fit_free.end();
    out.push_back(c);
  }
  return out;
}

// The candidates the search tries: the effects asked for, and the nominal parameters but the
// fixed ones and those fitted first ([fit] free: "backlash" is the candidate backlash_size).
std::vector<std::string> search_names(const model::CaseSpec& spec, const DiscrepancyOptions& options,
                                      std::vector<std::string>& free) {
  auto candidate_name = [](const std::string& key) { return key == "backlash" ? std::string("backlash_size") : key; };
  std::vector<std::string> fixed;
  for (const std::string& key : spec.fit_fixed) fixed.push_back(candidate_name(key));
  for (const std::string& key : spec.fit_free) free.push_back(candidate_name(key));
  std::vector<std::string> names;
  for (const std::string& name : options.candidates)
    if (std::find(fixed.begin(), fixed.end(), name) == fixed.end()) names.push_back(name);
  for (const std::string& name : options.parameters)
    if (std::find(fixed.begin(), fixed.end(), name) == fixed.end() && std::find(names.begin(), names.end(), name) == names.end())
      names.push_back(name);
  return names;
}

// The status (docs/discrepancy.md, "Statuses"), from what was named and what remains.
Status status_of(const detail::Search& s, bool at_noise, bool nominal_at_noise) {
  if (s.named.empty()) return nominal_at_noise ? Status::NoDiscrepancy : Status::Unexplained;
  if (!at_noise) return Status::PartlyExplained;
  if (!s.alike.empty()) return Status::Ambiguous;
  const bool effect = std::any_of(s.named.begin(), s.named.end(),
                                  [](const detail::Named& n) { return !is_parameter_correction(n.result.effect); });
  return effect ? Status::EffectFound : Status::ParametersCorrected;
}

}  // namespace

namespace detail {

double first_departure(const Observations& o, const std::vector<double>& model) {
  int run = 0;
  for (std::size_t i = 0; i < o.size(); ++i) {
    run = std::fabs(o.columns[0][i] - model[i]) > 3 * o.sigma[0] ? run + 1 : 0;
    if (run == 5) return o.t[i - 4];
  }
  return NAN;
}

NoiseFit reestimate_noise(Observations& o, const std::vector<std::vector<double>>& traces) {
  NoiseFit first;
  for (std::size_t c = 0; c < o.columns.size(); ++c) {
    std::vector<double> r(o.size());
    for (std::size_t i = 0; i < o.size(); ++i) r[i] = o.columns[c][i] - traces[c][i];
    const NoiseFit fit = noise_of_residual(r, o.skip, o.quantum[c], o.floor);
    o.sigma[c] = fit.sigma;
    if (c == 0) first = fit;
  }
  o.tau_int = first.tau_int;
  return first;
}

}  // namespace detail

namespace {

// The result's traces, features, regions and gaps, from the nominal and the corrected model.
// `robust_gap_after`: the corrected model's gap as the noise-level test reads it (Scores::robust_rms).
void describe(DiscrepancyResult& result, Simulator& simulator, const Observations& o, const ModelPoint& nominal,
              const ModelPoint& current, const std::vector<std::vector<double>>& nominal_traces, double step,
              double& robust_gap_after) {
  std::vector<numeric::SimulationEvent> corrected_events;
  const auto corrected = simulator.traces(current, o.size(), &corrected_events);
  result.theta_corrected = corrected ? (*corrected)[0] : result.theta_nominal;
  result.corrected_events = corrected_events;
  const detail::Scores before = detail::score(o, nominal_traces);
  result.rms_before = before.rms_theta_out;
  result.gap_before = before.rms();
  result.rms_after = corrected ? detail::score(o, *corrected).rms_theta_out : result.rms_before;
  result.gap_after = corrected ? detail::score(o, *corrected).rms() : result.gap_before;
  robust_gap_after = corrected ? detail::score(o, *corrected).robust_rms() : before.robust_rms();
  result.first_departure = detail::first_departure(o, result.theta_nominal);
  result.remaining_departure = detail::first_departure(o, result.theta_corrected);
  result.parameters = current.p;
  result.corrected_effects = current.e;
  const double theta_R = nominal.p.theta_R;
  result.measured = features_of(o.t, result.theta_measured, theta_R, step);
  result.nominal = features_of(o.t, result.theta_nominal, theta_R, step);
  result.corrected = features_of(o.t, result.theta_corrected, theta_R, step);
  result.regions = regions_of(result.nominal_events, o, result.theta_nominal, result.theta_corrected, nominal.e);
}

}  // namespace

DiscrepancyResult find_discrepancy(const model::CaseSpec& spec, const measurements::MeasuredRecord& data, double step,
                                   const DiscrepancyOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (step == 0) throw std::invalid_argument("the step is 0: there is no experiment to compare with");
  const double step_time = checked_step_time(spec, data);
  DiscrepancyResult result;
  Observations o = observations_of(data, step);
  const ModelPoint nominal{numeric::parameters_of(spec), numeric::effects_of(spec)};
  Simulator simulator(o, step, data.t.back(), step_time);
  simulator.prepare({nominal});
  const auto nominal_traces = simulator.traces(nominal, o.size(), &result.nominal_events);
  if (!nominal_traces) throw std::runtime_error("the nominal model could not be simulated over the record");
  read_noise(o, *nominal_traces, options.holdout_fraction);
  std::vector<std::string> free;
  const std::vector<std::string> names = search_names(spec, options, free);
  simulator.set_budget(options.total_work);
  detail::Search s{simulator, o, nominal, step, options, nominal, {}, {}, {}, {}, {}};
  s.rescore();
  const bool nominal_at_noise = s.scores.robust_rms() <= detail::at_noise_level(o, options.noise_level);
  detail::fit_free_parameters(s, free);
  detail::run_search(s, names);
  if (simulator.budget_reached())
    result.reason = "the work budget of " + std::to_string(options.total_work) +
                    " (1000 per simulation plus its events, more for a delayed model) was reached: the search stopped with what it had";
  // The noise as the corrected model leaves it, and the gaps in its units.
  const auto final_traces = simulator.traces(s.current, o.size());
  const detail::NoiseFit noise = detail::reestimate_noise(o, final_traces ? *final_traces : *nominal_traces);
  result.noise = o.sigma[0];
  result.noise_estimate = {noise.sigma, noise.white_sigma, noise.a, noise.tau_int,
                           static_cast<double>(o.fit_indices.size()) / noise.tau_int, detail::at_noise_level(o, options.noise_level)};
  result.t = o.t;
  result.theta_measured = o.columns[0];
  result.theta_nominal = (*nominal_traces)[0];
  double robust_gap_after = 0;
  describe(result, simulator, o, nominal, s.current, *nominal_traces, step, robust_gap_after);
  result.outliers = outliers_of(o, *nominal_traces);
  for (const detail::Named& n : s.named)
    if (!is_parameter_correction(n.result.effect) || n.result.effect == "backlash_size") result.effects.push_back(n.result);
  result.parameter_corrections = corrections_of(s.named, nominal.p, spec);
  result.rounds = s.rounds;
  result.alternatives = s.alike;
  result.distinguishing_experiment = s.experiment;
  result.status = status_of(s, robust_gap_after <= result.noise_estimate.at_noise, nominal_at_noise);
  result.simulations = simulator.simulations();
  result.work = simulator.work();
  if (std::getenv("BACKLASH_DEBUG_FITS"))
    std::fprintf(stderr, "discrepancy: %d simulations, %d of them kept ones, work %ld\n", simulator.simulations(),
                 simulator.cache_hits(), simulator.work());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace backlash::discrepancy
