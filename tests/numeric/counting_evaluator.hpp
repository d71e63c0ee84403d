// tests/numeric/counting_evaluator.hpp — a segment evaluator that counts its closed-form
// evaluations (free flight and contact), for the tests that bound a search's cost in them.
#pragma once

#include "backlash/numeric/evaluator.hpp"

#include <string>
#include <utility>

namespace backlash::testing {

/// Forwards to `inner`, counting every free_state and contact_state call in `evaluations`.
class CountingEvaluator final : public numeric::SegmentEvaluator {
 public:
  explicit CountingEvaluator(numeric::EvaluatorPtr inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  std::string kind() const override { return inner_->kind(); }
  const numeric::Parameters& parameters() const override { return inner_->parameters(); }
  numeric::BranchSelection branches() const override { return inner_->branches(); }
  double cot_phi() const override { return inner_->cot_phi(); }
  numeric::FreeState free_state(double t, double v0) const override {
    ++evaluations;
    return inner_->free_state(t, v0);
  }
  numeric::ContactState contact_state(double t, double x0, double v0) const override {
    ++evaluations;
    return inner_->contact_state(t, x0, v0);
  }
  mutable long evaluations = 0;

 private:
  numeric::EvaluatorPtr inner_;
};

}  // namespace backlash::testing
