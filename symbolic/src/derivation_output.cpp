#include "backlash/symbolic/derivation_output.hpp"

#include <sstream>

namespace backlash::symbolic {

using namespace GiNaC;
using nlohmann::json;

namespace {

struct DigitsGuard {
  long saved;
  explicit DigitsGuard(long digits) : saved(Digits) { Digits = digits; }
  ~DigitsGuard() { Digits = saved; }
};

std::string decimal_expression(const ex& e, const RadicalList& radicals) {
  DigitsGuard guard(10);
  return text(evalf(with_explicit_radicals(e, radicals)));
}

json exact_and_decimal(const ex& e, const RadicalList& radicals) {
  json j;
  j["exact"] = text(with_explicit_radicals(e, radicals));
  try {
    j["decimal"] = to_double(e, radicals);
  } catch (...) {
    j["decimal"] = decimal_expression(e, radicals);
  }
  return j;
}

const char* oscillation_name(Oscillation o) {
  return o == Oscillation::None ? "none" : (o == Oscillation::Cos ? "cos" : "sin");
}

json terms_json(const TimeFunction& f, const RadicalList& radicals) {
  json terms = json::array();
  for (const ExpTerm& term : f.terms()) {
    json j;
    j["coefficient"] = exact_and_decimal(term.coefficient, radicals);
    j["t_power"] = term.t_power;
    j["rate"] = exact_and_decimal(term.rate, radicals);
    j["oscillation"] = oscillation_name(term.oscillation);
    if (term.oscillation != Oscillation::None) j["frequency"] = exact_and_decimal(term.frequency, radicals);
    terms.push_back(j);
  }
  return terms;
}

json segment_json(const Segment& segment, const RadicalList& radicals) {
  json j;
  j["thesis_equations"] = segment.equations;
  j["laplace"] = text(with_explicit_radicals(segment.laplace, radicals));
  j["exact"] = exact_text(segment.solution, radicals);
  j["decimal"] = decimal_text(segment.solution, radicals);
  j["terms"] = terms_json(segment.solution, radicals);
  return j;
}

json checks_json(const std::vector<VerificationCheck>& checks) {
  json list = json::array();
  bool all = !checks.empty();
  for (const VerificationCheck& c : checks) {
    list.push_back({{"name", c.name}, {"passed", c.passed}});
    all = all && c.passed;
  }
  return {{"status", all ? "verified" : "failed"}, {"checks", list}};
}

json radicals_json(const RadicalList& radicals) {
  json list = json::array();
  for (const Radical& r : radicals)
    list.push_back({{"name", r.symbol.get_name()},
                    {"square", text(r.square)},
                    {"exact", text(canonical_sqrt(r.square))},
                    {"decimal", to_double(r.symbol, radicals)},
                    {"meaning", r.role}});
  return list;
}

json isocline_json(const IsoclineTable& table) {
  json rows = json::array();
  for (const IsoclineRow& row : table.rows) {
    json j;
    j["eta"] = row.is_infinite ? json("inf") : json(text(row.eta));
    j["vertical"] = row.is_vertical;
    j["tangent"] = row.is_vertical ? json("inf") : json(text(row.tangent));
    j["angle_degrees"] = {{"exact", text(row.angle_degrees)}, {"decimal", to_double(row.angle_degrees, {})}};
    rows.push_back(j);
  }
  return {{"system", table.system}, {"J", text(table.inertia)}, {"F", text(table.friction)}, {"rows", rows}};
}

json stability_json(const StabilityConstant& c, const RadicalList& radicals) {
  json j{{"applicable", c.applicable}, {"region", c.region}};
  if (c.applicable) {
    j["C"] = text(with_explicit_radicals(c.C, radicals));
    j["dlnC_dt"] = text(c.dlnC_dt);
    j["jump_factor_at_theta_R"] = exact_and_decimal(c.jump_factor, radicals);
  }
  return j;
}

std::string latex_of(const ex& e, const RadicalList& radicals) { return latex(with_explicit_radicals(e, radicals)); }

std::string latex_of(const TimeFunction& f, const RadicalList& radicals) {
  return latex_of(f.to_ex(derivation_symbols().t), radicals);
}

std::string measured_at_text(model::MeasuredAt where) { return where == model::MeasuredAt::Motor ? "motor" : "load"; }

}  // namespace

std::string exact_text(const TimeFunction& f, const RadicalList& radicals) {
  return text(with_explicit_radicals(f.to_ex(derivation_symbols().t), radicals));
}

std::string decimal_text(const TimeFunction& f, const RadicalList& radicals) {
  return decimal_expression(f.to_ex(derivation_symbols().t), radicals);
}

json to_json(const CaseDerivation& d) {
  const RadicalList& r = d.radicals;
  const CaseParameters& p = d.parameters;
  json j;
  j["case"] = d.case_id;
  j["name"] = d.name;
  j["measured_at"] = measured_at_text(p.measured_at);
  j["parameters"] = {{"Jm", exact_and_decimal(p.Jm, r)}, {"Fm", exact_and_decimal(p.Fm, r)},
                     {"JL", exact_and_decimal(p.JL, r)}, {"FL", exact_and_decimal(p.FL, r)},
                     {"K", exact_and_decimal(p.K, r)},   {"theta_R", exact_and_decimal(p.theta_R, r)},
                     {"backlash", exact_and_decimal(p.backlash, r)}};
  j["radicals"] = radicals_json(r);
  j["branches"] = {{"contact", contact_branch_name(d.contact_branch)}, {"free", free_branch_name(d.free_branch)}};
  j["contact"] = {{"initial_state", {"theta_o0", "dtheta_o0"}},
                  {"theta_o", segment_json(d.contact.position, r)},
                  {"dtheta_o", segment_json(d.contact.velocity, r)}};
  const ex phi_degrees = d.free.cot_phi.is_zero() ? ex(90) : ex(atan(1 / d.free.cot_phi) * 180 / Pi);
  double phi = to_double(phi_degrees, r);
  if (phi < 0) phi += 180;
  j["separation_line"] = {{"cot_phi", exact_and_decimal(d.free.cot_phi, r)},
                          {"phi_degrees", phi},
                          {"equation", "theta_o = theta_R + cot_phi * dtheta_o"},
                          {"theta_0", text(d.free.separation_theta)},
                          {"eta", exact_and_decimal(d.free.eta_separation, r)},
                          {"slopes_coincide", d.verified()}};
  j["free"] = {{"parameter", "dtheta_m0"},
               {"theta_m", segment_json(d.free.motor_position, r)},
               {"dtheta_m", segment_json(d.free.motor_velocity, r)},
               {"theta_L", segment_json(d.free.load_position, r)},
               {"dtheta_L", segment_json(d.free.load_velocity, r)},
               {"gap", {{"exact", exact_text(d.free.gap, r)}, {"meaning", "theta_L - theta_m; recombination when it reaches the backlash b (or returns to 0)"}}}};
  j["momentum_balance"] = {{"equation", "(Jm+JL)*dtheta_o = Jm*dtheta_m + JL*dtheta_L (eq. 24)"},
                           {"dtheta_o_after", {{"exact", exact_text(d.free.recombined_velocity, r)},
                                               {"decimal", decimal_text(d.free.recombined_velocity, r)}}}};
  json isoclines = json::array();
  for (const IsoclineTable& t : d.isoclines) isoclines.push_back(isocline_json(t));
  j["isoclines"] = isoclines;
  j["stability_constant"] = stability_json(d.contact.stability, r);
  j["verification"] = checks_json(d.checks);
  return j;
}

json to_json(const GeneralBranch& b) {
  json j;
  j["branch"] = b.name;
  j["condition"] = b.condition;
  json subs = json::object();
  for (const auto& [k, v] : b.substitution) subs[text(k)] = text(v);
  j["substitution"] = subs;
  json params = json::array();
  for (const BranchParameter& p : b.branch_parameters)
    params.push_back({{"name", p.symbol.get_name()}, {"square", text(p.square_in_physical_parameters)}, {"meaning", p.meaning}});
  j["branch_parameters"] = params;
  if (b.mode == GeneralBranch::Mode::Contact) {
    j["theta_o"] = segment_json(b.contact.position, {});
    j["dtheta_o"] = segment_json(b.contact.velocity, {});
  } else {
    j["cot_phi"] = text(b.free.cot_phi);
    j["theta_m"] = segment_json(b.free.motor_position, {});
    j["dtheta_m"] = segment_json(b.free.motor_velocity, {});
    j["theta_L"] = segment_json(b.free.load_position, {});
    j["dtheta_L"] = segment_json(b.free.load_velocity, {});
  }
  j["verification"] = checks_json(b.checks);
  return j;
}

std::string to_latex(const CaseDerivation& d) {
  const RadicalList& r = d.radicals;
  const CaseParameters& p = d.parameters;
  std::ostringstream out;
  out << "\\section*{" << d.name << " (case " << d.case_id << "), output at the " << measured_at_text(p.measured_at) << "}\n";
  out << "Parameters: $J_m = " << latex(p.Jm) << "$, $F_m = " << latex(p.Fm) << "$, $J_L = " << latex(p.JL)
      << "$, $F_L = " << latex(p.FL) << "$, $K = " << latex(p.K) << "$, $\\theta_R = " << latex(p.theta_R)
      << "$, backlash $b = " << latex(p.backlash) << "$.\n\n";
  for (const Radical& rad : r)
    out << "$$" << latex(rad.symbol) << " = \\sqrt{" << latex(rad.square) << "} = " << latex(canonical_sqrt(rad.square))
        << "\\quad\\text{(" << rad.role << ")}$$\n";
  out << "\\subsection*{Contact mode (eqs. 6, 15, 25), " << to_string(d.contact_branch) << "}\n";
  out << "$$\\Theta_o(s) = " << latex_of(d.contact.position.laplace, r) << "$$\n";
  out << "$$\\theta_o(t) = " << latex_of(d.contact.position.solution, r) << "$$\n";
  out << "$$\\dot\\theta_o(t) = " << latex_of(d.contact.velocity.solution, r) << "$$\n";
  out << "\\subsection*{Separation line}\n";
  out << "$$\\theta_o = \\theta_R + \\cot\\phi\\,\\dot\\theta_o,\\qquad \\cot\\phi = \\frac{J_m F_L - F_m J_L}{K J_L} = "
      << latex(d.free.cot_phi) << ",\\qquad \\eta_1 = \\eta_2 = \\eta_3 = " << latex(d.free.eta_separation) << "$$\n";
  out << "\\subsection*{Free mode (" << to_string(d.free_branch) << "), from $\\theta_m(0) = \\theta_L(0) = "
      << latex(d.free.separation_theta) << "$, $\\dot\\theta_m(0) = \\dot\\theta_L(0) = \\dot\\theta_{m0}$}\n";
  auto segment = [&](const char* name, const Segment& s) {
    out << "$$" << name << "(s) = " << latex_of(s.laplace, r) << "$$\n";
    out << "$$" << name << "(t) = " << latex_of(s.solution, r) << "\\qquad\\text{(eqs. " << s.equations << ")}$$\n";
  };
  segment("\\theta_m", d.free.motor_position);
  segment("\\dot\\theta_m", d.free.motor_velocity);
  segment("\\theta_L", d.free.load_position);
  segment("\\dot\\theta_L", d.free.load_velocity);
  out << "\\subsection*{Recombination (eq. 24)}\n";
  out << "$$\\dot\\theta_o^{+}(t) = \\frac{J_m\\dot\\theta_m + J_L\\dot\\theta_L}{J_m + J_L} = "
      << latex_of(d.free.recombined_velocity, r) << "$$\n";
  if (d.contact.stability.applicable) {
    out << "\\subsection*{Stability constant (eq. 38)}\n";
    out << "$$C = " << latex_of(d.contact.stability.C, r) << ",\\qquad \\frac{d\\ln C}{dt} = "
        << latex(d.contact.stability.dlnC_dt) << "$$\n";
    out << d.contact.stability.region << ".\n";
  }
  out << "\\subsection*{Verification}\n\\begin{itemize}\n";
  for (const VerificationCheck& c : d.checks) out << "\\item " << (c.passed ? "verified: " : "FAILED: ") << "\\verb|" << c.name << "|\n";
  out << "\\end{itemize}\n";
  return out.str();
}

std::string to_latex(const GeneralBranch& b) {
  std::ostringstream out;
  out << "\\subsection*{Branch \\texttt{" << b.name << "}: " << b.condition << "}\n";
  for (const BranchParameter& p : b.branch_parameters)
    out << "$$" << latex(p.symbol) << " = \\sqrt{" << latex(p.square_in_physical_parameters) << "}$$\n";
  auto line = [&](const char* name, const Segment& s) {
    out << "$$" << name << "(t) = " << latex(s.solution.to_ex(derivation_symbols().t)) << "$$\n";
  };
  if (b.mode == GeneralBranch::Mode::Contact) {
    line("\\theta_o", b.contact.position);
  } else {
    line("\\theta_m", b.free.motor_position);
    line("\\theta_L", b.free.load_position);
  }
  return out.str();
}

std::string to_text(const CaseDerivation& d) {
  const RadicalList& r = d.radicals;
  std::ostringstream out;
  out << d.name << " (case " << d.case_id << "), output at the " << measured_at_text(d.parameters.measured_at) << "\n";
  for (const Radical& rad : r) out << "  " << rad.symbol.get_name() << " = sqrt(" << rad.square << ") = " << canonical_sqrt(rad.square) << "\n";
  out << "contact (" << to_string(d.contact_branch) << "):\n  theta_o(t) = " << exact_text(d.contact.position.solution, r) << "\n";
  out << "separation line: theta_o = theta_R + cot_phi*dtheta_o, cot_phi = " << d.free.cot_phi << "\n";
  out << "free (" << to_string(d.free_branch) << "):\n";
  out << "  theta_m(t)  = " << exact_text(d.free.motor_position.solution, r) << "\n";
  out << "             ~ " << decimal_text(d.free.motor_position.solution, r) << "\n";
  out << "  dtheta_m(t) = " << exact_text(d.free.motor_velocity.solution, r) << "\n";
  out << "  theta_L(t)  = " << exact_text(d.free.load_position.solution, r) << "\n";
  out << "  dtheta_L(t) = " << exact_text(d.free.load_velocity.solution, r) << "\n";
  out << "verification: " << (d.verified() ? "verified" : "FAILED") << " (" << d.checks.size() << " exact checks)\n";
  return out.str();
}

}  // namespace backlash::symbolic
