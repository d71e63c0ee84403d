#include "backlash/numeric/evaluator.hpp"

#include "backlash/generated/cases.hpp"
#include "backlash/numeric/direct_branches.hpp"

#include <map>
#include <stdexcept>
#include <string_view>

namespace backlash::numeric {

namespace {

class GeneratedCaseEvaluator final : public SegmentEvaluator {
 public:
  using FreeFunction = FreeState (*)(double, double);
  using ContactFunction = ContactState (*)(double, double, double);
  GeneratedCaseEvaluator(std::string id, Parameters p, double cot, FreeFunction f, ContactFunction c)
      : id_(std::move(id)), p_(p), cot_(cot), free_(f), contact_(c), branches_(select_branches(p)) {}

  std::string name() const override { return "case " + id_ + " (generated)"; }
  std::string kind() const override { return "case"; }
  const Parameters& parameters() const override { return p_; }
  BranchSelection branches() const override { return branches_; }
  double cot_phi() const override { return cot_; }
  FreeState free_state(double t, double v0) const override { return free_(t, v0); }
  ContactState contact_state(double t, double x0, double v0) const override { return contact_(t, x0, v0); }

 private:
  std::string id_;
  Parameters p_;
  double cot_;
  FreeFunction free_;
  ContactFunction contact_;
  BranchSelection branches_;
};

struct GeneratedCase {
  std::string id;
  Parameters parameters;
  double cot_phi;
  GeneratedCaseEvaluator::FreeFunction free;
  GeneratedCaseEvaluator::ContactFunction contact;
  std::vector<std::string> exact;
  std::string contact_branch, free_branch;
};

template <class Metadata>
Parameters parameters_from_metadata() {
  Parameters p;
  p.Jm = Metadata::parameters[0];
  p.Fm = Metadata::parameters[1];
  p.JL = Metadata::parameters[2];
  p.FL = Metadata::parameters[3];
  p.K = Metadata::parameters[4];
  p.theta_R = Metadata::parameters[5];
  p.backlash = Metadata::parameters[6];
  p.measured_at = std::string_view(Metadata::measured_at) == "motor" ? model::MeasuredAt::Motor : model::MeasuredAt::Load;
  return p;
}

template <class Metadata>
std::vector<std::string> exact_from_metadata() {
  std::vector<std::string> out;
  for (int i = 0; i < Metadata::parameter_count; ++i) out.emplace_back(Metadata::parameters_exact[i]);
  return out;
}

const std::vector<GeneratedCase>& registry() {
  static const std::vector<GeneratedCase> cases = [] {
    std::vector<GeneratedCase> out;
#define BACKLASH_REGISTER_CASE(ID)                                                                               \
  {                                                                                                              \
    namespace g = backlash::generated::case_##ID;                                                               \
    out.push_back(GeneratedCase{                                                                                 \
        #ID, parameters_from_metadata<g::metadata>(), g::cot_phi,                                                \
        [](double t, double v0) {                                                                                \
          const auto s = g::free_state(t, v0);                                                                   \
          return FreeState{s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, s.gap};                                 \
        },                                                                                                       \
        [](double t, double x0, double v0) {                                                                     \
          const auto s = g::contact_state(t, x0, v0);                                                            \
          return ContactState{s.theta_o, s.dtheta_o};                                                            \
        },                                                                                                       \
        exact_from_metadata<g::metadata>(), g::metadata::contact_branch, g::metadata::free_branch});             \
  }
    BACKLASH_GENERATED_CASES(BACKLASH_REGISTER_CASE)
#undef BACKLASH_REGISTER_CASE
    return out;
  }();
  return cases;
}

const GeneratedCase* find_case(const std::string& id) {
  for (const GeneratedCase& c : registry())
    if (c.id == id) return &c;
  return nullptr;
}

class DirectEvaluator final : public SegmentEvaluator {
 public:
  explicit DirectEvaluator(const Parameters& p)
      : p_(p), branches_(select_branches(p)), cot_(direct_cot_phi(branches_.free, p)) {}
  std::string name() const override {
    return std::string("direct ") + branch_name(branches_.contact) + "/" + branch_name(branches_.free);
  }
  std::string kind() const override { return "direct"; }
  const Parameters& parameters() const override { return p_; }
  BranchSelection branches() const override { return branches_; }
  double cot_phi() const override { return cot_; }
  FreeState free_state(double t, double v0) const override { return direct_free_state(branches_.free, p_, t, v0); }
  ContactState contact_state(double t, double x0, double v0) const override {
    return direct_contact_state(branches_.contact, p_, t, x0, v0);
  }

 private:
  Parameters p_;
  BranchSelection branches_;
  double cot_;
};

}  // namespace

const std::vector<std::string>& generated_case_ids() {
  static const std::vector<std::string> ids = [] {
    std::vector<std::string> out;
    for (const GeneratedCase& c : registry()) out.push_back(c.id);
    return out;
  }();
  return ids;
}

EvaluatorPtr generated_case_evaluator(const std::string& case_id) {
  const GeneratedCase* c = find_case(case_id);
  if (!c) return nullptr;
  return std::make_shared<GeneratedCaseEvaluator>(c->id, c->parameters, c->cot_phi, c->free, c->contact);
}

std::vector<std::string> generated_case_exact_parameters(const std::string& case_id) {
  const GeneratedCase* c = find_case(case_id);
  return c ? c->exact : std::vector<std::string>{};
}

EvaluatorPtr direct_branch_evaluator(const Parameters& p) { return std::make_shared<DirectEvaluator>(p); }

EvaluatorPtr case_evaluator(const model::CaseSpec& spec) {
  if (const GeneratedCase* c = find_case(spec.id)) {
    const std::vector<std::string> exact{model::to_string(spec.Jm), model::to_string(spec.Fm),
                                         model::to_string(spec.JL), model::to_string(spec.FL),
                                         model::to_string(spec.K),  model::to_string(spec.reference),
                                         model::to_string(spec.backlash)};
    if (exact == c->exact && c->parameters.measured_at == spec.measured_at) return generated_case_evaluator(spec.id);
  }
  return parametric_evaluator(parameters_of(spec));
}

}  // namespace backlash::numeric
