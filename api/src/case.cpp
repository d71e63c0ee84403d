// case.cpp — errors, and a case from a thesis id, a file, text, or numbers given in code.
//
// Numbers given in code take the case file's route: they are written into a case file's
// text as exact strings ("p/q") and read back by the strict reader (model/case_spec.hpp),
// so a case from code obeys exactly the rules of a case file, with the same messages —
// only the key is named the way the caller named it (Jm, not motor.J) and the made-up
// file name and line are left out.
#include "backlash/api/backlash.hpp"

#include "backlash/measurements/measured_record.hpp"
#include "backlash/output/text.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <sstream>
#include <tuple>

namespace backlash::api {

namespace {

using output::toml_string;  // a TOML basic string (no control characters survive)

std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

std::string exact(const model::Rational& value) { return toml_string(model::to_string(value)); }

/// The facade's parameter names and the case file's keys they stand for.
struct ParameterKey {
  const char* name;
  const char* key;
};
constexpr std::array<ParameterKey, 21> parameter_keys{{
    {"name", "name"},
    {"measured_at", "measured_at"},
    {"K", "K"},
    {"backlash", "backlash"},
    {"reference", "reference"},
    {"Jm", "motor.J"},
    {"Fm", "motor.F"},
    {"JL", "load.J"},
    {"FL", "load.F"},
    {"experiment", "experiment.kind"},
    {"step", "experiment.step"},
    {"t_end", "experiment.t_end"},
    {"drive_gain", "experiment.drive_gain"},
    {"coulomb_motor", "effects.coulomb_motor"},
    {"coulomb_load", "effects.coulomb_load"},
    {"restitution", "effects.restitution"},
    {"saturation", "effects.saturation"},
    {"stiffness", "effects.compliance.stiffness"},
    {"damping", "effects.compliance.damping"},
    {"delay", "effects.delay"},
    {"torque_offset", "effects.torque_offset"},
}};

std::string allowed_names() {
  std::string names;
  for (const ParameterKey& k : parameter_keys) names += (names.empty() ? "" : " ") + std::string(k.name);
  return names;
}

/// The facade's name of a case-file key ("motor.J" → "Jm"); the key itself when it has none.
std::string name_of_key(const std::string& key) {
  for (const ParameterKey& k : parameter_keys)
    if (key == k.key) return k.name;
  if (key == "effects.compliance") return "stiffness";
  return key;
}

/// Reads `text` as a case file named `pseudo_file`; a problem becomes a BadInput naming
/// the facade's parameter (no made-up file or line in the message).
model::CaseSpec read_parameters_text(const std::string& text, const std::string& pseudo_file) {
  try {
    return model::parse_case(text, pseudo_file);
  } catch (const model::CaseFileError& error) {
    std::string message = error.what();
    const std::string prefix = pseudo_file + ":" + std::to_string(error.line()) + ": ";
    if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
    if (!error.key().empty() && message.rfind(error.key() + ": ", 0) == 0)
      message.erase(0, error.key().size() + 2);
    throw BadInput(error.key().empty() ? "parameters" : name_of_key(error.key()), message);
  }
}

}  // namespace

// ---------------------------------------------------------------------- errors

BadInput::BadInput(std::string argument, const std::string& problem)
    : std::invalid_argument(one_line(argument.empty() ? problem : argument + ": " + problem)),
      argument_(std::move(argument)),
      problem_(one_line(problem)) {}

bool is_bad_input(const std::exception& error) {
  return dynamic_cast<const BadInput*>(&error) != nullptr || dynamic_cast<const model::CaseFileError*>(&error) != nullptr ||
         dynamic_cast<const measurements::MeasuredDataError*>(&error) != nullptr;
}

// ---------------------------------------------------------------------- cases

Case Case::load(const std::string& case_or_path) { return Case(model::load_case(case_or_path)); }

Case Case::from_text(const std::string& toml, const std::string& name, const std::string& id) {
  model::CaseSpec spec = model::parse_case(toml, name);
  if (!id.empty()) spec.id = id;
  return Case(std::move(spec));
}

Case Case::from_texts(const std::vector<std::pair<std::string, std::string>>& parameters) {
  std::map<std::string, std::string> given;  // facade name → value text
  for (const auto& [name, value] : parameters) {
    const bool known = std::any_of(parameter_keys.begin(), parameter_keys.end(),
                                   [&](const ParameterKey& k) { return name == k.name; });
    if (!known) throw BadInput(name, "unknown parameter (allowed: " + allowed_names() + ")");
    if (!given.emplace(name, value).second) throw BadInput(name, "given twice");
  }
  auto value = [&](const char* name) -> const std::string* {
    const auto found = given.find(name);
    return found == given.end() ? nullptr : &found->second;
  };
  const std::string name = value("name") ? *value("name") : "parameters";
  if (name.empty()) throw BadInput("name", "empty name");

  // Every value as a TOML string: the reader parses numbers in strings exactly ("0.3" is 3/10).
  std::ostringstream toml;
  toml << "name = " << toml_string(name) << "\n";
  for (const char* key : {"measured_at", "K", "backlash", "reference"})
    if (const std::string* v = value(key)) toml << key << " = " << toml_string(*v) << "\n";
  for (const auto& [table, inertia, friction] :
       {std::tuple{"motor", "Jm", "Fm"}, std::tuple{"load", "JL", "FL"}}) {
    toml << "[" << table << "]\n";
    if (const std::string* v = value(inertia)) toml << "J = " << toml_string(*v) << "\n";
    if (const std::string* v = value(friction)) toml << "F = " << toml_string(*v) << "\n";
  }
  if (value("experiment") || value("step") || value("t_end") || value("drive_gain")) {
    toml << "[experiment]\n";
    if (const std::string* v = value("experiment")) toml << "kind = " << toml_string(*v) << "\n";
    for (const char* key : {"step", "t_end", "drive_gain"})
      if (const std::string* v = value(key)) toml << key << " = " << toml_string(*v) << "\n";
  }
  const bool compliance = value("stiffness") || value("damping");
  std::ostringstream effects;
  for (const char* key : {"coulomb_motor", "coulomb_load", "restitution", "saturation", "delay", "torque_offset"})
    if (const std::string* v = value(key)) effects << key << " = " << toml_string(*v) << "\n";
  if (compliance) {
    effects << "compliance = {";
    const char* separator = " ";
    for (const char* key : {"stiffness", "damping"})
      if (const std::string* v = value(key)) {
        effects << separator << key << " = " << toml_string(*v);
        separator = ", ";
      }
    effects << " }\n";
  }
  if (!effects.str().empty()) toml << "[effects]\n" << effects.str();

  model::CaseSpec spec = read_parameters_text(toml.str(), "<parameters>");
  spec.id = name;
  spec.name = name;
  spec.source.clear();
  return Case(std::move(spec));
}

Case Case::from_parameters(const CaseParameters& p) {
  std::vector<std::pair<std::string, std::string>> texts{
      {"name", p.name},
      {"measured_at", model::to_string(p.measured_at)},
      {"Jm", model::to_string(p.Jm)},
      {"Fm", model::to_string(p.Fm)},
      {"JL", model::to_string(p.JL)},
      {"FL", model::to_string(p.FL)},
      {"K", model::to_string(p.K)},
      {"backlash", model::to_string(p.backlash)},
      {"reference", model::to_string(p.reference)},
  };
  if (p.step) texts.emplace_back("step", model::to_string(*p.step));
  if (p.t_end) texts.emplace_back("t_end", model::to_string(*p.t_end));
  if (p.t_end && !p.step) throw BadInput("t_end", "an end time needs a step experiment (give step too)");
  const model::Effects& e = p.effects;
  if (e.coulomb_motor != 0) texts.emplace_back("coulomb_motor", model::to_string(e.coulomb_motor));
  if (e.coulomb_load != 0) texts.emplace_back("coulomb_load", model::to_string(e.coulomb_load));
  if (e.restitution != 0) texts.emplace_back("restitution", model::to_string(e.restitution));
  if (e.saturation) texts.emplace_back("saturation", model::to_string(*e.saturation));
  if (e.compliance) {
    texts.emplace_back("stiffness", model::to_string(e.compliance->stiffness));
    texts.emplace_back("damping", model::to_string(e.compliance->damping));
  }
  if (e.delay != 0) texts.emplace_back("delay", model::to_string(e.delay));
  if (e.torque_offset != 0) texts.emplace_back("torque_offset", model::to_string(e.torque_offset));
  return from_texts(texts);
}

std::string Case::case_file() const {
  const model::CaseSpec& s = spec_;
  std::ostringstream out;
  out << "name = " << toml_string(s.name) << "\n";
  out << "measured_at = \"" << model::to_string(s.measured_at) << "\"\n";
  out << "K = " << exact(s.K) << "\n";
  out << "backlash = " << exact(s.backlash) << "\n";
  out << "reference = " << exact(s.reference) << "\n";
  out << "[motor]\nJ = " << exact(s.Jm) << "\nF = " << exact(s.Fm) << "\n";
  out << "[load]\nJ = " << exact(s.JL) << "\nF = " << exact(s.FL) << "\n";
  if (s.experiment) {
    const model::Experiment& x = *s.experiment;
    out << "[experiment]\n";
    if (x.kind == model::ExperimentKind::Step) {
      out << "step = " << exact(x.step) << "\n";
    } else {
      out << "kind = \"drive\"\ndrive_gain = " << exact(x.drive_gain) << "\n";
    }
    if (x.t_end) out << "t_end = " << exact(*x.t_end) << "\n";
  }
  if (s.effects.any()) {
    const model::Effects& e = s.effects;
    out << "[effects]\n";
    if (e.coulomb_motor != 0) out << "coulomb_motor = " << exact(e.coulomb_motor) << "\n";
    if (e.coulomb_load != 0) out << "coulomb_load = " << exact(e.coulomb_load) << "\n";
    if (e.restitution != 0) out << "restitution = " << exact(e.restitution) << "\n";
    if (e.saturation) out << "saturation = " << exact(*e.saturation) << "\n";
    if (e.compliance)
      out << "compliance = { stiffness = " << exact(e.compliance->stiffness) << ", damping = " << exact(e.compliance->damping)
          << " }\n";
    if (e.delay != 0) out << "delay = " << exact(e.delay) << "\n";
    if (e.torque_offset != 0) out << "torque_offset = " << exact(e.torque_offset) << "\n";
  }
  if (!s.fit_free.empty()) {
    out << "[fit]\nfree = [";
    for (std::size_t i = 0; i < s.fit_free.size(); ++i) out << (i ? ", " : "") << toml_string(s.fit_free[i]);
    out << "]\n";
  }
  return out.str();
}

Case load(const std::string& case_or_path) { return Case::load(case_or_path); }
Case load(const CaseParameters& parameters) { return Case::from_parameters(parameters); }

}  // namespace backlash::api
