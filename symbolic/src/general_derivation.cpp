#include "backlash/symbolic/general_derivation.hpp"

namespace backlash::symbolic {

using namespace GiNaC;

const GeneralSymbols& general_symbols() {
  static const GeneralSymbols symbols{possymbol("Jm", "J_m"), possymbol("Fm", "F_m"), possymbol("JL", "J_L"),
                                      possymbol("FL", "F_L"), possymbol("K", "K"),    realsymbol("theta_R", "\\theta_R")};
  return symbols;
}

std::string contact_branch_name(ContactBranch branch) { return std::string("contact_") + to_string(branch); }
std::string free_branch_name(FreeBranch branch) { return to_string(branch); }

namespace {

CaseParameters symbolic_parameters(model::MeasuredAt where) {
  const GeneralSymbols& g = general_symbols();
  return CaseParameters{g.Jm, g.Fm, g.JL, g.FL, g.K, g.theta_R, 0, where};
}

CaseParameters substituted(CaseParameters p, const exmap& substitution) {
  for (ex* field : {&p.Jm, &p.Fm, &p.JL, &p.FL, &p.K, &p.theta_R}) *field = normal(field->subs(substitution));
  return p;
}

GeneralBranch make_branch(const std::string& name, GeneralBranch::Mode mode, const std::string& condition,
                          model::MeasuredAt where, exmap substitution, std::vector<BranchParameter> parameters) {
  GeneralBranch branch;
  branch.name = name;
  branch.mode = mode;
  branch.condition = condition;
  branch.substitution = std::move(substitution);
  branch.branch_parameters = std::move(parameters);
  branch.parameters = substituted(symbolic_parameters(where), branch.substitution);
  RadicalList radicals;  // branch parameters are plain positive symbols: no relations needed
  if (mode == GeneralBranch::Mode::Contact)
    branch.contact = derive_contact(branch.parameters, radicals, branch.checks);
  else
    branch.free = derive_free(branch.parameters, radicals, branch.checks);
  require_all_checks_passed("general branch " + name, branch.checks);
  return branch;
}

}  // namespace

std::vector<GeneralBranch> derive_general_branches() {
  const GeneralSymbols& g = general_symbols();
  using Mode = GeneralBranch::Mode;
  const auto Load = model::MeasuredAt::Load;
  const auto Motor = model::MeasuredAt::Motor;
  const ex J = g.Jm + g.JL, F = g.Fm + g.FL;
  const ex a_c = F / (2 * J), a_m = g.Fm / (2 * g.Jm);
  const possymbol omega_c("omega_c", "\\omega_c"), delta_c("delta_c", "\\delta_c");
  const possymbol omega_m("omega_m", "\\omega_m"), delta_m("delta_m", "\\delta_m");
  const BranchParameter w_c{omega_c, g.K / J - a_c * a_c, "damped frequency of the combined system"};
  const BranchParameter d_c{delta_c, a_c * a_c - g.K / J, "half-distance of the combined system's real poles"};
  const BranchParameter w_m{omega_m, g.K / g.Jm - a_m * a_m, "damped frequency of the motor-alone closed loop"};
  const BranchParameter d_m{delta_m, a_m * a_m - g.K / g.Jm, "half-distance of the motor-alone real poles"};

  std::vector<GeneralBranch> branches;
  branches.push_back(make_branch("contact_underdamped", Mode::Contact, "F^2 < 4*J*K", Load,
                                 {{g.K, J * (pow(omega_c, 2) + a_c * a_c)}}, {w_c}));
  branches.push_back(make_branch("contact_critically_damped", Mode::Contact, "F^2 = 4*J*K", Load, {{g.K, J * a_c * a_c}}, {}));
  branches.push_back(make_branch("contact_overdamped", Mode::Contact, "F^2 > 4*J*K", Load,
                                 {{g.K, J * (a_c * a_c - pow(delta_c, 2))}}, {d_c}));

  branches.push_back(make_branch("load_generic", Mode::Free, "output at load; Fm > 0, FL > 0, Fm/Jm != FL/JL", Load, {}, {}));
  branches.push_back(make_branch("load_FL0", Mode::Free, "output at load; FL = 0, Fm > 0", Load, {{g.FL, 0}}, {}));
  branches.push_back(make_branch("load_Fm0", Mode::Free, "output at load; Fm = 0, FL > 0", Load, {{g.Fm, 0}}, {}));
  branches.push_back(make_branch("load_Fm0_FL0", Mode::Free, "output at load; Fm = FL = 0", Load, {{g.Fm, 0}, {g.FL, 0}}, {}));
  branches.push_back(make_branch("load_equal_rates", Mode::Free, "output at load; Fm/Jm = FL/JL > 0", Load,
                                 {{g.FL, g.Fm * g.JL / g.Jm}}, {}));

  const ex K_under = g.Jm * (pow(omega_m, 2) + a_m * a_m), K_critical = g.Jm * a_m * a_m,
           K_over = g.Jm * (a_m * a_m - pow(delta_m, 2));
  for (bool no_load_friction : {false, true}) {
    const std::string suffix = no_load_friction ? "_FL0" : "";
    const std::string load_condition = no_load_friction ? "; FL = 0" : "; FL > 0";
    auto with_load = [&](exmap m) {
      if (no_load_friction) m[g.FL] = 0;
      return m;
    };
    branches.push_back(make_branch("motor_underdamped" + suffix, Mode::Free, "output at motor; Fm^2 < 4*Jm*K" + load_condition,
                                   Motor, with_load({{g.K, K_under}}), {w_m}));
    branches.push_back(make_branch("motor_critical" + suffix, Mode::Free, "output at motor; Fm^2 = 4*Jm*K" + load_condition,
                                   Motor, with_load({{g.K, K_critical}}), {}));
    branches.push_back(make_branch("motor_overdamped" + suffix, Mode::Free, "output at motor; Fm^2 > 4*Jm*K" + load_condition,
                                   Motor, with_load({{g.K, K_over}}), {d_m}));
  }
  return branches;
}

namespace {

bool same_solution(const std::string& what, const TimeFunction& general, const exmap& numbers,
                   const TimeFunction& specific, const RadicalList& radicals, std::string* why) {
  const TimeFunction difference = general.subs(numbers) - specific;
  if (difference.is_zero(radicals)) return true;
  if (why) *why = what + ": branch gives " + text(general.subs(numbers).combined(radicals).to_ex(derivation_symbols().t)) +
                  " instead of " + text(specific.to_ex(derivation_symbols().t));
  return false;
}

}  // namespace

bool reproduces_case(const GeneralBranch& branch, const CaseDerivation& d, std::string* why) {
  const GeneralSymbols& g = general_symbols();
  const CaseParameters& p = d.parameters;
  exmap numbers{{g.Jm, p.Jm}, {g.Fm, p.Fm}, {g.JL, p.JL}, {g.FL, p.FL}, {g.K, p.K}, {g.theta_R, p.theta_R}};
  // The branch's substitution must hold for the case's numbers (e.g. FL = 0).
  for (const auto& [physical, replacement] : branch.substitution) {
    bool replaced_by_parameter = false;
    for (const BranchParameter& bp : branch.branch_parameters) replaced_by_parameter |= replacement.has(bp.symbol);
    if (!replaced_by_parameter && !normal(physical.subs(numbers) - replacement.subs(numbers)).is_zero()) {
      if (why) *why = "the case does not satisfy the branch condition " + branch.condition;
      return false;
    }
  }
  // Each branch parameter becomes the case's radical (or rational) of the same square.
  for (const BranchParameter& bp : branch.branch_parameters) {
    const ex square = normal(bp.square_in_physical_parameters.subs(numbers));
    if (!is_a<numeric>(square) || !ex_to<numeric>(square).is_positive()) {
      if (why) *why = "branch parameter " + bp.symbol.get_name() + " has square " + text(square) + " for this case";
      return false;
    }
    const ex root = canonical_sqrt(square);
    if (is_a<numeric>(root)) {
      numbers[bp.symbol] = root;
    } else if (const Radical* r = find_radical_with_square(d.radicals, square)) {
      numbers[bp.symbol] = r->symbol;
    } else {
      if (why) *why = "the case has no radical with square " + text(square);
      return false;
    }
  }
  if (branch.mode == GeneralBranch::Mode::Contact)
    return same_solution("theta_o", branch.contact.position.solution, numbers, d.contact.position.solution, d.radicals, why) &&
           same_solution("dtheta_o", branch.contact.velocity.solution, numbers, d.contact.velocity.solution, d.radicals, why);
  return same_solution("theta_m", branch.free.motor_position.solution, numbers, d.free.motor_position.solution, d.radicals, why) &&
         same_solution("dtheta_m", branch.free.motor_velocity.solution, numbers, d.free.motor_velocity.solution, d.radicals, why) &&
         same_solution("theta_L", branch.free.load_position.solution, numbers, d.free.load_position.solution, d.radicals, why) &&
         same_solution("dtheta_L", branch.free.load_velocity.solution, numbers, d.free.load_velocity.solution, d.radicals, why);
}

}  // namespace backlash::symbolic
