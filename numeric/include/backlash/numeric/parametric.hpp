// backlash/numeric/parametric.hpp — parametric segment evaluators for any
// runtime parameters: the pole-structure branches, the dispatcher that picks
// one, and the stable evaluator that is accurate on and near every branch.
//
// Method (see numeric/evaluators/phi_functions.hpp for the building blocks).  With a = Fm/Jm,
// b = FL/JL, k = K/Jm, x = −a·t, y = −b·t and θ0 = θR + cot φ·θ̇m0 (the
// separation point), the free-mode solutions are written as divided
// differences of e^{st} over their poles instead of partial fractions:
//
//   load        θL  = θ0 + θ̇m0·t·φ1(y)                 θ̇L = θ̇m0·e^{y}
//   output at load (poles 0, 0, −a, −b):
//     θm  = θ0 + θ̇m0·[t φ1(x) + (a − b) t² φ2(x) − k t³ A2(x, y)]
//     θ̇m  = θ̇m0·[e^{x} + (a − b) t φ1(x) − k t² A1(x, y)]
//     gap = θL − θm = θ̇m0·(k − b(a − b))·t³·A2(x, y)
//     (Θm − θ0/s = θ̇m0/(s(s+a)) + (a−b)θ̇m0/(s²(s+a)) − kθ̇m0/(s²(s+a)(s+b)), and
//     1/∏(s − p_i) ↔ e^{·t}[p_i]); FL → 0, Fm → 0, Fm/Jm → FL/JL are limits the
//     formula passes through continuously.
//   output at motor: e = θm − θR solves e'' + 2αe' + w²e = 0, α = Fm/2Jm,
//     w² = K/Jm, e(0) = cot φ·θ̇m0, ė(0) = θ̇m0:
//     θm = θR + e0·c + (ė0 + α e0)·s,  θ̇m = ė0·c − (α ė0 + w² e0)·s
//     with (c, s) = damped_pair(α, w², t), continuous through critical damping.
//   contact: the same damped pair with α = F/2J, w² = K/J (J = Jm+JL, F = Fm+FL).
//
// The dispatcher (select_branches) names the branch the exact parameters
// would get from symbolic::classify_contact/classify_free, decided from the
// runtime doubles: FL == 0 and Fm == 0 exactly; F² = 4JK, Fm² = 4JmK and
// Fm·JL = FL·Jm when equal to within 4 ulps (so rounding exact parameters to
// doubles keeps a case on its branch, and any relative difference ≥ 1e-15 is
// resolved).  The stable
// evaluator does not need it — its formulas hold on every branch — but the
// direct generated formulas (direct_branches.hpp) do.
#pragma once

#include "backlash/numeric/parameters.hpp"

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace backlash::numeric {

/// Free-mode state at time t after separation (thesis convention: gap = θL − θm, 0 at separation).
struct FreeState {
  double theta_m = 0, dtheta_m = 0, theta_L = 0, dtheta_L = 0, gap = 0;
};
struct ContactState {
  double theta_o = 0, dtheta_o = 0;
};

/// The 14 pole-structure branches, in the order of symbolic::derive_general_branches().
enum class Branch : int {
  ContactUnderdamped, ContactCriticallyDamped, ContactOverdamped,
  LoadGeneric, LoadFL0, LoadFm0, LoadFm0FL0, LoadEqualRates,
  MotorUnderdamped, MotorCritical, MotorOverdamped,
  MotorUnderdampedFL0, MotorCriticalFL0, MotorOverdampedFL0,
};
inline constexpr int branch_count = 14;
const std::array<Branch, branch_count>& all_branches();
/// "contact_underdamped", "load_FL0", … (the names of symbolic/ and of the generated code).
const char* branch_name(Branch branch);
std::optional<Branch> branch_from_name(std::string_view name);
bool is_contact_branch(Branch branch);

struct BranchSelection {
  Branch contact = Branch::ContactUnderdamped;
  Branch free = Branch::LoadGeneric;
};
/// The dispatcher: the branches of these parameters, decided from the doubles.
BranchSelection select_branches(const Parameters& p);

/// cot φ = (Jm·FL − Fm·JL)/(K·JL).
double cot_phi(const Parameters& p);

/// The parameters of a damped pair (y'' + 2αy' + w²y = 0, α ≥ 0, w² ≥ 0) that do not depend on
/// time, formed once per parameter set: D = α² − w², ω = √(−D) (read when D < 0), δ = √D (read
/// when D > 0), the fast rate α + δ and the slow rate w²/(α + δ) of the over-damped tail (1/s).
struct DampedRates {
  double alpha = 0, w2 = 0, D = 0, omega = 0, delta = 0, fast = 0, slow = 0;
};

/// Stable parametric evaluators (accurate on and near every branch).
FreeState free_state(const Parameters& p, double t, double dtheta_m0);
ContactState contact_state(const Parameters& p, double t, double theta_o0, double dtheta_o0);

/// The same stable evaluators with the parameter combinations (rates, cot φ,
/// damping) computed once — for evaluating many points of one parameter set.
class StableSegments {
 public:
  explicit StableSegments(const Parameters& p);
  const Parameters& parameters() const { return p_; }
  double cot_phi() const { return cot_; }
  FreeState free_state(double t, double dtheta_m0) const;
  ContactState contact_state(double t, double theta_o0, double dtheta_o0) const;

 private:
  Parameters p_;
  bool at_load_;
  double cot_, a_, b_, k_, a_minus_b_, gap_factor_;  // output at load
  DampedRates motor_;                               // output at motor: α = Fm/2Jm, w² = K/Jm
  DampedRates contact_;                             // contact: α = F/2J, w² = K/J
};

/// A parameter set lying exactly on a branch (used by validation and tests).
struct BranchRepresentative {
  Branch branch;
  Parameters parameters;
  std::string description;
};
/// One representative per branch, in all_branches() order; select_branches
/// gives each its own branch.
const std::vector<BranchRepresentative>& branch_representatives();

}  // namespace backlash::numeric
