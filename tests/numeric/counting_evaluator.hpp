// tests/numeric/counting_evaluator.hpp — a segment evaluator that counts its closed-form
// evaluations (free flight and contact), for the tests that bound a search's cost in them, and
// optionally those repeated with the arguments of an earlier one (since `clear`).
#pragma once

#include "backlash/numeric/evaluator.hpp"

#include <array>
#include <set>
#include <string>
#include <utility>

namespace backlash::testing {

/// Forwards to `inner`, counting every free_state and contact_state call in `evaluations`, and
/// with `track_repeats` those whose arguments were already evaluated since `clear` in `repeats`.
class CountingEvaluator final : public numeric::SegmentEvaluator {
 public:
  explicit CountingEvaluator(numeric::EvaluatorPtr inner, bool track_repeats = false)
      : inner_(std::move(inner)), track_repeats_(track_repeats) {}
  std::string name() const override { return inner_->name(); }
  std::string kind() const override { return inner_->kind(); }
  const numeric::Parameters& parameters() const override { return inner_->parameters(); }
  numeric::BranchSelection branches() const override { return inner_->branches(); }
  double cot_phi() const override { return inner_->cot_phi(); }
  numeric::FreeState free_state(double t, double v0) const override {
    note({0, t, v0, 0});
    return inner_->free_state(t, v0);
  }
  numeric::ContactState contact_state(double t, double x0, double v0) const override {
    note({1, t, x0, v0});
    return inner_->contact_state(t, x0, v0);
  }
  void clear() const { seen_.clear(); }
  mutable long evaluations = 0, repeats = 0;

 private:
  void note(const std::array<double, 4>& call) const {
    ++evaluations;
    if (track_repeats_ && !seen_.insert(call).second) ++repeats;
  }
  numeric::EvaluatorPtr inner_;
  bool track_repeats_;
  mutable std::set<std::array<double, 4>> seen_;
};

}  // namespace backlash::testing
