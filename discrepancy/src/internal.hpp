// discrepancy/src/internal.hpp (internal) — the pieces of the workflow.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/output/text.hpp"

#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
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

/// The candidate for `effect` around the model `base` (ranges scaled to the model and experiment).
EffectCandidate candidate_for(const std::string& effect, const ModelPoint& base, double step);

/// The measured columns stacked with their weights (1/σ per column).
struct Observations {
  std::vector<double> t;                          ///< the record's times
  std::vector<std::vector<double>> columns;       ///< theta_out, then theta_motor / theta_load if present
  std::vector<int> which;                         ///< 0 theta_out, 1 theta_motor, 2 theta_load
  std::vector<double> sigma;                      ///< per column
  /// The samples fitted, and those held out of every fit: the record cut in ten blocks, the
  /// third, sixth and ninth held out — they cover the transient and the end alike.
  std::vector<std::size_t> fit_indices, holdout_indices, all_indices;
  std::size_t size() const { return t.size(); }
};

/// Simulations of model points on the record's grid, through a validated family.
class Simulator {
 public:
  /// `step_time`: the step's time on the record's clock ([experiment] step_time): the model,
  /// which starts with its step at 0, is sampled at t − step_time, its events reported at
  /// their time + step_time.
  Simulator(const Observations& data, double step, double t_end, double step_time = 0);
  /// θ at the record's times for each observed column; nothing if the model is outside the
  /// validated family or the simulation did not end in a normal status.
  std::optional<std::vector<std::vector<double>>> traces(const ModelPoint& m, std::size_t samples,
                                                         std::vector<numeric::SimulationEvent>* events = nullptr);
  /// Validates the family at these model points (a candidate's range corners).
  void prepare(const std::vector<ModelPoint>& points);
  int simulations() const { return simulations_.load(); }

 private:
  const Observations& data_;
  double step_, t_end_, step_time_;
  numeric::ValidatedModelFamily family_;
  std::atomic<int> simulations_{0};
};

/// Weighted residuals of a model against the observations at these samples.
std::vector<double> residuals(const Observations& data, const std::vector<std::vector<double>>& traces,
                              const std::vector<std::size_t>& indices);
double sum_of_squares(const std::vector<double>& r);

/// A candidate fitted: its parameters, and its scores.
struct Fit {
  bool ok = false;
  std::vector<double> u;       ///< in [0, 1]
  std::vector<double> values;  ///< physical
  std::vector<double> uncertainty;
  double sse_fit = 0;          ///< weighted, on the fitted samples
  int simulations = 0;
  bool budget_exhausted = false;  ///< the fit stopped at its work budget (its best point is kept)
};

/// Fits a candidate added to `base`: the scan, then Ceres from the best points.  With
/// `whole_record` the fit uses every sample and the covariance is computed.
/// The fit stops when its work (1000 per simulation plus the events simulated) reaches `budget`
/// (its best point kept; Fit::budget_exhausted says so) — a count, so the result does not depend
/// on the machine's speed or load.
/// `departure`: where the base model first leaves the record's noise band — the first stage of
/// the growing horizon ends a quarter servo period after it.
Fit fit_candidate(Simulator& simulator, const Observations& data, const ModelPoint& base, const EffectCandidate& c,
                  bool whole_record, const std::vector<double>* start_u = nullptr, long budget = std::numeric_limits<long>::max(),
                  double departure = NAN);

}  // namespace backlash::discrepancy::detail
