// discrepancy/src/internal.hpp (internal) — the pieces of the workflow.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/output/text.hpp"

#include <atomic>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace backlash::discrepancy::detail {

/// A model the workflow simulates: nominal parameters and effects.
struct ModelPoint {
  numeric::Parameters p;
  numeric::Effects e;
};

/// One parameter of a candidate effect, searched over [low, high] (logarithmically when
/// `logarithmic`): the fit works in u ∈ [0, 1].
struct ParameterRange {
  std::string name;
  double low = 0, high = 1;
  bool logarithmic = false;
  double value(double u) const;
  double derivative(double u) const;  ///< dvalue/du
};

/// An effect of the vocabulary as something the fit can vary.
struct EffectCandidate {
  std::string effect;
  std::vector<ParameterRange> ranges;
  std::function<ModelPoint(const ModelPoint& base, const std::vector<double>& values)> apply;
  /// The grid of the bracketing scan (points in u).
  std::vector<std::vector<double>> scan() const;
};

/// The candidate for `effect` — an effect of the vocabulary or a nominal parameter
/// (parameter_candidates(), backlash_size) — around the model `base` (ranges scaled to the model
/// and experiment).  Throws std::invalid_argument for an unknown name or a parameter that is 0.
EffectCandidate candidate_for(const std::string& effect, const ModelPoint& base, double step);

/// The value of a nominal parameter (a key of parameter_candidates(), "backlash" or backlash_size).
double nominal_value(const std::string& key, const numeric::Parameters& p);

/// Several candidates as one: their parameters side by side, applied in turn.
EffectCandidate combined(const std::vector<EffectCandidate>& parts);

/// The measured columns stacked with their weights (1/σ per column).
struct Observations {
  std::vector<double> t;                          ///< the record's times
  std::vector<std::vector<double>> columns;       ///< theta_out, then theta_motor / theta_load if present
  std::vector<int> which;                         ///< 0 theta_out, 1 theta_motor, 2 theta_load
  std::vector<double> sigma;                      ///< per column
  double tau_int = 1;  ///< the noise's integrated autocorrelation time [samples]: the BIC's n_eff = n/τ_int
  std::vector<char> skip;       ///< samples given no weight (spikes); left out of the index lists
  std::vector<double> quantum;  ///< per column: an encoder's step (0: none)
  double floor = 0;             ///< the smallest σ (a noise-free record still has a scale)
  /// The samples fitted, and those held out of every fit: the record cut in ten blocks, the
  /// third, sixth and ninth held out — they cover the transient and the end alike.
  std::vector<std::size_t> fit_indices, holdout_indices, all_indices;
  std::size_t size() const { return t.size(); }
};

/// Simulations of model points on the record's grid, through a validated family.
class Simulator {
 public:
  /// A simulation's traces: one column per observed column, each of the record's length asked for.
  using Traces = std::shared_ptr<const std::vector<std::vector<double>>>;
  /// Which samples a simulation computes: every one, or only those a fit reads (the fitted
  /// samples below the length asked for, and the last one — the held-out samples are left NaN).
  /// A sample is the model's state at its time whatever the others are (the engine's segments do
  /// not depend on the sample times), so both give the same bits where both have a sample.
  enum class Grid { all, fitted };
  /// `step_time`: the step's time on the record's clock ([experiment] step_time): the model,
  /// which starts with its step at 0, is sampled at t − step_time, its events reported at
  /// their time + step_time.
  Simulator(const Observations& data, double step, double t_end, double step_time = 0);
  /// θ at the record's times for each observed column; nothing if the model is outside the
  /// validated family or the simulation did not end in a normal status.
  /// `cost`, if given, receives the simulation's work (cost()).
  /// `grid`: Grid::fitted computes only the samples a fit reads (Observations::fit_indices); a
  /// simulation kept on the whole grid serves it too.
  /// `event_count`, if given, receives the number of its events (for a caller that needs no more:
  /// the events are not copied).
  Traces traces(const ModelPoint& m, std::size_t samples, std::vector<numeric::SimulationEvent>* events = nullptr,
                long* cost = nullptr, Grid grid = Grid::all, std::size_t* event_count = nullptr);
  /// A kept simulation (of `m` at this length, on this grid or the whole one) held past the last
  /// 256 kept for as long as the handle lives: a screened partner's best point, where its pair's
  /// fit starts once every other partner has been screened.  Empty if none is kept.
  using Held = std::shared_ptr<const void>;
  Held hold(const ModelPoint& m, std::size_t samples, Grid grid);
  /// `n` simulations served from what the search already knows (a screen done before), their
  /// `work` charged as kept ones are: the count and the budget as if they had been asked for.
  void charge(int n, long work) { simulations_ += n, hits_ += n, work_ += work; }
  /// Whether `work` more keeps the search below its budget (budget_reached() stays false throughout).
  bool affords(long work) const { return work_.load() + work < budget_; }
  /// Validates the family at these model points (a candidate's range corners).
  void prepare(const std::vector<ModelPoint>& points);
  int simulations() const { return simulations_.load(); }
  /// A simulation's work: 1000 plus its events; a delayed model's more (numerical integration:
  /// 400 per radian of the servo's oscillation over the record, 40 per radian of a mesh's; Stribeck
  /// friction 1000·(vs/v)^1.5 per radian of the servo's, v = |step|/servo period).
  long cost(const ModelPoint& m, std::size_t events) const;
  /// The work of every simulation so far (cost()).
  long work() const { return work_.load(); }
  /// Past this much work the fits stop (their best points kept): the whole search's budget.
  void set_budget(long budget) { budget_ = budget; }
  bool budget_reached() const { return work_.load() >= budget_; }
  int cache_hits() const { return hits_.load(); }
  /// The samples computed by every simulation so far (a kept simulation computes none).
  long samples_computed() const { return samples_.load(); }

 private:
  /// A simulation kept: the traces (empty: it failed), its events and its cost.
  struct Kept {
    Traces traces;
    std::vector<numeric::SimulationEvent> events;
    long cost = 0;
  };
  std::shared_ptr<const Kept> recall(const std::string& key);
  /// The record's rows a simulation of this length on this grid samples (ascending).
  std::vector<std::size_t> rows(std::size_t samples, Grid grid) const;
  /// rows(samples, grid).size() without forming them (a fit's grid is as long as the whole
  /// one exactly when it is the whole one).
  std::size_t row_count(std::size_t samples, Grid grid) const;
  /// The rows a simulation of this length on this grid samples and their times on the model's
  /// clock (from the step): formed once per length and grid, read by every simulation of them.
  struct SampleGrid {
    std::vector<std::size_t> rows;
    std::vector<double> times;
  };
  std::shared_ptr<const SampleGrid> sample_grid(std::size_t samples, Grid grid);
  Traces simulate(const ModelPoint& m, std::size_t samples, const SampleGrid& grid,
                  std::vector<numeric::SimulationEvent>* events, long* cost);
  void keep(const std::string& key, std::shared_ptr<const Kept> kept);
  std::mutex cache_mutex_;
  std::map<std::string, std::shared_ptr<const Kept>> cache_;  ///< the last simulations, by model point and length
  std::deque<std::string> cache_order_;                     ///< oldest first (the oldest leaves in O(1))
  std::map<std::string, std::weak_ptr<const Kept>> held_;   ///< hold()'s, while their handles live
  std::map<std::pair<std::size_t, Grid>, std::shared_ptr<const SampleGrid>> grids_;  ///< sample_grid()'s
  std::atomic<int> hits_{0};
  const Observations& data_;
  double step_, t_end_, step_time_;
  numeric::ValidatedModelFamily family_;
  std::atomic<int> simulations_{0};
  std::atomic<long> work_{0};
  std::atomic<long> samples_{0};
  long budget_ = std::numeric_limits<long>::max();
};

/// Weighted residuals of a model against the observations at these samples.
std::vector<double> residuals(const Observations& data, const std::vector<std::vector<double>>& traces,
                              const std::vector<std::size_t>& indices);
double sum_of_squares(const std::vector<double>& r);
/// The scale of the robust loss, in units of the noise's σ (the residuals are weighted by 1/σ):
/// a residual beyond it counts linearly, not squared (docs/discrepancy.md, "Outliers").
inline constexpr double kHuberScale = 3;
/// Σ ρ(r²) with Huber's ρ at kHuberScale (ceres::HuberLoss): what every fit of a step record
/// minimises — an outlier the spike test does not catch pulls no fit far.  (The scores — BIC,
/// held-out RMS, gaps — stay sums of squares: a systematic gap of 25σ is not an outlier.)
double robust_sum(const std::vector<double>& r, double scale = 1);
/// A residual's robust scale in σ: 1.4826·median|r| (the MAD of a centred residual), at least 1.
double residual_scale(const std::vector<double>& r);

/// A candidate fitted: its parameters, and its scores.
struct Fit {
  bool ok = false;
  std::vector<double> u;       ///< in [0, 1]
  std::vector<double> values;  ///< physical
  std::vector<double> uncertainty;  ///< NaN where no covariance (then no_sigma says why)
  std::string no_sigma;             ///< why `uncertainty` is NaN (empty when it is not)
  double sse_fit = 0;          ///< weighted, on the fitted samples
  int simulations = 0;
  bool budget_exhausted = false;  ///< the fit stopped at its work budget (its best point is kept)
};

/// The family validated over a candidate's whole range added to `base` (its corners): the points
/// within are then simulated without a validation each (Simulator::simulate validates a point
/// outside every validated box against the odeint reference — 20–50 closed-form simulations' time).
void prepare_candidate(Simulator& simulator, const EffectCandidate& c, const ModelPoint& base);

/// Fits a candidate added to `base`: the scan, then Ceres from the best points.  With
/// `whole_record` the fit uses every sample and the covariance is computed.
/// The fit stops when its work (1000 per simulation plus the events simulated) reaches `budget`
/// (its best point kept; Fit::budget_exhausted says so) — a count, so the result does not depend
/// on the machine's speed or load.
/// `departure`: where the base model first leaves the record's noise band — the first stage of
/// the growing horizon ends a quarter servo period after it.  Given `start_u`, only the last stage
/// (the whole horizon) runs, from it — unless `grow_from_start`: then every stage, from it (no scan).
Fit fit_candidate(Simulator& simulator, const Observations& data, const ModelPoint& base, const EffectCandidate& c,
                  bool whole_record, const std::vector<double>* start_u = nullptr, long budget = std::numeric_limits<long>::max(),
                  double departure = NAN, bool grow_from_start = false);

}  // namespace backlash::discrepancy::detail

namespace backlash::discrepancy::detail {

/// The noise of one residual column (docs/discrepancy.md, "Noise").
struct NoiseFit {
  double sigma = 0;        ///< its level
  double white_sigma = 0;  ///< MAD(Δ⁴r)/(0.6745·√70): the white-noise rule
  double a = 0;            ///< AR(1) coefficient per sample (0: white)
  double tau_int = 1;      ///< (1 + a)/(1 − a)
};

/// The level and correlation of the noise in a residual r (the record minus a model): the median
/// of |Δ⁴r| at lags 1, 2, 4, …, 32 samples — while it grows no faster than correlated noise lets it
/// (×2.5 per doubling of the lag; a smooth gap grows ×256) — fitted by an AR(1) process's
/// E[(Δ⁴_L e)²] = σ²·(70 − 112ρ + 56ρ² − 16ρ³ + 2ρ⁴), ρ = a^L.  White (a = 0, the lag-1 rule) when
/// the fit finds a < 0.3 or fewer than three lags are usable.  `quantum`: an encoder's step, the
/// floor of σ at quantum/√12.  Samples flagged in `skip` (spikes) are left out.
NoiseFit noise_of_residual(const std::vector<double>& r, const std::vector<char>& skip, double quantum, double floor);

/// An encoder's resolution read off a record: the smallest nonzero difference between samples
/// when ≥ 98 % of them are whole multiples of it (0: not quantised).
double quantum_of(const std::vector<double>& y);

/// Isolated spikes of a residual: samples that the linear extrapolations from either side and
/// the interpolation between their neighbours all miss by more than 6·√6 white σ (a kink — an
/// impact — is met by one of the three; a spike by none), and two spikes side by side (their
/// mean missed by 10 white σ by the same three predictions from outside the pair).  Flags them in
/// `skip`.
void flag_spikes(const std::vector<double>& r, double white_sigma, std::vector<char>& skip);

}  // namespace backlash::discrepancy::detail

namespace backlash::discrepancy::detail {

/// The scores of one model against the observations (weighted residuals).
struct Scores {
  double sse_fit = 0, sse_holdout = 0, sse = 0;
  std::size_t n_fit = 0, n_holdout = 0, n = 0;
  double tau_int = 1;        ///< the noise's: the BIC counts n_eff = n_fit/τ_int residuals
  double rms_theta_out = 0;  ///< unweighted, whole record
  double robust = 0;         ///< Σ ρ(r²) over every sample, Huber's ρ at kHuberScale (robust_sum)
  /// √(Σρ/n): the RMS the noise-level test reads — equal to rms() within 0.05 % on Gaussian noise,
  /// but an outlier the spike test missed counts linearly (a ±18σ spike 99, not 324).
  double robust_rms() const { return std::sqrt(robust / std::max<std::size_t>(1, n)); }
  double rms_fit() const { return std::sqrt(sse_fit / std::max<std::size_t>(1, n_fit)); }
  double rms_holdout() const { return std::sqrt(sse_holdout / std::max<std::size_t>(1, n_holdout)); }
  double rms() const { return std::sqrt(sse / std::max<std::size_t>(1, n)); }
  /// n_eff·ln(SSE/n) + k·ln n_eff on the fitted samples.
  double bic(int parameters) const {
    const double n_eff = std::max(1.0, static_cast<double>(n_fit) / tau_int);
    return n_eff * std::log(std::max(sse_fit, 1e-300) / std::max<std::size_t>(1, n_fit)) + parameters * std::log(n_eff);
  }
};
Scores score(const Observations& o, const std::vector<std::vector<double>>& traces);

/// The RMS (in σ) at or below which a model meets the record: the option's level, or three
/// standard deviations of a correlated noise's sample RMS, 1 + 3·√(τ_int/(2n)), if more.
double at_noise_level(const Observations& o, double noise_level);

/// A named candidate: its result and what the fit varies.
struct Named {
  Candidate result;
  EffectCandidate candidate;
};

/// The state of the search for what the model is missing (search.cpp).
struct Search {
  Simulator& simulator;
  Observations& o;
  const ModelPoint& base;  ///< the nominal model
  double step;
  const DiscrepancyOptions& options;
  ModelPoint current;
  Scores scores;
  std::vector<Named> named;
  std::vector<std::vector<Candidate>> rounds;
  std::vector<Candidate> alike;  ///< explanations that fit alike, the one adopted first
  std::string experiment;        ///< the one that would tell them apart
  int parameters() const;        ///< the fitted parameters of everything named
  /// Simulates `current` and updates `scores` (false: it could not be simulated).
  bool rescore();
};

/// Fits the [fit] free parameters (keys as parameter_candidates(), backlash_size) first, on the
/// whole record; named when decisive (ΔBIC < −decisive_bic against the nominal model).
void fit_free_parameters(Search& s, const std::vector<std::string>& free);

/// Rounds of candidates (`remaining`: effects and parameters), pairs where no single one is
/// decisive, a joint refit and the replacement of a named candidate the others make needless,
/// until the model meets the record, nothing is decisive, max_effects are named or the budget ends.
void run_search(Search& s, std::vector<std::string> remaining);

/// The noise of every column re-estimated from the residual of `traces` (σ per column and the
/// correlation of theta_out's); returns theta_out's.
NoiseFit reestimate_noise(Observations& o, const std::vector<std::vector<double>>& traces);

/// The first time theta_out's residual leaves the noise band (|r| > 3σ on five consecutive
/// samples), NaN if never.
double first_departure(const Observations& o, const std::vector<double>& model);

}  // namespace backlash::discrepancy::detail
