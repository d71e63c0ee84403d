// case_writer.cpp — the one case-file writer (case_writer.hpp).
#include "backlash/model/case_writer.hpp"

#include "backlash/output/text.hpp"

#include <charconv>
#include <sstream>

namespace backlash::model {

using output::toml_string;

std::string exact_text(const Rational& value) { return toml_string(to_string(value)); }

std::string decimal_text(double value) {
  char buffer[64];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, error == std::errc() ? end : buffer);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

std::string exact_or_decimal(const Rational& original, double value) {
  return to_double(original) == value ? exact_text(original) : decimal_text(value);
}

namespace {

void write_experiment(std::ostream& out, const ExperimentText& x) {
  out << "[experiment]\n";
  if (x.kind == ExperimentKind::Step)
    out << "step = " << x.step << "\n";
  else
    out << "kind = \"drive\"\ndrive_gain = " << x.drive_gain << "\n";
  if (x.t_end) out << "t_end = " << *x.t_end << "\n";
  if (x.step_time) out << "step_time = " << *x.step_time << "\n";
}

/// [effects]: each effect whose first parameter is present, `KEY = v` or `KEY = { k = v, ... }`.
void write_effects(std::ostream& out, const CaseFileText& c, const char* blank) {
  bool any = false;
  for (const EffectInfo& effect : effects_table) any = any || c.effects[effect.first].has_value();
  if (!any) return;
  out << blank << "[effects]\n";
  for (const EffectInfo& effect : effects_table) {
    if (!c.effects[effect.first]) continue;
    if (effect.single()) {
      out << effect.key << " = " << *c.effects[effect.first] << "\n";
      continue;
    }
    out << effect.key << " = {";
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      out << (i == effect.first ? " " : ", ") << effect_parameters[i].key << " = " << c.effects[i].value_or("0");
    out << " }\n";
  }
}

}  // namespace

std::string write_case_file(const CaseFileText& c) {
  std::ostringstream out;
  const char* blank = c.blank_line_before_tables ? "\n" : "";
  for (const std::string& line : c.comments) out << "# " << line << "\n";
  out << "name = " << toml_string(c.name) << "\n";
  out << "measured_at = \"" << to_string(c.measured_at) << "\"\n";
  out << "K = " << c.K << "\nbacklash = " << c.backlash << "\nreference = " << c.reference << "\n";
  out << blank << "[motor]\nJ = " << c.Jm << "\nF = " << c.Fm << "\n";
  out << blank << "[load]\nJ = " << c.JL << "\nF = " << c.FL << "\n";
  if (c.experiment) {
    out << blank;
    write_experiment(out, *c.experiment);
  }
  if (!c.fit_free.empty() || !c.fit_fixed.empty()) out << blank << "[fit]\n";
  for (const auto& [key, names] : {std::pair{"free", &c.fit_free}, std::pair{"fixed", &c.fit_fixed}}) {
    if (names->empty()) continue;
    out << key << " = [";
    for (std::size_t i = 0; i < names->size(); ++i) out << (i ? ", " : "") << toml_string((*names)[i]);
    out << "]\n";
  }
  write_effects(out, c, blank);
  return out.str();
}

std::string write_case_file(const CaseSpec& s) {
  CaseFileText c;
  c.name = s.name;
  c.measured_at = s.measured_at;
  c.K = exact_text(s.K), c.backlash = exact_text(s.backlash), c.reference = exact_text(s.reference);
  c.Jm = exact_text(s.Jm), c.Fm = exact_text(s.Fm), c.JL = exact_text(s.JL), c.FL = exact_text(s.FL);
  if (s.experiment) {
    const Experiment& x = *s.experiment;
    c.experiment = ExperimentText{x.kind, exact_text(x.step), exact_text(x.drive_gain), std::nullopt, std::nullopt};
    if (x.t_end) c.experiment->t_end = exact_text(*x.t_end);
    if (x.step_time) c.experiment->step_time = exact_text(*x.step_time);
  }
  for (const EffectInfo& effect : effects_table) {
    if (!s.effects.has(effect)) continue;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      if (const std::optional<Rational>& v = field(s.effects, effect_parameters[i].id)) c.effects[i] = exact_text(*v);
  }
  c.fit_free = s.fit_free;
  c.fit_fixed = s.fit_fixed;
  return write_case_file(c);
}

}  // namespace backlash::model
