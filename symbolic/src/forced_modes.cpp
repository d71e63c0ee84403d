#include "backlash/symbolic/forced_modes.hpp"

#include "backlash/symbolic/derivation_output.hpp"
#include "backlash/symbolic/escape.hpp"
#include "backlash/symbolic/inverse_laplace.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <stdexcept>
#include <utility>

namespace backlash::symbolic {

using namespace GiNaC;
using nlohmann::json;
namespace pp = pretty;

const ForcedSymbols& forced_symbols() {
  static const ForcedSymbols symbols{
      realsymbol("w0", "\\omega_0"), realsymbol("g", "g"),         realsymbol("v0", "v_0"),
      realsymbol("y0", "y_0"),       realsymbol("vm0", "v_{m0}"),  realsymbol("yL0", "y_{L0}"),
      realsymbol("vL0", "v_{L0}"),   realsymbol("um", "u_m"),      realsymbol("uL", "u_L"),
  };
  return symbols;
}

const ForcedOutput& ForcedSolution::output(const std::string& output_name) const {
  for (const ForcedOutput& o : outputs)
    if (o.segment.name == output_name) return o;
  throw std::out_of_range("forced mode " + name + " has no output " + output_name);
}

std::vector<const ForcedSolution*> ForcedModes::solutions() const {
  std::vector<const ForcedSolution*> out{&contact_constant, &load_constant, &motor_constant};
  if (motor_closed) out.push_back(&*motor_closed);
  if (coupled) out.push_back(&*coupled);
  return out;
}

bool ForcedModes::verified() const {
  for (const VerificationCheck& check : checks)
    if (!check.passed) return false;
  return !checks.empty();
}

namespace {

const char* const motor_frequency_role = "damped frequency of the motor-alone closed loop, sqrt(K/Jm - Fm^2/(4Jm^2))";

// Exactly zero as an expression: normal(expand(·)) with the radicals written as square roots.
bool expression_is_zero(const ex& e, const RadicalList& radicals) {
  return normal(expand(with_explicit_radicals(e, radicals))).is_zero();
}

// The checks of one mode, each recorded under "<mode>: <what>".  Every property is
// checked on the structured TimeFunction (the derivations' own verification: like
// terms combined, radicals reduced by their relations) and again on the plain
// expression in t, differentiated by GiNaC, radicals explicit, normal(expand(·)) = 0.
class Verifier {
 public:
  Verifier(std::string mode, std::vector<VerificationCheck>& checks, const RadicalList& radicals)
      : mode_(std::move(mode)), checks_(checks), radicals_(radicals) {}

  /// a2 y'' + a1 y' + a0 y = forcing.
  void ode(const std::string& what, const TimeFunction& y, const ex& a2, const ex& a1, const ex& a0,
           const TimeFunction& forcing) {
    const TimeFunction dy = y.derivative();
    const TimeFunction residual = dy.derivative() * a2 + dy * a1 + y * a0 - forcing;
    expect(what, residual.is_zero(radicals_));
    const ex& t = derivation_symbols().t;
    const ex Y = y.to_ex(t);
    const ex r = a2 * Y.diff(ex_to<symbol>(t), 2) + a1 * Y.diff(ex_to<symbol>(t)) + a0 * Y - forcing.to_ex(t);
    expect(what + " [normal(expand(residual(t))) = 0]", expression_is_zero(r, radicals_));
  }
  /// f(0) = value.
  void initial(const std::string& what, const TimeFunction& f, const ex& value) {
    expect(what, is_exactly_zero(f.at_zero() - value, radicals_));
    const ex& t = derivation_symbols().t;
    expect(what + " [normal(expand(f(0) - value)) = 0]", expression_is_zero(f.to_ex(t).subs(t == 0) - value, radicals_));
  }
  /// f'(0) = value.
  void initial_rate(const std::string& what, const TimeFunction& f, const ex& value) {
    expect(what, is_exactly_zero(f.derivative().at_zero() - value, radicals_));
    const ex& t = derivation_symbols().t;
    expect(what + " [normal(expand(f'(0) - value)) = 0]",
           expression_is_zero(f.to_ex(t).diff(ex_to<symbol>(t)).subs(t == 0) - value, radicals_));
  }
  /// a ≡ b (e.g. the inverse of s·X − x(0) is the derivative of x).
  void same(const std::string& what, const TimeFunction& a, const TimeFunction& b) {
    expect(what, (a - b).is_zero(radicals_));
    const ex& t = derivation_symbols().t;
    expect(what + " [normal(expand(a(t) - b(t))) = 0]", expression_is_zero(a.to_ex(t) - b.to_ex(t), radicals_));
  }

 private:
  void expect(const std::string& what, bool passed) { checks_.push_back({mode_ + ": " + what, passed}); }
  std::string mode_;
  std::vector<VerificationCheck>& checks_;
  const RadicalList& radicals_;
};

ForcedOutput make_output(const std::string& name, const std::string& equations, const ex& laplace, RadicalList& radicals,
                         const std::string& lhs_latex, const std::string& meaning, const std::string& radical_name = "",
                         const std::string& radical_role = "") {
  ForcedOutput out;
  out.segment = Segment{name, equations, laplace,
                        inverse_laplace(laplace, derivation_symbols().s, radicals, radical_name, radical_role)};
  out.lhs_latex = lhs_latex;
  out.meaning = meaning;
  return out;
}

// "c·x" in LaTeX with the model's number c (terminating decimal when short), "" for c = 0.
std::string scaled_latex(const ex& c, const std::string& x) {
  const ex v = normal(c);
  if (v.is_zero()) return "";
  if (v == 1) return x;
  return model_number_latex(v) + "\\," + x;
}

// a2·D'' + a1·D' (+ a0·D) in LaTeX.
std::string ode_lhs_latex(const ex& a2, const ex& a1, const ex& a0, const std::string& second, const std::string& first,
                          const std::string& zeroth) {
  std::string out;
  for (const std::string& piece : {scaled_latex(a2, second), scaled_latex(a1, first), scaled_latex(a0, zeroth)}) {
    if (piece.empty()) continue;
    if (out.empty()) out = piece;
    else if (piece[0] == '-') out += " - " + piece.substr(1);
    else out += " + " + piece;
  }
  return out.empty() ? "0" : out;
}

std::string number_text(const ex& value) { return pp::text(value); }

// J Δ'' + F Δ' = g from Δ(0) = 0, Δ'(0) = v (a body, or the pair in contact, under a constant torque).
ForcedSolution constant_torque_mode(const std::string& name, const std::string& meaning, const ex& inertia,
                                    const ex& friction, const std::string& inertia_name, const std::string& friction_name,
                                    const ex& initial_velocity, const std::string& velocity_name,
                                    const std::string& subscript, const std::string& angle,
                                    const std::string& equations, RadicalList& radicals,
                                    std::vector<VerificationCheck>& checks) {
  const DerivationSymbols& x = derivation_symbols();
  const ForcedSymbols& f = forced_symbols();
  const ex& s = x.s;
  ForcedSolution out;
  out.name = name;
  out.meaning = meaning;
  out.arguments = {initial_velocity, f.g};
  out.argument_names = {velocity_name, "g"};
  out.equation = inertia_name + "*D'' + " + friction_name + "*D' = g, " + inertia_name + " = " + number_text(inertia) +
                 ", " + friction_name + " = " + number_text(friction) + "; D(0) = 0, D'(0) = " + velocity_name;
  const std::string D = "\\Delta" + subscript;
  const std::string lhs = ode_lhs_latex(inertia, friction, 0, "\\ddot\\Delta" + subscript, "\\dot\\Delta" + subscript, "");
  out.equation_latex = lhs + " = g,\\quad " + D + "(0) = 0,\\ \\dot\\Delta" + subscript + "(0) = " +
                       (velocity_name == "w0" ? std::string("\\omega_0") : std::string("v_0"));
  // J (s² X − v) + F s X = g/s
  const ex transform = (inertia * initial_velocity + f.g / s) / (s * (inertia * s + friction));
  out.outputs.push_back(make_output("displacement", equations, transform, radicals, D + "(t)",
                                    "displacement " + angle + "(t) - " + angle + "(0)"));
  out.outputs.push_back(make_output("velocity", equations, s * transform, radicals, "\\dot\\Delta" + subscript + "(t)",
                                    "velocity " + angle + "'(t)"));
  const TimeFunction& position = out.outputs[0].segment.solution;
  Verifier check(name, checks, radicals);
  check.ode(inertia_name + "*D'' + " + friction_name + "*D' = g", position, inertia, friction, 0,
            TimeFunction::constant(f.g));
  check.initial("D(0) = 0", position, 0);
  check.initial_rate("D'(0) = " + velocity_name, position, initial_velocity);
  check.same("L^-1[s*X - D(0)] = d/dt D", out.outputs[1].segment.solution, position.derivative());
  return out;
}

ForcedSolution motor_closed_mode(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks) {
  const DerivationSymbols& x = derivation_symbols();
  const ForcedSymbols& f = forced_symbols();
  const ex& s = x.s;
  ForcedSolution out;
  out.name = "motor_closed";
  out.meaning =
      "free motor, output measured at the motor, drive linear: y = theta_m - theta_R - (T0 - Tm*sm)/K, the deviation "
      "from the equilibrium the offset and the Coulomb torque shift";
  out.arguments = {f.y0, f.v0};
  out.argument_names = {"y0", "v0"};
  out.equation = "Jm*y'' + Fm*y' + K*y = 0, Jm = " + number_text(p.Jm) + ", Fm = " + number_text(p.Fm) +
                 ", K = " + number_text(p.K) + "; y(0) = y0, y'(0) = v0";
  out.equation_latex = ode_lhs_latex(p.Jm, p.Fm, p.K, "\\ddot y", "\\dot y", "y") + " = 0,\\quad y(0) = y_0,\\ \\dot y(0) = v_0";
  const ex transform = (p.Jm * (s * f.y0 + f.v0) + p.Fm * f.y0) / (p.Jm * s * s + p.Fm * s + p.K);
  const std::string equations = "16, 18, 20, 21 (shifted)";
  out.outputs.push_back(make_output("y", equations, transform, radicals, "y(t)", "deviation y(t)", "omega_m",
                                    motor_frequency_role));
  out.outputs.push_back(make_output("velocity", equations, s * transform - f.y0, radicals, "\\dot y(t)",
                                    "velocity y'(t) = theta_m'(t)", "omega_m", motor_frequency_role));
  out.outputs.push_back(make_output("displacement", equations, transform - f.y0 / s, radicals, "\\Delta_m(t)",
                                    "displacement theta_m(t) - theta_m(0) = y(t) - y0", "omega_m",
                                    motor_frequency_role));
  const TimeFunction& y = out.outputs[0].segment.solution;
  Verifier check(out.name, checks, radicals);
  check.ode("Jm*y'' + Fm*y' + K*y = 0", y, p.Jm, p.Fm, p.K, TimeFunction{});
  check.initial("y(0) = y0", y, f.y0);
  check.initial_rate("y'(0) = v0", y, f.v0);
  check.same("L^-1[s*Y - y0] = d/dt y", out.outputs[1].segment.solution, y.derivative());
  check.same("L^-1[Y - y0/s] = y - y0", out.outputs[2].segment.solution, y - TimeFunction::constant(f.y0));
  return out;
}

ForcedSolution coupled_mode(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks) {
  const DerivationSymbols& x = derivation_symbols();
  const ForcedSymbols& f = forced_symbols();
  const ex& s = x.s;
  ForcedSolution out;
  out.name = "coupled";
  out.meaning =
      "free flight, output measured at the load, drive linear: the motor driven by the moving load through "
      "-K*(theta_L - theta_R), constant torques um (offset, Coulomb) on the motor and uL on the load";
  out.arguments = {f.vm0, f.yL0, f.vL0, f.um, f.uL};
  out.argument_names = {"vm0", "yL0", "vL0", "um", "uL"};
  out.equation = "Jm*Dm'' + Fm*Dm' = -K*(yL0 + DL(t)) + um, JL*DL'' + FL*DL' = uL, Jm = " + number_text(p.Jm) +
                 ", Fm = " + number_text(p.Fm) + ", JL = " + number_text(p.JL) + ", FL = " + number_text(p.FL) +
                 ", K = " + number_text(p.K) + "; Dm(0) = DL(0) = 0, Dm'(0) = vm0, DL'(0) = vL0";
  out.equation_latex = ode_lhs_latex(p.Jm, p.Fm, 0, "\\ddot\\Delta_m", "\\dot\\Delta_m", "") + " = -" +
                       scaled_latex(p.K, "\\left(y_{L0} + \\Delta_L(t)\\right)") + " + u_m,\\quad " +
                       ode_lhs_latex(p.JL, p.FL, 0, "\\ddot\\Delta_L", "\\dot\\Delta_L", "") +
                       " = u_L,\\quad \\Delta_m(0) = \\Delta_L(0) = 0,\\ \\dot\\Delta_m(0) = v_{m0},\\ \\dot\\Delta_L(0) = v_{L0}";
  // JL (s² XL − vL0) + FL s XL = uL/s;  Jm (s² XM − vm0) + Fm s XM = −K (yL0/s + XL) + um/s
  const ex load = (p.JL * f.vL0 + f.uL / s) / (s * (p.JL * s + p.FL));
  const ex motor = (p.Jm * f.vm0 - p.K * load + (f.um - p.K * f.yL0) / s) / (s * (p.Jm * s + p.Fm));
  const std::string motor_equations = "39, 40, 41 (forced)", load_equations = "17, 22, 23 (forced)";
  out.outputs.push_back(make_output("motor_displacement", motor_equations, motor, radicals, "\\Delta_m(t)",
                                    "motor displacement theta_m(t) - theta_m(0)"));
  out.outputs.push_back(make_output("motor_velocity", motor_equations, s * motor, radicals, "\\dot\\theta_m(t)",
                                    "motor velocity theta_m'(t)"));
  out.outputs.push_back(make_output("load_displacement", load_equations, load, radicals, "\\Delta_L(t)",
                                    "load displacement theta_L(t) - theta_L(0)"));
  out.outputs.push_back(make_output("load_velocity", load_equations, s * load, radicals, "\\dot\\theta_L(t)",
                                    "load velocity theta_L'(t)"));
  const TimeFunction& dm = out.outputs[0].segment.solution;
  const TimeFunction& dl = out.outputs[2].segment.solution;
  Verifier check(out.name, checks, radicals);
  check.ode("JL*DL'' + FL*DL' = uL", dl, p.JL, p.FL, 0, TimeFunction::constant(f.uL));
  check.ode("Jm*Dm'' + Fm*Dm' = -K*(yL0 + DL(t)) + um", dm, p.Jm, p.Fm, 0,
            TimeFunction::constant(f.um - p.K * f.yL0) - dl * p.K);
  check.initial("DL(0) = 0", dl, 0);
  check.initial_rate("DL'(0) = vL0", dl, f.vL0);
  check.initial("Dm(0) = 0", dm, 0);
  check.initial_rate("Dm'(0) = vm0", dm, f.vm0);
  check.same("L^-1[s*XM] = d/dt Dm", out.outputs[1].segment.solution, dm.derivative());
  check.same("L^-1[s*XL] = d/dt DL", out.outputs[3].segment.solution, dl.derivative());
  return out;
}

}  // namespace

ForcedModes derive_forced_modes(const std::string& case_id, const std::string& name, const CaseParameters& p,
                                RadicalList radicals) {
  ForcedModes m;
  m.case_id = case_id;
  m.name = name;
  m.parameters = p;
  m.radicals = std::move(radicals);
  const ForcedSymbols& f = forced_symbols();
  m.contact_constant = constant_torque_mode(
      "contact_constant",
      "rigid contact with the drive clipped (or any constant torque g = +-L + T0 - (Tm+TL)*s): the pair as one body",
      p.Jm + p.JL, p.Fm + p.FL, "J", "F", f.w0, "w0", "", "theta_o", "", m.radicals, m.checks);
  m.load_constant = constant_torque_mode("load_constant",
                                         "free load under a constant torque g (its Coulomb torque -TL*sL)", p.JL, p.FL,
                                         "JL", "FL", f.v0, "v0", "_L", "theta_L", "17, 22, 23 (forced)", m.radicals, m.checks);
  m.motor_constant = constant_torque_mode(
      "motor_constant", "free motor under a constant torque g (clipped drive +-L + T0, Coulomb -Tm*sm)", p.Jm, p.Fm,
      "Jm", "Fm", f.v0, "v0", "_m", "theta_m", "", m.radicals, m.checks);
  if (p.measured_at == model::MeasuredAt::Motor)
    m.motor_closed = motor_closed_mode(p, m.radicals, m.checks);
  else
    m.coupled = coupled_mode(p, m.radicals, m.checks);
  require_all_checks_passed("forced modes of case " + case_id, m.checks);
  return m;
}

ForcedModes derive_forced_modes(const model::CaseSpec& spec) {
  return derive_forced_modes(spec.id, spec.name, exact_parameters(spec));
}

ForcedModes derive_forced_modes(const CaseDerivation& d) {
  return derive_forced_modes(d.case_id, d.name, d.parameters, d.radicals);
}

// ---------------------------------------------------------------- output

namespace {

constexpr pp::Format decimal10{pp::Style::Text, 10};

json exact_and_decimal(const ex& e, const RadicalList& radicals) {
  json j;
  j["exact"] = pp::text(with_explicit_radicals(e, radicals));
  try {
    j["decimal"] = to_double(e, radicals);
  } catch (...) {
    j["decimal"] = pp::print(with_explicit_radicals(e, radicals), decimal10);
  }
  return j;
}

json terms_json(const TimeFunction& f, const RadicalList& radicals) {
  json terms = json::array();
  for (const ExpTerm& term : pp::sorted_terms(f, radicals)) {
    json j;
    j["coefficient"] = exact_and_decimal(term.coefficient, radicals);
    j["t_power"] = term.t_power;
    j["rate"] = exact_and_decimal(term.rate, radicals);
    j["oscillation"] = term.oscillation == Oscillation::None ? "none" : (term.oscillation == Oscillation::Cos ? "cos" : "sin");
    if (term.oscillation != Oscillation::None) j["frequency"] = exact_and_decimal(term.frequency, radicals);
    terms.push_back(j);
  }
  return terms;
}

// The forced symbols renamed so pretty's LaTeX prints them in the thesis's style
// (pretty names symbols by their name, not their TeX name).
const exmap& display_symbols() {
  static const exmap map = [] {
    const ForcedSymbols& f = forced_symbols();
    exmap m;
    m[f.w0] = symbol("omega_0");
    m[f.v0] = symbol("v_0");
    m[f.y0] = symbol("y_0");
    m[f.vm0] = symbol("v_m0");
    m[f.yL0] = symbol("y_L0");
    m[f.vL0] = symbol("v_L0");
    m[f.um] = symbol("u_m");
    m[f.uL] = symbol("u_L");
    return m;
  }();
  return map;
}

}  // namespace

json forced_modes_json(const ForcedModes& m) {
  const RadicalList& r = m.radicals;
  json j;
  j["case"] = escape::valid_utf8(m.case_id);
  j["measured_at"] = m.parameters.measured_at == model::MeasuredAt::Motor ? "motor" : "load";
  json radicals = json::array();
  for (const Radical& rad : r)
    radicals.push_back({{"name", rad.symbol.get_name()},
                        {"square", pp::text(rad.square)},
                        {"exact", pp::text(canonical_sqrt(rad.square))},
                        {"decimal", to_double(rad.symbol, r)},
                        {"meaning", rad.role}});
  j["radicals"] = radicals;
  json modes = json::array();
  for (const ForcedSolution* s : m.solutions()) {
    json mode;
    mode["name"] = s->name;
    mode["meaning"] = s->meaning;
    mode["equation"] = s->equation;
    json arguments = json::array({"t"});
    for (const std::string& a : s->argument_names) arguments.push_back(a);
    mode["arguments"] = arguments;
    json outputs = json::array();
    for (const ForcedOutput& o : s->outputs) {
      json out;
      out["name"] = o.segment.name;
      out["meaning"] = o.meaning;
      if (!o.segment.equations.empty()) out["thesis_equations"] = o.segment.equations;
      out["laplace"] = pp::text(with_explicit_radicals(o.segment.laplace, r));
      out["exact"] = exact_text(o.segment.solution, r);
      out["decimal"] = decimal_text(o.segment.solution, r);
      out["terms"] = terms_json(o.segment.solution, r);
      outputs.push_back(out);
    }
    mode["outputs"] = outputs;
    modes.push_back(mode);
  }
  j["modes"] = modes;
  json checks = json::array();
  for (const VerificationCheck& c : m.checks) checks.push_back({{"name", c.name}, {"passed", c.passed}});
  j["verification"] = {{"status", m.verified() ? "verified" : "failed"}, {"checks", checks}};
  return j;
}

doc::Document forced_modes_document(const ForcedModes& m, int level) {
  const RadicalList& r = m.radicals;
  doc::Document out;
  out.push_back(doc::heading(level, doc::text("Forced modes (effects)")));
  out.push_back(doc::paragraph(
      doc::text("With Coulomb friction, saturation or a torque offset (docs/effects.md) every mode keeps a linear "
                "ODE with a constant forcing. Each is solved here exactly by the residue inverse Laplace transform "
                "with symbolic initial state and symbolic forcing, as displacements ") +
      doc::math("\\Delta = \\theta - \\theta(0)") + doc::text(".")));
  for (const Radical& rad : r)
    out.push_back(doc::paragraph(doc::math(pp::latex_symbol_name(rad.symbol.get_name()) + " = " +
                                           pp::latex(canonical_sqrt(rad.square))) +
                                 doc::text(" (" + rad.role + ")")));
  for (const ForcedSolution* s : m.solutions()) {
    out.push_back(doc::heading(level + 1, doc::code(s->name) + doc::text(": " + s->meaning)));
    out.push_back(doc::equation(s->equation_latex));
    for (const ForcedOutput& o : s->outputs) {
      const TimeFunction shown = o.segment.solution.subs(display_symbols());
      out.push_back(doc::equation(pp::display(o.lhs_latex, pp::time_function_terms(shown, r, pp::latex_exact))));
    }
  }
  std::size_t passed = 0;
  for (const VerificationCheck& c : m.checks) passed += c.passed;
  out.push_back(doc::paragraph(doc::text(std::to_string(passed) + " of " + std::to_string(m.checks.size()) +
                                         " exact checks pass (ODE residuals, initial conditions and velocities, each "
                                         "as a structured solution and as normal(expand(...)) of the expression in t).")));
  return out;
}

std::string forced_modes_latex(const ForcedModes& m) {
  doc::LatexOptions options;
  options.top_level = 1;  // heading 1 → \section
  return doc::to_latex(forced_modes_document(m, 1), options);
}

}  // namespace backlash::symbolic
