#include "backlash/numeric/direct_branches.hpp"

#include "backlash/generated/branches.hpp"

#include <stdexcept>

namespace backlash::numeric {

namespace gb = backlash::generated::branches;

namespace {

gb::Parameters generated(const Parameters& p) { return gb::Parameters{p.Jm, p.Fm, p.JL, p.FL, p.K, p.theta_R}; }

FreeState from(const gb::free_state_t& s) { return FreeState{s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, s.gap}; }
ContactState from(const gb::contact_state_t& s) { return ContactState{s.theta_o, s.dtheta_o}; }

}  // namespace

#define BACKLASH_FREE_BRANCHES(X)                                                                          \
  X(LoadGeneric, load_generic) X(LoadFL0, load_FL0) X(LoadFm0, load_Fm0) X(LoadFm0FL0, load_Fm0_FL0)      \
  X(LoadEqualRates, load_equal_rates) X(MotorUnderdamped, motor_underdamped) X(MotorCritical, motor_critical) \
  X(MotorOverdamped, motor_overdamped) X(MotorUnderdampedFL0, motor_underdamped_FL0)                        \
  X(MotorCriticalFL0, motor_critical_FL0) X(MotorOverdampedFL0, motor_overdamped_FL0)

FreeState direct_free_state(Branch branch, const Parameters& p, double t, double v0) {
  const gb::Parameters g = generated(p);
  switch (branch) {
#define X(enumerator, ns) \
  case Branch::enumerator: return from(gb::ns::free_state(g, t, v0));
    BACKLASH_FREE_BRANCHES(X)
#undef X
    default: break;
  }
  throw std::invalid_argument(std::string("direct_free_state: not a free-mode branch: ") + branch_name(branch));
}

double direct_cot_phi(Branch branch, const Parameters& p) {
  const gb::Parameters g = generated(p);
  switch (branch) {
#define X(enumerator, ns) \
  case Branch::enumerator: return gb::ns::cot_phi(g);
    BACKLASH_FREE_BRANCHES(X)
#undef X
    default: break;
  }
  throw std::invalid_argument(std::string("direct_cot_phi: not a free-mode branch: ") + branch_name(branch));
}

ContactState direct_contact_state(Branch branch, const Parameters& p, double t, double theta_o0, double dtheta_o0) {
  const gb::Parameters g = generated(p);
  switch (branch) {
    case Branch::ContactUnderdamped: return from(gb::contact_underdamped::contact_state(g, t, theta_o0, dtheta_o0));
    case Branch::ContactCriticallyDamped:
      return from(gb::contact_critically_damped::contact_state(g, t, theta_o0, dtheta_o0));
    case Branch::ContactOverdamped: return from(gb::contact_overdamped::contact_state(g, t, theta_o0, dtheta_o0));
    default: break;
  }
  throw std::invalid_argument(std::string("direct_contact_state: not a contact-mode branch: ") + branch_name(branch));
}

}  // namespace backlash::numeric
