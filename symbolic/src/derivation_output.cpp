#include "backlash/symbolic/derivation_output.hpp"

#include "backlash/symbolic/derivation_steps.hpp"
#include "backlash/symbolic/escape.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <algorithm>
#include <cmath>
#include <regex>
#include <sstream>

namespace backlash::symbolic {

using namespace GiNaC;
using nlohmann::json;
namespace pp = pretty;

namespace {

constexpr pp::Format decimal10{pp::Style::Text, 10};
constexpr pp::Format latex6{pp::Style::Latex, 6};

std::string canonical(const ex& e) { return pp::text(e); }

json exact_and_decimal(const ex& e, const RadicalList& radicals) {
  json j;
  j["exact"] = canonical(with_explicit_radicals(e, radicals));
  try {
    j["decimal"] = to_double(e, radicals);
  } catch (...) {
    j["decimal"] = pp::print(with_explicit_radicals(e, radicals), decimal10);
  }
  return j;
}

const char* oscillation_name(Oscillation o) {
  return o == Oscillation::None ? "none" : (o == Oscillation::Cos ? "cos" : "sin");
}

json terms_json(const TimeFunction& f, const RadicalList& radicals) {
  json terms = json::array();
  for (const ExpTerm& term : pp::sorted_terms(f, radicals)) {
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

json steps_json(const Segment& segment, const RadicalList& radicals) {
  json j;
  try {
    const SegmentSteps steps = segment_steps(segment, radicals);
    j["rational_function"] = pp::print(steps.transform, pp::text_exact);
    j["denominator_factored"] = pp::factored(steps.leading_constant, steps.factors, pp::text_exact);
    json poles = json::array();
    for (const PoleResidues& row : steps.poles) {
      json p;
      p["kind"] = row.pole.kind == Pole::Kind::Real ? "real" : (row.pole.kind == Pole::Kind::RealPair ? "real_pair" : "complex_pair");
      p["center"] = canonical(with_explicit_radicals(row.pole.center, steps.radicals));
      p["half_width"] = canonical(with_explicit_radicals(row.pole.half_width, steps.radicals));
      p["multiplicity"] = row.pole.multiplicity;
      json locations = json::array();
      for (const auto& location : row.locations) {
        json coefficients = json::array();
        for (const ex& a : location.coefficients) coefficients.push_back(canonical(with_explicit_radicals(a, steps.radicals)));
        locations.push_back({{"at", canonical(with_explicit_radicals(location.at, steps.radicals))},
                             {"coefficients_of_1_over_s_minus_at_to_the_r", coefficients}});
      }
      p["partial_fractions"] = locations;
      poles.push_back(p);
    }
    j["poles"] = poles;
    j["partial_fractions_sum_to_transform"] = steps.partial_fractions_sum_to_transform;
    j["residues_give_solution"] = steps.residues_give_solution;
  } catch (const std::exception& e) {
    j["error"] = e.what();
  }
  return j;
}

json segment_json(const Segment& segment, const RadicalList& radicals, bool with_steps = true) {
  json j;
  j["thesis_equations"] = segment.equations;
  j["laplace"] = canonical(with_explicit_radicals(segment.laplace, radicals));
  j["exact"] = exact_text(segment.solution, radicals);
  j["decimal"] = decimal_text(segment.solution, radicals);
  j["terms"] = terms_json(segment.solution, radicals);
  if (with_steps) j["steps"] = steps_json(segment, radicals);
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
                    {"square", canonical(r.square)},
                    {"exact", canonical(canonical_sqrt(r.square))},
                    {"decimal", to_double(r.symbol, radicals)},
                    {"meaning", r.role}});
  return list;
}

json isocline_json(const IsoclineTable& table) {
  json rows = json::array();
  for (const IsoclineRow& row : table.rows) {
    json j;
    j["eta"] = row.is_infinite ? json("inf") : json(canonical(row.eta));
    j["vertical"] = row.is_vertical;
    j["tangent"] = row.is_vertical ? json("inf") : json(canonical(row.tangent));
    j["angle_degrees"] = {{"exact", canonical(row.angle_degrees)}, {"decimal", to_double(row.angle_degrees, {})}};
    rows.push_back(j);
  }
  return {{"system", table.system}, {"J", canonical(table.inertia)}, {"F", canonical(table.friction)}, {"rows", rows}};
}

json stability_json(const StabilityConstant& c, const RadicalList& radicals) {
  json j{{"applicable", c.applicable}, {"region", c.region}};
  if (c.applicable) {
    j["C"] = canonical(with_explicit_radicals(c.C, radicals));
    j["dlnC_dt"] = canonical(c.dlnC_dt);
    j["jump_factor_at_theta_R"] = exact_and_decimal(c.jump_factor, radicals);
  }
  return j;
}

std::string measured_at_text(model::MeasuredAt where) { return where == model::MeasuredAt::Motor ? "motor" : "load"; }

double phi_degrees(const CaseDerivation& d) {
  const ex phi = d.free.cot_phi.is_zero() ? ex(90) : ex(atan(1 / d.free.cot_phi) * 180 / Pi);
  double value = to_double(phi, d.radicals);
  if (value < 0) value += 180;
  return value;
}

}  // namespace

std::string exact_text(const TimeFunction& f, const RadicalList& radicals) {
  return pp::time_function(f, radicals, pp::text_exact, false);
}

std::string decimal_text(const TimeFunction& f, const RadicalList& radicals) {
  return pp::time_function(f, radicals, decimal10, false);
}

json to_json(const CaseDerivation& d) {
  const RadicalList& r = d.radicals;
  const CaseParameters& p = d.parameters;
  json j;
  j["case"] = escape::valid_utf8(d.case_id);
  j["name"] = escape::valid_utf8(d.name);
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
  j["separation_line"] = {{"cot_phi", exact_and_decimal(d.free.cot_phi, r)},
                          {"phi_degrees", phi_degrees(d)},
                          {"equation", "theta_o = theta_R + cot_phi * dtheta_o"},
                          {"theta_0", canonical(d.free.separation_theta)},
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
  for (const auto& [k, v] : b.substitution) subs[canonical(k)] = canonical(v);
  j["substitution"] = subs;
  json params = json::array();
  for (const BranchParameter& p : b.branch_parameters)
    params.push_back({{"name", p.symbol.get_name()}, {"square", canonical(p.square_in_physical_parameters)}, {"meaning", p.meaning}});
  j["branch_parameters"] = params;
  // (the partial-fraction steps of the symbolic branches are omitted: they are slow and add nothing
  // a reader of JSON needs beyond the solution itself)
  if (b.mode == GeneralBranch::Mode::Contact) {
    j["theta_o"] = segment_json(b.contact.position, {}, false);
    j["dtheta_o"] = segment_json(b.contact.velocity, {}, false);
  } else {
    j["cot_phi"] = canonical(b.free.cot_phi);
    j["theta_m"] = segment_json(b.free.motor_position, {}, false);
    j["dtheta_m"] = segment_json(b.free.motor_velocity, {}, false);
    j["theta_L"] = segment_json(b.free.load_position, {}, false);
    j["dtheta_L"] = segment_json(b.free.load_velocity, {}, false);
  }
  j["verification"] = checks_json(b.checks);
  return j;
}

// ---------------------------------------------------------------- document blocks

std::string model_number_latex(const ex& value) {
  if (is_a<numeric>(value) && ex_to<numeric>(value).is_rational()) {
    const numeric q = ex_to<numeric>(value);
    numeric d = q.denom();
    int twos = 0, fives = 0;
    while (irem(d, 2).is_zero()) { d = d / 2; ++twos; }
    while (irem(d, 5).is_zero()) { d = d / 5; ++fives; }
    const int digits = std::max(twos, fives);
    if (d == 1 && digits <= 8) {
      const numeric scaled = abs(q) * numeric(10).power(digits);
      std::ostringstream s;
      s << scaled;
      std::string body = s.str();
      if (digits > 0) {
        if (static_cast<int>(body.size()) <= digits) body = std::string(digits - body.size() + 1, '0') + body;
        body.insert(body.size() - digits, ".");
      }
      return (q.is_negative() ? "-" : "") + body;
    }
  }
  return pp::latex(value);
}

namespace {

using doc::Rich;

std::string tag(const EquationTags& tags, const std::string& slot) {
  const auto found = tags.find(slot);
  return found == tags.end() ? std::string() : found->second;
}

// Σ c_k x_k as summands, with model numbers (terminating decimals) and zero terms dropped.
std::vector<pp::Summand> combination(const std::vector<std::pair<ex, std::string>>& terms) {
  std::vector<pp::Summand> out;
  for (const auto& [c, x] : terms) {
    const ex value = normal(c);
    if (value.is_zero()) continue;
    std::string number = model_number_latex(value);
    bool negative = false;
    if (!number.empty() && number[0] == '-') {
      negative = true;
      number.erase(0, 1);
    }
    if (number == "1" && !x.empty()) number.clear();
    out.push_back({negative, number + x});
  }
  if (out.empty()) out.push_back({false, "0"});
  return out;
}

std::string combination_latex(const std::vector<std::pair<ex, std::string>>& terms) {
  return pp::join(combination(terms));
}


// A coefficient in front of a symbol: "" for 1, "-" for −1, else its LaTeX (a sum in parentheses).
std::string coefficient_latex(const ex& value) {
  const ex v = normal(value);
  if (v == 1) return "";
  if (v == -1) return "-";
  const pp::Summand f = pp::factor(v);
  return (f.negative ? "-" : "") + f.body;
}

// a + b i with a, b each a factor.
std::string complex_latex(const ex& value, const RadicalList& radicals) {
  const symbol& i = imaginary_unit().symbol;
  const ex re = with_explicit_radicals(simplify(value.subs(i == 0), radicals), radicals);
  const ex im = with_explicit_radicals(simplify(value.coeff(i, 1), radicals), radicals);
  if (im.is_zero()) return pp::latex(re);
  const pp::Summand b = pp::factor(im);
  const std::string imaginary = (b.body == "1" ? std::string() : b.body) + "\\,\\mathrm{i}";
  if (re.is_zero()) return (b.negative ? "-" : "") + imaginary;
  const pp::Summand a = pp::factor(re);
  return (a.negative ? "-" : "") + a.body + (b.negative ? " - " : " + ") + imaginary;
}

// The denominator as constant × its factors, a complex pair α ± iω written (s − α)² + ω²
// and a real pair α ± δ as (s − α − δ)(s − α + δ), so the poles can be read off.
// A check's formula, written in ASCII in its name ("Jm*theta_m'' + Fm*theta_m' = …"), in
// the thesis's notation (J_m\ddot\theta_m + F_m\dot\theta_m = …), token by token.
std::string check_formula_latex(const std::string& f) {
  static const std::regex token(R"(L\^-1\[|d/dt |cot\(phi\)\*|(d?)([tT])heta(_[mLoR]0?)?('*)(\+?)|eta([12])|\b([JF])([mL])\b|\*|\+)");
  std::string out;
  std::size_t from = 0;
  for (auto it = std::sregex_iterator(f.begin(), f.end(), token); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    out += f.substr(from, static_cast<std::size_t>(m.position()) - from);
    from = static_cast<std::size_t>(m.position() + m.length());
    const std::string t = m.str();
    if (t == "L^-1[") out += "\\mathcal{L}^{-1}[";
    else if (t == "d/dt ") out += "\\frac{d}{dt}";
    else if (t == "cot(phi)*") out += "\\cot\\varphi\\,";
    else if (t == "*") continue;
    else if (t == "+") out += " + ";
    else if (m[6].matched) out += "\\eta_" + m[6].str();
    else if (m[7].matched) out += m[7].str() + "_" + m[8].str();
    else {
      const std::size_t dots = (m[1].length() > 0 ? 1 : 0) + static_cast<std::size_t>(m[4].length());
      const std::string sub = m[3].str();
      out += std::string(dots == 0 ? "" : dots == 1 ? "\\dot" : "\\ddot") + (m[2].str() == "T" ? "\\Theta" : "\\theta") +
             (sub.size() > 2 ? "_{" + sub.substr(1) + "}" : sub) + (m[5].length() > 0 ? "^{+}" : "");
    }
  }
  out += f.substr(from);
  static const std::regex spaces(" +");
  return std::regex_replace(out, spaces, " ");
}

// A verification check as the page prints it: its words as text, its formulas as
// mathematics ("free motor: " + J_m\ddot\theta_m + … + " (eq. 39)").  The name itself
// stays the check's identifier (JSON).
Rich check_rich(const std::string& name) {
  Rich out;
  std::string body = name;
  const auto colon = body.find(": ");
  if (colon != std::string::npos) {
    out = doc::text(body.substr(0, colon + 2));
    body = body.substr(colon + 2);
  }
  std::string tail;
  const std::regex trailing(R"(( \(eq\. [0-9]+\)| along .*)$)");
  std::smatch m;
  if (std::regex_search(body, m, trailing)) {
    tail = m.str();
    body = body.substr(0, static_cast<std::size_t>(m.position()));
  }
  // words between formulas: "… at t = 0 gives dtheta_m0", a label before a formula: "transmitted torque JL*…"
  const std::regex words(R"( (at|gives) |^((?:[a-z-]+ )+)(?=[A-Za-z]+[0-9_*(]))");
  std::size_t from = 0;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), words); it != std::sregex_iterator(); ++it) {
    const std::size_t at = static_cast<std::size_t>(it->position());
    if (at > from) out = out + doc::math(check_formula_latex(body.substr(from, at - from)));
    out = out + doc::text(it->str());
    from = at + static_cast<std::size_t>(it->length());
  }
  if (from < body.size()) out = out + doc::math(check_formula_latex(body.substr(from)));
  if (!tail.empty()) out = out + doc::text(tail);
  return out;
}

std::string factored_latex(const SegmentSteps& steps) {
  const symbol& s = derivation_symbols().s;
  ex constant = steps.leading_constant;
  std::string pieces;
  const auto width_latex = [&](const ex& w) {
    return is_a<symbol>(w) ? pp::latex_symbol_name(ex_to<symbol>(w).get_name()) : pp::latex(with_explicit_radicals(w, steps.radicals));
  };
  for (const PoleResidues& row : steps.poles) {
    const Pole& pole = row.pole;
    const std::string power = pole.multiplicity > 1 ? "^{" + std::to_string(pole.multiplicity) + "}" : "";
    if (pole.kind == Pole::Kind::Real) {
      const std::string f = pp::latex(pole.factor);
      pieces += (is_a<symbol>(pole.factor) ? f : "\\left(" + f + "\\right)") + power;
      continue;
    }
    constant *= pow(pole.factor.coeff(s, 2), pole.multiplicity);
    const std::string shifted = pp::latex(s - with_explicit_radicals(pole.center, steps.radicals));
    const std::string base = shifted == "s" ? "s" : "\\left(" + shifted + "\\right)";
    if (pole.kind == Pole::Kind::ComplexPair) {
      pieces += "\\left(" + base + "^{2} + " + width_latex(pole.half_width) + "^{2}\\right)" + power;
    } else {
      const std::string w = width_latex(pole.half_width);
      pieces += "\\left(" + shifted + " - " + w + "\\right)" + power + "\\left(" + shifted + " + " + w + "\\right)" + power;
    }
  }
  constant = normal(constant);
  const std::string c = coefficient_latex(constant);
  return c + pieces;
}

// What a radical is: the role's words, with its defining formula as mathematics.
doc::Rich radical_meaning(const Radical& r) {
  static const std::map<std::string, std::string> definitions{
      {"omega_c", "\\omega_c^2 = \\frac{K}{J} - \\frac{F^2}{4J^2}"}, {"omega_m", "\\omega_m^2 = \\frac{K}{J_m} - \\frac{F_m^2}{4J_m^2}"},
      {"delta_c", "\\delta_c^2 = \\frac{F^2}{4J^2} - \\frac{K}{J}"}, {"delta_m", "\\delta_m^2 = \\frac{F_m^2}{4J_m^2} - \\frac{K}{J_m}"}};
  std::string words = r.role;
  const auto formula = words.find(", sqrt(");
  if (formula != std::string::npos) words.erase(formula);
  const auto found = definitions.find(r.symbol.get_name());
  if (found == definitions.end()) return doc::text(" (" + words + ")");
  return doc::text(" (" + words + ", ") + doc::math(found->second) + doc::text(")");
}

struct SegmentView {
  const Segment* segment;
  std::string key;         // theta_o, dtheta_o, theta_m, …
  doc::Rich title;
  std::string time_lhs;    // \theta_m(t)
  std::string laplace_lhs; // \Theta_m(s)
  std::string transformed_equation;  // LaTeX of the transformed ODE (may be empty: velocity)
  std::string checks_prefix;         // "contact:", "free motor:", "free load:"
};

std::string with_tag(std::string body, const std::string& t) { return t.empty() ? body : body + " \\tag{" + t + "}"; }

// The transform solved as one rational function and its denominator factored.
void transform_blocks(doc::Document& out, const SegmentView& v, const SegmentSteps& steps, const EquationTags& tags) {
  out.push_back(doc::paragraph(doc::text("Solved for the transform, as one rational function in lowest terms:")));
  out.push_back(doc::equation(with_tag(v.laplace_lhs + " = " + pp::print(steps.transform), tag(tags, v.key + "_transform"))));
  const std::string denominator = pp::print(steps.transform.denominator), factored = factored_latex(steps);
  const std::string factored_tag = tag(tags, v.key + "_factored");
  if (factored == denominator || factored == "\\left(" + denominator + "\\right)") {
    // one linear factor (s, 5s + 3): nothing to factor, and "s = s" reads as a slip
    out.push_back(doc::paragraph(doc::text("Its denominator is already a single linear factor: ") + doc::math(denominator) +
                                 doc::text(".")));
    if (!factored_tag.empty()) out.push_back(doc::equation(with_tag(denominator, factored_tag)));
  } else {
    out.push_back(doc::paragraph(doc::text("Its denominator factored:")));
    out.push_back(doc::equation(with_tag(denominator + " = " + factored, factored_tag)));
  }
}

// The term of the solution that the coefficient A_r at one pole location gives (a complex pair: twice the real part).
TimeFunction residue_term(const PoleResidues& row, const ex& at, const ex& A, std::size_t r, const SegmentSteps& steps) {
  const symbol& i = imaginary_unit().symbol;
  const numeric fact = factorial(numeric(static_cast<int>(r - 1)));
  if (row.pole.kind != Pole::Kind::ComplexPair)
    return TimeFunction({{A / fact, static_cast<unsigned>(r - 1), at, Oscillation::None, 0}});
  const ex a = A / fact;
  const ex re = simplify(a.subs(i == 0), steps.radicals), im = simplify(a.coeff(i, 1), steps.radicals);
  return TimeFunction({{2 * re, static_cast<unsigned>(r - 1), row.pole.center, Oscillation::Cos, row.pole.half_width},
                       {-2 * im, static_cast<unsigned>(r - 1), row.pole.center, Oscillation::Sin, row.pole.half_width}});
}

// The poles, their partial-fraction coefficients and terms, and the partial fractions.
void residue_blocks(doc::Document& out, const SegmentView& v, const SegmentSteps& steps, const EquationTags& tags) {
  std::vector<Rich> header{doc::text("pole"), doc::text("multiplicity"), doc::text("power r"),
                           doc::text("coefficient of ") + doc::math("1/(s-p)^r"), doc::text("term of the solution")};
  std::vector<std::vector<Rich>> rows;
  for (const PoleResidues& row : steps.poles) {
    for (const auto& location : row.locations) {
      for (std::size_t r = 1; r <= location.coefficients.size(); ++r) {
        const ex A = location.coefficients[r - 1];
        std::string where = pp::latex(with_explicit_radicals(location.at, steps.radicals));
        if (row.pole.kind == Pole::Kind::ComplexPair) where = pole_latex(row.pole, steps.radicals);
        const TimeFunction term = residue_term(row, location.at, A, r, steps);
        rows.push_back({doc::math(where), doc::text(std::to_string(row.pole.multiplicity)), doc::text(std::to_string(r)),
                        doc::math(complex_latex(A, steps.radicals)),
                        doc::math(pp::time_function(term, steps.radicals, pp::latex_exact))});
      }
    }
  }
  out.push_back(doc::paragraph(doc::text("Poles (multiplicity) and partial-fraction coefficients ") +
                               doc::math("A_r = \\frac{1}{(m-r)!}\\frac{d^{m-r}}{ds^{m-r}}\\left[(s-p)^m F(s)\\right]_{s=p}") +
                               doc::text(" (a complex pair by its coefficient at the upper pole; the term is twice the real part):")));
  out.push_back(doc::table(header, rows, "lrrll"));
  // ragged right: a long coefficient breaks after a "+" and the "+" stays beside it
  out.back().latex_columns = "p{2.6cm}rr>{\\raggedright\\arraybackslash}p{4.4cm}>{\\raggedright\\arraybackslash}p{5.6cm}";
  out.back().small = true;
  out.push_back(doc::paragraph(doc::text("The partial fractions:")));
  out.push_back(doc::equation(pp::display(v.laplace_lhs, partial_fraction_terms(steps, pp::latex_exact),
                                          tag(tags, v.key + "_partial"))));
}

// The time-domain result, exactly and in decimals (the decimal line with ≈).
void time_domain_blocks(doc::Document& out, const SegmentView& v, const RadicalList& radicals, const EquationTags& tags) {
  out.push_back(doc::paragraph(doc::text("The time-domain result, exactly and in decimals:")));
  out.push_back(doc::equation(pp::display(v.time_lhs, pp::time_function_terms(v.segment->solution, radicals, pp::latex_exact),
                                          tag(tags, v.key))));
  out.push_back(doc::equation(pp::display(v.time_lhs, pp::time_function_terms(v.segment->solution, radicals, latex6, false))));
  std::string& last = out.back().equation;
  const std::string eq = v.time_lhs + " = ";
  if (last.rfind(eq, 0) == 0) last.replace(0, eq.size(), v.time_lhs + " \\approx ");
  const std::string aligned = "\\begin{aligned}" + v.time_lhs + " &= ";
  if (last.rfind(aligned, 0) == 0) last.replace(0, aligned.size(), "\\begin{aligned}" + v.time_lhs + " &\\approx ");
}

// The segment's exact self-checks: the steps' own two and the derivation's checks of this segment.
void self_check_blocks(doc::Document& out, const SegmentView& v, const SegmentSteps* steps, const std::vector<VerificationCheck>& checks) {
  std::vector<Rich> passed;
  if (steps) {
    passed.push_back(doc::text(steps->partial_fractions_sum_to_transform ? "passed: " : "FAILED: ") +
                     doc::text("the partial fractions add up to the transform exactly"));
    passed.push_back(doc::text(steps->residues_give_solution ? "passed: " : "FAILED: ") +
                     doc::text("the terms of the table are the solution, term by term"));
  }
  for (const VerificationCheck& c : checks) {
    const bool velocity_check = c.name.find("L^-1[s*") != std::string::npos;
    const bool mine = c.name.rfind(v.checks_prefix, 0) == 0 && velocity_check == (v.key[0] == 'd');
    if (!mine) continue;
    passed.push_back(doc::text(c.passed ? "passed: " : "FAILED: ") + check_rich(c.name));
  }
  out.push_back(doc::paragraph(doc::text("Exact self-checks (each reduces to 0 in exact arithmetic):")));
  out.push_back(doc::list(passed));
}

doc::Document segment_blocks(const SegmentView& v, const RadicalList& radicals, const std::vector<VerificationCheck>& checks,
                             const EquationTags& tags, int level) {
  doc::Document out;
  out.push_back(doc::heading(level, v.title));
  if (!v.transformed_equation.empty()) {
    // a velocity's transform comes from its position's by the derivative rule, not from an equation of motion
    const bool velocity = v.key[0] == 'd';
    out.push_back(doc::paragraph(doc::text(velocity ? "The transform of the velocity, by the derivative rule from the position's:"
                                                    : "The Laplace transform of the equation of motion with its initial state:")));
    out.push_back(doc::equation(v.transformed_equation));
  }
  SegmentSteps steps;
  bool have_steps = true;
  try {
    steps = segment_steps(*v.segment, radicals);
  } catch (const std::exception& e) {
    have_steps = false;
    out.push_back(doc::paragraph(doc::text(std::string("(steps not available: ") + e.what() + ")")));
  }
  if (have_steps) {
    transform_blocks(out, v, steps, tags);
    residue_blocks(out, v, steps, tags);
  }
  time_domain_blocks(out, v, radicals, tags);
  self_check_blocks(out, v, have_steps ? &steps : nullptr, checks);
  return out;
}

// The model's parameters: symbol, meaning, value as the model file gives it, exact.
doc::Block parameter_table(const CaseParameters& p) {
  std::vector<std::vector<Rich>> rows;
  const std::vector<std::tuple<std::string, std::string, ex>> params{
      {"J_m", "inertia of the motor (system without load)", p.Jm}, {"F_m", "viscous friction of the motor, back-emf included", p.Fm},
      {"J_L", "inertia of the load", p.JL},                         {"F_L", "viscous friction of the load", p.FL},
      {"K", "loop gain", p.K},                                     {"\\theta_R", "reference", p.theta_R},
      {"b", "total backlash (rad)", p.backlash}};
  for (const auto& [symbol_latex, meaning, value] : params)
    rows.push_back({doc::math(symbol_latex), doc::text(meaning), doc::math(model_number_latex(value)),
                    doc::math(pp::latex(value))});
  return doc::table({doc::text("symbol"), doc::text("meaning"), doc::text("value"), doc::text("exact")}, rows, "llrr");
}

// The equations of motion: contact, the motor with the load separated, the load drifting.
void motion_equations(doc::Document& out, const CaseParameters& p, const EquationTags& tags) {
  const bool at_motor = p.measured_at == model::MeasuredAt::Motor;
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  out.push_back(doc::paragraph(doc::text("Contact (backlash taken up), the bodies move as one, ") +
                               doc::math("J\\ddot\\theta_o + F\\dot\\theta_o + K\\theta_o = K\\theta_R") + doc::text(" with ") +
                               doc::math("J = J_m + J_L") + doc::text(", ") + doc::math("F = F_m + F_L") + doc::text(":")));
  out.push_back(doc::equation(with_tag(
      combination_latex({{J, "\\ddot\\theta_o"}, {F, "\\dot\\theta_o"}, {p.K, "\\theta_o"}}) + " = " +
          combination_latex({{p.K * p.theta_R, ""}}),
      tag(tags, "contact_equation"))));
  if (at_motor) {
    out.push_back(doc::paragraph(doc::text("The motor with the load separated, a closed loop of its own, ") +
                                 doc::math("J_m\\ddot\\theta_m + F_m\\dot\\theta_m + K\\theta_m = K\\theta_R") + doc::text(":")));
    out.push_back(doc::equation(with_tag(
        combination_latex({{p.Jm, "\\ddot\\theta_m"}, {p.Fm, "\\dot\\theta_m"}, {p.K, "\\theta_m"}}) + " = " +
            combination_latex({{p.K * p.theta_R, ""}}),
        tag(tags, "free_motor_equation"))));
  } else {
    out.push_back(doc::paragraph(doc::text("The motor with the load separated, driven open loop by the load's error, ") +
                                 doc::math("J_m\\ddot\\theta_m + F_m\\dot\\theta_m = K(\\theta_R - \\theta_L)") + doc::text(":")));
    out.push_back(doc::equation(with_tag(
        combination_latex({{p.Jm, "\\ddot\\theta_m"}, {p.Fm, "\\dot\\theta_m"}}) + " = " +
            combination_latex({{p.K * p.theta_R, ""}, {-p.K, "\\theta_L"}}),
        tag(tags, "free_motor_equation"))));
  }
  out.push_back(doc::paragraph(doc::text("The load drifting separately, ") + doc::math("J_L\\ddot\\theta_L + F_L\\dot\\theta_L = 0") +
                               doc::text(":")));
  out.push_back(doc::equation(with_tag(combination_latex({{p.JL, "\\ddot\\theta_L"}, {p.FL, "\\dot\\theta_L"}}) + " = 0",
                                       tag(tags, "free_load_equation"))));
}

// The isoclines (η = θ̈/θ̇) of the combined system and, with the output at the motor, of the motor alone.
void model_isoclines(doc::Document& out, const CaseParameters& p, const EquationTags& tags) {
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  out.push_back(doc::paragraph(doc::text("Isoclines of the combined system, ") + doc::math("\\eta_1 = \\ddot\\theta_o/\\dot\\theta_o") +
                               doc::text(" constant (straight lines through ") + doc::math("(\\theta_R, 0)") + doc::text("):")));
  out.push_back(doc::equation(with_tag("\\eta_1 + " + pp::latex(F / J) + " = " + coefficient_latex(p.K / J) +
                                           "\\frac{" + model_number_latex(p.theta_R) + " - \\theta_o}{\\dot\\theta_o}",
                                       tag(tags, "combined_isocline"))));
  if (!tag(tags, "combined_isocline_line").empty())
    out.push_back(doc::equation(with_tag("\\theta_o = " + model_number_latex(p.theta_R) + " - " + coefficient_latex(J / p.K) +
                                             "\\dot\\theta_o\\left(\\eta_1 + " + pp::latex(F / J) + "\\right)",
                                         tag(tags, "combined_isocline_line"))));
  if (p.measured_at != model::MeasuredAt::Motor) return;
  out.push_back(doc::paragraph(doc::text("Isoclines of the motor alone, ") + doc::math("\\eta_2 = \\ddot\\theta_m/\\dot\\theta_m") +
                               doc::text(":")));
  out.push_back(doc::equation(with_tag("\\eta_2 + " + pp::latex(p.Fm / p.Jm) + " = " + coefficient_latex(p.K / p.Jm) + "\\frac{" +
                                           model_number_latex(p.theta_R) + " - \\theta_m}{\\dot\\theta_m}",
                                       tag(tags, "motor_isocline"))));
  out.push_back(doc::paragraph(doc::text("The motor alone, normalised:")));
  out.push_back(doc::equation(with_tag(
      "\\ddot\\theta_m + " + coefficient_latex(p.Fm / p.Jm) + "\\dot\\theta_m + " + coefficient_latex(p.K / p.Jm) + "\\theta_m = " +
          pp::latex(p.K * p.theta_R / p.Jm),
      tag(tags, "motor_equation_normalized"))));
}

// Section 1: the model, its parameters, equations of motion and isoclines.
void model_section(doc::Document& out, const CaseParameters& p, const EquationTags& tags, int level) {
  const bool at_motor = p.measured_at == model::MeasuredAt::Motor;
  out.push_back(doc::heading(level, doc::text("The model")));
  out.push_back(doc::paragraph(
      doc::text(at_motor ? "The output is measured at the motor shaft, " : "The output is measured at the load, ") +
      doc::math(at_motor ? "\\theta_o = \\theta_m" : "\\theta_o = \\theta_L") +
      doc::text(at_motor ? ": the backlash is outside the feedback loop and the motor alone is a closed loop when the load "
                           "has separated."
                         : ": the backlash is inside the feedback loop and the motor is driven open loop by the load's "
                           "error while the load drifts in the backlash.") +
      doc::text(" Gear ratio 1, torques in units of ") + doc::math("K\\cdot\\mathrm{rad}") + doc::text(".")));
  out.push_back(parameter_table(p));
  motion_equations(out, p, tags);
  model_isoclines(out, p, tags);
}

// The six segments the derivation solves: contact θo and θ̇o, the free motor and the free load, each with its transformed equation.
std::vector<SegmentView> segment_views(const CaseDerivation& d) {
  const CaseParameters& p = d.parameters;
  const bool at_motor = p.measured_at == model::MeasuredAt::Motor;
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  const std::string Jc = coefficient_latex(J), Fc = coefficient_latex(F);
  auto poly = [](const ex& e) { return pp::latex(expand(e)); };
  const symbol& s = derivation_symbols().s;
  std::vector<SegmentView> views;
  views.push_back({&d.contact.position, "theta_o", doc::text("Contact mode: the measured shaft ") + doc::math("\\theta_o(t)") + doc::text(" from ") + doc::math("(\\theta_{o0}, \\dot\\theta_{o0})"), "\\theta_o(t)",
                   "\\Theta_o(s)",
                   "\\left(" + poly(J * s * s + F * s + p.K) + "\\right)\\Theta_o(s) = " + Jc + "\\left(s\\theta_{o0} + \\dot\\theta_{o0}\\right) + " +
                       Fc + "\\theta_{o0} + \\frac{" + pp::latex(p.K * p.theta_R) + "}{s}",
                   "contact:"});
  views.push_back({&d.contact.velocity, "dtheta_o", doc::text("Contact mode: its velocity ") + doc::math("\\dot\\theta_o(t)"), "\\dot\\theta_o(t)", "\\dot\\Theta_o(s)",
                   "\\dot\\Theta_o(s) = s\\,\\Theta_o(s) - \\theta_{o0}", "contact:"});
  const std::string motor_lhs = at_motor ? poly(p.Jm * s * s + p.Fm * s + p.K) : poly(p.Jm * s * s + p.Fm * s);
  std::string motor_rhs = coefficient_latex(p.Jm) + "\\left(s\\theta_0 + \\dot\\theta_{m0}\\right) + " + coefficient_latex(p.Fm) + "\\theta_0";
  if (at_motor) motor_rhs += " + \\frac{" + pp::latex(p.K * p.theta_R) + "}{s}";
  else motor_rhs += " + " + coefficient_latex(p.K) + "\\left(\\frac{" + pp::latex(p.theta_R) + "}{s} - \\Theta_L(s)\\right)";
  const std::string theta0_text = ", \\quad \\theta_0 = " + pp::latex(d.free.separation_theta);
  views.push_back({&d.free.motor_position, "theta_m", doc::text("Free mode: the motor ") + doc::math("\\theta_m(t)"), "\\theta_m(t)", "\\Theta_m(s)",
                   "\\left(" + motor_lhs + "\\right)\\Theta_m(s) = " + motor_rhs + theta0_text, "free motor:"});
  views.push_back({&d.free.motor_velocity, "dtheta_m", doc::text("Free mode: the motor's velocity ") + doc::math("\\dot\\theta_m(t)"), "\\dot\\theta_m(t)", "\\dot\\Theta_m(s)",
                   "\\dot\\Theta_m(s) = s\\,\\Theta_m(s) - \\theta_0", "free motor:"});
  views.push_back({&d.free.load_position, "theta_L", doc::text("Free mode: the load ") + doc::math("\\theta_L(t)"), "\\theta_L(t)", "\\Theta_L(s)",
                   "\\left(" + poly(p.JL * s * s + p.FL * s) + "\\right)\\Theta_L(s) = " + coefficient_latex(p.JL) +
                       "\\left(s\\theta_0 + \\dot\\theta_{m0}\\right)" + (p.FL.is_zero() ? std::string() : " + " + coefficient_latex(p.FL) + "\\theta_0") + theta0_text,
                   "free load:"});
  views.push_back({&d.free.load_velocity, "dtheta_L", doc::text("Free mode: the load's velocity ") + doc::math("\\dot\\theta_L(t)"), "\\dot\\theta_L(t)", "\\dot\\Theta_L(s)",
                   "\\dot\\Theta_L(s) = s\\,\\Theta_L(s) - \\theta_0", "free load:"});
  return views;
}

// Section 2: the derivation step by step, its named radicals and every segment.
void steps_section(doc::Document& out, const CaseDerivation& d, const EquationTags& tags, int level) {
  const RadicalList& r = d.radicals;
  out.push_back(doc::heading(level, doc::text("The derivation, step by step")));
  out.push_back(doc::paragraph(
      doc::text("Each segment's equation of motion is transformed with its initial state, solved for the transform, "
                "and inverted by residues at the poles of the factored denominator; every result is checked exactly.  "
                "Free motion starts on the separation line: ") +
      doc::math("\\theta_m(0) = \\theta_L(0) = \\theta_0 = \\theta_R + \\cot\\varphi\\,\\dot\\theta_{m0} = " +
                pp::latex(d.free.separation_theta)) +
      doc::text(", ") + doc::math("\\dot\\theta_m(0) = \\dot\\theta_L(0) = \\dot\\theta_{m0}") +
      doc::text("; contact starts from ") + doc::math("(\\theta_{o0}, \\dot\\theta_{o0})") + doc::text(".")));
  if (!r.empty()) {
    std::vector<Rich> items;
    for (const Radical& rad : r)
      items.push_back(doc::math(pp::latex_symbol_name(rad.symbol.get_name()) + " = \\sqrt{" + pp::latex(rad.square) + "} = " +
                                pp::latex(canonical_sqrt(rad.square)) + " \\approx " +
                                pp::decimal(to_double(rad.symbol, r), 9)) +
                      radical_meaning(rad));
    out.push_back(doc::paragraph(doc::text("Square roots are kept exact and named:")));
    out.push_back(doc::list(items));
  }
  for (const SegmentView& v : segment_views(d))
    for (doc::Block& b : segment_blocks(v, r, d.checks, tags, level + 1)) out.push_back(std::move(b));
}

// The checks whose name starts with `prefix` (all of them for ""), as a list of passed/FAILED items.
doc::Block checks_list(const std::vector<VerificationCheck>& checks, const std::string& prefix) {
  std::vector<Rich> items;
  for (const VerificationCheck& c : checks)
    if (c.name.rfind(prefix, 0) == 0) items.push_back(doc::text(c.passed ? "passed: " : "FAILED: ") + check_rich(c.name));
  return doc::list(items);
}

// Section 3, first part: the separation line from the three slopes (eqs. of η2 = η3), its tangent and angle.
void separation_line_blocks(doc::Document& out, const CaseDerivation& d, const EquationTags& tags) {
  const CaseParameters& p = d.parameters;
  out.push_back(doc::paragraph(doc::text("The load separates where its free deceleration ratio is reached:")));
  out.push_back(doc::equation(with_tag("\\eta_3 = \\frac{\\ddot\\theta_L}{\\dot\\theta_L} = -\\frac{F_L}{J_L} = " +
                                           pp::latex(d.free.eta_separation),
                                       tag(tags, "separation_slope"))));
  out.push_back(doc::paragraph(doc::text("On the motor-alone isocline of that slope, ") +
                               doc::math("\\eta_2 + F_m/J_m = (K/J_m)(\\theta_R - \\theta_{m0})/\\dot\\theta_{m0}") +
                               doc::text(" with ") + doc::math("\\eta_2 = \\eta_3") + doc::text(":")));
  out.push_back(doc::equation(with_tag("\\eta_2 + " + pp::latex(p.Fm / p.Jm) + " = " + coefficient_latex(p.K / p.Jm) + "\\frac{" +
                                           model_number_latex(p.theta_R) + " - \\theta_{m0}}{\\dot\\theta_{m0}}",
                                       tag(tags, "separation_isocline"))));
  const bool infinite = normal(d.free.eta_separation + p.Fm / p.Jm).is_zero();
  const ex tangent_value = infinite ? ex(0) : normal((p.K / p.Jm) / (d.free.eta_separation + p.Fm / p.Jm));
  out.push_back(doc::equation(with_tag(
      "\\frac{\\dot\\theta_{m0}}{" + model_number_latex(p.theta_R) + " - \\theta_{m0}} = \\frac{" + pp::latex(p.K / p.Jm) +
          "}{\\eta_2 + " + pp::latex(p.Fm / p.Jm) + "} = " + (infinite ? std::string("\\infty") : pp::latex(tangent_value)),
      tag(tags, "separation_tangent"))));
  const double psi = infinite ? 90.0 : std::atan(to_double(tangent_value, d.radicals)) * 180.0 / M_PI;
  out.push_back(doc::equation(with_tag("\\arctan\\frac{\\dot\\theta_{m0}}{" + model_number_latex(p.theta_R) +
                                           " - \\theta_{m0}} = " + pp::decimal(psi, 6) + "^\\circ, \\qquad \\varphi = " +
                                           pp::decimal(phi_degrees(d), 6) + "^\\circ",
                                       tag(tags, "separation_angle"))));
  out.push_back(doc::paragraph(doc::text("So the separation line is")));
  out.push_back(doc::equation("\\theta_o = \\theta_R + \\cot\\varphi\\,\\dot\\theta_o, \\qquad \\cot\\varphi = \\frac{J_m F_L - F_m J_L}{K J_L} = " +
                              pp::latex(d.free.cot_phi) + ", \\qquad \\eta_1 = \\eta_2 = \\eta_3 = " +
                              pp::latex(d.free.eta_separation)));
  out.push_back(doc::paragraph(doc::text("Exact checks on the line (the three slopes coincide, the transmitted torque vanishes):")));
  out.push_back(checks_list(d.checks, "separation line:"));
}

// The isocline table: tangent and angle per slope η, combined system beside the motor alone.
void isocline_table(doc::Document& out, const CaseDerivation& d) {
  if (d.isoclines.size() != 2) return;
  const IsoclineTable &c = d.isoclines[0], &m = d.isoclines[1];
  std::vector<std::vector<Rich>> rows;
  auto cell_tangent = [](const IsoclineRow& row) {
    if (row.is_vertical) return doc::math("\\infty");
    return doc::math(pp::latex(row.tangent));
  };
  for (std::size_t k = 0; k < c.rows.size() && k < m.rows.size(); ++k) {
    const IsoclineRow &a = c.rows[k], &b = m.rows[k];
    rows.push_back({doc::math(a.is_infinite ? "\\infty" : pp::latex(a.eta)), cell_tangent(a),
                    doc::math(pp::decimal(to_double(a.angle_degrees, {}), 5) + "^\\circ"), cell_tangent(b),
                    doc::math(pp::decimal(to_double(b.angle_degrees, {}), 5) + "^\\circ")});
  }
  out.push_back(doc::paragraph(doc::text("Isocline slopes: on the isocline of slope ") + doc::math("\\eta") +
                               doc::text(", ") + doc::math("\\dot\\theta/(\\theta - \\theta_R) = -(K/J)/(\\eta + F/J)") +
                               doc::text(" and its angle ") + doc::math("\\psi = \\arctan\\dot\\theta/(\\theta-\\theta_R)") +
                               doc::text(" (combined system: ") + doc::math("J, F") + doc::text("; motor alone: ") +
                               doc::math("J_m, F_m") + doc::text(").")));
  out.push_back(doc::table({doc::math("\\eta"), doc::text("combined: tangent"), doc::math("\\psi_1"),
                            doc::text("motor alone: tangent"), doc::math("\\psi_2")},
                           rows, "rrrrr"));
  out.back().small = true;
}

// Eq. 38 with the case's numbers: C = (1/ωc)·sqrt(θ̇o² − (F/J)θ̇o e + (K/J)e²)·exp((a/ωc) arctan((θ̇o − a e)/(ωc e))).
std::string stability_constant_numbers(const CaseParameters& p, const Radical& omega) {
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  const ex a = F / (2 * J);
  const ex w = canonical_sqrt(omega.square);
  // c·body with the case's numbers: "e^{2}" for 1·e², nothing for 0 (no "1\,e^{2}", no "- 0\,…")
  const auto times = [](const ex& c, const std::string& body) {
    return c.is_zero() ? std::string() : (c.is_equal(1) ? body : pp::latex(c) + "\\," + body);
  };
  const std::string damping = (F / J).is_zero() ? "" : " - " + times(F / J, "\\dot\\theta_o e");
  const std::string shift = a.is_zero() ? "" : " - " + times(a, "e");
  return "C = " + pp::latex(1 / w) + "\\sqrt{\\dot\\theta_o^{2}" + damping + " + " + times(p.K / J, "e^{2}") +
         "}\\;\\exp\\left(" + pp::latex(a / w) + "\\arctan\\frac{\\dot\\theta_o" + shift + "}{" + times(w, "e") + "}\\right)";
}

// Section 3, last part: the stability constant (eq. 38), its rate and its jump at θo = θR.
void stability_constant_blocks(doc::Document& out, const CaseDerivation& d) {
  const CaseParameters& p = d.parameters;
  const RadicalList& r = d.radicals;
  const StabilityConstant& sc = d.contact.stability;
  if (!sc.applicable) {
    out.push_back(doc::paragraph(doc::text("Stability constant (eq. 38): " + sc.region + ".")));
    return;
  }
  const ex a = (p.Fm + p.FL) / (2 * (p.Jm + p.JL));
  const Radical* omega = nullptr;
  for (const Radical& rad : r)
    if (rad.symbol.get_name() == "omega_c") omega = &rad;
  out.push_back(doc::paragraph(
      doc::text("The stability constant (eq. 38), with ") + doc::math("a = F/2J = " + pp::latex(a)) + doc::text(", ") +
      doc::math("\\omega_c") + doc::text(" as above and ") + doc::math("e = \\theta_R - \\theta_o") + doc::text(":")));
  out.push_back(doc::equation(
      "C = \\frac{1}{\\omega_c}\\sqrt{\\dot\\theta_o^{2} - \\frac{F}{J}\\dot\\theta_o e + \\frac{K}{J}e^{2}}\\;"
      "\\exp\\left(\\frac{a}{\\omega_c}\\arctan\\frac{\\dot\\theta_o - a e}{\\omega_c e}\\right)"));
  if (omega) out.push_back(doc::equation(stability_constant_numbers(p, *omega)));
  out.push_back(doc::paragraph(doc::math("d\\ln C/dt = " + pp::latex(sc.dlnC_dt)) +
                               doc::text(" exactly along every contact trajectory.  Crossing ") + doc::math("\\theta_o = \\theta_R") +
                               doc::text(" multiplies the principal-branch C by ") +
                               doc::math("e^{-\\pi a/\\omega_c} = " + pp::latex(with_explicit_radicals(sc.jump_factor, r)) + " \\approx " +
                                         pp::decimal(to_double(sc.jump_factor, r), 6)) +
                               doc::text(".  Where it holds: inside each open half-plane ") + doc::math("\\theta_o < \\theta_R") +
                               doc::text(", ") + doc::math("\\theta_o > \\theta_R") +
                               doc::text("; C compares a separation point with a recombination point only when both lie in the "
                                         "same half-plane, or after that factor is applied.")));
}

}  // namespace

doc::Document derivation_document(const CaseDerivation& d, const EquationTags& tags, int level) {
  doc::Document out;
  model_section(out, d.parameters, tags, level);
  steps_section(out, d, tags, level);
  // ---- separation line, isoclines, momentum, stability
  out.push_back(doc::heading(level, doc::text("Separation line, isoclines, momentum balance, stability constant")));
  separation_line_blocks(out, d, tags);
  isocline_table(out, d);
  out.push_back(doc::paragraph(doc::text("Recombination is an inelastic impact that conserves momentum, ") +
                               doc::math("(J_m + J_L)\\dot\\theta_o^{+} = J_m\\dot\\theta_m + J_L\\dot\\theta_L") +
                               doc::text("; after a free flight of duration t from the separation line:")));
  out.push_back(doc::equation(pp::display("\\dot\\theta_o^{+}(t)", pp::time_function_terms(d.free.recombined_velocity, d.radicals, pp::latex_exact),
                                          "")));
  stability_constant_blocks(out, d);
  out.push_back(doc::heading(level, doc::text("Every exact check of this derivation")));
  out.push_back(checks_list(d.checks, ""));
  return out;
}

namespace {

// A branch condition ("output at motor; Fm^2 < 4*Jm*K; FL = 0") as a reader's text:
// the words as words, the relations as mathematics (F_m^2 < 4J_mK).
doc::Rich condition_rich(const std::string& condition) {
  doc::Rich out;
  for (std::size_t from = 0; from < condition.size();) {
    const std::size_t end = std::min(condition.find("; ", from), condition.size());
    const std::string clause = condition.substr(from, end - from);
    if (!out.empty()) out = out + doc::text("; ");
    if (clause.rfind("output at ", 0) == 0) {
      out = out + doc::text(clause);
    } else {
      std::string math;
      for (std::size_t k = 0; k < clause.size(); ++k) {
        const char c = clause[k], next = k + 1 < clause.size() ? clause[k + 1] : '\0';
        if ((c == 'F' || c == 'J') && (next == 'm' || next == 'L')) math += std::string(1, c) + "_" + next, ++k;
        else if (c == '*') continue;
        else if (c == '!' && next == '=') math += "\\neq", ++k;
        else if (c == ',') math += ",\\ ";
        else math += c;
      }
      out = out + doc::math(math);
    }
    from = end + 2;
  }
  return out;
}

}  // namespace

doc::Document general_document(const std::vector<GeneralBranch>& branches, int level) {
  doc::Document out;
  for (const GeneralBranch& b : branches) {
    out.push_back(doc::heading(level, doc::text("Branch ") + doc::code(b.name)));
    out.push_back(doc::paragraph(doc::text("Where it applies: ") + condition_rich(b.condition) + doc::text(".")));
    for (const BranchParameter& bp : b.branch_parameters)
      out.push_back(doc::paragraph(doc::math(pp::latex_symbol_name(bp.symbol.get_name()) + " = \\sqrt{" +
                                             pp::latex(bp.square_in_physical_parameters) + "}") +
                                   doc::text(" (" + bp.meaning + ")")));
    std::vector<std::tuple<const Segment*, std::string, std::string, std::string>> segments;
    const bool motor = b.name.rfind("motor_", 0) == 0;
    if (b.mode == GeneralBranch::Mode::Contact) {
      segments.push_back({&b.contact.position, "\\Theta_o(s)", "\\theta_o(t)", "15, 25"});
    } else {
      segments.push_back({&b.free.motor_position, "\\Theta_m(s)", "\\theta_m(t)", motor ? "20" : "40"});
      segments.push_back({&b.free.motor_velocity, "\\dot\\Theta_m(s)", "\\dot\\theta_m(t)", motor ? "21" : "41"});
      segments.push_back({&b.free.load_position, "\\Theta_L(s)", "\\theta_L(t)", "22"});
      segments.push_back({&b.free.load_velocity, "\\dot\\Theta_L(s)", "\\dot\\theta_L(t)", "23"});
    }
    if (b.mode == GeneralBranch::Mode::Free)
      out.push_back(doc::paragraph(doc::text("Separation line ") + doc::math("\\cot\\varphi = " + pp::latex(b.free.cot_phi)) +
                                   doc::text(", ") + doc::math("\\theta_0 = " + pp::latex(b.free.separation_theta)) +
                                   doc::text(" (eq. 19).")));
    for (const auto& [segment, laplace_lhs, time_lhs, tag_text] : segments) {
      try {
        // (the transform itself is the thesis's general form, on the general page; here its poles)
        const pp::RationalFunction f = pp::rational_function(segment->laplace, derivation_symbols().s);
        RadicalList radicals;
        const std::vector<Pole> poles = find_poles(f.denominator, derivation_symbols().s, radicals, "omega", "");
        std::vector<std::string> texts;
        for (const Pole& pole : poles)
          texts.push_back(pole_latex(pole, radicals) +
                          (pole.multiplicity > 1 ? "\\ (\\times" + std::to_string(pole.multiplicity) + ")" : std::string()));
        std::sort(texts.begin(), texts.end());  // factor() returns them in hash order
        std::string list;
        for (const std::string& t : texts) list += (list.empty() ? "" : ",\\quad ") + t;
        out.push_back(doc::paragraph(doc::text("Poles of ") + doc::math(laplace_lhs) + doc::text(" (eq. " + tag_text + "): ") +
                                     doc::math("s = " + list)));
      } catch (const std::exception& e) {
        out.push_back(doc::equation(laplace_lhs + " = " + pp::latex(segment->laplace) + " \\tag{" + tag_text + "}"));
      }
      out.push_back(doc::equation(pp::display(time_lhs, pp::time_function_terms(segment->solution, {}, pp::latex_exact), "")));
    }
    bool all = !b.checks.empty();
    for (const VerificationCheck& c : b.checks) all = all && c.passed;
    out.push_back(doc::paragraph(doc::text(std::to_string(b.checks.size()) + " exact checks " + (all ? "passed." : "— SOME FAILED."))));
  }
  return out;
}

std::string to_latex(const CaseDerivation& d) {
  doc::Document document;
  const bool redundant = d.name == "Case " + d.case_id || d.name == d.case_id;
  document.push_back(doc::heading(1, doc::text((redundant ? d.name : d.name + " (case " + d.case_id + ")") + ": output at the " +
                                               measured_at_text(d.parameters.measured_at))));
  for (doc::Block& b : derivation_document(d, {}, 2)) document.push_back(std::move(b));
  doc::LatexOptions options;
  options.top_level = 1;  // heading 1 → \section
  return doc::to_latex(document, options);
}

std::string to_latex(const GeneralBranch& b) {
  doc::LatexOptions options;
  options.top_level = 1;
  return doc::to_latex(general_document({b}, 2), options);
}

std::string to_text(const CaseDerivation& d) {
  const RadicalList& r = d.radicals;
  std::ostringstream out;
  out << escape::cpp_comment(d.name) << " (case " << escape::cpp_comment(d.case_id) << "), output at the "
      << measured_at_text(d.parameters.measured_at) << "\n";
  for (const Radical& rad : r)
    out << "  " << rad.symbol.get_name() << " = sqrt(" << canonical(rad.square) << ") = " << canonical(canonical_sqrt(rad.square)) << "\n";
  out << "contact (" << to_string(d.contact_branch) << "):\n  theta_o(t) = " << exact_text(d.contact.position.solution, r) << "\n";
  out << "separation line: theta_o = theta_R + cot_phi*dtheta_o, cot_phi = " << canonical(d.free.cot_phi) << "\n";
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
