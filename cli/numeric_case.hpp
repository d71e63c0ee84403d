// backlash/cli/numeric_case.hpp — a case's evaluator through the validation gate.
//
// trace, simulate and limit-cycle work only on an evaluator that passed the
// gate (numeric/validation.hpp); if it did not, the command stops with a
// one-line error naming the failing states (exit 1) and writes nothing.
#pragma once

#include "commands.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/validation.hpp"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace backlash::cli {

struct ValidatedCase {
  model::CaseSpec spec;
  numeric::ValidationResult validation;
  numeric::EffectValidationResult effects;  ///< the [effects] table's modes through their gate
  const numeric::ValidatedEvaluator& evaluator() const { return validation.evaluator(); }
  /// The model with its effects (the nominal model when the case has none).
  const numeric::ValidatedEffectModel& model() const { return effects.model(); }
};

/// Refuses, before any work, parameters whose rates double precision or the event searches
/// cannot handle (numeric/scales.hpp): bad input, "FILE: K, motor.J: problem".
inline void check_parameter_scales(const model::CaseSpec& spec) {
  numeric::Parameters p = numeric::parameters_of(spec);
  p.theta_R = 0;  // the numerics run in error coordinates: θR plays no part
  if (const std::optional<std::string> problem = numeric::parameter_scale_problem(p))
    throw model::CaseFileError(spec.source, 0, "", "cannot be computed in double precision: " + *problem);
}

inline ValidatedCase validated_case(const std::string& case_name) {
  model::CaseSpec spec = model::load_case(case_name);
  check_parameter_scales(spec);
  numeric::ValidationResult result = numeric::validate(numeric::case_evaluator(spec));
  if (!result.passed()) {
    std::string failing;
    for (const numeric::StateError& s : result.report().states)
      if (!s.passed) failing += (failing.empty() ? "" : ", ") + s.state;
    throw std::runtime_error("case " + spec.id + ": the evaluator failed validation against odeint (" + failing +
                             "); refusing to use it");
  }
  numeric::EffectValidationResult effects = numeric::validate_effects(result.evaluator(), numeric::effects_of(spec));
  if (!effects.passed()) (void)effects.model();  // throws, naming the failing modes
  return ValidatedCase{std::move(spec), std::move(result), std::move(effects)};
}

/// The effects as JSON: {"coulomb_load": 0.03, ...}, only those present.
inline nlohmann::json effects_json(const numeric::Effects& e) {
  nlohmann::json out = nlohmann::json::object();
  if (e.coulomb_motor > 0) out["coulomb_motor"] = e.coulomb_motor;
  if (e.coulomb_load > 0) out["coulomb_load"] = e.coulomb_load;
  if (e.restitution != 0) out["restitution"] = e.restitution;
  if (e.saturating()) out["saturation"] = e.saturation;
  if (e.compliant()) out["compliance"] = {{"stiffness", e.mesh_stiffness}, {"damping", e.mesh_damping}};
  if (e.delayed()) out["delay"] = e.delay;
  if (e.torque_offset != 0) out["torque_offset"] = e.torque_offset;
  return out;
}

/// A finite number, or UsageError naming the flag and what is wrong: not a number at all, or
/// one double precision cannot hold (beyond ±1.8e308, or nonzero below 2.2e-308 in size, where
/// it keeps fewer digits — use 0 or a larger value).
inline double parse_number(const std::string& text, const std::string& flag) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) throw UsageError(flag + ": empty value");
  const std::string trimmed = text.substr(first, text.find_last_not_of(" \t") - first + 1);
  const char* begin = trimmed.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  const int range = errno;
  if (end == begin || *end != '\0') throw UsageError(flag + ": '" + text + "' is not a number");
  if (std::isnan(value) || (std::isinf(value) && range != ERANGE)) throw UsageError(flag + ": '" + text + "' is not finite");
  if (range == ERANGE && std::isinf(value))
    throw UsageError(flag + ": '" + text + "' is too large for double precision (beyond 1.8e308)");
  if (value != 0 && !std::isnormal(value))
    throw UsageError(flag + ": '" + text + "' is too small for double precision (nonzero below 2.2e-308 in size); "
                     "use 0 or a larger value");
  if (range == ERANGE && value == 0)
    throw UsageError(flag + ": '" + text + "' is too small for double precision (nonzero below 2.2e-308 in size); "
                     "use 0 or a larger value");
  return value;
}

/// A comma-separated list of numbers; empty entries are errors.
inline std::vector<double> parse_number_list(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    if (first == std::string::npos) throw UsageError(flag + ": empty entry in '" + text + "'");
    values.push_back(parse_number(item.substr(first, last - first + 1), flag));
  }
  if (values.empty() || text.back() == ',') throw UsageError(flag + ": empty entry in '" + text + "'");
  return values;
}

}  // namespace backlash::cli
