// Simulating model points on the record's grid, and fitting a candidate effect:
// a bracketing scan of its range, then Ceres's Levenberg–Marquardt (central
// differences: each residual evaluation is one simulation) from the best points,
// with the covariance of the final fit.
#include "internal.hpp"
#include "quiet_ceres.hpp"

#include "backlash/numeric/effects.hpp"

#include <boost/math/tools/minima.hpp>
#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>

namespace backlash::discrepancy::detail {

// ------------------------------------------------------------------ Simulator

Simulator::Simulator(const Observations& data, double step, double t_end, double step_time)
    : data_(data), step_(step), t_end_(t_end), step_time_(step_time) {}

void Simulator::prepare(const std::vector<ModelPoint>& points) {
  std::vector<std::pair<numeric::Parameters, numeric::Effects>> samples;
  // A point inside a box its structure already passed at is not validated again (its sample
  // would not grow the box): every fit prepares its candidate's corners, a joint refit of four
  // parameters sixteen of them, each validated against the odeint reference — most of a search's
  // time when repeated (half of a record's CPU seconds, perf, in odeint's dopri5).
  for (const ModelPoint& m : points)
    if (!family_.at(m.p, m.e)) samples.push_back({m.p, m.e});
  family_.validate_samples(samples);
}

namespace {

/// A model point, a length and a grid as bytes: the key of a kept simulation.
std::string key_of(const ModelPoint& m, std::size_t samples, Simulator::Grid grid) {
  const double p[] = {m.p.Jm, m.p.Fm, m.p.JL, m.p.FL, m.p.K, m.p.theta_R, m.p.backlash,
                      static_cast<double>(m.p.measured_at), static_cast<double>(samples)};
  std::string key(reinterpret_cast<const char*>(p), sizeof p);
  key.append(reinterpret_cast<const char*>(&m.e), sizeof m.e);  // Effects: doubles only
  key.push_back(grid == Simulator::Grid::all ? 'a' : 'f');
  return key;
}

constexpr std::size_t kKeptSimulations = 256;

}  // namespace

std::shared_ptr<const Simulator::Kept> Simulator::recall(const std::string& key) {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (const auto found = cache_.find(key); found != cache_.end()) return found->second;
  const auto held = held_.find(key);
  return held == held_.end() ? nullptr : held->second.lock();
}

Simulator::Held Simulator::hold(const ModelPoint& m, std::size_t samples, Grid grid) {
  samples = std::min(samples, data_.size());
  if (row_count(samples, grid) == samples) grid = Grid::all;  // as traces() keeps it
  std::lock_guard<std::mutex> lock(cache_mutex_);
  std::erase_if(held_, [](const auto& entry) { return entry.second.expired(); });
  for (const std::string& key : {key_of(m, samples, Grid::all), key_of(m, samples, grid)})
    if (const auto found = cache_.find(key); found != cache_.end()) {
      held_[key] = found->second;
      return found->second;
    }
  return nullptr;
}

void Simulator::keep(const std::string& key, std::shared_ptr<const Kept> kept) {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (!cache_.emplace(key, std::move(kept)).second) return;
  cache_order_.push_back(key);
  if (cache_order_.size() > kKeptSimulations) {
    cache_.erase(cache_order_.front());
    cache_order_.pop_front();
  }
}

std::vector<std::size_t> Simulator::rows(std::size_t samples, Grid grid) const {
  std::vector<std::size_t> out;
  if (grid == Grid::fitted) {
    const std::vector<std::size_t>& fitted = data_.fit_indices;
    out.assign(fitted.begin(), std::lower_bound(fitted.begin(), fitted.end(), samples - 1));
  }
  if (grid == Grid::all || out.size() + 1 == samples) {  // every sample below the last: the whole grid
    out.resize(samples);
    std::iota(out.begin(), out.end(), std::size_t{0});
    return out;
  }
  out.push_back(samples - 1);  // the last: where the simulation ends, and a failure before it shows
  return out;
}

std::size_t Simulator::row_count(std::size_t samples, Grid grid) const {
  if (grid == Grid::all) return samples;
  const std::vector<std::size_t>& fitted = data_.fit_indices;
  return static_cast<std::size_t>(std::lower_bound(fitted.begin(), fitted.end(), samples - 1) - fitted.begin()) + 1;
}

// A model point simulated before at this length is not simulated again (a fit's bracket, a
// refit from the same point, a candidate judged after its fit): its work is charged all the same,
// so the budget — a count — does not depend on which thread simulated it first.  A fit's request
// (Grid::fitted) is served by a simulation of the whole grid as well.
Simulator::Traces Simulator::traces(const ModelPoint& m, std::size_t samples, std::vector<numeric::SimulationEvent>* events,
                                    long* cost, Grid grid, std::size_t* event_count) {
  samples = std::min(samples, data_.size());
  if (row_count(samples, grid) == samples) grid = Grid::all;
  std::shared_ptr<const Kept> kept = recall(key_of(m, samples, Grid::all));
  if (!kept && grid == Grid::fitted) kept = recall(key_of(m, samples, grid));
  if (kept) {
    ++simulations_, ++hits_;
    work_ += kept->cost;
  } else {
    auto fresh = std::make_shared<Kept>();
    fresh->traces = simulate(m, samples, *sample_grid(samples, grid), &fresh->events, &fresh->cost);
    if (fresh->cost > 0) keep(key_of(m, samples, grid), fresh);
    kept = std::move(fresh);
  }
  if (events) *events = kept->events;
  if (event_count) *event_count = kept->events.size();
  if (cost) *cost = kept->cost;
  return kept->traces;
}

// The lengths a search asks for are few (a fit's horizons): the last kKeptGrids of them are kept.
std::shared_ptr<const Simulator::SampleGrid> Simulator::sample_grid(std::size_t samples, Grid grid) {
  constexpr std::size_t kKeptGrids = 64;
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (const auto found = grids_.find({samples, grid}); found != grids_.end()) return found->second;
  auto fresh = std::make_shared<SampleGrid>();
  fresh->rows = rows(samples, grid);
  fresh->times.resize(fresh->rows.size());
  for (std::size_t k = 0; k < fresh->rows.size(); ++k)
    fresh->times[k] = data_.t[fresh->rows[k]] - step_time_;  // the model's clock starts at the step
  if (grids_.size() >= kKeptGrids) grids_.clear();  // a grid in use stays with its handle
  grids_.emplace(std::pair{samples, grid}, fresh);
  return fresh;
}

Simulator::Traces Simulator::simulate(const ModelPoint& m, std::size_t samples, const SampleGrid& grid,
                                      std::vector<numeric::SimulationEvent>* events, long* cost) {
  const std::vector<std::size_t>& rows = grid.rows;
  std::optional<numeric::ValidatedEffectModel> model = family_.at(m.p, m.e);
  if (!model) {
    prepare({m});
    model = family_.at(m.p, m.e);
    if (!model) return nullptr;
  }
  numeric::SimulationOptions o;
  o.sample_times = grid.times;
  o.t_end = std::min(t_end_ - step_time_, o.sample_times.back()) + 1e-9;
  o.max_events = 20000;  // a fit's trial point that needs more (a stiff, barely damped mesh) is a failed point
  // The samples go straight into the traces (no list of full trajectory samples: on a long
  // record that list was most of the workflow's memory, per worker thread); the rows not sampled
  // stay NaN.
  auto out = std::make_shared<std::vector<std::vector<double>>>();
  out->reserve(data_.which.size());
  for (std::size_t c = 0; c < data_.which.size(); ++c) out->emplace_back(samples, NAN);  // no column copied
  std::size_t filled = 0;
  auto keep = [&](const numeric::TrajectorySample& s) {
    if (filled < rows.size())
      for (std::size_t c = 0; c < data_.which.size(); ++c)
        (*out)[c][rows[filled]] = data_.which[c] == 0 ? s.theta_o : data_.which[c] == 1 ? s.theta_m : s.theta_L;
    ++filled;
  };
  o.sample_theta_o_only = std::all_of(data_.which.begin(), data_.which.end(), [](int c) { return c == 0; });  // θo alone read
  if (o.sample_theta_o_only && data_.which.size() == 1) {  // one column of θo: keep()'s work without its loop and choice
    o.sample_sink = [column = (*out)[0].data(), row = rows.data(), count = rows.size(), &filled](const numeric::TrajectorySample& s) {
      if (filled < count) column[row[filled]] = s.theta_o;
      ++filled;
    };
  } else {
    o.sample_sink = keep;
  }
  ++simulations_;
  samples_ += static_cast<long>(rows.size());
  numeric::SimulationResult r;
  const auto started = std::chrono::steady_clock::now();
  try {
    r = numeric::simulate_effects_step(*model, step_, o, {.general_engine = true});
  } catch (const std::exception& error) {  // a point the simulation cannot resolve: no trace there
    if (std::getenv("BACKLASH_DEBUG_FITS")) std::fprintf(stderr, "discrepancy: simulation failed (%s): %s\n", m.e.describe().c_str(), error.what());
    return nullptr;
  }
  *cost = this->cost(m, r.events.size());
  if (std::getenv("BACKLASH_DEBUG_COST"))  // calibrating the cost: work against the clock
    std::fprintf(stderr, "cost %ld us %.0f events %zu samples %zu %s\n", *cost,
                 1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), r.events.size(),
                 samples, m.e.describe().c_str());
  work_ += *cost;
  for (const numeric::TrajectorySample& s : r.samples) keep(s);  // a simulator that kept its samples
  *events = std::move(r.events);  // r's are not read again
  for (numeric::SimulationEvent& event : *events) event.t += step_time_;  // on the record's clock
  if (r.status == numeric::SimulationStatus::NonFinite || r.status == numeric::SimulationStatus::EventLimit ||
      r.status == numeric::SimulationStatus::Chattering || filled != rows.size())
    return nullptr;
  return out;
}

long Simulator::cost(const ModelPoint& m, std::size_t events) const {
  // Calibrated against the clock (BACKLASH_DEBUG_COST=1 prints both per simulation; about 0.1–0.3 µs
  // per unit for every kind of model, docs/discrepancy.md "Work budget").  A closed-form model:
  // 1000 plus its events.  A delayed model is integrated numerically: its steps follow the servo's
  // oscillation over the record (a delayed case V over 30 s: about 12 closed-form simulations,
  // 400 per radian) and a compliant mesh's, whose stiff oscillation then dominates (1300 per
  // radian of the mesh: 0.1 s for a mesh of ω ≈ 26/s over 30 s), as with a saturating drive
  // (50 per radian).  A compliant mesh alone is in closed form.  Stribeck friction is integrated
  // (dopri5) wherever a body slips slower than √50·vs: 1000·(vs/v)^1.5 per radian of the servo's
  // oscillation, v the step over the servo period (case V's 30 s record: vs = 0.06·v costs 1.5
  // closed-form simulations, 0.2·v 3, 0.6·v 15).
  const double span = t_end_ - step_time_;
  const double servo = span * 2 * M_PI / numeric::servo_period(m.p);
  const double mesh = m.e.compliant() ? span * std::sqrt(m.e.mesh_stiffness * (m.p.Jm + m.p.JL) / (m.p.Jm * m.p.JL)) : 0.0;
  double work = 1000 + static_cast<double>(events);
  if (m.e.delay > 0) work += 400 * servo + 1300 * mesh;
  else if (m.e.saturating()) work += 50 * mesh;
  const double v = std::fabs(step_) / numeric::servo_period(m.p);
  for (const auto& [level, vs] : {std::pair{m.e.stribeck_motor_static, m.e.stribeck_motor_velocity},
                                  std::pair{m.e.stribeck_load_static, m.e.stribeck_load_velocity}})
    if (level > 0 && std::isfinite(vs)) work += 1000 * std::pow(vs / v, 1.5) * servo;
  return static_cast<long>(std::min(work, 1e15));
}

std::vector<double> residuals(const Observations& data, const std::vector<std::vector<double>>& traces,
                              const std::vector<std::size_t>& indices) {
  std::vector<double> r;
  r.reserve(indices.size() * data.columns.size());
  for (std::size_t c = 0; c < data.columns.size(); ++c)
    for (std::size_t i : indices) r.push_back((data.columns[c][i] - traces[c][i]) / data.sigma[c]);
  return r;
}

double sum_of_squares(const std::vector<double>& r) {
  return std::inner_product(r.begin(), r.end(), r.begin(), 0.0);
}

namespace {
double huber_rho(const ceres::HuberLoss& loss, double r) {
  // ceres::HuberLoss's ρ(s) of s = r²: s inside the scale a, 2a|r| − a² beyond (at a = 3, a
  // residual of 20σ counts 111 instead of 400).
  double rho[3];
  loss.Evaluate(r * r, rho);
  return rho[0];
}
}  // namespace

double robust_sum(const std::vector<double>& r, double scale) {
  const ceres::HuberLoss loss(kHuberScale * scale);
  double sum = 0;
  for (double x : r) sum += huber_rho(loss, x);
  return sum;
}

double residual_scale(const std::vector<double>& r) {
  if (r.empty()) return 1;
  std::vector<double> size(r.size());
  std::transform(r.begin(), r.end(), size.begin(), [](double x) { return std::fabs(x); });
  std::nth_element(size.begin(), size.begin() + static_cast<std::ptrdiff_t>(size.size() / 2), size.end());
  return std::max(1.0, 1.4826 * size[size.size() / 2]);
}

// ------------------------------------------------------------------ the fit

// Ceres reports through glog: a failed evaluation is a status here, not a line on stderr.
void quiet_ceres() {
  static const bool once = [] {
    FLAGS_minloglevel = google::GLOG_FATAL;
    return true;
  }();
  (void)once;
}

namespace {

struct Objective {
  Simulator& simulator;
  const Observations& data;
  const ModelPoint& base;
  const EffectCandidate& candidate;
  const std::vector<std::size_t>& indices;  ///< the samples fitted
  std::atomic<int>& calls;  ///< simulations of this fit
  std::atomic<long>& work;  ///< work of this fit: 1000 per simulation plus its events
  std::atomic<long>& weighted;  ///< its cost as the search counts it (Simulator::cost): at most 4 budgets
  long budget;              ///< past it, no further simulation (deterministic, unlike a clock)
  double loss_scale = 1;    ///< the robust loss's scale, in σ (residual_scale() at the fit's start)
  Simulator::Grid grid = Simulator::Grid::all;  ///< fitted: `indices` are fit_indices (the rest not simulated)

  ModelPoint point(const double* u) const {
    std::vector<double> values;
    for (std::size_t k = 0; k < candidate.ranges.size(); ++k) values.push_back(candidate.ranges[k].value(u[k]));
    return candidate.apply(base, values);
  }
  std::optional<std::vector<double>> residuals_at(const double* u) const {
    if (work.load() >= budget || weighted.load() / 4 >= budget || simulator.budget_reached()) return std::nullopt;
    ++calls;
    std::size_t events = 0;  // their number alone
    long cost = 0;
    const auto traces = simulator.traces(point(u), indices.back() + 1, nullptr, &cost, grid, &events);
    work += 1000 + static_cast<long>(events);
    weighted += cost;
    if (!traces) return std::nullopt;
    return residuals(data, *traces, indices);
  }
};

// Ceres's view of the objective: the weighted residuals of one simulation.
struct CostFunctor {
  const Objective* objective;
  bool operator()(double const* const* parameters, double* out) const {
    const auto r = objective->residuals_at(parameters[0]);
    if (!r) return false;
    // Each residual through Huber's ρ on its own (sgn r·√ρ(r²)): the sum of squares Ceres
    // minimises is robust_sum().  (A loss function on the residual block would act on the
    // block's whole squared norm, Σ r², and robustify nothing.)
    const ceres::HuberLoss loss(kHuberScale * objective->loss_scale);
    std::transform(r->begin(), r->end(), out, [&loss](double x) { return std::copysign(std::sqrt(huber_rho(loss, x)), x); });
    return true;
  }
};

struct Solved {
  std::vector<double> u;
  double sse = INFINITY;
  std::vector<double> covariance;  ///< of u (k × k), scaled by the residual variance
  std::string no_covariance;       ///< why `covariance` is empty when it was asked for
};

Solved solve(const Objective& objective, std::vector<double> u, bool with_covariance, int iterations) {
  quiet_ceres();
  const int k = static_cast<int>(u.size());
  const int n = static_cast<int>(objective.indices.size() * objective.data.columns.size());
  auto* cost = new ceres::DynamicNumericDiffCostFunction<CostFunctor, ceres::CENTRAL>(new CostFunctor{&objective});
  cost->AddParameterBlock(k);
  cost->SetNumResiduals(n);
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, u.data());  // the residuals come robust (CostFunctor)
  for (int i = 0; i < k; ++i) {
    problem.SetParameterLowerBound(u.data(), i, 0.0);
    problem.SetParameterUpperBound(u.data(), i, 1.0);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = iterations;
  options.function_tolerance = 1e-10;
  options.parameter_tolerance = 1e-9;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Solved out;
  out.u = u;
  out.sse = 2 * summary.final_cost;
  // The covariance, from a Jacobian that every simulation around the optimum could deliver.
  std::vector<double> jacobian_values;
  ceres::CRSMatrix jacobian;
  double cost_value = 0;
  const bool evaluated = with_covariance && n > k &&
                         problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost_value, nullptr, nullptr, &jacobian) &&
                         std::all_of(jacobian.values.begin(), jacobian.values.end(), [](double v) { return std::isfinite(v); });
  if (with_covariance && !evaluated)
    out.no_covariance = n <= k ? "fewer samples than parameters"
                               : "the Jacobian at the optimum could not be evaluated (a simulation near it failed)";
  if (evaluated) {
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
    } else {
      out.no_covariance = "the covariance is singular: the record does not determine the parameters separately";
    }
  }
  return out;
}

}  // namespace

namespace {

// The samples up to time `until` (at least 8).
std::vector<std::size_t> prefix(const Observations& data, const std::vector<std::size_t>& indices, double until) {
  std::size_t n = 0;
  while (n < indices.size() && data.t[indices[n]] <= until) ++n;
  n = std::min(indices.size(), std::max<std::size_t>(8, n));
  return std::vector<std::size_t>(indices.begin(), indices.begin() + static_cast<std::ptrdiff_t>(n));
}

// One parameter within ±cell of a start: a grid of 11 points first (the cost can have several
// narrow valleys there: Brent alone, which assumes one, jumps over them), then Brent's
// minimisation in the best grid cell — robust where event timing puts kinks in the cost.
Solved brent(const Objective& objective, double start, double cell) {
  auto sse = [&](double x) {
    const double at[1] = {x};
    const auto r = objective.residuals_at(at);
    return r ? robust_sum(*r, objective.loss_scale) : INFINITY;
  };
  const double lo = std::max(0.0, start - cell), hi = std::min(1.0, start + cell);
  constexpr int points = 11;
  double best_x = start, best_value = sse(start);
  for (int i = 0; i < points; ++i) {
    const double x = lo + (hi - lo) * i / (points - 1), value = sse(x);
    if (value < best_value) best_x = x, best_value = value;
  }
  const double spacing = (hi - lo) / (points - 1);
  std::uintmax_t iterations = 60;
  const auto [x, value] = boost::math::tools::brent_find_minima(sse, std::max(0.0, best_x - spacing),
                                                                std::min(1.0, best_x + spacing), 40, iterations);
  return value < best_value ? Solved{{x}, value, {}, {}} : Solved{{best_x}, best_value, {}, {}};
}

// The best distinct points of the candidate's scan on these samples.
std::vector<std::vector<double>> scan_starts(const Objective& objective, const EffectCandidate& c) {
  const std::size_t k = c.ranges.size();
  std::vector<std::pair<double, std::vector<double>>> scored;
  for (const std::vector<double>& u : c.scan()) {
    const auto r = objective.residuals_at(u.data());
    if (r) scored.push_back({robust_sum(*r, objective.loss_scale), u});
  }
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::vector<double>> starts;
  const std::size_t wanted = k == 1 ? 3 : 2;
  for (const auto& [sse, u] : scored) {
    if (starts.size() >= wanted) break;
    bool distinct = true;
    for (const auto& s : starts)
      for (std::size_t i = 0; i < k; ++i) distinct = distinct && std::fabs(s[i] - u[i]) > (k == 1 ? 0.05 : 0.1);
    if (starts.empty() || distinct) starts.push_back(u);
  }
  return starts;
}

}  // namespace

void prepare_candidate(Simulator& simulator, const EffectCandidate& c, const ModelPoint& base) {
  std::vector<ModelPoint> corners;
  const std::size_t k = c.ranges.size();
  for (int mask = 0; mask < (1 << k); ++mask) {
    std::vector<double> values;
    for (std::size_t i = 0; i < k; ++i) values.push_back(c.ranges[i].value((mask >> i) & 1 ? 1.0 : 0.0));
    corners.push_back(c.apply(base, values));
  }
  simulator.prepare(corners);
}

namespace {

// The scale of the residual where a fit starts: its start, or the base model (1 when that model
// cannot be simulated).
double starting_residual_scale(Simulator& simulator, const Observations& data, const ModelPoint& base,
                               const EffectCandidate& c, const std::vector<double>* start_u,
                               const std::vector<std::size_t>& samples, Simulator::Grid grid) {
  ModelPoint from = base;
  if (start_u) {
    std::vector<double> values;
    for (std::size_t i = 0; i < c.ranges.size(); ++i) values.push_back(c.ranges[i].value((*start_u)[i]));
    from = c.apply(base, values);
  }
  if (const auto traces = simulator.traces(from, samples.back() + 1, nullptr, nullptr, grid))
    return residual_scale(residuals(data, *traces, samples));
  return 1;
}

}  // namespace

// The fit grows its horizon: scanned and refined up to a quarter servo period past the base
// model's first departure from the record (where the response still depends smoothly on the
// parameter — over a long record a lively gear's response, say with a high restitution, is
// nearly chaotic in it), then refined from there on horizons growing by half, the bracket
// narrowing as the valley of the cost does.  Given a start (a refit), only the last stage runs —
// or, with `grow_from_start`, every stage from that start (a pair refined: docs/discrepancy.md).
Fit fit_candidate(Simulator& simulator, const Observations& data, const ModelPoint& base, const EffectCandidate& c,
                  bool whole_record, const std::vector<double>* start_u, long budget, double departure, bool grow_from_start) {
  Fit fit;
  std::atomic<int> calls{0};
  std::atomic<long> work{0}, weighted{0};
  const std::vector<std::size_t>& samples = whole_record ? data.all_indices : data.fit_indices;
  const Simulator::Grid grid = whole_record ? Simulator::Grid::all : Simulator::Grid::fitted;
  const std::size_t k = c.ranges.size();
  prepare_candidate(simulator, c, base);
  // The robust loss's scale: Huber's at kHuberScale times the scale of the residual where the fit
  // starts (its start, or the base model) — an M-estimate with a preliminary scale: at the noise
  // level the noise's σ (a spike is an outlier), over a systematic gap the gap's size (a gap the
  // model does not yet explain is no outlier: the fit then minimises the sum of squares its score is).
  const double loss_scale = starting_residual_scale(simulator, data, base, c, start_u, samples, grid);
  // The horizons: from a quarter servo period past where the base model first leaves the noise
  // band (the first events that tell the parameter apart), growing by half each stage.
  const double t0 = data.t.front(), t_end = data.t.back();
  std::vector<double> horizons{t_end};
  std::vector<std::vector<double>> starts;
  if (!start_u || grow_from_start) {
    const double first = std::isfinite(departure) ? departure : t0;
    double h = std::min(t_end, std::max(first + 0.25 * numeric::servo_period(base.p), t0 + 0.05 * (t_end - t0)));
    horizons.clear();
    for (; h < t_end; h = t0 + 1.5 * (h - t0)) horizons.push_back(h);
    horizons.push_back(t_end);
  }
  if (start_u) {
    starts.push_back(*start_u);
  } else {
    const std::vector<std::size_t> first_samples = prefix(data, samples, horizons.front());
    starts = scan_starts(Objective{simulator, data, base, c, first_samples, calls, work, weighted, budget, loss_scale, grid}, c);
  }
  // One parameter: the best two distinct valleys are followed from stage to stage (a valley
  // that looks best on a short horizon can lose on a longer one).
  Solved best;
  double cell = start_u && !grow_from_start ? 0.02 : 1.0 / 39;  // one parameter: Brent's bracket, narrowing as the horizon grows
  for (std::size_t stage = 0; stage < horizons.size(); ++stage, cell = std::max(0.004, 0.6 * cell)) {
    const std::vector<std::size_t> stage_samples = prefix(data, samples, horizons[stage]);
    const Objective objective{simulator, data, base, c, stage_samples, calls, work, weighted, budget, loss_scale, grid};
    std::vector<Solved> found;
    for (const std::vector<double>& u : starts) {
      Solved s = k == 1 ? brent(objective, u[0], cell) : solve(objective, u, false, 25);
      if (std::isfinite(s.sse)) found.push_back(std::move(s));
    }
    if (found.empty()) return fit;
    std::sort(found.begin(), found.end(), [](const Solved& a, const Solved& b) { return a.sse < b.sse; });
    best = found.front();
    if (std::getenv("BACKLASH_DEBUG_FITS") && k == 1) {
      std::fprintf(stderr, "%s stage %zu horizon %.3f cell %.4f:", c.effect.c_str(), stage, horizons[stage], cell);
      for (const Solved& f : found) std::fprintf(stderr, " u=%.5f (%.5g) sse %.4g", f.u[0], c.ranges[0].value(f.u[0]), f.sse);
      std::fprintf(stderr, "\n");
    }
    starts = {best.u};
    for (const Solved& s : found)
      if (k == 1 && starts.size() < 2 && std::fabs(s.u[0] - best.u[0]) > cell) starts.push_back(s.u);
    if (stage + 1 == horizons.size() && whole_record) {
      Solved at = solve(objective, best.u, true, 0);
      best.covariance = std::move(at.covariance), best.no_covariance = std::move(at.no_covariance);
    }
  }
  fit.simulations = calls.load();
  fit.budget_exhausted = work.load() >= budget || weighted.load() / 4 >= budget || simulator.budget_reached();
  fit.ok = true;
  fit.u = best.u;
  fit.sse_fit = best.sse;
  fit.no_sigma = whole_record ? best.no_covariance : "fitted on the first part only (no covariance)";
  for (std::size_t i = 0; i < k; ++i) {
    fit.values.push_back(c.ranges[i].value(best.u[i]));
    const double var = best.covariance.empty() ? NAN : best.covariance[i * k + i];
    fit.uncertainty.push_back(std::fabs(c.ranges[i].derivative(best.u[i])) * std::sqrt(var));
    if (!std::isfinite(fit.uncertainty.back()) && fit.no_sigma.empty())
      fit.no_sigma = "the covariance's variance of " + c.ranges[i].name + " is not a finite positive number";
  }
  return fit;
}

}  // namespace backlash::discrepancy::detail
