#include "backlash/numeric/validated_family.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>

namespace backlash::numeric {

bool ValidatedParametricFamily::validate_one(const Parameters& p) { return record(p, validate(parametric_evaluator(p), options_)); }

bool ValidatedParametricFamily::record(const Parameters& p, const ValidationResult& r) {
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

bool ValidatedParametricFamily::validate_samples(const std::vector<Parameters>& samples, int threads) {
  // The gates run in any order; their verdicts are recorded in the samples' order (the first
  // passing sample's report is its branches').
  std::vector<std::optional<ValidationResult>> results(samples.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    try {
      for (std::size_t i; (i = next++) < samples.size();) results[i].emplace(validate(parametric_evaluator(samples[i]), options_));
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < std::min<int>(threads, static_cast<int>(samples.size())); ++k) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  bool all = true;
  for (std::size_t i = 0; i < samples.size(); ++i) all = record(samples[i], *results[i]) && all;
  return all;
}

std::optional<ValidatedEvaluator> ValidatedParametricFamily::at(const Parameters& p) {
  const BranchSelection b = select_branches(p);
  bool tainted = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tainted = failed_.count(b.contact) || failed_.count(b.free);
    if (!tainted && passed_.count(b.contact) && passed_.count(b.free))
      return ValidatedEvaluator(parametric_evaluator(p), passed_.at(b.free));
  }
  if (tainted) {  // a sample of this branch failed: this point is judged on its own merit
    const EvaluatorPtr evaluator = parametric_evaluator(p);
    ValidationResult r = validate(evaluator, options_);
    if (!r.passed()) return std::nullopt;
    return ValidatedEvaluator(evaluator, r.report());
  }
  if (!validate_one(p)) return std::nullopt;  // a pass covers the branches for later calls
  std::lock_guard<std::mutex> lock(mutex_);
  return ValidatedEvaluator(parametric_evaluator(p), passed_.at(b.free));
}

ValidatedParametricFamily::Verdict ValidatedParametricFamily::judge(const Parameters& p) const {
  const BranchSelection b = select_branches(p);
  Verdict verdict;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool tainted = failed_.count(b.contact) || failed_.count(b.free);
    if (!tainted && passed_.count(b.contact) && passed_.count(b.free)) {
      verdict.evaluator = ValidatedEvaluator(parametric_evaluator(p), passed_.at(b.free));
      return verdict;
    }
  }
  verdict.itself = true;
  const EvaluatorPtr evaluator = parametric_evaluator(p);
  const ValidationResult r = validate(evaluator, options_);
  if (r.passed()) verdict.evaluator = ValidatedEvaluator(evaluator, r.report());
  else verdict.reason = "failed validation against odeint: " + r.report().failures();
  return verdict;
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
