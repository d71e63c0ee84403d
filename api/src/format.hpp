// format.hpp — printf into a std::string (the CLI's text output, byte for byte), the JSON
// values the writers share, and the checks every route takes.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"

#include <nlohmann/json.hpp>

#include <cstdarg>
#include <cstdio>
#include <string>
#include <type_traits>

namespace backlash::api::detail {

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
inline void appendf(std::string& out, const char* format, ...) {
  va_list arguments;
  va_start(arguments, format);
  va_list copy;
  va_copy(copy, arguments);
  const int length = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (length > 0) {
    const std::size_t start = out.size();
    out.resize(start + static_cast<std::size_t>(length) + 1);
    std::vsnprintf(out.data() + start, static_cast<std::size_t>(length) + 1, format, arguments);
    out.resize(start + static_cast<std::size_t>(length));
  }
  va_end(arguments);
}

/// A number as printf's %g writes it (the facade's messages: "got -3").
inline std::string number_text(double value) {
  std::string out;
  appendf(out, "%g", value);
  return out;
}

/// The effects as JSON: {"coulomb_load": 0.03, ...}, only those present.
inline nlohmann::json effects_json(const numeric::Effects& e) {
  nlohmann::json out = nlohmann::json::object();
  for (const model::EffectInfo& effect : model::effects_table) {
    if (!e.has(effect)) continue;
    if (effect.single()) {
      out[std::string(effect.key)] = model::field(e, effect.primary().id);
      continue;
    }
    nlohmann::json& parameters = out[std::string(effect.key)] = nlohmann::json::object();
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      parameters[std::string(model::effect_parameters[i].key)] = model::field(e, model::effect_parameters[i].id);
  }
  return out;
}

/// A status as text, whether the numeric layer keeps it as text or as an enum with a
/// to_string() beside it (as numeric::SimulationStatus).
template <class Status>
  requires std::is_enum_v<Status>
std::string status_text(Status status) {
  return to_string(status);  // found by argument-dependent lookup in the enum's namespace
}

/// Refuses, before any work, parameters whose rates double precision or the certified event
/// searches cannot handle (numeric/scales.hpp): model::CaseFileError "FILE: cannot be
/// computed in double precision: K, motor.J: problem" (model.cpp).
void check_parameter_scales(const model::CaseSpec& spec);

/// A JSON document as the CLI prints it: two-space indentation, final newline.
inline std::string document(const nlohmann::json& value) { return value.dump(2) + "\n"; }

}  // namespace backlash::api::detail
