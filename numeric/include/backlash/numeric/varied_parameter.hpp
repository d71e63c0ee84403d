// backlash/numeric/varied_parameter.hpp — the parameters a sweep or a design-space map varies.
//
// By name: the structure Jm, Fm, JL, FL, K, backlash, reference; the ratios JL_over_Jm (JL/Jm
// keeping J = Jm + JL) and FL_over_F (FL/F keeping F = Fm + FL); and every effect parameter
// of the table of effects (backlash/model/effect_table.hpp) by its NAME.  `sweep` and `map`
// set a point's parameters through this one function, so a one-axis map is that sweep.
#pragma once

#include "backlash/model/effect_table.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/parametric.hpp"

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace backlash::numeric {

/// The structural names, in the order sweeps and maps list them (the effects follow).
inline constexpr std::array<std::string_view, 9> structural_parameter_names{
    "Jm", "Fm", "JL", "FL", "K", "backlash", "reference", "JL_over_Jm", "FL_over_F"};

/// A varied parameter: a structural one (its index in structural_parameter_names) or an effect's.
struct VariedParameter {
  std::string_view name;
  int structural = -1;                  ///< >= 0 for the structure
  const model::EffectParameterInfo* effect = nullptr;
};

/// The parameter called `name`, or nothing.
inline std::optional<VariedParameter> varied_parameter(std::string_view name) {
  for (std::size_t i = 0; i < structural_parameter_names.size(); ++i)
    if (structural_parameter_names[i] == name) return VariedParameter{structural_parameter_names[i], static_cast<int>(i)};
  if (const model::EffectParameterInfo* e = model::effect_parameter_named(name)) return VariedParameter{e->name, -1, e};
  return std::nullopt;
}

/// Every name, separated by `separator` ("Jm, Fm, ..., torque offset's NAME").
inline std::string varied_parameter_names(std::string_view separator) {
  std::string names;
  for (std::string_view n : structural_parameter_names) names += (names.empty() ? "" : std::string(separator)) + std::string(n);
  for (const model::EffectParameterInfo& e : model::effect_parameters) names += std::string(separator) + std::string(e.name);
  return names;
}

/// Sets the parameter to x in (p, e); `base` is the case's own parameters (the ratios keep its sums).
inline void set_varied(const VariedParameter& v, double x, Parameters& p, Effects& e, const Parameters& base) {
  if (v.effect != nullptr) {
    model::field(e, v.effect->id) = x;
    return;
  }
  switch (v.structural) {
    case 0: p.Jm = x; break;
    case 1: p.Fm = x; break;
    case 2: p.JL = x; break;
    case 3: p.FL = x; break;
    case 4: p.K = x; break;
    case 5: p.backlash = x; break;
    case 6: p.theta_R = x; break;
    case 7: {  // keeping J = Jm + JL
      const double J = base.Jm + base.JL;
      p.Jm = J / (1 + x);
      p.JL = J * x / (1 + x);
      break;
    }
    default: {  // FL_over_F, keeping F = Fm + FL
      const double F = base.Fm + base.FL;
      p.FL = x * F;
      p.Fm = F - p.FL;
    }
  }
}

/// True when the structure is physical: inertias and K > 0, frictions and backlash >= 0.
inline bool physical(const Parameters& p) {
  return p.Jm > 0 && p.JL > 0 && p.Fm >= 0 && p.FL >= 0 && p.K > 0 && p.backlash >= 0;
}

/// True when every effect parameter is admissible (the table's ADMISSIBLE).
inline bool admissible(const Effects& e) {
  for (const model::EffectParameterInfo& parameter : model::effect_parameters)
    if (!parameter.admits(model::field(e, parameter.id))) return false;
  return true;
}

/// True when two contact laws (restitution, compliance) are both present.
inline bool contact_laws_clash(const Effects& e) {
  int present = 0;
  for (const model::EffectInfo& effect : model::effects_table) present += effect.contact_law && e.has(effect);
  return present > 1;
}

/// True when varying `v` adds a second contact law to the effects `e` already has.
inline bool adds_contact_law(const VariedParameter& v, const Effects& e) {
  if (v.effect == nullptr || !model::effect_of(v.effect->id).contact_law) return false;
  for (const model::EffectInfo& other : model::effects_table)
    if (&other != &model::effect_of(v.effect->id) && other.contact_law && e.has(other)) return true;
  return false;
}

/// `v` is a parameter of an effect of several parameters that `e` does not have (a mesh's
/// damping without its stiffness): the message, else "".
inline std::string missing_effect(const VariedParameter& v, const Effects& e) {
  if (v.effect == nullptr) return "";
  const model::EffectInfo& effect = model::effect_of(v.effect->id);
  if (effect.single() || e.has(effect)) return "";
  return std::string(v.name) + ": the case has no [effects] " + std::string(effect.key) +
         " to vary (give one in the case file)";
}

/// The message of two contact laws (sweeps, maps).
inline std::string contact_law_message(std::string_view name) {
  return std::string(name) + ": restitution and compliance both model the impact; give one of them";
}

/// A point's whole parameter set as the columns of a sweep's or map's rows: the structure
/// Jm, Fm, JL, FL, K, backlash, reference, then every effect parameter by its NAME.
inline std::vector<std::string> point_column_names() {
  std::vector<std::string> names(structural_parameter_names.begin(), structural_parameter_names.begin() + 7);
  for (const model::EffectParameterInfo& e : model::effect_parameters) names.emplace_back(e.name);
  return names;
}

/// The values of point_column_names() for (p, e).
inline std::vector<double> point_column_values(const Parameters& p, const Effects& e) {
  std::vector<double> values{p.Jm, p.Fm, p.JL, p.FL, p.K, p.backlash, p.theta_R};
  for (const model::EffectParameterInfo& parameter : model::effect_parameters) values.push_back(model::field(e, parameter.id));
  return values;
}

}  // namespace backlash::numeric
