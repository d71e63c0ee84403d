// The noise of a residual as it is (docs/discrepancy.md, "Noise"): its level and its correlation
// from lagged fourth differences, an encoder's quantum, and isolated spikes.
#include "internal.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::discrepancy::detail {

namespace {

/// E[(Δ⁴_L e)²]/σ² for an AR(1) process of coefficient a (ρ_k = a^k; Δ⁴_L with weights
/// 1, −4, 6, −4, 1 at lag L: the sum of c_j·c_k·ρ_{|j−k|L}).
double ar1_fourth_difference(double a, int lag) {
  const double rho = std::pow(a, lag);
  return 70 - 112 * rho + 56 * rho * rho - 16 * rho * rho * rho + 2 * rho * rho * rho * rho;
}

/// The median of |Δ⁴_L r| over samples none of which is skipped, over 0.6745: √E[(Δ⁴_L r)²] for
/// Gaussian noise (NaN with fewer than 50 usable differences).
double fourth_difference_scale(const std::vector<double>& r, const std::vector<char>& skip, std::size_t lag) {
  std::vector<double> d;
  for (std::size_t i = 4 * lag; i < r.size(); ++i) {
    bool usable = true;
    for (std::size_t j = 0; j <= 4; ++j) usable = usable && !skip[i - j * lag];
    if (usable) d.push_back(std::fabs(r[i] - 4 * r[i - lag] + 6 * r[i - 2 * lag] - 4 * r[i - 3 * lag] + r[i - 4 * lag]));
  }
  if (d.size() < 50) return NAN;
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2] / 0.6745;
}

}  // namespace

NoiseFit noise_of_residual(const std::vector<double>& r, const std::vector<char>& skip, double quantum, double floor) {
  NoiseFit out;
  const double minimum = std::max(floor, quantum / std::sqrt(12.0));
  const double s1 = fourth_difference_scale(r, skip, 1);
  out.white_sigma = out.sigma = std::max(std::isfinite(s1) ? s1 / std::sqrt(70.0) : 0.0, minimum);
  // The lags whose fourth differences grow as correlated noise can (at most ×2.5 per doubling).
  std::vector<int> lags;
  std::vector<double> log_v;
  for (int lag = 1; lag <= 32; lag *= 2) {
    const double s = fourth_difference_scale(r, skip, static_cast<std::size_t>(lag));
    if (!(s > 0) || (!log_v.empty() && 2 * std::log(s) - log_v.back() > std::log(2.5))) break;
    lags.push_back(lag);
    log_v.push_back(2 * std::log(s));
  }
  if (lags.size() < 3) return out;
  // a on a grid of correlation lengths 0.1 … 500 samples (a = e^(−1/ℓ)); σ² profiled out.
  double best_cost = INFINITY, best_a = 0, best_log_sigma2 = 0;
  for (int g = -1; g < 240; ++g) {
    const double a = g < 0 ? 0.0 : std::exp(-1 / (0.1 * std::pow(5000.0, g / 239.0)));
    double mean = 0, cost = 0;
    for (std::size_t k = 0; k < lags.size(); ++k) mean += log_v[k] - std::log(ar1_fourth_difference(a, lags[k]));
    mean /= static_cast<double>(lags.size());
    for (std::size_t k = 0; k < lags.size(); ++k) {
      const double e = log_v[k] - mean - std::log(ar1_fourth_difference(a, lags[k]));
      cost += e * e;
    }
    if (cost < best_cost) best_cost = cost, best_a = a, best_log_sigma2 = mean;
  }
  // White where the fit finds little correlation, or where the lags do not follow an AR(1) (a
  // smooth gap's growth: an RMS misfit of the logarithms above 0.15).
  if (best_a < 0.3 || std::sqrt(best_cost / static_cast<double>(lags.size())) > 0.15) return out;
  out.a = best_a;
  out.tau_int = (1 + best_a) / (1 - best_a);
  out.sigma = std::max(std::sqrt(std::exp(best_log_sigma2)), minimum);
  return out;
}

double quantum_of(const std::vector<double>& y) {
  double q = INFINITY;
  std::size_t changes = 0;
  for (std::size_t i = 1; i < y.size(); ++i)
    if (const double d = std::fabs(y[i] - y[i - 1]); d > 0) q = std::min(q, d), ++changes;
  if (!std::isfinite(q) || changes < 10) return 0;
  std::size_t multiples = 0;
  for (std::size_t i = 1; i < y.size(); ++i) {
    const double k = std::fabs(y[i] - y[i - 1]) / q;
    multiples += std::fabs(k - std::round(k)) < 1e-6 * std::max(1.0, k);
  }
  return multiples >= 0.98 * (y.size() - 1) ? q : 0;
}

void flag_spikes(const std::vector<double>& r, double white_sigma, std::vector<char>& skip) {
  const double threshold = 6 * std::sqrt(6.0) * white_sigma;
  for (std::size_t i = 2; i + 2 < r.size(); ++i) {
    const double left = 2 * r[i - 1] - r[i - 2], right = 2 * r[i + 1] - r[i + 2], middle = 0.5 * (r[i - 1] + r[i + 1]);
    const double miss = std::min({std::fabs(r[i] - left), std::fabs(r[i] - right), std::fabs(r[i] - middle)});
    if (miss > threshold) skip[i] = 1;
  }
  // Two spikes side by side (each one's neighbour is the other: the test above misses them):
  // their mean, at i + ½, missed by more than 10 white σ by the lines from either side and by the
  // interpolation across the two (σ of those predictions: 2.9σ, 2.9σ and 0.7σ, the mean's 0.7σ),
  // each of the two off that interpolation by more than half of it, on the same side.
  const double pair_threshold = 10 * white_sigma;
  for (std::size_t i = 2; i + 3 < r.size(); ++i) {
    if (skip[i - 1] || skip[i] || skip[i + 1] || skip[i + 2]) continue;
    const double a = r[i - 2], b = r[i - 1], c = r[i + 2], d = r[i + 3], mean = 0.5 * (r[i] + r[i + 1]), across = 0.5 * (b + c);
    const double miss = std::min({std::fabs(mean - (2.5 * b - 1.5 * a)), std::fabs(mean - (2.5 * c - 1.5 * d)), std::fabs(mean - across)});
    const bool both = (r[i] - across) * (r[i + 1] - across) > 0 && std::fabs(r[i] - across) > 0.5 * pair_threshold &&
                      std::fabs(r[i + 1] - across) > 0.5 * pair_threshold;
    if (miss > pair_threshold && both) skip[i] = skip[i + 1] = 1;
  }
}

}  // namespace backlash::discrepancy::detail
