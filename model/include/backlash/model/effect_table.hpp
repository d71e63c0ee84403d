// backlash/model/effect_table.hpp — the one table of the effects the thesis left out.
//
// Every effect parameter is declared here once, in BACKLASH_EFFECT_PARAMETERS, and every
// library reads it from here: the case-file reader and writer (model/), the exact and
// double structs of effects (model::Effects, numeric::Effects, both generated from the
// table), the sweeps and maps (their names, columns and range checks), the facade's JSON,
// Python, the map figures (symbol and axis label) and the discrepancy candidates (the range
// a fit searches, scaled to the model).  What an effect DOES — its modes, guards and resets —
// is physics and lives with each simulator in numeric/ (docs/effects.md).
//
// Adding an effect: one row per parameter below, one row in BACKLASH_EFFECTS, its physics in
// each simulator, its tests (docs/design.md, "Where to change what").
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

// ------------------------------------------------------------------ the parameters
//
// X(FIELD, EFFECT, KEY, NAME, SYMBOL, DESCRIPTION, UNIT, NEUTRAL, ADMISSIBLE, PROBLEM,
//   SCALE, LOW, HIGH, LOGARITHMIC, FIT_NAME)
//   FIELD        the member of model::Effects / numeric::Effects
//   EFFECT       the effect's key in the case file's [effects] table
//   KEY          the parameter's key: EFFECT itself, or its key inside EFFECT = { ... }
//   NAME         its name for sweeps, maps, Python, CSV/JSON/HDF5 columns and describe()
//   SYMBOL       the figures' symbol (gnuplot enhanced text); DESCRIPTION and UNIT the axis label
//   NEUTRAL      the value that is the thesis's model (0, or kAbsent = +∞: no limit, a rigid mesh)
//   ADMISSIBLE   the values a case file, a sweep or a map may give (Admissible below), and the
//                reader's PROBLEM when one is outside
//   SCALE..FIT_NAME  the discrepancy candidate: the range a fit searches, LOW·s to HIGH·s with s
//                the model's own scale (CandidateScale below), logarithmic or linear, and the
//                name of the fitted parameter on the page and in the JSON
// Across parameters: an effect with a `static` and a `kinetic` level (Stribeck friction) needs
// kinetic <= static (the reader and numeric::effect_scale_problem refuse the rest): its candidate
// fits the static level as a ratio to the kinetic one (KineticRatio, LOW = 1).
#define BACKLASH_EFFECT_PARAMETERS(X)                                                                            \
  X(coulomb_motor, "coulomb_motor", "coulomb_motor", "coulomb_motor", "T_{m}", "Coulomb friction on the motor", \
    "N·m", 0.0, NonNegative, "negative Coulomb torque; a friction torque must be >= 0",                          \
    StepTorque, 1e-4, 0.3, true, "torque")                                                                       \
  X(coulomb_load, "coulomb_load", "coulomb_load", "coulomb_load", "T_{L}", "Coulomb friction on the load",       \
    "N·m", 0.0, NonNegative, "negative Coulomb torque; a friction torque must be >= 0",                          \
    StepTorque, 1e-4, 0.3, true, "torque")                                                                       \
  X(restitution, "restitution", "restitution", "restitution", "e", "restitution", "dimensionless", 0.0,          \
    BelowOne, "coefficient of restitution outside [0, 1): 0 is the inelastic impact, 1 would never settle",      \
    Absolute, 0.02, 0.95, false, "e")                                                                            \
  X(saturation, "saturation", "saturation", "saturation", "L", "torque limit", "N·m", ::backlash::model::kAbsent, Positive,         \
    "non-positive saturation limit; the drive torque limit must be > 0", StepTorque, 0.02, 1.0, true, "limit")   \
  X(mesh_stiffness, "compliance", "stiffness", "stiffness", "k_{c}", "mesh stiffness", "N·m/rad", ::backlash::model::kAbsent,       \
    Positive, "non-positive mesh stiffness; a spring must be > 0 (omit the effect for a rigid mesh)", Gain, 1.0,  \
    1e5, true, "stiffness")                                                                                      \
  X(mesh_damping, "compliance", "damping", "damping", "c_{c}", "mesh damping", "N·m·s/rad", 0.0, NonNegative,    \
    "negative mesh damping; it must be >= 0", DampingRatio, 0.02, 4.0, true, "damping")                          \
  X(delay, "delay", "delay", "delay", "τ", "feedback delay", "s", 0.0, NonNegative,                              \
    "negative delay; tau must be >= 0", ServoPeriod, 1e-3, 0.1, true, "tau")                                     \
  X(torque_offset, "torque_offset", "torque_offset", "torque_offset", "T_{0}", "torque offset", "N·m", 0.0, Any, \
    "", StepTorque, -0.2, 0.2, false, "torque")                                                            \
  X(stribeck_motor_static, "stribeck_motor", "static", "stribeck_motor_static", "T_{sm}",                   \
    "static friction on the motor", "N·m", 0.0, NonNegative,                                                       \
    "negative static friction; a friction torque must be >= 0", KineticRatio, 1.0, 4.0, true, "static")         \
  X(stribeck_motor_kinetic, "stribeck_motor", "kinetic", "stribeck_motor_kinetic", "T_{km}",                \
    "kinetic friction on the motor", "N·m", 0.0, NonNegative,                                                      \
    "negative kinetic friction; a friction torque must be >= 0", StepTorque, 1e-4, 0.3, true, "kinetic")         \
  X(stribeck_motor_velocity, "stribeck_motor", "velocity", "stribeck_motor_velocity", "v_{sm}",             \
    "Stribeck velocity of the motor", "rad/s", ::backlash::model::kAbsent, Positive,                              \
    "non-positive Stribeck velocity; it must be > 0", StepVelocity, 1e-3, 0.5, true, "velocity") \
  X(stribeck_load_static, "stribeck_load", "static", "stribeck_load_static", "T_{sL}",                   \
    "static friction on the load", "N·m", 0.0, NonNegative,                                                       \
    "negative static friction; a friction torque must be >= 0", KineticRatio, 1.0, 4.0, true, "static")         \
  X(stribeck_load_kinetic, "stribeck_load", "kinetic", "stribeck_load_kinetic", "T_{kL}",                \
    "kinetic friction on the load", "N·m", 0.0, NonNegative,                                                      \
    "negative kinetic friction; a friction torque must be >= 0", StepTorque, 1e-4, 0.3, true, "kinetic")         \
  X(stribeck_load_velocity, "stribeck_load", "velocity", "stribeck_load_velocity", "v_{sL}",             \
    "Stribeck velocity of the load", "rad/s", ::backlash::model::kAbsent, Positive,                              \
    "non-positive Stribeck velocity; it must be > 0", StepVelocity, 1e-3, 0.5, true, "velocity")

// ------------------------------------------------------------------ the effects
//
// E(EFFECT, CONTACT_LAW, NEEDS_GAP, STEP_RANK, DRIVE_RANK)
//   CONTACT_LAW  the effect models the impact at the faces: two contact laws cannot be combined
//                (the reader refuses the pair; a discrepancy candidate replaces the other)
//   NEEDS_GAP    only a model with its gap can have it (a rigid measured drive refuses it)
//   STEP_RANK, DRIVE_RANK  the order in which the step and measured-drive workflows try it
//                (0: not a candidate there)
#define BACKLASH_EFFECTS(E)                    \
  E("coulomb_motor", false, false, 1, 1)       \
  E("coulomb_load", false, false, 2, 0)        \
  E("restitution", true, true, 3, 0)           \
  E("saturation", false, false, 4, 4)          \
  E("compliance", true, true, 5, 0)            \
  E("delay", false, false, 6, 3)               \
  E("torque_offset", false, false, 8, 2)       \
  E("stribeck_motor", false, false, 9, 0)      \
  E("stribeck_load", false, false, 10, 0)

namespace backlash::model {

/// NEUTRAL = kAbsent: the parameter's absence is the thesis's model (no limit, a rigid mesh).
inline constexpr double kAbsent = std::numeric_limits<double>::infinity();

/// The values an effect parameter may take.
enum class Admissible {
  NonNegative,  ///< x >= 0
  Positive,     ///< x > 0
  BelowOne,     ///< 0 <= x < 1
  Any,          ///< any finite number
};

/// The model's own scale s of a discrepancy candidate's range [LOW·s, HIGH·s] (docs/discrepancy.md).
enum class CandidateScale {
  StepTorque,    ///< the drive at the start of the step, K·|step| [torque]
  Gain,          ///< the loop gain K [torque/rad]
  ServoPeriod,   ///< 2π·sqrt((Jm + JL)/K) [s]
  Absolute,      ///< 1: the range as written
  DampingRatio,  ///< the range is ζ; the damping is 2ζ·sqrt(kc·Jm·JL/(Jm + JL)), kc the stiffness fitted with it
  StepVelocity,  ///< the step over the servo period, |step|/(2π·sqrt((Jm + JL)/K)) [rad/s]
  KineticRatio,  ///< the range is Ts/Tk >= 1; the static level is that ratio times the kinetic level fitted with it (the next row): Ts >= Tk at every point a fit tries
};

/// The effect parameters, in the table's order.
enum class EffectParameter {
#define BACKLASH_EFFECT_PARAMETER_ID(FIELD, ...) FIELD,
  BACKLASH_EFFECT_PARAMETERS(BACKLASH_EFFECT_PARAMETER_ID)
#undef BACKLASH_EFFECT_PARAMETER_ID
};

/// One row of BACKLASH_EFFECT_PARAMETERS.
struct EffectParameterInfo {
  EffectParameter id;
  std::string_view effect, key, name, symbol, description, unit;
  double neutral;
  Admissible admissible;
  std::string_view problem;
  CandidateScale scale;
  double low, high;
  bool logarithmic;
  std::string_view fit_name;

  /// True when `value` is the thesis's model (NEUTRAL).
  constexpr bool is_neutral(double value) const { return value == neutral; }
  /// True when `value` is admissible.
  constexpr bool admits(double value) const {
    switch (admissible) {
      case Admissible::NonNegative: return value >= 0;
      case Admissible::Positive: return value > 0;
      case Admissible::BelowOne: return value >= 0 && value < 1;
      case Admissible::Any: return value == value;
    }
    return false;
  }
};

inline constexpr std::array effect_parameters{
#define BACKLASH_EFFECT_PARAMETER_INFO(FIELD, EFFECT, KEY, NAME, SYMBOL, DESCRIPTION, UNIT, NEUTRAL, ADMISSIBLE, \
                                       PROBLEM, SCALE, LOW, HIGH, LOGARITHMIC, FIT_NAME)                      \
  EffectParameterInfo{EffectParameter::FIELD, EFFECT, KEY, NAME, SYMBOL, DESCRIPTION, UNIT, NEUTRAL,            \
                      Admissible::ADMISSIBLE, PROBLEM, CandidateScale::SCALE, LOW, HIGH, LOGARITHMIC, FIT_NAME},
    BACKLASH_EFFECT_PARAMETERS(BACKLASH_EFFECT_PARAMETER_INFO)
#undef BACKLASH_EFFECT_PARAMETER_INFO
};

inline constexpr std::size_t kEffectParameterCount = effect_parameters.size();

/// One row of BACKLASH_EFFECTS, with the range of its parameters in effect_parameters.
struct EffectInfo {
  std::string_view key;
  bool contact_law, needs_gap;
  int step_rank, drive_rank;
  std::size_t first, count;  ///< its parameters: effect_parameters[first .. first + count)

  /// Its first parameter decides whether it is present (a limit, a stiffness, a torque).
  constexpr const EffectParameterInfo& primary() const { return effect_parameters[first]; }
  /// True when the effect has a single parameter (`KEY = value`), false for `KEY = { ... }`.
  constexpr bool single() const { return count == 1 && effect_parameters[first].key == key; }
};

namespace detail {
constexpr EffectInfo effect_row(std::string_view key, bool contact_law, bool needs_gap, int step_rank, int drive_rank) {
  std::size_t first = 0, count = 0;
  for (std::size_t i = 0; i < effect_parameters.size(); ++i)
    if (effect_parameters[i].effect == key) {
      if (count == 0) first = i;
      ++count;
    }
  return {key, contact_law, needs_gap, step_rank, drive_rank, first, count};
}
}  // namespace detail

inline constexpr std::array effects_table{
#define BACKLASH_EFFECT_INFO(KEY, CONTACT_LAW, NEEDS_GAP, STEP_RANK, DRIVE_RANK) \
  detail::effect_row(KEY, CONTACT_LAW, NEEDS_GAP, STEP_RANK, DRIVE_RANK),
    BACKLASH_EFFECTS(BACKLASH_EFFECT_INFO)
#undef BACKLASH_EFFECT_INFO
};

/// The row of a parameter.
constexpr const EffectParameterInfo& info(EffectParameter id) { return effect_parameters[static_cast<std::size_t>(id)]; }

/// The parameter called NAME (sweeps, maps, Python), or nullptr.
constexpr const EffectParameterInfo* effect_parameter_named(std::string_view name) {
  for (const EffectParameterInfo& p : effect_parameters)
    if (p.name == name) return &p;
  return nullptr;
}

/// The effect with case-file key KEY, or nullptr.
constexpr const EffectInfo* effect_keyed(std::string_view key) {
  for (const EffectInfo& e : effects_table)
    if (e.key == key) return &e;
  return nullptr;
}

/// The effect a parameter belongs to.
constexpr const EffectInfo& effect_of(EffectParameter id) { return *effect_keyed(info(id).effect); }

/// The effects a workflow tries, as (rank, key) in rank order: `rank` is &EffectInfo::step_rank
/// or &EffectInfo::drive_rank; `more` adds candidates of the workflow's own (a nominal parameter).
inline std::vector<std::string> ranked_effects(int EffectInfo::*rank,
                                               std::vector<std::pair<int, std::string>> more = {}) {
  for (const EffectInfo& effect : effects_table)
    if (effect.*rank > 0) more.emplace_back(effect.*rank, std::string(effect.key));
  std::sort(more.begin(), more.end());
  std::vector<std::string> keys;
  for (const auto& ranked : more) keys.push_back(ranked.second);
  return keys;
}

/// The generic access of both structs of effects (model::Effects, numeric::Effects): their
/// member for each row, by FIELD, so that code reading the table can get and set any of them.
template <class Effects>
constexpr auto& field(Effects& effects, EffectParameter id) {
  switch (id) {
#define BACKLASH_EFFECT_PARAMETER_FIELD(FIELD, ...) \
  case EffectParameter::FIELD: return effects.FIELD;
    BACKLASH_EFFECT_PARAMETERS(BACKLASH_EFFECT_PARAMETER_FIELD)
#undef BACKLASH_EFFECT_PARAMETER_FIELD
  }
  __builtin_unreachable();  // every id has its case
}

}  // namespace backlash::model
