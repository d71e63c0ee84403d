// backlash/numeric/validated_family.hpp — the validation gate for parameter sweeps.
//
// A sweep evaluates the stable parametric layer at up to 10⁵ parameter points;
// running the full odeint gate at each (≈ 2.5 ms) would dominate.  The
// parametric layer is one code path per pole-structure branch, so a sweep
// validates it as a family: at sample points of the sweep (its ends, every
// k-th point, and the first point of each branch it enters, on demand) and at
// the branch's representative.  An evaluator is handed out only for
// parameters whose contact and free branches both passed at some sample of
// this family; a point in a branch not yet covered is validated itself first.
// A failed sample poisons its branch: points there are refused (never used
// unvalidated).
#pragma once

#include "backlash/numeric/validation.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace backlash::numeric {

class ValidatedParametricFamily {
 public:
  explicit ValidatedParametricFamily(ValidationOptions options = {}) : options_(std::move(options)) {}

  /// Validate the parametric evaluator at `samples` (thread-safe), on up to `threads` threads and
  /// recorded in the samples' order: the same family for any thread count.  False if any failed.
  bool validate_samples(const std::vector<Parameters>& samples, int threads = 1);

  /// A validated evaluator for `p`, validating `p` itself when its branches are not covered
  /// yet (a pass then covers them for later calls) or a sample of its branch failed; nothing
  /// when `p` itself fails (thread-safe).
  std::optional<ValidatedEvaluator> at(const Parameters& p);

  struct Verdict {
    std::optional<ValidatedEvaluator> evaluator;
    std::string reason;    ///< why refused: the failing states and their errors
    bool itself = false;   ///< validated at this point (its branches were not covered by passing samples)
  };
  /// The deterministic verdict for `p`: accepted when both its branches passed at samples and
  /// failed at none, else validated itself.  Records nothing (thread-safe).
  Verdict judge(const Parameters& p) const;

  long samples_validated() const;
  long samples_failed() const;
  std::vector<std::string> covered_branches() const;

 private:
  bool validate_one(const Parameters& p);
  bool record(const Parameters& p, const ValidationResult& r);  // a sample's verdict, counted
  ValidationOptions options_;
  mutable std::mutex mutex_;
  std::map<Branch, ValidationReport> passed_;
  std::set<Branch> failed_;
  long validated_ = 0, failed_count_ = 0;
};

}  // namespace backlash::numeric
