// Simulating model points on the record's grid, and fitting a candidate effect:
// a bracketing scan of its range, then Ceres's Levenberg–Marquardt (central
// differences: each residual evaluation is one simulation) from the best points,
// with the covariance of the final fit.
#include "internal.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace backlash::discrepancy::detail {

// ------------------------------------------------------------------ Simulator

Simulator::Simulator(const Observations& data, double step, double t_end) : data_(data), step_(step), t_end_(t_end) {}

void Simulator::prepare(const std::vector<ModelPoint>& points) {
  std::vector<std::pair<numeric::Parameters, numeric::Effects>> samples;
  for (const ModelPoint& m : points) samples.push_back({m.p, m.e});
  family_.validate_samples(samples);
}

std::optional<std::vector<std::vector<double>>> Simulator::traces(const ModelPoint& m, std::size_t samples,
                                                                  std::vector<numeric::SimulationEvent>* events) {
  std::optional<numeric::ValidatedEffectModel> model = family_.at(m.p, m.e);
  if (!model) {
    prepare({m});
    model = family_.at(m.p, m.e);
    if (!model) return std::nullopt;
  }
  numeric::SimulationOptions o;
  samples = std::min(samples, data_.size());
  o.sample_times.assign(data_.t.begin(), data_.t.begin() + static_cast<std::ptrdiff_t>(samples));
  o.t_end = std::min(t_end_, o.sample_times.back()) + 1e-9;
  o.general_engine = true;
  o.max_events = 200000;
  ++simulations_;
  const numeric::SimulationResult r = numeric::simulate_effects_step(*model, step_, o);
  if (r.status == numeric::SimulationStatus::NonFinite || r.status == numeric::SimulationStatus::EventLimit ||
      r.status == numeric::SimulationStatus::Chattering || r.samples.size() != samples)
    return std::nullopt;
  std::vector<std::vector<double>> out(data_.which.size(), std::vector<double>(samples));
  for (std::size_t c = 0; c < data_.which.size(); ++c)
    for (std::size_t i = 0; i < samples; ++i) {
      const numeric::TrajectorySample& s = r.samples[i];
      out[c][i] = data_.which[c] == 0 ? s.theta_o : data_.which[c] == 1 ? s.theta_m : s.theta_L;
    }
  if (events) *events = r.events;
  return out;
}

std::vector<double> residuals(const Observations& data, const std::vector<std::vector<double>>& traces, std::size_t from,
                              std::size_t to) {
  std::vector<double> r;
  r.reserve((to - from) * data.columns.size());
  for (std::size_t c = 0; c < data.columns.size(); ++c)
    for (std::size_t i = from; i < to; ++i) r.push_back((data.columns[c][i] - traces[c][i]) / data.sigma[c]);
  return r;
}

double sum_of_squares(const std::vector<double>& r) {
  return std::inner_product(r.begin(), r.end(), r.begin(), 0.0);
}

// ------------------------------------------------------------------ the fit

namespace {

struct Objective {
  Simulator& simulator;
  const Observations& data;
  const ModelPoint& base;
  const EffectCandidate& candidate;
  std::size_t samples;
  std::atomic<int>& calls;  ///< simulations of this fit

  ModelPoint point(const double* u) const {
    std::vector<double> values;
    for (std::size_t k = 0; k < candidate.ranges.size(); ++k) values.push_back(candidate.ranges[k].value(u[k]));
    return candidate.apply(base, values);
  }
  std::optional<std::vector<double>> residuals_at(const double* u) const {
    ++calls;
    const auto traces = simulator.traces(point(u), samples);
    if (!traces) return std::nullopt;
    return residuals(data, *traces, 0, samples);
  }
};

// Ceres's view of the objective: the weighted residuals of one simulation.
struct CostFunctor {
  const Objective* objective;
  bool operator()(double const* const* parameters, double* out) const {
    const auto r = objective->residuals_at(parameters[0]);
    if (!r) return false;
    std::copy(r->begin(), r->end(), out);
    return true;
  }
};

struct Solved {
  std::vector<double> u;
  double sse = INFINITY;
  std::vector<double> covariance;  ///< of u (k × k), scaled by the residual variance
};

Solved solve(const Objective& objective, std::vector<double> u, bool with_covariance) {
  const int k = static_cast<int>(u.size());
  const int n = static_cast<int>(objective.samples * objective.data.columns.size());
  auto* cost = new ceres::DynamicNumericDiffCostFunction<CostFunctor, ceres::CENTRAL>(new CostFunctor{&objective});
  cost->AddParameterBlock(k);
  cost->SetNumResiduals(n);
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, u.data());
  for (int i = 0; i < k; ++i) {
    problem.SetParameterLowerBound(u.data(), i, 0.0);
    problem.SetParameterUpperBound(u.data(), i, 1.0);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 25;
  options.function_tolerance = 1e-10;
  options.parameter_tolerance = 1e-9;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Solved out;
  out.u = u;
  out.sse = 2 * summary.final_cost;
  if (with_covariance && n > k) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.null_space_rank = -1;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> blocks{{u.data(), u.data()}};
    if (covariance.Compute(blocks, &problem)) {
      out.covariance.assign(static_cast<std::size_t>(k * k), 0.0);
      covariance.GetCovarianceBlock(u.data(), u.data(), out.covariance.data());
      const double variance = out.sse / (n - k);
      for (double& c : out.covariance) c *= variance;
    }
  }
  return out;
}

}  // namespace

Fit fit_candidate(Simulator& simulator, const Observations& data, const ModelPoint& base, const EffectCandidate& c,
                  bool whole_record, const std::vector<double>* start_u) {
  Fit fit;
  std::atomic<int> calls{0};
  const std::size_t samples = whole_record ? data.size() : data.fit_samples;
  const Objective objective{simulator, data, base, c, samples, calls};
  // The family validated over the candidate's whole range (its corners).
  std::vector<ModelPoint> corners;
  const std::size_t k = c.ranges.size();
  for (int mask = 0; mask < (1 << k); ++mask) {
    std::vector<double> values;
    for (std::size_t i = 0; i < k; ++i) values.push_back(c.ranges[i].value((mask >> i) & 1 ? 1.0 : 0.0));
    corners.push_back(c.apply(base, values));
  }
  simulator.prepare(corners);
  // Starting points: the given one, or the best two of the scan (distinct cells).
  std::vector<std::vector<double>> starts;
  if (start_u) {
    starts.push_back(*start_u);
  } else {
    std::vector<std::pair<double, std::vector<double>>> scored;
    for (const std::vector<double>& u : c.scan()) {
      const auto r = objective.residuals_at(u.data());
      if (r) scored.push_back({sum_of_squares(*r), u});
    }
    std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [sse, u] : scored) {
      if (starts.size() >= 2) break;
      bool distinct = true;
      for (const auto& s : starts)
        for (std::size_t i = 0; i < k; ++i) distinct = distinct && std::fabs(s[i] - u[i]) > 0.1;
      if (starts.empty() || distinct) starts.push_back(u);
    }
  }
  Solved best;
  for (const std::vector<double>& u : starts) {
    Solved s = solve(objective, u, whole_record);
    if (s.sse < best.sse) best = std::move(s);
  }
  fit.simulations = calls.load();
  if (!std::isfinite(best.sse)) return fit;
  fit.ok = true;
  fit.u = best.u;
  fit.sse_fit = best.sse;
  for (std::size_t i = 0; i < k; ++i) {
    fit.values.push_back(c.ranges[i].value(best.u[i]));
    const double var = best.covariance.empty() ? NAN : best.covariance[i * k + i];
    fit.uncertainty.push_back(std::fabs(c.ranges[i].derivative(best.u[i])) * std::sqrt(var));
  }
  return fit;
}

}  // namespace backlash::discrepancy::detail
