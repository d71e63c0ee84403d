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
#include "backlash/model/case_writer.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <sstream>
#include <tuple>
#include <vector>

namespace backlash::api {

namespace {

using output::toml_string;  // a TOML basic string (no control characters survive)

std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}


/// The facade's parameter names and the case file's keys they stand for: the structure and
/// the experiment here, then every effect parameter of the table of effects by its NAME.
struct ParameterKey {
  std::string name;
  std::string key;
};

const std::vector<ParameterKey>& parameter_keys() {
  static const std::vector<ParameterKey> keys = [] {
    std::vector<ParameterKey> k{{"name", "name"},
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
                                {"drive_gain", "experiment.drive_gain"}};
    for (const model::EffectParameterInfo& p : model::effect_parameters) {
      const std::string effect(p.effect), key(p.key);
      k.push_back({std::string(p.name), "effects." + (key == effect ? key : effect + "." + key)});
    }
    return k;
  }();
  return keys;
}

std::string allowed_names() {
  std::string names;
  for (const ParameterKey& k : parameter_keys()) names += (names.empty() ? "" : " ") + k.name;
  return names;
}

/// The facade's name of a case-file key ("motor.J" → "Jm"); the key itself when it has none
/// (an effect of several parameters is named by its first).
std::string name_of_key(const std::string& key) {
  for (const ParameterKey& k : parameter_keys())
    if (key == k.key) return k.name;
  for (const model::EffectInfo& effect : model::effects_table)
    if (key == "effects." + std::string(effect.key)) return std::string(effect.primary().name);
  return key;
}

/// The [effects] table of the facade's texts, `NAME = "value"` (an effect of several
/// parameters as `KEY = { ... }` with those given).
std::string effects_text(const std::function<const std::string*(const std::string&)>& value) {
  std::ostringstream effects;
  for (const bool single : {true, false})
    for (const model::EffectInfo& effect : model::effects_table) {
      if (effect.single() != single) continue;
      std::ostringstream entries;
      const char* separator = " ";
      for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
        if (const std::string* v = value(std::string(model::effect_parameters[i].name))) {
          entries << separator << model::effect_parameters[i].key << " = " << toml_string(*v);
          separator = ", ";
        }
      if (entries.str().empty()) continue;
      if (single)
        effects << entries.str().substr(1) << "\n";  // "KEY = value"
      else
        effects << effect.key << " = {" << entries.str() << " }\n";
    }
  return effects.str();
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
    const bool known = std::any_of(parameter_keys().begin(), parameter_keys().end(),
                                   [&name = name](const ParameterKey& k) { return name == k.name; });
    if (!known) throw BadInput(name, "unknown parameter (allowed: " + allowed_names() + ")");
    if (!given.emplace(name, value).second) throw BadInput(name, "given twice");
  }
  auto value = [&](const std::string& name) -> const std::string* {
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
  const std::string effects = effects_text(value);
  if (!effects.empty()) toml << "[effects]\n" << effects;

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
  for (const model::EffectInfo& effect : model::effects_table) {
    if (!p.effects.has(effect)) continue;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      if (const auto& v = model::field(p.effects, model::effect_parameters[i].id))
        texts.emplace_back(std::string(model::effect_parameters[i].name), model::to_string(*v));
  }
  return from_texts(texts);
}

std::string Case::case_file() const { return model::write_case_file(spec_); }

Case load(const std::string& case_or_path) { return Case::load(case_or_path); }
Case load(const CaseParameters& parameters) { return Case::from_parameters(parameters); }

}  // namespace backlash::api
