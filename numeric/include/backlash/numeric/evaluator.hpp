// backlash/numeric/evaluator.hpp — one interface over every segment evaluator:
//
//   "case"        the generated per-case header (backlash/generated/case_<ID>.hpp),
//                 exact closed forms with the case's numbers folded in;
//   "parametric"  the stable parametric layer (parametric.hpp), any parameters;
//   "direct"      the generated per-branch formulas (direct_branches.hpp) of the
//                 branches the dispatcher selects.
//
// Evaluators are raw: before tracing or simulating with one, pass it through
// the validation gate (validation.hpp), which hands out a ValidatedEvaluator
// only when it agrees with Boost.Odeint.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/parametric.hpp"

#include <memory>
#include <string>
#include <vector>

namespace backlash::numeric {

class SegmentEvaluator {
 public:
  virtual ~SegmentEvaluator() = default;
  /// e.g. "case V (generated)", "parametric", "direct load_generic/contact_underdamped".
  virtual std::string name() const = 0;
  /// "case", "parametric" or "direct".
  virtual std::string kind() const = 0;
  virtual const Parameters& parameters() const = 0;
  virtual BranchSelection branches() const = 0;
  virtual double cot_phi() const = 0;
  /// Free mode from the separation point θ0 = θR + cot φ·θ̇m0 with velocity θ̇m0.
  virtual FreeState free_state(double t, double dtheta_m0) const = 0;
  /// Contact mode from (θo0, θ̇o0).
  virtual ContactState contact_state(double t, double theta_o0, double dtheta_o0) const = 0;

  double separation_theta(double dtheta_m0) const { return parameters().theta_R + cot_phi() * dtheta_m0; }
};

using EvaluatorPtr = std::shared_ptr<const SegmentEvaluator>;

/// Ids of the cases compiled in from generated headers (I … VIII).
const std::vector<std::string>& generated_case_ids();
/// The generated evaluator of a compiled-in case; null when there is none.
EvaluatorPtr generated_case_evaluator(const std::string& case_id);
/// Exact parameter texts ("1/2", …) of a compiled-in case, in the order
/// Jm, Fm, JL, FL, K, theta_R, backlash; empty when there is none.
std::vector<std::string> generated_case_exact_parameters(const std::string& case_id);

EvaluatorPtr parametric_evaluator(const Parameters& p);
EvaluatorPtr direct_branch_evaluator(const Parameters& p);  ///< branches chosen by select_branches

/// The generated evaluator when `spec` has exactly the numbers of a
/// compiled-in case (same id, parameters and measured_at), else the parametric one.
EvaluatorPtr case_evaluator(const model::CaseSpec& spec);

}  // namespace backlash::numeric
