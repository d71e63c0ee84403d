#include "backlash/numeric/parametric.hpp"

#include "backlash/numeric/evaluator.hpp"

#include "evaluators/phi_functions.hpp"
#include "evaluators/phi_kernels.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace backlash::numeric {

Parameters parameters_of(const model::CaseSpec& spec) {
  Parameters p;
  p.Jm = model::to_double(spec.Jm);
  p.Fm = model::to_double(spec.Fm);
  p.JL = model::to_double(spec.JL);
  p.FL = model::to_double(spec.FL);
  p.K = model::to_double(spec.K);
  p.theta_R = model::to_double(spec.reference);
  p.backlash = model::to_double(spec.backlash);
  p.measured_at = spec.measured_at;
  return p;
}

const std::array<Branch, branch_count>& all_branches() {
  static const std::array<Branch, branch_count> branches{
      Branch::ContactUnderdamped, Branch::ContactCriticallyDamped, Branch::ContactOverdamped,
      Branch::LoadGeneric,        Branch::LoadFL0,                 Branch::LoadFm0,
      Branch::LoadFm0FL0,         Branch::LoadEqualRates,          Branch::MotorUnderdamped,
      Branch::MotorCritical,      Branch::MotorOverdamped,         Branch::MotorUnderdampedFL0,
      Branch::MotorCriticalFL0,   Branch::MotorOverdampedFL0};
  return branches;
}

const char* branch_name(Branch branch) {
  switch (branch) {
    case Branch::ContactUnderdamped: return "contact_underdamped";
    case Branch::ContactCriticallyDamped: return "contact_critically_damped";
    case Branch::ContactOverdamped: return "contact_overdamped";
    case Branch::LoadGeneric: return "load_generic";
    case Branch::LoadFL0: return "load_FL0";
    case Branch::LoadFm0: return "load_Fm0";
    case Branch::LoadFm0FL0: return "load_Fm0_FL0";
    case Branch::LoadEqualRates: return "load_equal_rates";
    case Branch::MotorUnderdamped: return "motor_underdamped";
    case Branch::MotorCritical: return "motor_critical";
    case Branch::MotorOverdamped: return "motor_overdamped";
    case Branch::MotorUnderdampedFL0: return "motor_underdamped_FL0";
    case Branch::MotorCriticalFL0: return "motor_critical_FL0";
    case Branch::MotorOverdampedFL0: return "motor_overdamped_FL0";
  }
  return "?";
}

std::optional<Branch> branch_from_name(std::string_view name) {
  for (Branch b : all_branches())
    if (name == branch_name(b)) return b;
  return std::nullopt;
}

bool is_contact_branch(Branch branch) {
  return branch == Branch::ContactUnderdamped || branch == Branch::ContactCriticallyDamped ||
         branch == Branch::ContactOverdamped;
}

namespace {

// Sign of a − b, 0 when they agree to a few ulps (the rounding of exact
// parameters to doubles must not move a case off its branch; any genuine
// difference of relative size ≥ 1e-15 is resolved).
int compare(double a, double b) {
  const double scale = std::fabs(a) + std::fabs(b);
  const double difference = a - b;
  if (std::fabs(difference) <= 4 * std::numeric_limits<double>::epsilon() * scale) return 0;
  return difference > 0 ? 1 : -1;
}

}  // namespace

BranchSelection select_branches(const Parameters& p) {
  BranchSelection out;
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const int contact = compare(F * F, 4 * J * p.K);
  out.contact = contact < 0 ? Branch::ContactUnderdamped
                : contact == 0 ? Branch::ContactCriticallyDamped
                               : Branch::ContactOverdamped;
  const bool no_load_friction = p.FL == 0;
  if (p.measured_at == model::MeasuredAt::Load) {
    const bool no_motor_friction = p.Fm == 0;
    if (no_load_friction && no_motor_friction) out.free = Branch::LoadFm0FL0;
    else if (no_load_friction) out.free = Branch::LoadFL0;
    else if (no_motor_friction) out.free = Branch::LoadFm0;
    else if (compare(p.Fm * p.JL, p.FL * p.Jm) == 0) out.free = Branch::LoadEqualRates;
    else out.free = Branch::LoadGeneric;
  } else {
    const int motor = compare(p.Fm * p.Fm, 4 * p.Jm * p.K);
    if (motor < 0) out.free = no_load_friction ? Branch::MotorUnderdampedFL0 : Branch::MotorUnderdamped;
    else if (motor == 0) out.free = no_load_friction ? Branch::MotorCriticalFL0 : Branch::MotorCritical;
    else out.free = no_load_friction ? Branch::MotorOverdampedFL0 : Branch::MotorOverdamped;
  }
  return out;
}

double cot_phi(const Parameters& p) { return (p.Jm * p.FL - p.Fm * p.JL) / (p.K * p.JL); }

StableSegments::StableSegments(const Parameters& p)
    : p_(p),
      at_load_(p.measured_at == model::MeasuredAt::Load),
      cot_(numeric::cot_phi(p)),
      a_(p.Fm / p.Jm),
      b_(p.FL / p.JL),
      k_(p.K / p.Jm),
      a_minus_b_(a_ - b_),
      gap_factor_(k_ - b_ * a_minus_b_),
      motor_(damped_rates(p.Fm / (2 * p.Jm), p.K / p.Jm)),
      contact_(damped_rates((p.Fm + p.FL) / (2 * (p.Jm + p.JL)), p.K / (p.Jm + p.JL))) {}

FreeState StableSegments::free_state(double t, double v0) const {
  FreeState s;
  const double y = -b_ * t;
  const double theta0 = p_.theta_R + cot_ * v0;
  if (at_load_) {
    const LoadKernels q = detail::load_kernels_of(-a_ * t, y);
    const double t2 = t * t, t3 = t2 * t;
    s.theta_L = theta0 + v0 * t * q.phi1_y;
    s.dtheta_L = v0 * q.exp_y;
    s.theta_m = theta0 + v0 * (t * q.phi1_x + a_minus_b_ * t2 * q.phi2_x - k_ * t3 * q.a2);
    s.dtheta_m = v0 * (q.exp_x + a_minus_b_ * t * q.phi1_x - k_ * t2 * q.a1);
    s.gap = v0 * gap_factor_ * t3 * q.a2;
  } else {
    const ExpPhi1 load = exp_phi1(y);
    const double phi1_y = load.phi1_x;
    s.theta_L = theta0 + v0 * t * phi1_y;
    s.dtheta_L = v0 * load.exp_x;
    const double e0 = theta0 - p_.theta_R;
    const DampedPair q = damped_pair(motor_, t);
    const double e = e0 * q.c + (v0 + motor_.alpha * e0) * q.s;
    s.theta_m = p_.theta_R + e;
    s.dtheta_m = v0 * q.c - (motor_.alpha * v0 + motor_.w2 * e0) * q.s;
    // θL − θm = (θ0 − θR) + θ̇m0 t φ1(y) − e(t)
    s.gap = e0 + v0 * t * phi1_y - e;
  }
  return s;
}

ContactState StableSegments::contact_state(double t, double theta_o0, double dtheta_o0) const {
  const double e0 = theta_o0 - p_.theta_R;
  const DampedPair q = detail::damped_pair_of(contact_, t);
  return {p_.theta_R + e0 * q.c + (dtheta_o0 + contact_.alpha * e0) * q.s,
          dtheta_o0 * q.c - (contact_.alpha * dtheta_o0 + contact_.w2 * e0) * q.s};
}

namespace {

// The parametric evaluator (evaluator.hpp), beside its closed forms: its evaluations inline
// StableSegments' (one call per evaluation, the same bits).
class ParametricEvaluator final : public SegmentEvaluator {
 public:
  explicit ParametricEvaluator(const Parameters& p) : segments_(p), branches_(select_branches(p)) {}
  std::string name() const override { return "parametric (stable)"; }
  std::string kind() const override { return "parametric"; }
  const Parameters& parameters() const override { return segments_.parameters(); }
  BranchSelection branches() const override { return branches_; }
  double cot_phi() const override { return segments_.cot_phi(); }
  FreeState free_state(double t, double v0) const override { return segments_.free_state(t, v0); }
  ContactState contact_state(double t, double x0, double v0) const override {
    return segments_.contact_state(t, x0, v0);
  }

 private:
  StableSegments segments_;
  BranchSelection branches_;
};

}  // namespace

EvaluatorPtr parametric_evaluator(const Parameters& p) { return std::make_shared<ParametricEvaluator>(p); }

FreeState free_state(const Parameters& p, double t, double v0) { return StableSegments(p).free_state(t, v0); }

ContactState contact_state(const Parameters& p, double t, double theta_o0, double dtheta_o0) {
  return StableSegments(p).contact_state(t, theta_o0, dtheta_o0);
}

const std::vector<BranchRepresentative>& branch_representatives() {
  using M = model::MeasuredAt;
  auto make = [](Branch b, double Jm, double Fm, double JL, double FL, double K, double theta_R, double backlash, M where,
                 const char* description) {
    return BranchRepresentative{b, Parameters{Jm, Fm, JL, FL, K, theta_R, backlash, where}, description};
  };
  static const std::vector<BranchRepresentative> representatives{
      make(Branch::ContactUnderdamped, 0.5, 0.1, 0.5, 0.3, 1, 1, 0.3, M::Load, "case V: F^2 = 0.16 < 4JK = 4"),
      make(Branch::ContactCriticallyDamped, 0.5, 1, 0.5, 1, 1, 0.5, 0.2, M::Load, "J = 1, F = 2, K = 1: F^2 = 4JK"),
      make(Branch::ContactOverdamped, 0.5, 1, 0.5, 2, 1, -0.5, 0.2, M::Load, "J = 1, F = 3, K = 1: F^2 > 4JK"),
      make(Branch::LoadGeneric, 0.2, 0.3, 0.8, 0.1, 1, 1, 0.3, M::Load, "case VIII"),
      make(Branch::LoadFL0, 0.5, 0.2, 0.5, 0, 1, 1, 0.3, M::Load, "case III: FL = 0"),
      make(Branch::LoadFm0, 0.5, 0, 0.5, 0.3, 1, 1, 0.3, M::Load, "Fm = 0"),
      make(Branch::LoadFm0FL0, 0.5, 0, 0.5, 0, 1, 1, 0.3, M::Load, "Fm = FL = 0"),
      make(Branch::LoadEqualRates, 0.5, 0.25, 0.5, 0.25, 1, 1, 0.3, M::Load, "Fm/Jm = FL/JL = 1/2"),
      make(Branch::MotorUnderdamped, 0.6, 0.48, 0.4, 0.32, 1, 1, 0.2, M::Motor, "case I"),
      make(Branch::MotorCritical, 0.25, 1, 0.5, 0.3, 1, 1, 0.2, M::Motor, "Jm = 1/4, Fm = 1, K = 1: Fm^2 = 4JmK"),
      make(Branch::MotorOverdamped, 0.25, 2, 0.5, 0.3, 1, 1, 0.2, M::Motor, "Jm = 1/4, Fm = 2, K = 1: Fm^2 > 4JmK"),
      make(Branch::MotorUnderdampedFL0, 0.5, 0.2, 0.5, 0, 1, 1, 0.3, M::Motor, "case II: FL = 0"),
      make(Branch::MotorCriticalFL0, 0.25, 1, 0.5, 0, 1, 1, 0.2, M::Motor, "Fm^2 = 4JmK, FL = 0"),
      make(Branch::MotorOverdampedFL0, 0.25, 2, 0.5, 0, 1, 1, 0.2, M::Motor, "Fm^2 > 4JmK, FL = 0"),
  };
  return representatives;
}

}  // namespace backlash::numeric
