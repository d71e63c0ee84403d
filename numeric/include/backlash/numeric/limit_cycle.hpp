// backlash/numeric/limit_cycle.hpp — limit cycles from the return map on the
// separation line.
//
// The system is odd-symmetric about (θR, 0) with the backlash faces swapped,
// so a symmetric cycle is two mirror-image halves.  The half-cycle map
//   g(v) = −θ̇o at the next separation,  starting from the separation point
//          θo = θR + cot φ·v, θ̇o = v > 0 (free flight, impact, contact arc),
// is computed with the exact hybrid simulator; a limit cycle is a fixed point
// g(v*) = v*, found by Newton's method from a first guess (the neighbour's cycle
// in sweeps and maps, else the describing function's: describing_function.hpp)
// with g' from the closed forms, or — when Newton's steps do not settle on a stable
// cycle — bracketed on a logarithmic grid and refined with Boost.Math's toms748
// (LimitCycle::survey_fallback; only the survey lists other_fixed_points, run after Newton too
// when LimitCycleOptions::list_other_fixed_points asks).  The full return map is P = g∘g, so its multiplier is P'(v*) = g'(v*)²
// (stable when < 1).  On the cycle: the amplitude max|θo − θR|, the peak-to-peak
// swings of θo, θm and θL (one frame, docs/physics.md), the period and the
// separation velocity v*, and eq. 38's C at separation and just after
// recombination.  No fixed point (cases I, II: the backlash is outside the loop)
// is the status none, with the reason.
#pragma once

#include "backlash/numeric/hybrid_simulation.hpp"

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace backlash::numeric {

struct HalfCycle {
  bool valid = false;      ///< reached a separation with the opposite velocity sign
  Extremes extremes;       ///< exact extremes over the half cycle (when requested)
  std::vector<SimulationEvent> events;
  std::string outcome;     ///< why not, when invalid ("rest", "same-face separation", …)
  double v_in = 0, v_out = 0;  ///< v_out = g(v_in) = −θ̇o at the next separation
  double duration = 0;
  bool bounced = false;
};

/// One half cycle from the separation line with θ̇o = v > 0.
HalfCycle half_cycle(const ValidatedEvaluator& evaluator, double v, bool track_extremes = false);

/// Eq. 38: C(θo, θ̇o) for the contact mode (principal arctan; requires 4JK > F²).
double stability_constant(const Parameters& p, double theta_o, double dtheta_o);
/// exp(−π a/ω): the factor by which the principal-branch C jumps across θo = θR.
double stability_constant_jump(const Parameters& p);

/// What a limit-cycle search found: a cycle, none (the motion settles; the reason says how), an
/// oscillation that grows instead of settling (g(v) > v wherever sampled), or unresolved: the
/// search could not decide (with effects: the return map settled at no period from 1 to 4, a
/// simulation stopped early, or the cycle it converged to had inconsistent figures) — never a
/// claim that the motion settles (docs/design.md, "limit-cycle").
enum class CycleStatus { LimitCycle, None, Divergent, Unresolved };
/// "limit_cycle", "none", "divergent", "unresolved": the text of the CLI's and the CSV's `status`.
const char* to_string(CycleStatus status);
std::ostream& operator<<(std::ostream& out, CycleStatus status);  ///< as to_string (test messages)

struct LimitCycle {
  CycleStatus status = CycleStatus::None;
  std::string reason;           ///< for "none" and "divergent": what the search computed, in words
  double separation_velocity = 0;   ///< v*
  double multiplier = 0;            ///< P'(v*) = g'(v*)² of the full return map (with effects: of P^k,
                                    ///< its eigenvalue of largest modulus; stable ⇔ |multiplier| < 1)
  double half_map_derivative = 0;   ///< g'(v*)
  bool stable = false;
  double period = 0;                ///< [s], the whole period (all k crossings of the section)
  int period_count = 1;             ///< k: crossings of the return map's section per period (period-k cycle)
  double amplitude = 0;             ///< max |θo − θR|
  double peak_to_peak = 0;          ///< of θo
  double peak_to_peak_motor = 0, peak_to_peak_load = 0;
  double theta_o_max = 0, theta_o_min = 0;
  // Eq. 38 on the cycle (principal branch): at separation, just after recombination.
  double C_separation = 0, C_recombination = 0;
  double theta_o_separation = 0, theta_o_recombination = 0, dtheta_o_recombination = 0;
  int contact_arc_crossings_of_theta_R = 0;  ///< crossings of θo = θR between recombination and separation
  bool bounced = false;
  std::vector<double> other_fixed_points;     ///< further (e.g. unstable) cycles found
  // With effects (effects_limit_cycle.hpp):
  std::string method = "half-cycle map";      ///< or "return map (Steffensen iteration)", "return map (Newton's method)", …
  double residual = 0;                        ///< |P(s*) − s*| at the fixed point (section coordinates)
  int iterations = 0;                         ///< full cycles iterated before convergence
  double rest_error = 0;                      ///< "none" because the motion stops: θo − θR at rest
  HybridState section_state;                  ///< the cycle's crossing of the return map's section (warm starts)
  /// Nominal searches: Newton's method from the first guess did not settle on a stable cycle, so
  /// the logarithmic grid survey ran (every "none" and "divergent" answer comes from it).
  bool survey_fallback = false;
};

struct LimitCycleOptions {
  double v_min = 1e-4, v_max = 10;  ///< search range of separation velocities (× limit_cycle_velocity_unit)
  int grid = 40;                    ///< logarithmic grid points for the bracketing search
  double guess = 0;                 ///< > 0: Newton's first guess (continuation in sweeps and maps), tried
                                    ///< before the describing function's; the grid survey if neither settles
  bool survey_only = false;         ///< the grid survey alone, no Newton (checks of the fast path)
  bool list_other_fixed_points = false;  ///< also run the grid survey after Newton has settled, so that
                                         ///< other_fixed_points lists every further cycle (the facade's
                                         ///< single answer); off in sweeps and maps, where it stays empty
};

LimitCycle find_limit_cycle(const ValidatedEvaluator& evaluator, const LimitCycleOptions& options = {});

/// The cycle's angles (θo extremes, separation and recombination angles, section state)
/// moved by `offset`: from error coordinates to absolute ones.
void shift_angles(LimitCycle& cycle, double offset);

/// The unit of the search range: b/0.3 · √(K/J) — 1 for the thesis's cases III–VIII.  Cycles scale
/// with the backlash and with the contact frequency, never with θR.
double limit_cycle_velocity_unit(const Parameters& p);

}  // namespace backlash::numeric
