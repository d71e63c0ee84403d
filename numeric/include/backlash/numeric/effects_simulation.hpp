// backlash/numeric/effects_simulation.hpp — the hybrid model with the effects
// the thesis left out (docs/effects.md), simulated on closed forms.
//
// Every mode that stays linear with constant forcing (Coulomb friction with
// sticking, restitution, saturation, compliance, torque offset) is a closed
// form (numeric/effects/effect_modes.hpp), and every event is the first exit of a witness
// w = row·z + constant from its valid side (w ≥ 0), found by the certified
// search of first_crossing.hpp:
//   rigid contact    −σ·Tc (separation), s·ω (the pair's velocity zero), the drive's limits
//   free flight      the gap to either face (impacts), s·θ̇ per slipping body (velocity zeros),
//                    Tm ∓ D for a stuck motor (break-away), the drive's limits
//   mesh engaged     P = kc δ + cc δ̇ (release), velocity zeros and break-away of each body
//   free, compliant  −δ to each face (engagement), or −P and δ while the teeth overlap
// A witness that starts on its boundary (w(0) within rounding) is decided by its first
// derivative that is not rounding noise: leaving the valid side is an event at once,
// entering it starts the search after a certified departure time.
// The static rules (sticking, break-away, the pair's band), the impact law with
// restitution and the accumulation of a bounce series are those of docs/effects.md.
// With a delay the model has no closed form: the fed-back angle comes from a
// history and the segments are integrated with Boost.Odeint (effects_delay.cpp).
//
// The closed forms pass a gate first: validate_effects() checks every reachable
// mode's flow against Boost.Odeint integrating the mode's own z' = A z + c, and
// only then hands out a ValidatedEffectModel.  Without effects the nominal
// simulator (hybrid_simulation.hpp) runs, on the validated nominal evaluator.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/effects_engine_options.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/mode.hpp"
#include "backlash/numeric/reference.hpp"
#include "backlash/numeric/validated_family.hpp"
#include "backlash/numeric/validation.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace backlash::numeric {

struct EffectValidationOptions {
  double tolerance = 1e-9;          ///< max abs error of every local coordinate
  double odeint_tolerance = 1e-12;  ///< abs = rel tolerance of the reference
  int time_points = 120;            ///< samples per trajectory
  double time_constants = 6;        ///< horizon in units of the slowest time scale
  double max_horizon = 30;          ///< cap on the horizon [s]
};

struct ModeValidation {
  Mode mode;
  double max_abs_error = 0;
  double at_tau = 0;
  int trajectories = 0;
  bool matrix_exponential = false;  ///< the generic flow fell back to the Padé exponential
  bool passed = false;
};

struct EffectValidationReport {
  Effects effects;
  double tolerance = 0;
  std::vector<ModeValidation> modes;
  bool passed = false;
  /// One line per mode: "free (left face -1) motor + load stuck  max |error| 3e-14 at τ = 2.1  pass".
  std::string summary() const;
};

class EffectValidationResult;
class ValidatedModelFamily;

/// A model with effects whose nominal evaluator and effect-mode flows passed their gates.
class ValidatedEffectModel {
 public:
  const Parameters& parameters() const { return nominal_.parameters(); }
  const Effects& effects() const { return effects_; }
  const ValidatedEvaluator& nominal() const { return nominal_; }
  const EffectValidationReport& report() const { return report_; }

 private:
  friend EffectValidationResult validate_effects(const ValidatedEvaluator& nominal, const Effects& effects,
                                                 const EffectValidationOptions& options);
  friend class ValidatedModelFamily;
  ValidatedEffectModel(ValidatedEvaluator nominal, Effects effects, EffectValidationReport report)
      : nominal_(std::move(nominal)), effects_(effects), report_(std::move(report)) {}
  ValidatedEvaluator nominal_;
  Effects effects_;
  EffectValidationReport report_;
};

class EffectValidationResult {
 public:
  bool passed() const { return report_.passed; }
  const EffectValidationReport& report() const { return report_; }
  /// The validated model; throws ValidationFailed naming the failing modes otherwise.
  const ValidatedEffectModel& model() const;

 private:
  friend EffectValidationResult validate_effects(const ValidatedEvaluator& nominal, const Effects& effects,
                                                 const EffectValidationOptions& options);
  EffectValidationReport report_;
  std::optional<ValidatedEffectModel> validated_;
};

/// The effects gate.  Never throws for a failing flow: the result says so.
EffectValidationResult validate_effects(const ValidatedEvaluator& nominal, const Effects& effects,
                                        const EffectValidationOptions& options = {});

/// The gate for a family of models (fits over parameters, sweeps): the nominal evaluator
/// validated per pole-structure branch (validated_family.hpp), the effect modes validated at
/// sample points.  A model is handed out only when its nominal branches passed and its effects'
/// structure (which effects are present) was validated at samples whose box — each parameter
/// between the smallest and largest sampled value — contains it.  Thread-safe.
class ValidatedModelFamily {
 public:
  explicit ValidatedModelFamily(EffectValidationOptions options = {}) : options_(options) {}
  /// Validates each sample (nominal and effect modes); false if any failed.
  bool validate_samples(const std::vector<std::pair<Parameters, Effects>>& samples);
  /// A validated model for (p, e), or nothing (outside every validated box, or a failed sample).
  std::optional<ValidatedEffectModel> at(const Parameters& p, const Effects& e);
  long samples_validated() const;

 private:
  struct Box {
    std::vector<double> low, high;
  };
  static std::string structure(const Effects& e);
  static std::vector<double> coordinates(const Parameters& p, const Effects& e);
  ValidatedParametricFamily nominal_;
  EffectValidationOptions options_;
  /// The gate's reference integrations, kept by their exact inputs (the same verdicts, bit for bit).
  LinearReferenceCache references_;
  mutable std::mutex mutex_;
  std::map<std::string, Box> boxes_;
  std::set<std::string> failed_;
  long validated_ = 0;
};

/// Simulates from `start`.  Without effects (and without engine.general_engine) this is
/// simulate() on the nominal evaluator, bit for bit.
SimulationResult simulate_effects(const ValidatedEffectModel& model, const HybridState& start,
                                  const SimulationOptions& options, const EffectsEngineOptions& engine = {});
/// effects_step_start(p, e, step) simulated.
SimulationResult simulate_effects_step(const ValidatedEffectModel& model, double step,
                                       const SimulationOptions& options, const EffectsEngineOptions& engine = {});

}  // namespace backlash::numeric
