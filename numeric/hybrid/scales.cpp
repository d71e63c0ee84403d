#include "backlash/numeric/scales.hpp"

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace backlash::numeric {

namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

bool normal_or_zero(double value) { return value == 0 || std::isnormal(value); }

// The time scale of an overdamped mode's slow root, 1/(w²/(α + sqrt(α² − w²))) for
// s² + 2αs + w² with α > w (about 2α/w²: the contact creeping toward θR when F² ≫ 4JK), else 0.
// slowest_time_scale counts a decay as α; an overdamped mode decays far slower than that.
double overdamped_time_scale(double two_alpha, double w2) {
  const double alpha = two_alpha / 2, D = alpha * alpha - w2;
  return D > 0 ? (alpha + std::sqrt(D)) / w2 : 0.0;
}

}  // namespace

double fastest_mode_rate(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  return std::max({F / J + std::sqrt(p.K / J), p.Fm / p.Jm + std::sqrt(p.K / p.Jm), p.FL / p.JL});
}

std::optional<std::string> parameter_scale_problem(const Parameters& p) {
  struct Named {
    const char* name;
    double value;
    bool positive;
  };
  const Named parameters[] = {{"K", p.K, true},         {"motor.J", p.Jm, true}, {"load.J", p.JL, true},
                              {"motor.F", p.Fm, false}, {"load.F", p.FL, false}, {"backlash", p.backlash, false},
                              {"reference", p.theta_R, false}};
  for (const Named& n : parameters) {
    if (!std::isfinite(n.value)) return std::string(n.name) + " is not a finite number";
    if (n.positive && !(n.value > 0)) return std::string(n.name) + " = " + number(n.value) + " must be > 0";
    if (!normal_or_zero(n.value))
      return std::string(n.name) + " = " + number(n.value) + " is below the smallest normal double (2.2e-308)";
  }
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const Named derived[] = {{"K/(motor.J + load.J)", p.K / J, true},
                           {"K/motor.J", p.K / p.Jm, true},
                           {"(motor.F + load.F)/(motor.J + load.J)", F / J, false},
                           {"motor.F/motor.J", p.Fm / p.Jm, false},
                           {"load.F/load.J", p.FL / p.JL, false},
                           {"(motor.F + load.F)^2", F * F, false},
                           {"4 (motor.J + load.J) K", 4 * J * p.K, true},
                           {"motor.F^2", p.Fm * p.Fm, false},
                           {"4 motor.J K", 4 * p.Jm * p.K, true}};
  for (const Named& d : derived)
    if (!std::isfinite(d.value) || !normal_or_zero(d.value) || (d.positive && !(d.value > 0)))
      return std::string(d.name) + " = " + number(d.value) +
             " is outside double precision (the parameters are too far apart in size)";
  // Stiffness: the fastest rate against the slowest time scale.
  double slowest = std::max(slowest_time_scale(p), overdamped_time_scale(F / J, p.K / J));
  if (p.measured_at == model::MeasuredAt::Motor) slowest = std::max(slowest, overdamped_time_scale(p.Fm / p.Jm, p.K / p.Jm));
  const double fastest = fastest_mode_rate(p), stiffness = fastest * slowest;
  if (!std::isfinite(stiffness) || stiffness > max_stiffness) {
    const double rates[] = {F / J + std::sqrt(p.K / J), p.Fm / p.Jm + std::sqrt(p.K / p.Jm), p.FL / p.JL};
    const char* names[] = {"the contact mode ((motor.F + load.F)/J + sqrt(K/J), J = motor.J + load.J)",
                           "the free motor (motor.F/motor.J + sqrt(K/motor.J))", "the free load (load.F/load.J)"};
    const int which = static_cast<int>(std::max_element(std::begin(rates), std::end(rates)) - std::begin(rates));
    return "time scales too far apart: the fastest rate, " + number(fastest) + "/s of " + names[which] +
           ", times the slowest time scale, " + number(slowest) + " s, is " + number(stiffness) + " > " +
           number(max_stiffness) + ": no event search can span it in double precision";
  }
  return std::nullopt;
}

double fastest_mode_rate(const Parameters& p, const Effects& e) {
  double rate = fastest_mode_rate(p);
  if (e.compliant()) {
    const double m = 1 / p.Jm + 1 / p.JL;
    rate = std::max(rate, std::sqrt(e.mesh_stiffness * m) + e.mesh_damping * m);
  }
  return rate;
}

namespace {

// The case-file key of a parameter: "delay", "compliance.stiffness".
std::string key_of(const model::EffectParameterInfo& parameter) {
  return parameter.key == parameter.effect ? std::string(parameter.key)
                                           : std::string(parameter.effect) + "." + std::string(parameter.key);
}

// Each present parameter a finite, normal double (or 0) inside its admissible range (the table's
// ADMISSIBLE and PROBLEM columns: the reader's rule, for models built in code as well).
std::optional<std::string> effect_value_problem(const Effects& e) {
  for (const model::EffectParameterInfo& parameter : model::effect_parameters) {
    const double value = model::field(e, parameter.id);
    if (parameter.is_neutral(value)) continue;
    const std::string key = key_of(parameter);
    if (!std::isfinite(value)) return key + " is not a finite number";
    if (!parameter.admits(value)) return key + " = " + number(value) + ": " + std::string(parameter.problem);
    if (!normal_or_zero(value))
      return key + " = " + number(value) + " is below the smallest normal double (2.2e-308)";
  }
  return std::nullopt;
}

// Stribeck friction on each body (docs/effects.md, "Stribeck friction"): kinetic ≤ static, the
// curve's steepest slope held to max_stiffness like a mode's rate, no delay with it.
std::optional<std::string> stribeck_problem(const Parameters& p, const Effects& e, double slowest) {
  struct Body {
    const char* key;
    double Ts, Tk, vs, J;
  };
  for (const Body& b : {Body{"stribeck_motor", e.stribeck_motor_static, e.stribeck_motor_kinetic,
                             e.stribeck_motor_velocity, p.Jm},
                        Body{"stribeck_load", e.stribeck_load_static, e.stribeck_load_kinetic, e.stribeck_load_velocity,
                             p.JL}}) {
    const std::string key = b.key;
    if (b.Tk > b.Ts)
      return key + ".kinetic = " + number(b.Tk) + " is above " + key + ".static = " + number(b.Ts) +
             ": the kinetic friction level must be <= the static one";
    if (!(b.Ts > 0)) continue;
    if (e.delayed())
      return key + " with delay = " + number(e.delay) +
             ": the delayed model has no Stribeck friction (docs/effects.md); give one of them";
    // |d/dv| of (Ts − Tk)·e^{−(v/vs)²} is at most sqrt(2/e)·(Ts − Tk)/vs: a negative damping rate.
    const double rate = std::sqrt(2 / M_E) * (b.Ts - b.Tk) / (b.vs * b.J), stiffness = rate * slowest;
    if (!std::isfinite(stiffness) || stiffness > max_stiffness)
      return key + ".velocity = " + number(b.vs) + ": time scales too far apart: the Stribeck curve's steepest " +
             "rate, " + number(rate) + "/s (0.858 (static - kinetic)/(velocity J)), times the slowest time scale, " +
             number(slowest) + " s, is " + number(stiffness) + " > " + number(max_stiffness) +
             ": no integration can span it in double precision";
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> effect_scale_problem(const Parameters& p, const Effects& e) {
  if (auto problem = effect_value_problem(e)) return problem;
  const double slowest = slowest_time_scale(p);
  if (auto problem = stribeck_problem(p, e, slowest)) return problem;
  if (e.compliant()) {
    // The engaged mesh is a mode like the others: its rate against the slowest time scale.
    const double m = 1 / p.Jm + 1 / p.JL, spring = std::sqrt(e.mesh_stiffness * m), damper = e.mesh_damping * m;
    const double rate = spring + damper, stiffness = rate * slowest;
    if (!std::isfinite(stiffness) || stiffness > max_stiffness)
      return std::string(spring >= damper ? "compliance.stiffness = " + number(e.mesh_stiffness)
                                          : "compliance.damping = " + number(e.mesh_damping)) +
             ": time scales too far apart: the engaged mesh's rate, " + number(rate) +
             "/s (sqrt(stiffness (1/motor.J + 1/load.J)) + damping (1/motor.J + 1/load.J)), times the slowest "
             "time scale, " + number(slowest) + " s, is " + number(stiffness) + " > " + number(max_stiffness) +
             ": no event search can span it in double precision";
  }
  if (e.delayed()) {
    const double shortest = min_delay_fraction / fastest_mode_rate(p, e);
    if (e.delay < shortest)
      return "delay = " + number(e.delay) + " s is shorter than " + number(min_delay_fraction) +
             " of the fastest time scale (" + number(shortest) +
             " s): the delayed model is integrated in steps no longer than the delay, so its cost grows as "
             "t_end/delay; use delay = 0 (no delay) or a delay of at least " + number(shortest) + " s";
  }
  return std::nullopt;
}

std::optional<std::string> time_resolution_problem(const Parameters& p, const Effects& e, double t_end) {
  const double fastest = fastest_mode_rate(p, e);
  const double latest = backlash_resolution / (std::numeric_limits<double>::epsilon() * fastest);
  if (t_end <= latest) return std::nullopt;
  return "t_end = " + number(t_end) + " s: double precision resolves times there to " +
         number(t_end * std::numeric_limits<double>::epsilon()) + " s, more than " + number(backlash_resolution) +
         " of the fastest time scale " + number(1 / fastest) + " s (the latest end it resolves is " + number(latest) +
         " s)";
}

double resolvable_scale(const Parameters& p) {
  if (p.backlash <= 0) return std::numeric_limits<double>::infinity();
  return backlash_resolution * p.backlash / std::numeric_limits<double>::epsilon();
}

double motion_scale(const Parameters& p, double theta_m, double theta_L) {
  return std::max(std::fabs(theta_m - p.theta_R), std::fabs(theta_L - p.theta_R)) + std::fabs(p.theta_R);
}

std::optional<std::string> resolution_problem(const Parameters& p, double scale, const std::string& what) {
  if (motion_resolved(scale, resolvable_scale(p))) return std::nullopt;  // (infinite for b = 0)
  if (!std::isfinite(scale)) return what + " makes the motion overflow double precision";
  return what + " makes the motion " + number(scale) + " rad in size, where double precision resolves angles to " +
         number(scale * std::numeric_limits<double>::epsilon()) + " rad, more than " + number(backlash_resolution) +
         " of the backlash " + number(p.backlash) + " (the largest size it resolves is " +
         number(resolvable_scale(p)) + ")";
}

}  // namespace backlash::numeric
