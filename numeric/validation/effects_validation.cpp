// The effects gate (effects_simulation.hpp): every reachable mode's closed-form
// flow against Boost.Odeint integrating the mode's own z' = A z + c.
#include "backlash/numeric/effects_simulation.hpp"

#include "backlash/numeric/reference.hpp"
#include "effects/effect_modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace backlash::numeric {

namespace {

// Start states of a mode: two positions and two velocities of either sign, scaled to the model
// (positions by max(1, b), velocities by the servo's rate), on the mode's face; the mesh
// modes with a small penetration.
std::vector<HybridState> starts_of(const Parameters& p, const Effects& e, const Mode& m) {
  const double position = std::max(1.0, p.backlash), rate = std::sqrt(p.K / (p.Jm + p.JL));
  std::vector<HybridState> out;
  for (const auto& [offset, velocity] : {std::pair{-0.8, 0.4}, std::pair{0.5, -0.7}}) {
    HybridState s = state_on_face(p, m.face, p.theta_R + offset * position, velocity * rate * position,
                                  m.kind != ModeKind::Free);
    if (m.kind != ModeKind::Contact) {
      s.dtheta_L = -0.6 * velocity * rate * position;  // bodies at different velocities
      if (m.kind == ModeKind::Mesh) {  // teeth overlapping by δ: x = σ(b/2 + δ)
        const double depth = 0.05 * std::max(p.backlash, 1e-3);
        if (p.measured_at == model::MeasuredAt::Motor) s.theta_L += m.face * depth; else s.theta_m -= m.face * depth;
      }
    }
    s.drive_regime = m.regime;
    s.motor_stuck = m.slip_motor == 0;
    s.load_stuck = m.slip_load == 0;
    if (s.motor_stuck) s.dtheta_m = 0;
    if (s.load_stuck) s.dtheta_L = 0;
    if (m.kind == ModeKind::Contact && m.slip_motor == 0) s.dtheta_m = s.dtheta_L = 0;
    out.push_back(s);
  }
  (void)e;
  return out;
}

double horizon_of(const Parameters& p, const Effects& e, const Mode& m, const EffectValidationOptions& o) {
  double horizon = std::min(o.max_horizon, o.time_constants * slowest_time_scale(p));
  if (m.kind == ModeKind::Mesh) {
    const double fastest = std::sqrt(e.mesh_stiffness * (1 / p.Jm + 1 / p.JL)) +
                           e.mesh_damping * (1 / p.Jm + 1 / p.JL);
    horizon = std::min(horizon, 400 / fastest);  // a few hundred mesh periods
  }
  return horizon;
}

// `references`, if given, keeps the reference integrations (the same bits as integrating anew).
ModeValidation validate_mode(const Parameters& p, const Effects& e, const Mode& m, const EffectValidationOptions& o,
                             LinearReferenceCache* references) {
  ModeValidation v;
  v.mode = m;
  const double horizon = horizon_of(p, e, m, o);
  std::vector<double> times;
  for (int i = 1; i <= o.time_points; ++i) times.push_back(horizon * i / o.time_points);
  for (const HybridState& start : starts_of(p, e, m)) {
    const ModeFlow flow(p, e, m, start);
    v.matrix_exponential = v.matrix_exponential || flow.uses_matrix_exponential();
    const std::vector<SmallVector> reference =
        references ? references->trajectory(flow.segment(), flow.local_start(), times, o.odeint_tolerance)
                   : reference_linear_trajectory(flow.segment(), flow.local_start(), times, o.odeint_tolerance);
    for (std::size_t i = 0; i < times.size(); ++i) {
      const SmallVector z = flow.local(times[i]);
      // Absolute error, relative to the trajectory's size where it grows beyond 1.
      const double error =
          (z - reference[i]).cwiseAbs().maxCoeff() / std::max(1.0, reference[i].cwiseAbs().maxCoeff());
      if (!(error <= v.max_abs_error)) {
        v.max_abs_error = std::isfinite(error) ? error : INFINITY;
        v.at_tau = times[i];
      }
    }
    ++v.trajectories;
  }
  v.passed = v.max_abs_error <= o.tolerance;
  return v;
}

// Every reachable mode of (p, effects) validated (none for no effects or a delay).
EffectValidationReport effects_report(const Parameters& p, const Effects& effects, const EffectValidationOptions& options,
                                      LinearReferenceCache* references) {
  EffectValidationReport report;
  report.effects = effects;
  report.tolerance = options.tolerance;
  if (effects.any() && !effects.delayed())
    for (const Mode& m : reachable_modes(p, effects)) report.modes.push_back(validate_mode(p, effects, m, options, references));
  report.passed = std::all_of(report.modes.begin(), report.modes.end(), [](const ModeValidation& m) { return m.passed; });
  return report;
}

}  // namespace

std::string EffectValidationReport::summary() const {
  std::ostringstream out;
  for (const ModeValidation& m : modes) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-58s max |error| %.2e at tau = %.3g%s  %s\n", m.mode.describe().c_str(),
                  m.max_abs_error, m.at_tau, m.matrix_exponential ? " (matrix exponential)" : "",
                  m.passed ? "pass" : "FAIL");
    out << line;
  }
  return out.str();
}

const ValidatedEffectModel& EffectValidationResult::model() const {
  if (!validated_) {
    std::string failing;
    for (const ModeValidation& m : report_.modes)
      if (!m.passed) failing += (failing.empty() ? "" : "; ") + m.mode.describe();
    throw ValidationFailed("the closed forms of the effect modes failed validation against odeint (" + failing +
                           "); refusing to use them");
  }
  return *validated_;
}

EffectValidationResult validate_effects(const ValidatedEvaluator& nominal, const Effects& effects,
                                        const EffectValidationOptions& options) {
  EffectValidationResult result;
  EffectValidationReport& report = result.report_;
  report = effects_report(nominal.parameters(), effects, options, nullptr);
  if (report.passed) result.validated_ = ValidatedEffectModel(nominal, effects, report);
  return result;
}

std::string ValidatedModelFamily::structure(const Effects& e) {
  std::string key;  // one character per effect of the table: '+' present, '-' absent
  for (const model::EffectInfo& effect : model::effects_table) key += e.has(effect) ? '+' : '-';
  return key;
}

std::vector<double> ValidatedModelFamily::coordinates(const Parameters& p, const Effects& e) {
  std::vector<double> x{p.Jm, p.Fm, p.JL, p.FL, p.K, p.theta_R, p.backlash};
  for (const model::EffectParameterInfo& parameter : model::effect_parameters) {
    const double value = model::field(e, parameter.id);
    x.push_back(value == model::kAbsent ? 0.0 : value);  // an absent limit or mesh counts as 0
  }
  x.push_back(p.measured_at == model::MeasuredAt::Motor ? 1.0 : 0.0);
  return x;
}

bool ValidatedModelFamily::validate_samples(const std::vector<std::pair<Parameters, Effects>>& samples) {
  bool all = true;
  for (const auto& [p, e] : samples) {
    const std::string key = structure(e);
    const std::optional<ValidatedEvaluator> nominal = nominal_.at(p);
    // The gate of validate_effects, its reference integrations kept across the family's samples.
    const bool passed = nominal && effects_report(nominal->parameters(), e, options_, &references_).passed;
    std::lock_guard<std::mutex> lock(mutex_);
    ++validated_;
    if (!passed) {
      failed_.insert(key);
      all = false;
      continue;
    }
    const std::vector<double> x = coordinates(p, e);
    auto [it, inserted] = boxes_.try_emplace(key, Box{x, x});
    if (!inserted)
      for (std::size_t i = 0; i < x.size(); ++i) {
        it->second.low[i] = std::min(it->second.low[i], x[i]);
        it->second.high[i] = std::max(it->second.high[i], x[i]);
      }
  }
  return all;
}

std::optional<ValidatedEffectModel> ValidatedModelFamily::at(const Parameters& p, const Effects& e) {
  const std::string key = structure(e);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failed_.count(key)) return std::nullopt;
    const auto box = boxes_.find(key);
    if (box == boxes_.end()) return std::nullopt;
    const std::vector<double> x = coordinates(p, e);
    for (std::size_t i = 0; i < x.size(); ++i)
      if (!(x[i] >= box->second.low[i] && x[i] <= box->second.high[i])) return std::nullopt;
  }
  std::optional<ValidatedEvaluator> nominal = nominal_.at(p);
  if (!nominal) return std::nullopt;
  EffectValidationReport report;
  report.effects = e;
  report.tolerance = options_.tolerance;
  report.passed = true;
  return ValidatedEffectModel(std::move(*nominal), e, std::move(report));
}

long ValidatedModelFamily::samples_validated() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return validated_;
}

}  // namespace backlash::numeric
