// The independent hybrid simulator with every effect, on Boost.Odeint (see
// odeint_effects_simulation.hpp; semantics: docs/effects.md).  Written from the
// semantics document only: it shares with the closed-form effects simulator the
// data types (Effects, HybridState, SimulationResult) and effects_step_start(),
// never its dynamics.  The drive, the impact law, the static (stick) rules and the
// accumulation rule are written out again below.  The technique is that of the
// nominal odeint simulator (odeint_simulation.cpp), which this one reproduces when
// every effect is neutral.
//
// Modes (each integrated with runge_kutta_dopri5 + dense output from its start):
//   rigid contact on face σ   (e, ω), e = θo − θR − c, c the equilibrium offset of the
//                             mode ((T0 − (Tm+TL)·s)/K in the linear regime, else 0), so
//                             Tc keeps its relative accuracy near equilibrium; the pair
//                             slipping with direction s, or stuck (then nothing moves
//                             and only the delayed drive can change)
//   two bodies                (θm − θm0, θ̇m, S·Δ, S·Δ̇), Δ the gap change since the mode
//                             start (the nominal simulator's start-relative frame): free
//                             flight, or the mesh engaged on face σ (compliance, the
//                             linear force P = kc·δ + cc·δ̇ while engaged); each body
//                             slipping with its direction or stuck
//   drive regime              linear / clipped at ±L: part of the mode (constant forcing)
// Guards (witnesses, positive inside the mode; an event where one reaches ≤ 0):
//   contact:  −σ·Tc (separation), s·ω (the pair's velocity zero, Coulomb only), the
//             stuck pair's band edges (Tm+TL) − v and v + Tm with v = −σ·D
//   two-body: rigid: σΔ + x0' + b (recombination), −(σΔ + x0') (recontact), x0' the
//             start's offset from face σ; compliant free flight: max(−kc·δ_σ', −P_σ')
//             for both faces σ' (engagement: δ reaches 0 from below, or P rises through
//             0 while the teeth overlap); mesh: P_σ (release); each body: s·v (velocity
//             zero, Coulomb only) or, stuck, T − |N| (breakaway)
//   drive:    L ∓ K(θR − θo(t−τ)) (saturation), ±K(θR − θo(t−τ)) − L (desaturation)
// A witness that starts at 0 is armed once it has been seen positive; one seen
// negative while unarmed fires at the previous sample (a return the samples missed,
// or a mode entered on its boundary that leaves at once).  The earliest event of a
// step wins.  Each step is bounded by max_step_fraction / (fastest rate of the
// mode) (the mesh adds cc/μ + √(kc/μ), μ = JmJL/J) and by τ; its dense interpolant
// is checked at points ≤ dt_max/(interior_checks + 1) apart, sign changes refined
// with Boost.Math's toms748 on the interpolant.  Quick returns that a first step could
// hide are bounded as in the nominal simulator, generalised: a gap leaving a face with
// Δ' inward and Δ'' outward returns after 2|Δ'/Δ''| (a bounce), a released mesh whose
// force has Ṗ < 0 < P̈ after 2|Ṗ/P̈|: the first step is a quarter of that.
// Rounding at mode switches: the penetration δ beyond a face is carried from the
// integrator (or the impact law: 0) to the next mode rather than recomputed from the
// positions (kc·ε·|θ| would be a spurious mesh force); a gap within rounding of a face
// (relative to the positions too) is on it; an impact whose Tc is at rounding level
// holds or bounces by the sign of dTc/dt (as a contact starting on the separation line).
//
// Delay (method of steps): θo(t − τ) is read from a history of dense-output segments,
// one per accepted step (a quintic Hermite of θo built from θo, θ̇o, θ̈o at the step's
// ends, θ̈o from the mode's right-hand side, so the history is O(h⁶) accurate and every
// stage only reads the past: steps never exceed τ).  The integrator is re-initialised
// to land exactly on the breakpoints t_s + kτ, k = 1..4, of every mode switch t_s
// (and of t = 0): a jump of the m-th derivative of θo at t_s is one of order m + 2k
// at t_s + kτ (m ≥ 1, an impact), so beyond k = 4 it is below dopri5's order anyway.
//
// Stribeck friction: a moving body's friction level is Coulomb + Tk + (Ts − Tk)·exp(−(v/vs)²)
// in every right-hand side, Tc and impact formula (Model::motor_friction, load_friction); the
// static rules, the stuck bands and the breakaway witnesses use the static level Coulomb + Ts
// (Model::Tm, TL).  Nothing else changes: the modes are integrated numerically anyway.
//
// Decisions where docs/effects.md is silent or needs a reading (reported):
//  1. Rest "at the time the last body stuck": reported at the last event's time (the
//     last stick, or a saturation switch while the delayed drive settles, so that event
//     times stay ordered); t_final = t_end, status rest, final state the stuck state.
//     With a delay the rest is only declared once the history has been constant for τ;
//     a breakaway in that window is simulated.
//  2. The impact at t of a summed bounce series is reported (bounce flag) and then the
//     `recontact` with the `accumulation` flag at t + τ∞; the contact motion over τ∞ is
//     a second-order Taylor step of the contact mode from the inelastic state (error
//     O(τ∞³)).  An e > 0 impact with zero relative velocity is the inelastic impact.
//  3. Static rule in the mesh (compliance): N_m = D + σP, N_L = −σP (the general rule
//     with R the mesh torque); at the step start (P = 0) a load with Coulomb friction
//     is therefore stuck until the mesh force exceeds TL.  Two bodies that stick at the
//     same instant are one `stick` event with body `both`.
//  4. A body with zero velocity after an impact gets the static rule at once (`stick`
//     event if it sticks).  A stuck pair broken away at the pulling edge, or a pair
//     stopping there, is a `separation` (the load stuck when TL > 0).
//  5. With b = 0 the faces coincide: a separation is followed at once by the impact on
//     the other face (recombination) — the rigid drive's torque reversal, with no
//     change of velocity.  (Witnesses unarmed at 0 that go negative fire at the start.)
//  6. Mesh engagements count towards the chattering guard like impacts; impacts of a
//     converging bounce series (e > 0, α > 0, the previous event a bounce on the same face)
//     do not.
//  7. The nominal rest rule (velocities below rest_velocity at t_end, no further event)
//     applies to free flight only, as in the nominal simulators.
//  8. The rounding-level rule of the nominal simulators (a zero of Tc where the contact
//     motion has decayed to rounding level is not a separation) applies in the linear
//     regime, measured from the mode's equilibrium θR + c.
//  9. A contact that clearly does not hold at its start (an offset or Coulomb torque can
//     make the step start pull apart) separates at once.
// Statuses: completed, rest, chattering, event_limit (also after 20·max_events + 10⁴
// mode switches: a guard against switches that report no event), non_finite (also when
// odeint gives up: a step that no longer advances time, or 5·10⁷ steps in one run).
// Cost: steps are bounded by τ, so a delay costs ∝ 1/τ (60 s of case V with τ = 0.05 at
// tolerance 1e-10: about 1 ms); a stiff mesh costs ∝ √kc + cc (the mesh mode's rate).
#include "backlash/numeric/odeint_effects_simulation.hpp"

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace backlash::numeric {

namespace odeint = boost::numeric::odeint;

namespace {

using Vec2 = std::array<double, 2>;  // contact: e = θo − θR − c, ω
using Vec4 = std::array<double, 4>;  // two bodies: θm − θm0, θ̇m, S·Δ, S·Δ̇

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kSlots = 6;
// Witness slots.  Contact: separation, -, the pair's velocity zero / band's pushing edge,
// band's pulling edge.  Two bodies: gap (recombination / engagement on +1 / release),
// gap (recontact / engagement on −1), motor, load.  Both: saturation high, low.
enum Slot { kGapA = 0, kGapB = 1, kMotor = 2, kLoad = 3, kSatA = 4, kSatB = 5 };
constexpr double kInactive = 1.0;  // the value of an unused witness (never fires)
constexpr int kBreakpointOrders = 4;
constexpr long kStepBudget = 50'000'000;  // accepted steps per run: beyond, odeint has given up
// An impact slower than this many sqrt(K/J)·max(1, b) of relative velocity is inelastic
// whatever the restitution: the bounces it would start are below any resolved motion
// (docs/effects.md: it ends a stick–bounce cascade).
constexpr double kSlowestBounce = 1e-9;
// A bounce series that ends within this fraction of the servo period 2π√(J/K) is summed
// (one inelastic impact, then contact over τ∞) instead of simulated bounce by bounce.
constexpr double kSeriesSummed = 1e-7;

int sgn(double x) { return (x > 0) - (x < 0); }

struct NonFiniteState {};

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}
template <class V>
bool finite(const V& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// Root of f on [a, b] (f(a), f(b) of opposite signs or one zero) with toms748.
template <class F>
double refine_root(F f, double a, double b, double fa, double fb) {
  if (fa == 0) return a;
  if (fb == 0) return b;
  if ((fa > 0) == (fb > 0)) return fa < 0 ? a : b;  // no bracket (rounding): the nearer end
  std::uintmax_t iterations = 200;
  const auto bracket =
      boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(52), iterations);
  return 0.5 * (bracket.first + bracket.second);
}

inline double sample_time(double t_old, double t_new, int k, int n) {
  return k == n ? t_new : t_old + (t_new - t_old) * k / n;
}

// ---------------------------------------------------------------- the history of θo
// θo, θ̇o, θ̈o at one time.
struct Jet {
  double x = 0, v = 0, a = 0;
};

// Dense-output segments of the measured shaft (quintic Hermite per accepted step),
// θo(0) before the first one (the constant history before the experiment starts).
class History {
 public:
  void reset(double theta0) {
    segments_.clear();
    theta0_ = theta0;
    cursor_ = 0;
  }
  void push(double ta, double tb, const Jet& a, const Jet& b) {
    const double h = tb - ta;
    if (!(h > 0)) return;
    Segment s;
    s.ta = ta;
    s.h = h;
    const double c0 = a.x, c1 = h * a.v, c2 = 0.5 * h * h * a.a;
    const double d0 = b.x - (c0 + c1 + c2), d1 = h * b.v - (c1 + 2 * c2), d2 = h * h * b.a - 2 * c2;
    s.c = {c0, c1, c2, 10 * d0 - 4 * d1 + 0.5 * d2, -15 * d0 + 7 * d1 - d2, 6 * d0 - 3 * d1 + 0.5 * d2};
    segments_.push_back(s);
  }
  double value(double t) const {
    const Segment* s = find(t);
    if (!s) return theta0_;
    const double u = (t - s->ta) / s->h;
    const auto& c = s->c;
    return c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
  }
  double rate(double t) const {
    const Segment* s = find(t);
    if (!s) return 0;
    const double u = (t - s->ta) / s->h;
    const auto& c = s->c;
    return (c[1] + u * (2 * c[2] + u * (3 * c[3] + u * (4 * c[4] + u * 5 * c[5])))) / s->h;
  }

 private:
  struct Segment {
    double ta = 0, h = 0;
    std::array<double, 6> c{};
  };
  const Segment* find(double t) const {
    if (segments_.empty() || t <= segments_.front().ta) return nullptr;
    std::size_t i = std::min(cursor_, segments_.size() - 1);
    while (i + 1 < segments_.size() && t >= segments_[i + 1].ta) ++i;
    while (i > 0 && t < segments_[i].ta) --i;
    cursor_ = i;
    return &segments_[i];  // beyond the last segment: its polynomial (rounding-level overshoot)
  }
  std::vector<Segment> segments_;
  double theta0_ = 0;
  mutable std::size_t cursor_ = 0;
};

// ---------------------------------------------------------------- the model
struct Model {
  Parameters p;
  double J = 0, F = 0, mu = 0;  // J = Jm + JL, F = Fm + FL, μ = Jm·JL/J
  double Tm = 0, TL = 0, Tsum = 0, e = 0, L = kInfinity, kc = kInfinity, cc = 0, tau = 0, T0 = 0;
  bool at_motor = false, delayed = false, saturating = false, compliant = false;
  // Stribeck friction (docs/effects.md): per body its Coulomb torque, kinetic and static levels
  // and Stribeck velocity; Tm, TL above are the static levels (Coulomb + static), the band a
  // body at rest sticks in.
  bool stribeck = false;
  double coulomb_m = 0, coulomb_L = 0, kinetic_m = 0, kinetic_L = 0, static_m = 0, static_L = 0;
  double vs_m = kInfinity, vs_L = kInfinity;
  const History* history = nullptr;

  Model(const Parameters& parameters, const Effects& fx, const History* h) : p(parameters), history(h) {
    J = p.Jm + p.JL;
    F = p.Fm + p.FL;
    mu = p.Jm * p.JL / J;
    coulomb_m = fx.coulomb_motor;
    coulomb_L = fx.coulomb_load;
    static_m = fx.stribeck_motor_static;
    static_L = fx.stribeck_load_static;
    kinetic_m = fx.stribeck_motor_kinetic;
    kinetic_L = fx.stribeck_load_kinetic;
    vs_m = fx.stribeck_motor_velocity;
    vs_L = fx.stribeck_load_velocity;
    stribeck = static_m > 0 || static_L > 0;
    Tm = coulomb_m + static_m;
    TL = coulomb_L + static_L;
    Tsum = Tm + TL;
    e = fx.restitution;
    saturating = fx.saturating();
    L = fx.saturation;
    compliant = fx.compliant();
    kc = fx.mesh_stiffness;
    cc = fx.mesh_damping;
    delayed = fx.delayed();
    tau = fx.delay;
    T0 = fx.torque_offset;
    at_motor = p.measured_at == model::MeasuredAt::Motor;
  }
  /// The friction level of a moving body at velocity v: its Coulomb torque plus the Stribeck
  /// curve Tk + (Ts − Tk)·exp(−(v/vs)²) (the static level Tm, TL without Stribeck friction).
  double motor_friction(double v) const {
    if (!stribeck) return Tm;
    const double x = v / vs_m;
    return coulomb_m + kinetic_m + (static_m - kinetic_m) * std::exp(-x * x);
  }
  double load_friction(double v) const {
    if (!stribeck) return TL;
    const double x = v / vs_L;
    return coulomb_L + kinetic_L + (static_L - kinetic_L) * std::exp(-x * x);
  }
  /// d/dv of the pair's friction level, motor_friction + load_friction, and of the load's.
  double pair_friction_slope(double v) const { return friction_slope(v, static_m - kinetic_m, vs_m) + load_friction_slope(v); }
  double load_friction_slope(double v) const { return friction_slope(v, static_L - kinetic_L, vs_L); }
  static double friction_slope(double v, double drop, double vs) {
    if (!(drop > 0)) return 0;
    const double x = v / vs;
    return -2 * drop * x / vs * std::exp(-x * x);
  }
  /// K(θR − θo(t − τ)) from the history.
  double delayed_demand(double t) const { return p.K * (p.theta_R - history->value(t - tau)); }
  double delayed_demand_rate(double t) const { return -p.K * history->rate(t - tau); }
  /// D in a regime from the demand K(θR − θo_fed_back).
  double drive(int regime, double demand) const { return (regime == 0 ? demand : regime * L) + T0; }
  /// Saturation witnesses (> 0 inside the regime).
  void saturation_witnesses(int regime, double demand, double& a, double& b) const {
    a = b = kInactive;
    if (!saturating) return;
    if (regime == 0) {
      a = L - demand;  // → clipped high
      b = L + demand;  // → clipped low
    } else {
      a = regime * demand - L;  // back to linear
    }
  }
  int consistent_regime(int regime, double demand) const {
    if (!saturating) return 0;
    if (regime == +1 && demand >= L) return +1;
    if (regime == -1 && demand <= -L) return -1;
    if (regime == 0 && std::fabs(demand) <= L) return 0;
    return demand > L ? +1 : demand < -L ? -1 : 0;
  }
};

// ---------------------------------------------------------------- mode systems
// Rigid contact on face σ: J·ω̇ = D − F·ω − (Tm+TL)·s, in e = θo − θR − c.
struct ContactSystem {
  const Model* m;
  double t0;    // global time of the mode start
  int regime;   // drive regime
  int s;        // the pair's slip direction
  double c;     // equilibrium offset (linear regime, no delay)
  bool stuck;   // the pair stuck: nothing moves
  bool linear_undelayed() const { return regime == 0 && !m->delayed; }
  double demand(const Vec2& y, double tau) const {
    return m->delayed ? m->delayed_demand(t0 + tau) : -m->p.K * (y[0] + c);
  }
  double drive(const Vec2& y, double tau) const { return m->drive(regime, demand(y, tau)); }
  double acceleration(const Vec2& y, double tau) const {
    if (stuck) return 0;
    if (m->stribeck) return (drive(y, tau) - m->F * y[1] - friction(y[1]) * s) / m->J;
    if (linear_undelayed()) return (-m->p.K * y[0] - m->F * y[1]) / m->J;  // c absorbs T0 − (Tm+TL)s
    return (drive(y, tau) - m->F * y[1] - m->Tsum * s) / m->J;
  }
  /// The pair's friction level at ω (Tm + TL without Stribeck friction).
  double friction(double omega) const { return m->motor_friction(omega) + m->load_friction(omega); }
  /// Tc = JL·ω̇ + FL·ω + TL·s (the torque the motor transmits, its Coulomb part included).
  double transmitted(const Vec2& y, double tau) const {
    return m->p.JL * acceleration(y, tau) + m->p.FL * y[1] + m->load_friction(y[1]) * s;
  }
  double transmitted_rate(const Vec2& y, double tau) const {
    const double a = acceleration(y, tau);
    const double drive_rate =
        regime != 0 ? 0.0 : m->delayed ? m->delayed_demand_rate(t0 + tau) : -m->p.K * y[1];
    const double jerk = (drive_rate - m->F * a - m->pair_friction_slope(y[1]) * a * s) / m->J;
    return m->p.JL * jerk + m->p.FL * a + m->load_friction_slope(y[1]) * a * s;
  }
  void operator()(const Vec2& y, Vec2& dy, double tau) const {
    dy[0] = stuck ? 0.0 : y[1];
    dy[1] = acceleration(y, tau);
  }
};

// Two bodies (free flight, or the mesh engaged on face `mesh`), start-relative.
struct TwoBodySystem {
  const Model* m;
  double t0;
  int regime;
  double e0;     // θo − θR at the start
  double S;      // gap scale
  bool motor_stuck, load_stuck;
  int s_m, s_L;  // slip directions
  int mesh;      // 0 free, ±1 engaged on that face
  int face;      // σ of reference: the face last left, or the mesh face
  double off;    // σ·x0 − b/2 at the start (x0 = θL − θm)
  double gap(const Vec4& y) const { return load_stuck ? -y[0] : y[2] / S; }  // Δ
  double gap_rate(const Vec4& y) const { return load_stuck ? -y[1] : y[3] / S; }
  double load_velocity(const Vec4& y) const { return load_stuck ? 0.0 : y[1] + y[3] / S; }
  double deviation(const Vec4& y) const { return m->at_motor ? e0 + y[0] : e0 + y[0] + gap(y); }  // θo − θR
  double demand(const Vec4& y, double tau) const {
    return m->delayed ? m->delayed_demand(t0 + tau) : -m->p.K * deviation(y);
  }
  double drive(const Vec4& y, double tau) const { return m->drive(regime, demand(y, tau)); }
  /// δ_σ' = σ'·x − b/2, from the start's offset to face `face`.
  double penetration(const Vec4& y, int side) const {
    const double own = face * gap(y) + off;
    return side == face ? own : -own - m->p.backlash;
  }
  double mesh_force(const Vec4& y, int side) const {
    return m->kc * penetration(y, side) + m->cc * side * gap_rate(y);
  }
  void accelerations(const Vec4& y, double tau, double& am, double& aL) const {
    const double P = mesh != 0 ? mesh_force(y, mesh) : 0.0;
    am = motor_stuck ? 0.0 : (drive(y, tau) - m->p.Fm * y[1] - m->motor_friction(y[1]) * s_m + mesh * P) / m->p.Jm;
    aL = load_stuck ? 0.0
                    : (-m->p.FL * load_velocity(y) - m->load_friction(load_velocity(y)) * s_L - mesh * P) / m->p.JL;
  }
  void operator()(const Vec4& y, Vec4& dy, double tau) const {
    double am, aL;
    accelerations(y, tau, am, aL);
    dy[0] = y[1];
    dy[1] = am;
    dy[2] = y[3];
    dy[3] = S * (aL - am);
  }
};

// ---------------------------------------------------------------- segment scanning
struct Probe {
  std::array<double, kSlots> g{};  // witnesses, > 0 inside
  std::array<double, 2> v{};       // velocities whose zeros are extremes (θ̇m, θ̇L)
  double speed = 0;                // max |velocity| − rest_velocity (free flight)
};

template <class Vector>
struct Outcome {
  int slot = -1;  // -1: horizon reached
  double tau = 0;
  Vector y{};
  double rest_tau = 0;  // the last time the speed fell below rest_velocity
  Vector y_rest{};
};

struct ScanSetup {
  std::array<bool, kSlots> armed{};
  int velocities = 2;
  bool rest_bookkeeping = false;
  double first_step = 0;
  std::optional<int> immediate;  // fire this slot at τ = 0 without integrating
};

// What a scan has seen so far: the witnesses armed (seen inside), the last sample's probe and
// time, and the jet at the end of the last step (the delay's history).
struct ScanState {
  std::array<bool, kSlots> armed;
  Probe prev;
  Jet jet_prev;
  double s_prev;
};

// The witness that fires first between the last sample and the probe `pr`: an armed witness
// crossing zero (root from `refine(slot)`), or an unarmed one found negative (it left at once,
// or the samples missed a return: the last sample's time).  The slot, or -1.
template <class Refine>
int first_witness(const ScanState& seen, const Probe& pr, double& root, Refine refine) {
  int slot = -1;
  root = kInfinity;
  for (int i = 0; i < kSlots; ++i) {
    double r = kInfinity;
    if (seen.armed[i] && seen.prev.g[i] > 0 && pr.g[i] <= 0) {
      r = refine(i);
    } else if (!seen.armed[i] && pr.g[i] < 0) {
      r = seen.s_prev;
    }
    if (r < root) {
      root = r;
      slot = i;
    }
  }
  return slot;
}

// ---------------------------------------------------------------- the modes, as a segment sees them
// Rigid contact on face σ in the scan's coordinates y = (θo − θR − c, ω): the state, the
// witnesses (separation, or the stuck band's edges; the pair's velocity; saturation) and the
// measured shaft's jet for the delay's history.
struct ContactMode {
  ContactSystem system;
  HybridState base;  // the state at the segment's start
  int face;

  HybridState at_state(const Vec2& y) const {
    const Model& m = *system.m;
    HybridState h = state_on_face(m.p, face, m.p.theta_R + system.c + y[0], y[1], true);
    h.motor_stuck = base.motor_stuck;
    h.load_stuck = base.load_stuck;
    h.drive_regime = system.regime;
    if (system.stuck) {
      h.theta_m = base.theta_m;
      h.theta_L = base.theta_L;
    }
    return h;
  }
  Probe probe(double tau, const Vec2& y) const {
    const Model& m = *system.m;
    Probe pr;
    pr.g.fill(kInactive);
    const double demand = system.demand(y, tau);
    if (system.stuck) {
      const double v = -face * m.drive(system.regime, demand);
      pr.g[kMotor] = m.Tsum - v;  // pushing edge
      pr.g[kLoad] = v + m.Tm;     // pulling edge
    } else {
      pr.g[kGapA] = -face * system.transmitted(y, tau);
      if (m.Tsum > 0) pr.g[kMotor] = system.s * y[1];
    }
    m.saturation_witnesses(system.regime, demand, pr.g[kSatA], pr.g[kSatB]);
    pr.v = {y[1], y[1]};
    return pr;
  }
  Jet jet(double tau, const Vec2& y) const {
    return Jet{system.m->p.theta_R + system.c + y[0], y[1], system.acceleration(y, tau)};
  }
};

// Two bodies (free flight, or the mesh engaged) in the scan's coordinates
// y = (θm − θm0, θ̇m, S·Δ, S·Δ̇): the state, the witnesses (the faces of the gap, or the mesh's
// release and engagement; a body's velocity zero or breakaway; saturation), the speed above
// rest_velocity and the measured shaft's jet.
struct TwoBodyMode {
  TwoBodySystem system;
  double theta_m0, theta_L0;
  double rest_velocity;

  bool in_mesh() const { return system.mesh != 0; }
  HybridState at_state(const Vec4& y) const {
    HybridState h;
    h.in_contact = in_mesh();
    h.face = system.face;
    h.motor_stuck = system.motor_stuck;
    h.load_stuck = system.load_stuck;
    h.drive_regime = system.regime;
    h.theta_m = theta_m0 + y[0];
    h.dtheta_m = y[1];
    h.theta_L = system.load_stuck ? theta_L0 : theta_L0 + y[0] + y[2] / system.S;
    h.dtheta_L = system.load_velocity(y);
    return h;
  }
  Probe probe(double tau, const Vec4& y) const {
    const Model& m = *system.m;
    const int face = system.face, mesh = system.mesh;
    Probe pr;
    pr.g.fill(kInactive);
    const double vm = y[1], vL = system.load_velocity(y);
    const double demand = system.demand(y, tau);
    double P = 0;
    if (!m.compliant) {
      const double own = face * system.gap(y) + system.off;
      pr.g[kGapA] = own + m.p.backlash;  // ≥ 0 inside: the opposite face not reached
      pr.g[kGapB] = -own;                // > 0 inside: the face left not reached again
    } else if (mesh != 0) {
      P = system.mesh_force(y, mesh);
      pr.g[kGapA] = P;  // release when the mesh would pull
    } else {
      for (int side : {+1, -1}) {
        const double d = system.penetration(y, side);
        const double force = m.kc * d + m.cc * side * system.gap_rate(y);
        pr.g[side > 0 ? kGapA : kGapB] = std::max(-m.kc * d, -force);
      }
    }
    if (system.motor_stuck) {
      pr.g[kMotor] = m.Tm - std::fabs(m.drive(system.regime, demand) + mesh * P);
    } else if (m.Tm > 0) {
      pr.g[kMotor] = system.s_m * vm;
    }
    if (system.load_stuck) {
      if (mesh != 0) pr.g[kLoad] = m.TL - std::fabs(P);
    } else if (m.TL > 0) {
      pr.g[kLoad] = system.s_L * vL;
    }
    m.saturation_witnesses(system.regime, demand, pr.g[kSatA], pr.g[kSatB]);
    pr.v = {vm, vL};
    pr.speed = std::max(std::fabs(vm), std::fabs(vL)) - rest_velocity;
    return pr;
  }
  Jet jet(double tau, const Vec4& y) const {
    double am, aL;
    system.accelerations(y, tau, am, aL);
    const HybridState h = at_state(y);
    return system.m->at_motor ? Jet{h.theta_m, h.dtheta_m, am} : Jet{h.theta_L, h.dtheta_L, aL};
  }
};

}  // namespace

// ---------------------------------------------------------------- the simulator
namespace {

class Simulator {
 public:
  Simulator(const Parameters& p, const Effects& fx, const SimulationOptions& o, const OdeintSimulationOptions& oo)
      : m_(p, fx, &history_), o_(o), oo_(oo), recorder_(m_.p, o, result_) {
    dt_rigid_ = oo.max_step_fraction / fastest_rate(p);
    if (m_.compliant) {
      const double mesh_rate = m_.cc / m_.mu + std::sqrt(m_.kc / m_.mu);
      dt_mesh_ = oo.max_step_fraction / (fastest_rate(p) + mesh_rate);
    } else {
      dt_mesh_ = dt_rigid_;
    }
    if (m_.delayed) {
      dt_rigid_ = std::min(dt_rigid_, m_.tau);
      dt_mesh_ = std::min(dt_mesh_, m_.tau);
    }
    servo_period_ = 2 * M_PI * std::sqrt(m_.J / p.K);
    transition_limit_ = 20 * std::max(0L, o.max_events) + 10000;
  }

  SimulationResult run(const HybridState& start);

 private:
  // ---- bookkeeping
  SimulationResult& finish(SimulationStatus status) {
    result_.status = status;
    result_.t_final = t_;
    result_.final_state = st_;
    result_.theta_o_final = measured(m_.p, st_);
    return result_;
  }
  void push_event(EventKind kind, bool bounce = false, Body body = Body::None, bool accumulation = false,
                  std::optional<double> at = std::nullopt) {
    SimulationEvent e;
    e.t = at ? *at : t_;
    e.kind = kind;
    e.theta_o = measured(m_.p, st_);
    e.dtheta_o = measured_velocity(m_.p, st_);
    e.after = st_;
    e.bounce = bounce;
    e.body = body;
    e.accumulation = accumulation;
    result_.events.push_back(e);
    include(st_);
    converged_ = false;
  }
  void include(const HybridState& h) {
    if (!o_.track_extremes) return;
    include_extremes(m_.p, h, result_.extremes);
  }
  // Breakpoints of the delayed drive after a mode switch at t.
  void add_breakpoints(double t) {
    if (!m_.delayed) return;
    for (int k = 1; k <= kBreakpointOrders; ++k) breakpoints_.push_back(t + k * m_.tau);
    std::sort(breakpoints_.begin(), breakpoints_.end());
  }
  std::vector<double> local_stops(double t0, double horizon) {
    std::vector<double> stops;
    if (!m_.delayed) return stops;
    breakpoints_.erase(breakpoints_.begin(),
                       std::find_if(breakpoints_.begin(), breakpoints_.end(), [&](double b) { return b > t0; }));
    const double guard = 1e-12 * std::max(1.0, std::fabs(t0));
    for (double b : breakpoints_) {
      const double local = b - t0;
      if (local >= horizon) break;
      if (local <= guard || (!stops.empty() && local - stops.back() <= guard)) continue;
      stops.push_back(local);
    }
    return stops;
  }
  // The time since which the measured shaft has been stuck (θo constant): called at every
  // transition, at the time it happens.
  void update_still() {
    if (m_.at_motor ? st_.motor_stuck : st_.load_stuck) {
      if (still_since_ == kInfinity) still_since_ = t_;
    } else {
      still_since_ = kInfinity;
    }
  }
  bool count_impact() {  // true: chattering
    impacts_.push_back(t_);
    while (!impacts_.empty() && impacts_.front() < t_ - zeno_window(m_.p, o_)) impacts_.pop_front();
    return static_cast<int>(impacts_.size()) >= o_.zeno_impacts;
  }
  bool separation_limit() { return o_.stop_after_separations > 0 && ++separations_ >= o_.stop_after_separations; }

  // ---- drive and torques at the current time, from a HybridState
  double demand_now() const {
    return m_.delayed ? m_.delayed_demand(t_) : m_.p.K * (m_.p.theta_R - measured(m_.p, st_));
  }
  double drive_now() const { return m_.drive(st_.drive_regime, demand_now()); }
  double mesh_force_now(int side) const {
    const double x = st_.theta_L - st_.theta_m;
    return m_.kc * (side * x - m_.p.backlash / 2) + m_.cc * side * (st_.dtheta_L - st_.dtheta_m);
  }
  bool mesh_engaged() const { return m_.compliant && st_.in_contact; }
  double motor_static_torque() const { return drive_now() + (mesh_engaged() ? st_.face * mesh_force_now(st_.face) : 0.0); }
  double load_static_torque() const { return mesh_engaged() ? -st_.face * mesh_force_now(st_.face) : 0.0; }

  enum class PairRule { Stick, Push, Pull };
  // The static rule of a pair at rest on face σ: the stuck band [−Tm, Tm+TL] of v = −σ·u.
  PairRule pair_rule(int face, double u) const {
    const double v = -face * u;
    if (v > m_.Tsum) return PairRule::Push;
    if (v < -m_.Tm) return PairRule::Pull;
    return PairRule::Stick;
  }
  void set_stuck_pair() {
    st_.motor_stuck = st_.load_stuck = true;
    st_.dtheta_m = st_.dtheta_L = 0;
    s_m_ = s_L_ = 0;
  }
  // The pair stops at the pulling edge: the motor leaves the load, slipping toward σ.
  void pull_away() {
    on_face(st_.face);
    st_.in_contact = false;
    st_.dtheta_m = st_.dtheta_L = 0;
    st_.motor_stuck = false;
    s_m_ = st_.face;
    st_.load_stuck = m_.TL > 0;
    s_L_ = 0;
  }
  // The pair pulled apart at the pulling edge: a separation.
  std::optional<SimulationStatus> pull_apart() {
    pull_away();
    push_event(EventKind::Separation);
    if (separation_limit()) return SimulationStatus::Completed;
    return std::nullopt;
  }
  // The drive crossing a saturation witness (slot kSatA: the upper limit, kSatB: the lower)
  // in `regime`: it enters the limit from the linear regime, or leaves it.
  void switch_drive_regime(int slot, int regime) {
    const int to = regime != 0 ? 0 : slot == kSatA ? +1 : -1;
    st_.drive_regime = to;
    push_event(to == 0 ? EventKind::Desaturation : EventKind::Saturation);
  }
  // Applies the static rules to the bodies at rest that are neither stuck nor decided
  // (the start, after an impact); reports stick (and separation) events.  Returns a
  // status when a stop rule fires.
  std::optional<SimulationStatus> settle();
  bool settle_body(Body body);

  // ---- segments
  template <class Vector, class System, class AtState, class ProbeFn, class JetFn>
  Outcome<Vector> scan(const System& system, const Vector& y0, double horizon, double dt_max, const ScanSetup& setup,
                       AtState at_state, ProbeFn probe, JetFn jet);
  template <class Vector, class Stepper, class System>
  std::pair<double, double> advance(Stepper& stepper, const System& system, const std::vector<double>& stops,
                                    std::size_t& next_stop, double t_old);
  template <class Vector, class AtTau, class AtState, class ProbeFn>
  bool scan_step(double ta, double tb, double dt_max, const ScanSetup& setup, ScanState& seen, Outcome<Vector>& out,
                 AtTau at_tau, AtState at_state, ProbeFn probe);
  ContactMode contact_mode() const;
  ScanSetup contact_setup(const ContactMode& mode, const Vec2& y0) const;
  bool at_rounding_level(const Vec2& y) const;
  std::optional<SimulationStatus> contact_segment();
  std::optional<SimulationStatus> contact_event(int slot, const ContactMode& mode);
  double face_offset(int face) const;
  TwoBodyMode two_body_mode() const;
  double two_body_first_step(const TwoBodyMode& mode, const Vec4& y0, double vm0, double vL0) const;
  std::optional<SimulationStatus> two_body_segment();
  std::optional<SimulationStatus> two_body_event(const Outcome<Vec4>& out, const TwoBodyMode& mode);
  std::optional<SimulationStatus> gap_event(int slot, const TwoBodyMode& mode);
  void body_event(Body body, double n, bool was_stuck);
  std::optional<SimulationStatus> impact(int face_hit, EventKind kind);
  std::optional<SimulationStatus> bounce(int face_hit, EventKind kind);
  std::optional<SimulationStatus> sum_bounce_series(int face_hit, double theta_o, double V, double tau_inf, int regime);
  std::optional<SimulationStatus> inelastic_impact(int face_hit, EventKind kind);
  SimulationStatus rest_now();

  Model m_;
  const SimulationOptions& o_;
  const OdeintSimulationOptions& oo_;
  SimulationResult result_;
  TrajectoryRecorder recorder_;
  History history_;
  std::vector<double> breakpoints_;
  double dt_rigid_ = 0, dt_mesh_ = 0, servo_period_ = 0;
  long transition_limit_ = 0;

  HybridState st_;
  int s_m_ = 0, s_L_ = 0;  // slip directions (in rigid contact: the pair's, both equal)
  double t_ = 0;
  double still_since_ = kInfinity;  // θo constant since (the measured body stuck)
  long separations_ = 0;
  std::deque<double> impacts_;
  bool converged_ = false;  // contact at rounding level: no separation to t_end
  long steps_ = 0;          // accepted integrator steps
  // The penetration δ = σ·x − b/2 beyond face σ at the current state, as the integrator
  // (or the impact law) left it: the positions' rounding would cost kc·ε in the mesh force.
  struct Penetration {
    bool known = false;
    int face = -1;
    double delta = 0;
  } penetration_;
  void on_face(int face, double delta = 0) { penetration_ = {true, face, delta}; }
};

// One segment: dopri5 + dense output from τ = 0 over [0, horizon], landing exactly on the
// stops (delay breakpoints); witnesses checked on the interpolant between samples.
template <class Vector, class System, class AtState, class ProbeFn, class JetFn>
Outcome<Vector> Simulator::scan(const System& system, const Vector& y0, double horizon, double dt_max,
                                const ScanSetup& setup, AtState at_state, ProbeFn probe, JetFn jet) {
  Outcome<Vector> out;
  out.y = y0;
  out.y_rest = y0;
  const double t0 = t_;
  include(at_state(0.0, y0));
  if (setup.immediate) {
    out.slot = *setup.immediate;
    recorder_.record(t0, t0 + 1e-12, [&](double) { return at_state(0.0, y0); });
    return out;
  }
  ScanState seen{setup.armed, probe(0.0, y0), m_.delayed ? jet(0.0, y0) : Jet{}, 0.0};
  const std::vector<double> stops = local_stops(t0, horizon);
  std::size_t next_stop = 0;

  auto stepper = odeint::make_dense_output(oo_.tolerance, oo_.tolerance, dt_max, odeint::runge_kutta_dopri5<Vector>());
  double dt0 = std::min(dt_max, horizon) * 0.05;
  if (setup.first_step > 0) dt0 = std::min(dt0, setup.first_step);
  if (!stops.empty()) dt0 = std::min(dt0, stops.front());
  stepper.initialize(y0, 0.0, dt0);
  double t_old = 0;
  while (t_old < horizon) {
    const auto step = advance<Vector>(stepper, system, stops, next_stop, t_old);
    const double ta = t_old, tb = std::min(step.second, horizon);
    auto at_tau = [&](double tau) {
      Vector z;
      stepper.calc_state(tau, z);
      return z;
    };
    auto samples_upto = [&](double upto) {
      recorder_.record(t0, upto, [&](double tau) { return at_state(tau, at_tau(tau)); });
    };
    seen.s_prev = ta;
    if (scan_step(ta, tb, dt_max, setup, seen, out, at_tau, at_state, probe)) {
      samples_upto(t0 + out.tau + 1e-12);
      if (m_.delayed) history_.push(t0 + ta, t0 + out.tau, seen.jet_prev, jet(out.tau, out.y));
      return out;
    }
    const bool last = tb >= horizon;
    samples_upto(t0 + tb + (last ? 1e-12 : 0.0));
    const Vector y_tb = last ? at_tau(horizon) : stepper.current_state();
    if (m_.delayed) {
      const Jet jb = jet(tb, y_tb);
      history_.push(t0 + ta, t0 + tb, seen.jet_prev, jb);
      seen.jet_prev = jb;
    }
    if (last) {
      out.y = y_tb;
      out.tau = horizon;
      break;
    }
    t_old = tb;
  }
  return out;
}

// One accepted step of the dense-output stepper from t_old, shortened to land exactly on the next
// stop (a delay breakpoint); a non-finite state, a step that no longer advances time or an
// absurd number of steps is odeint giving up.
template <class Vector, class Stepper, class System>
std::pair<double, double> Simulator::advance(Stepper& stepper, const System& system, const std::vector<double>& stops,
                                             std::size_t& next_stop, double t_old) {
  if (next_stop < stops.size() && stepper.current_time() + stepper.current_time_step() > stops[next_stop]) {
    const Vector here = stepper.current_state();
    stepper.initialize(here, t_old, stops[next_stop] - t_old);
  }
  const auto step = stepper.do_step(system);
  if (!finite(stepper.current_state()) || !std::isfinite(step.second)) throw NonFiniteState{};
  if (!(step.second > step.first) || ++steps_ > kStepBudget) throw NonFiniteState{};
  while (next_stop < stops.size() &&
         stops[next_stop] <= step.second + 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, step.second))
    ++next_stop;
  return {step.first, step.second};
}

// The samples of one accepted step [ta, tb] (spaced so that oo_.interior_checks fit in a step of
// dt_max): the first witness that fires between two samples (its root refined on the interpolant)
// ends the segment there (true, with `out` set); the extremes of the velocities and the rest
// time are bookkept on the way.
template <class Vector, class AtTau, class AtState, class ProbeFn>
bool Simulator::scan_step(double ta, double tb, double dt_max, const ScanSetup& setup, ScanState& seen,
                          Outcome<Vector>& out, AtTau at_tau, AtState at_state, ProbeFn probe) {
  const double spacing = dt_max / std::max(1, oo_.interior_checks + 1);
  const double count = std::ceil((tb - ta) / spacing * (1 - 1e-12));
  const int n = !(count > 1) ? 1 : count > 1e6 ? 1000000 : static_cast<int>(count);
  for (int k = 1; k <= n; ++k) {
    const double s = sample_time(ta, tb, k, n);
    const Vector y = at_tau(s);
    const Probe pr = probe(s, y);
    double root = kInfinity;
    const int slot = first_witness(seen, pr, root, [&](int i) {
      return refine_root([&](double tau) { return probe(tau, at_tau(tau)).g[i]; }, seen.s_prev, s, seen.prev.g[i], pr.g[i]);
    });
    const double until = slot >= 0 ? root : s;
    const Vector y_until = slot >= 0 ? at_tau(root) : y;
    const Probe pr_until = slot >= 0 ? probe(root, y_until) : pr;
    for (int j = 0; j < setup.velocities && o_.track_extremes; ++j) {
      const double va = seen.prev.v[j], vb = pr_until.v[j];
      if ((va < 0 && vb >= 0) || (va > 0 && vb <= 0)) {
        const double z = refine_root([&](double tau) { return probe(tau, at_tau(tau)).v[j]; }, seen.s_prev, until, va, vb);
        include(at_state(z, at_tau(z)));
      }
    }
    if (slot >= 0) {
      out.slot = slot;
      out.tau = root;
      out.y = y_until;
      return true;
    }
    for (int i = 0; i < kSlots; ++i)
      if (!seen.armed[i] && pr.g[i] > 0) seen.armed[i] = true;
    if (setup.rest_bookkeeping && seen.prev.speed >= 0 && pr.speed < 0) {
      out.rest_tau = refine_root([&](double tau) { return probe(tau, at_tau(tau)).speed; }, seen.s_prev, s,
                                 seen.prev.speed, pr.speed);
      out.y_rest = at_tau(out.rest_tau);
    }
    seen.prev = pr;
    seen.s_prev = s;
  }
  return false;
}

// One separate body at the start of a mode: a stuck body stays stuck (its Coulomb level > 0); a
// body at rest sticks when its static torque is within its Coulomb level, else it slips toward
// that torque.  True: it sticks now (the caller marks it, after both bodies are settled).
bool Simulator::settle_body(Body body) {
  const bool motor = body == Body::Motor;
  bool& stuck = motor ? st_.motor_stuck : st_.load_stuck;
  double& velocity = motor ? st_.dtheta_m : st_.dtheta_L;
  int& slip = motor ? s_m_ : s_L_;
  const double level = motor ? m_.Tm : m_.TL;
  if (stuck && level > 0) {
    velocity = 0;
    slip = 0;
    return false;
  }
  stuck = false;
  slip = sgn(velocity);
  if (velocity == 0 && level > 0) {
    const double n = motor ? motor_static_torque() : load_static_torque();
    if (std::fabs(n) <= level) return true;
    slip = sgn(n);
  }
  return false;
}

std::optional<SimulationStatus> Simulator::settle() {
  if (st_.in_contact && !m_.compliant) {
    if (st_.motor_stuck || st_.load_stuck) {
      if (m_.Tsum > 0) {
        set_stuck_pair();
        return std::nullopt;
      }
      st_.motor_stuck = st_.load_stuck = false;
    }
    const double omega = st_.dtheta_m;
    if (omega != 0 || m_.Tsum == 0) {
      s_m_ = s_L_ = sgn(omega);
      return std::nullopt;
    }
    switch (pair_rule(st_.face, drive_now())) {
      case PairRule::Stick:
        set_stuck_pair();
        push_event(EventKind::Stick, false, Body::Both);
        break;
      case PairRule::Push:
        s_m_ = s_L_ = -st_.face;
        break;
      case PairRule::Pull:
        pull_away();
        push_event(EventKind::Separation);
        add_breakpoints(t_);
        if (separation_limit()) return SimulationStatus::Completed;
        break;
    }
    return std::nullopt;
  }
  // Separate bodies (free flight or the mesh): the motor first (the load's static torque
  // through the mesh sees the motor's velocity as settled).
  const bool motor_sticks = settle_body(Body::Motor), load_sticks = settle_body(Body::Load);
  if (motor_sticks) st_.motor_stuck = true;
  if (load_sticks) st_.load_stuck = true;
  if (motor_sticks || load_sticks) {
    push_event(EventKind::Stick, false, motor_sticks && load_sticks ? Body::Both : motor_sticks ? Body::Motor : Body::Load);
  }
  return std::nullopt;
}

SimulationStatus Simulator::rest_now() {
  const double rest_t = result_.events.empty() ? 0.0 : std::max(0.0, result_.events.back().t);
  push_event(EventKind::Rest, false, Body::None, false, rest_t);
  const HybridState still = st_;
  recorder_.record(t_, o_.t_end + 1e-12, [&](double) { return still; });
  t_ = std::max(t_, o_.t_end);
  return SimulationStatus::Rest;
}

// ---- rigid contact on face σ (the pair slipping or stuck)
ContactMode Simulator::contact_mode() const {
  const bool stuck = st_.motor_stuck && st_.load_stuck;
  const int s = stuck ? 0 : s_m_;
  const int regime = st_.drive_regime;
  const double c = (regime == 0 && !stuck) ? (m_.T0 - m_.Tsum * s) / m_.p.K : 0.0;
  return ContactMode{ContactSystem{&m_, t_, regime, s, c, stuck}, st_, st_.face};
}

ScanSetup Simulator::contact_setup(const ContactMode& mode, const Vec2& y0) const {
  ScanSetup setup;
  setup.velocities = 1;
  const Probe p0 = mode.probe(0.0, y0);
  for (int i = 0; i < kSlots; ++i) setup.armed[i] = p0.g[i] > 0;
  // Starting on the separation line (Tc ≈ 0): Tc leaving toward its non-holding sign
  // separates at once; otherwise the witness is armed once it has the holding sign.
  if (!mode.system.stuck) {
    setup.armed[kGapA] = true;
    if (std::fabs(p0.g[kGapA]) <= 1e-13 * std::max(1.0, std::fabs(y0[1]))) {
      if (-mode.face * mode.system.transmitted_rate(y0, 0.0) < 0) setup.immediate = kGapA;
      setup.armed[kGapA] = false;
    } else if (p0.g[kGapA] < 0) {
      setup.immediate = kGapA;  // a contact that does not hold (a start the drive pulls apart)
    }
  }
  if (converged_) setup.armed[kGapA] = true, setup.immediate.reset();
  return setup;
}

// The rounding-level rule (as the nominal simulators): in the linear regime, a zero of Tc
// where the motion has decayed to rounding level about θR + c is not a separation.
bool Simulator::at_rounding_level(const Vec2& y) const {
  const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(m_.p.theta_R));
  const double rate = std::sqrt(m_.p.K / m_.J);
  return std::fabs(y[0]) <= noise && std::fabs(y[1]) <= noise * rate;
}

std::optional<SimulationStatus> Simulator::contact_segment() {
  const ContactMode mode = contact_mode();
  const bool stuck = mode.system.stuck;
  const double remaining = o_.t_end - t_;
  double horizon = remaining;
  bool waiting = false;  // the stuck pair waits for the delayed drive to settle
  if (stuck) {
    horizon = std::min(remaining, still_since_ + m_.tau - t_);
    waiting = horizon < remaining;
  }
  const Vec2 y0{measured(m_.p, st_) - m_.p.theta_R - mode.system.c, stuck ? 0.0 : st_.dtheta_m};
  const ScanSetup setup = contact_setup(mode, y0);
  auto at_state = [&mode](double, const Vec2& y) { return mode.at_state(y); };
  auto probe_mode = [&](double tau, const Vec2& y) {
    Probe pr = mode.probe(tau, y);
    if (converged_) pr.g[kGapA] = kInactive;
    return pr;
  };
  auto jet = [&mode](double tau, const Vec2& y) { return mode.jet(tau, y); };
  const Outcome<Vec2> out = scan(mode.system, y0, horizon, dt_rigid_, setup, at_state, probe_mode, jet);
  if (out.slot == kGapA && mode.system.regime == 0 && !setup.immediate && at_rounding_level(out.y)) {
    // Not a separation: contact holds to t_end (the remaining motion is rounding noise);
    // the mode goes on from here without the separation witness.
    t_ += out.tau;
    st_ = mode.at_state(out.y);
    converged_ = true;
    return std::nullopt;
  }
  t_ += out.tau;
  st_ = mode.at_state(out.y);
  include(st_);
  if (out.slot < 0) {
    if (waiting) return rest_now();
    t_ = o_.t_end;
    return SimulationStatus::Completed;
  }
  add_breakpoints(t_);
  return contact_event(out.slot, mode);
}

// What a witness of the contact mode that fired means, applied at the current state.
std::optional<SimulationStatus> Simulator::contact_event(int slot, const ContactMode& mode) {
  const int face = mode.face;
  switch (slot) {
    case kGapA: {  // separation
      on_face(face);
      st_.in_contact = false;
      s_m_ = s_L_ = sgn(st_.dtheta_m) != 0 ? sgn(st_.dtheta_m) : mode.system.s;
      push_event(EventKind::Separation);
      if (separation_limit()) return SimulationStatus::Completed;
      return std::nullopt;
    }
    case kMotor: {
      if (mode.system.stuck) {  // the drive beyond the pushing edge: the pair moves on
        st_.motor_stuck = st_.load_stuck = false;
        s_m_ = s_L_ = -face;
        push_event(EventKind::Slip, false, Body::Both);
        return std::nullopt;
      }
      // The pair's velocity reaches 0: the static rule.
      st_.dtheta_m = st_.dtheta_L = 0;
      switch (pair_rule(face, drive_now())) {
        case PairRule::Stick:
          set_stuck_pair();
          push_event(EventKind::Stick, false, Body::Both);
          break;
        case PairRule::Push:
          s_m_ = s_L_ = -face;  // an instantaneous reversal: no event
          break;
        case PairRule::Pull:
          return pull_apart();
      }
      return std::nullopt;
    }
    case kLoad:  // stuck pair, the drive beyond the pulling edge
      return pull_apart();
    case kSatA:
    case kSatB:
      switch_drive_regime(slot, mode.system.regime);
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

// ---- two bodies: free flight or the mesh engaged
// σ·x − b/2 at the current state: how far the gap is beyond face σ (≤ 0 inside the backlash),
// as the integrator or the impact law left it; on the face up to rounding (of the gap, and of
// positions far from 0), a rigid mesh is exactly on it.
double Simulator::face_offset(int face) const {
  const double half = m_.p.backlash / 2;
  const double x0 = st_.theta_L - st_.theta_m;
  double off = face * x0 - half;
  if (penetration_.known) off = penetration_.face == face ? penetration_.delta : -penetration_.delta - m_.p.backlash;
  const double snap = std::max(1e-12 * std::max(1.0, m_.p.backlash),
                               16 * std::numeric_limits<double>::epsilon() *
                                   std::max(std::fabs(st_.theta_m), std::fabs(st_.theta_L)));
  if (!m_.compliant && std::fabs(off) <= snap) off = 0;
  return off;
}

TwoBodyMode Simulator::two_body_mode() const {
  const int face = st_.face;
  const int mesh = mesh_engaged() ? face : 0;
  const TwoBodySystem system{&m_,          t_,           st_.drive_regime, measured(m_.p, st_) - m_.p.theta_R,
                             oo_.gap_scale, st_.motor_stuck, st_.load_stuck, s_m_, s_L_, mesh, face, face_offset(face)};
  return TwoBodyMode{system, st_.theta_m, st_.theta_L, o_.rest_velocity};
}

// A gap that leaves the face with Δ'' inward and Δ''' outward turns back after about
// 3|Δ''/Δ'''|: the first step is kept below that so its samples see the excursion.
// Likewise a gap leaving inward with Δ' and pressed back by Δ'' returns after 2|Δ'/Δ''|
// (a bounce), and a released mesh whose force P (Ṗ < 0, P̈ > 0) comes back after 2|Ṗ/P̈|:
// the first step is kept to a quarter of that.  0: no such bound.
double Simulator::two_body_first_step(const TwoBodyMode& mode, const Vec4& y0, double vm0, double vL0) const {
  const TwoBodySystem& system = mode.system;
  const int face = system.face, regime = system.regime;
  double am, aL;
  system.accelerations(y0, 0.0, am, aL);
  const double drive_rate = regime != 0 ? 0.0
                            : m_.delayed ? m_.delayed_demand_rate(t_)
                                         : -m_.p.K * (m_.at_motor ? y0[1] : system.load_velocity(y0));
  const double jm = system.motor_stuck ? 0.0 : (drive_rate - m_.p.Fm * am) / m_.p.Jm;
  const double jL = system.load_stuck ? 0.0 : -m_.p.FL * aL / m_.p.JL;
  const double first = vL0 - vm0, second = aL - am, third = jL - jm;  // the gap's derivatives
  if (!m_.compliant) {
    if (y0[3] == 0) {
      if (face * second < 0 && face * third > 0) return 0.5 * std::fabs(second / third);
    } else if (face * first < 0 && face * second > 0) {
      return 0.5 * std::fabs(first / second);
    }
  } else if (system.off > -1e-9 * std::max(1.0, m_.p.backlash)) {  // just released (or at the face)
    const double P1 = face * (m_.kc * first + m_.cc * second), P2 = face * (m_.kc * second + m_.cc * third);
    if (P1 < 0 && P2 > 0) return 0.5 * std::fabs(P1 / P2);
  }
  return 0;
}

std::optional<SimulationStatus> Simulator::two_body_segment() {
  const TwoBodyMode mode = two_body_mode();
  const TwoBodySystem& system = mode.system;
  const double vm0 = system.motor_stuck ? 0.0 : st_.dtheta_m, vL0 = system.load_stuck ? 0.0 : st_.dtheta_L;
  const Vec4 y0{0, vm0, 0, system.S * (vL0 - vm0)};
  const double remaining = o_.t_end - t_;
  double horizon = remaining;
  bool waiting = false;
  if (system.motor_stuck && system.load_stuck) {
    horizon = std::min(remaining, still_since_ + m_.tau - t_);
    waiting = horizon < remaining;
  }
  ScanSetup setup;
  setup.rest_bookkeeping = !mode.in_mesh();
  const Probe p0 = mode.probe(0.0, y0);
  for (int i = 0; i < kSlots; ++i) setup.armed[i] = p0.g[i] > 0;
  if (!mode.in_mesh() && (m_.compliant || system.off == 0)) setup.first_step = two_body_first_step(mode, y0, vm0, vL0);
  auto at_state = [&mode](double, const Vec4& y) { return mode.at_state(y); };
  auto probe = [&mode](double tau, const Vec4& y) { return mode.probe(tau, y); };
  auto jet = [&mode](double tau, const Vec4& y) { return mode.jet(tau, y); };
  const Outcome<Vec4> out = scan(system, y0, horizon, mode.in_mesh() ? dt_mesh_ : dt_rigid_, setup, at_state, probe, jet);
  t_ += out.tau;
  st_ = mode.at_state(out.y);
  if (out.slot < 0) {
    include(st_);
    if (waiting) return rest_now();
    t_ = o_.t_end;
    if (!mode.in_mesh() && mode.probe(out.tau, out.y).speed < 0) {
      const HybridState end = st_;
      st_ = mode.at_state(out.y_rest);
      push_event(EventKind::Rest, false, Body::None, false, t_ - remaining + out.rest_tau);
      st_ = end;
      return SimulationStatus::Rest;
    }
    return SimulationStatus::Completed;
  }
  on_face(system.face, system.face * system.gap(out.y) + system.off);
  add_breakpoints(t_);
  return two_body_event(out, mode);
}

// What a witness of the two-body mode that fired means, applied at the current state.
std::optional<SimulationStatus> Simulator::two_body_event(const Outcome<Vec4>& out, const TwoBodyMode& mode) {
  const TwoBodySystem& system = mode.system;
  const int mesh = system.mesh;
  switch (out.slot) {
    case kGapA:
    case kGapB:
      return gap_event(out.slot, mode);
    case kMotor:
      body_event(Body::Motor, system.drive(out.y, out.tau) + mesh * (mode.in_mesh() ? system.mesh_force(out.y, mesh) : 0.0),
                 system.motor_stuck);
      return std::nullopt;
    case kLoad:
      body_event(Body::Load, mode.in_mesh() ? -mesh * system.mesh_force(out.y, mesh) : 0.0, system.load_stuck);
      return std::nullopt;
    case kSatA:
    case kSatB:
      switch_drive_regime(out.slot, system.regime);
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

// The gap reaching a face (slot kGapA: the opposite face −σ, or with compliance the face +1;
// kGapB: the face σ left, or −1): a rigid impact, the mesh released, or the mesh engaging.
std::optional<SimulationStatus> Simulator::gap_event(int slot, const TwoBodyMode& mode) {
  const int face = mode.system.face;
  if (!m_.compliant) {
    include(st_);
    return impact(slot == kGapA ? -face : face, slot == kGapA ? EventKind::Recombination : EventKind::Recontact);
  }
  if (mode.in_mesh()) {  // the mesh would pull: release
    st_.in_contact = false;
    push_event(EventKind::Separation);
    if (separation_limit()) return SimulationStatus::Completed;
    return std::nullopt;
  }
  const int side = slot == kGapA ? +1 : -1;
  st_.in_contact = true;
  st_.face = side;
  push_event(side == face ? EventKind::Recontact : EventKind::Recombination);
  if (count_impact()) return SimulationStatus::Chattering;
  return std::nullopt;
}

// One body's Coulomb event: a stuck body breaking away (toward its static torque n), or a
// moving body's velocity reaching 0 — it sticks when |n| is within its Coulomb level, else it
// reverses at once (no event).
void Simulator::body_event(Body body, double n, bool was_stuck) {
  const bool motor = body == Body::Motor;
  bool& stuck = motor ? st_.motor_stuck : st_.load_stuck;
  int& slip = motor ? s_m_ : s_L_;
  if (was_stuck) {  // breakaway
    stuck = false;
    slip = sgn(n);
    push_event(EventKind::Slip, false, body);
    return;
  }
  (motor ? st_.dtheta_m : st_.dtheta_L) = 0;
  if (std::fabs(n) <= (motor ? m_.Tm : m_.TL)) {
    stuck = true;
    slip = 0;
    push_event(EventKind::Stick, false, body);
  } else {
    slip = sgn(n);  // reversal: no event
  }
}

// ---- the impact on face σ_hit (rigid mesh): momentum conserved, v_rel⁺ = −e·v_rel⁻.
std::optional<SimulationStatus> Simulator::impact(int face_hit, EventKind kind) {
  const double v_rel = st_.dtheta_L - st_.dtheta_m;
  on_face(face_hit);
  // Restitution applies above the slowest bounce, 1e-9·sqrt(K/J)·max(1, b) of relative velocity;
  // a slower impact is inelastic (docs/effects.md: it ends a stick–bounce cascade).
  const double slowest = kSlowestBounce * std::sqrt(m_.p.K / m_.J) * std::max(1.0, m_.p.backlash);
  if (m_.e > 0 && std::fabs(v_rel) >= slowest) return bounce(face_hit, kind);
  return inelastic_impact(face_hit, kind);
}

// Restitution: the bodies part at once with v_rel⁺ = −e·v_rel⁻.  When the free-flight relative
// acceleration α presses them back, the series of ever smaller bounces ends after
// τ∞ = 2e|v_rel|/(α(1 − e)); a τ∞ below kSeriesSummed of the servo period is summed.
std::optional<SimulationStatus> Simulator::bounce(int face_hit, EventKind kind) {
  const double Jm = m_.p.Jm, JL = m_.p.JL, J = m_.J;
  const double vm = st_.dtheta_m, vL = st_.dtheta_L;
  const double V = (Jm * vm + JL * vL) / J;
  const double v_rel = vL - vm;
  const double theta_o = measured(m_.p, st_);
  const int regime = st_.drive_regime;
  const double v_rel_after = -m_.e * v_rel;
  const double vm_after = V - JL / J * v_rel_after, vL_after = V + Jm / J * v_rel_after;
  st_ = state_on_face(m_.p, face_hit, theta_o, 0, false);
  st_.dtheta_m = vm_after;
  st_.dtheta_L = vL_after;
  st_.drive_regime = regime;
  st_.motor_stuck = st_.load_stuck = false;
  // Free-flight relative acceleration pressing the bodies back together.
  const double D = drive_now();
  auto direction = [](double v, double n, double T) { return v != 0 ? sgn(v) : std::fabs(n) <= T ? 0 : sgn(n); };
  const int sm = direction(vm_after, D, m_.Tm), sL = direction(vL_after, 0.0, m_.TL);
  const double am = (D - m_.p.Fm * vm_after - m_.motor_friction(vm_after) * sm) / Jm;
  const double aL = (-m_.p.FL * vL_after - m_.load_friction(vL_after) * sL) / JL;
  const double alpha = face_hit * (aL - am);
  const double w = m_.e * std::fabs(v_rel);
  // A bounce series continues when the event before this impact was a bounce on this face;
  // only then are its impacts exempt from the chattering guard (a stick-bounce cascade is not).
  const bool continues_series = !result_.events.empty() && result_.events.back().bounce &&
                                (result_.events.back().kind == EventKind::Recombination ||
                                 result_.events.back().kind == EventKind::Recontact) &&
                                result_.events.back().after.face == face_hit;
  const bool converging = alpha > 0;
  push_event(kind, true);
  if (converging) {
    const double tau_inf = 2 * w / (alpha * (1 - m_.e));
    if (tau_inf <= kSeriesSummed * servo_period_) return sum_bounce_series(face_hit, theta_o, V, tau_inf, regime);
  }
  if (!(converging && continues_series) && count_impact()) return SimulationStatus::Chattering;
  s_m_ = sgn(vm_after);
  s_L_ = sgn(vL_after);
  return settle();
}

// The bounce series summed: the inelastic impact at t (both at V), then the contact motion over τ∞.
std::optional<SimulationStatus> Simulator::sum_bounce_series(int face_hit, double theta_o, double V, double tau_inf,
                                                             int regime) {
  const int s = V != 0 ? sgn(V) : 0;
  st_ = state_on_face(m_.p, face_hit, theta_o, V, true);
  st_.drive_regime = regime;
  const double acc = (drive_now() - m_.F * V - (m_.motor_friction(V) + m_.load_friction(V)) * s) / m_.J;
  const double theta_after = theta_o + V * tau_inf + 0.5 * acc * tau_inf * tau_inf;
  const double omega_after = V + acc * tau_inf;
  if (m_.delayed) history_.push(t_, t_ + tau_inf, Jet{theta_o, V, acc}, Jet{theta_after, omega_after, acc});
  t_ += tau_inf;
  st_ = state_on_face(m_.p, face_hit, theta_after, omega_after, true);
  st_.drive_regime = regime;
  add_breakpoints(t_);
  push_event(EventKind::Recontact, false, Body::None, true);
  s_m_ = s_L_ = sgn(omega_after);
  if (omega_after == 0) return settle();
  return std::nullopt;
}

// Inelastic impact (eq. 24): both at V; contact holds if −σ·Tc ≥ 0 there.
std::optional<SimulationStatus> Simulator::inelastic_impact(int face_hit, EventKind kind) {
  const double Jm = m_.p.Jm, JL = m_.p.JL, J = m_.J;
  const double V = (Jm * st_.dtheta_m + JL * st_.dtheta_L) / J;
  const double theta_o = measured(m_.p, st_);
  const int regime = st_.drive_regime;
  st_ = state_on_face(m_.p, face_hit, theta_o, V, true);
  st_.drive_regime = regime;
  st_.motor_stuck = st_.load_stuck = false;
  const bool chattering = count_impact();
  if (V == 0 && m_.Tsum > 0) {
    switch (pair_rule(face_hit, drive_now())) {
      case PairRule::Stick:
        push_event(kind, false);
        set_stuck_pair();
        push_event(EventKind::Stick, false, Body::Both);
        break;
      case PairRule::Push:
        s_m_ = s_L_ = -face_hit;
        push_event(kind, false);
        break;
      case PairRule::Pull:
        pull_away();
        push_event(kind, true);
        break;
    }
    if (chattering) return SimulationStatus::Chattering;
    return std::nullopt;
  }
  const int s = sgn(V);
  const double acc = (drive_now() - m_.F * V - (m_.motor_friction(V) + m_.load_friction(V)) * s) / J;
  const double tc = JL * acc + m_.p.FL * V + m_.load_friction(V) * s;
  bool holds = -face_hit * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
  if (!holds && std::fabs(tc) <= 1e-13 * std::max(1.0, std::fabs(V))) {
    // Tc at rounding level (an impact right at the separation line; with b = 0 every
    // separation is one): where it is heading decides, as at the start of a contact.
    const double drive_rate = regime != 0 ? 0.0 : m_.delayed ? m_.delayed_demand_rate(t_) : -m_.p.K * V;
    const double jerk = (drive_rate - m_.F * acc - m_.pair_friction_slope(V) * acc * s) / J;
    holds = -face_hit * (JL * jerk + m_.p.FL * acc + m_.load_friction_slope(V) * acc * s) > 0;
  }
  s_m_ = s_L_ = s;
  if (!holds) st_.in_contact = false;  // a bounce: the bodies part again at once
  push_event(kind, !holds);
  if (chattering) return SimulationStatus::Chattering;
  return std::nullopt;
}

SimulationResult Simulator::run(const HybridState& start) {
  st_ = start;
  t_ = 0;
  history_.reset(measured(m_.p, st_));
  st_.drive_regime = m_.consistent_regime(start.drive_regime, m_.p.K * (m_.p.theta_R - measured(m_.p, st_)));
  add_breakpoints(0.0);
  try {
    if (auto status = settle()) return finish(*status);
    if (m_.at_motor ? st_.motor_stuck : st_.load_stuck) still_since_ = -kInfinity;  // θo(t ≤ 0) constant
    long transitions = 0;
    while (t_ < o_.t_end) {
      update_still();
      if (!finite(st_)) return finish(SimulationStatus::NonFinite);
      if (static_cast<long>(result_.events.size()) >= o_.max_events || ++transitions > transition_limit_)
        return finish(SimulationStatus::EventLimit);
      const bool all_stuck = st_.motor_stuck && st_.load_stuck;
      if (all_stuck && (!m_.delayed || t_ >= still_since_ + m_.tau)) return finish(rest_now());
      const bool rigid_contact = st_.in_contact && !m_.compliant;
      const std::optional<SimulationStatus> status = rigid_contact ? contact_segment() : two_body_segment();
      if (status) return finish(*status);
    }
  } catch (const NonFiniteState&) {
    return finish(SimulationStatus::NonFinite);
  } catch (const odeint::step_adjustment_error&) {
    return finish(SimulationStatus::NonFinite);
  } catch (const odeint::no_progress_error&) {
    return finish(SimulationStatus::NonFinite);
  }
  return finish(SimulationStatus::Completed);
}

}  // namespace

SimulationResult simulate_effects_with_odeint(const Parameters& p, const Effects& e, const HybridState& start,
                                              const SimulationOptions& options,
                                              const OdeintSimulationOptions& odeint_options) {
  Simulator simulator(p, e, options, odeint_options);
  return simulator.run(start);
}

SimulationResult simulate_effects_step_with_odeint(const Parameters& p, const Effects& e, double step,
                                                   const SimulationOptions& options,
                                                   const OdeintSimulationOptions& odeint_options) {
  return simulate_effects_with_odeint(p, e, effects_step_start(p, e, step), options, odeint_options);
}

}  // namespace backlash::numeric
