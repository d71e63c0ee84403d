#include "backlash/numeric/scales.hpp"

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
  const double fastest = fastest_mode_rate(p), slowest = slowest_time_scale(p);
  const double stiffness = fastest * slowest;
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

double resolvable_scale(const Parameters& p) {
  if (p.backlash <= 0) return std::numeric_limits<double>::infinity();
  return backlash_resolution * p.backlash / std::numeric_limits<double>::epsilon();
}

double motion_scale(const Parameters& p, double theta_m, double theta_L) {
  return std::max(std::fabs(theta_m - p.theta_R), std::fabs(theta_L - p.theta_R)) + std::fabs(p.theta_R);
}

std::optional<std::string> resolution_problem(const Parameters& p, double scale, const std::string& what) {
  if (std::isfinite(scale) && (p.backlash <= 0 || scale <= resolvable_scale(p))) return std::nullopt;
  if (!std::isfinite(scale)) return what + " makes the motion overflow double precision";
  return what + " makes the motion " + number(scale) + " rad in size, where double precision resolves angles to " +
         number(scale * std::numeric_limits<double>::epsilon()) + " rad, more than " + number(backlash_resolution) +
         " of the backlash " + number(p.backlash) + " (the largest size it resolves is " +
         number(resolvable_scale(p)) + ")";
}

}  // namespace backlash::numeric
