#include "backlash/numeric/validated_family.hpp"

namespace backlash::numeric {

bool ValidatedParametricFamily::validate_one(const Parameters& p) {
  const ValidationResult r = validate(parametric_evaluator(p), options_);
  const BranchSelection b = select_branches(p);
  std::lock_guard<std::mutex> lock(mutex_);
  ++validated_;
  if (!r.passed()) {
    ++failed_count_;
    failed_.insert(b.contact);
    failed_.insert(b.free);
    return false;
  }
  passed_.emplace(b.contact, r.report());
  passed_.emplace(b.free, r.report());
  return true;
}

bool ValidatedParametricFamily::validate_samples(const std::vector<Parameters>& samples) {
  bool all = true;
  for (const Parameters& p : samples) all = validate_one(p) && all;
  return all;
}

std::optional<ValidatedEvaluator> ValidatedParametricFamily::at(const Parameters& p) {
  const BranchSelection b = select_branches(p);
  auto covered = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failed_.count(b.contact) || failed_.count(b.free)) return std::optional<bool>(false);
    if (passed_.count(b.contact) && passed_.count(b.free)) return std::optional<bool>(true);
    return std::optional<bool>();
  };
  std::optional<bool> state = covered();
  if (!state) {
    validate_one(p);
    state = covered();
  }
  if (!state || !*state) return std::nullopt;
  std::lock_guard<std::mutex> lock(mutex_);
  return ValidatedEvaluator(parametric_evaluator(p), passed_.at(b.free));
}

long ValidatedParametricFamily::samples_validated() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return validated_;
}

long ValidatedParametricFamily::samples_failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failed_count_;
}

std::vector<std::string> ValidatedParametricFamily::covered_branches() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> names;
  for (const auto& [branch, report] : passed_) names.push_back(branch_name(branch));
  return names;
}

}  // namespace backlash::numeric
