#include "backlash/numeric/hybrid_simulation.hpp"

#include "backlash/numeric/first_crossing.hpp"
#include "hybrid/linear_flight.hpp"
#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/rest_search.hpp"
#include "hybrid/run_constants.hpp"
#include "hybrid/sample_band.hpp"

#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <functional>
#include <limits>

namespace backlash::numeric {

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::Separation: return "separation";
    case EventKind::Recombination: return "recombination";
    case EventKind::Recontact: return "recontact";
    case EventKind::Rest: return "rest";
    case EventKind::Stick: return "stick";
    case EventKind::Slip: return "slip";
    case EventKind::Saturation: return "saturation";
    case EventKind::Desaturation: return "desaturation";
  }
  return "?";
}

const char* to_string(Body body) {
  switch (body) {
    case Body::None: return "none";
    case Body::Motor: return "motor";
    case Body::Load: return "load";
    case Body::Both: return "both";
  }
  return "?";
}

const char* to_string(SimulationStatus status) {
  switch (status) {
    case SimulationStatus::Completed: return "completed";
    case SimulationStatus::Rest: return "rest";
    case SimulationStatus::Chattering: return "chattering";
    case SimulationStatus::EventLimit: return "event_limit";
    case SimulationStatus::NonFinite: return "non_finite";
    case SimulationStatus::Unresolved: return "unresolved";
    case SimulationStatus::WorkLimit: return "work_limit";
  }
  return "?";
}

bool stopped_early(SimulationStatus status) {
  return status != SimulationStatus::Completed && status != SimulationStatus::Rest;
}

double zeno_window(const Parameters& p, const SimulationOptions& options) {
  if (options.zeno_window > 0) return options.zeno_window;
  return zeno_time_scales / fastest_mode_rate(p);
}

std::string zeno_reason(const SimulationOptions& options, double window) {
  char text[96];
  std::snprintf(text, sizeof text, "%d impacts within %.3g s (Zeno)", options.zeno_impacts, window);
  return text;
}

std::string event_limit_reason(const SimulationOptions& options) {
  return "the event cap of " + std::to_string(options.max_events) + " events was reached";
}

double measured(const Parameters& p, const HybridState& s) {
  return p.measured_at == model::MeasuredAt::Motor ? s.theta_m : s.theta_L;
}

double measured_velocity(const Parameters& p, const HybridState& s) {
  return p.measured_at == model::MeasuredAt::Motor ? s.dtheta_m : s.dtheta_L;
}

void include_extremes(const Parameters& p, const HybridState& h, Extremes& x) {
  const double o = measured(p, h);
  x.theta_o_min = std::min(x.theta_o_min, o);
  x.theta_o_max = std::max(x.theta_o_max, o);
  x.theta_m_min = std::min(x.theta_m_min, h.theta_m);
  x.theta_m_max = std::max(x.theta_m_max, h.theta_m);
  x.theta_L_min = std::min(x.theta_L_min, h.theta_L);
  x.theta_L_max = std::max(x.theta_L_max, h.theta_L);
}

namespace {

HybridState contact_state_on_face(const Parameters& p, int face, double theta_o, double velocity) {
  return state_on_face(p, face, theta_o, velocity, true);
}

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}

// x = (θm, θ̇m, θL, θ̇L)
HybridState free_state_of(const double* x, int face) {
  HybridState h;
  h.in_contact = false;
  h.face = face;
  h.theta_m = x[0];
  h.dtheta_m = x[1];
  h.theta_L = x[2];
  h.dtheta_L = x[3];
  return h;
}

// A free flight in the simulation frame: state(τ) and the gap change since its start — from the
// separation line's validated closed form (t, θ̇m0), or after a bounce from the exact exponential
// of the segment (linear_flight.hpp).  Held by value: no allocation per flight.
class Flight {
 public:
  static Flight from_separation_line(const ValidatedEvaluator& evaluator, const HybridState& start) {
    Flight f;
    f.evaluator_ = &evaluator;
    f.v_ = start.dtheta_m;
    const double theta0 = evaluator.evaluator().separation_theta(f.v_);  // thesis frame: θm(0) = θL(0) = θ0
    f.offset_m_ = start.theta_m - theta0;
    f.offset_L_ = start.theta_L - theta0;
    f.face_ = start.face;
    f.start_ = f.evaluated(0.0);  // the searches' first point, the recorder's and the extremes' start
    return f;
  }
  static Flight from_state(const Parameters& p, const HybridState& start) {
    SmallVector x0(4);
    x0 << start.theta_m, start.dtheta_m, start.theta_L, start.dtheta_L;
    Flight f;
    f.linear_.emplace(free_mode_segment(p), x0);
    f.face_ = start.face;
    return f;
  }
  HybridState at(double tau) const { return free_state_of(vector(tau).data(), face_); }
  /// at(τ) from the x of a gap_sample(τ) already taken (the same evaluation).
  HybridState at(const double* x) const { return free_state_of(x, face_); }
  /// The turns of θo in (0, duration) (sample_band.hpp); −1 after a bounce (no closed form of them).
  int turns(const Parameters& p, double duration, double* out, int capacity) const {
    if (linear_) return -1;
    if (p.measured_at == model::MeasuredAt::Load) return 0;  // θ̇L = θ̇m0·e^{−(FL/JL)τ}: monotone
    return detail::damped_turns(p.Fm / (2 * p.Jm), p.K / p.Jm, evaluator_->cot_phi() * v_, v_, duration, out, capacity);
  }
  SmallVector vector(double tau) const { return gap_sample(tau, false).x; }
  /// What at(τ).θm adds to the closed form's own θm (the separation line's frame to the run's).
  double motor_offset() const { return offset_m_; }
  /// x(τ) and the gap change Δx(τ): one closed-form evaluation (`with_gap` false: x alone).
  WitnessSample gap_sample(double tau, bool with_gap = true) const {
    if (linear_) {
      WitnessSample s{linear_->state(tau), 0};
      if (with_gap) {
        const SmallVector dx = linear_->change(tau);
        s.value = dx(2) - dx(0);
      }
      return s;
    }
    if (tau == 0 && !std::signbit(tau)) return start_;  // τ = +0: evaluated once, at the flight's start
    return evaluated(tau);
  }

 private:
  // One closed-form evaluation: x(τ) in the run's frame and the gap change.
  WitnessSample evaluated(double tau) const {
    const FreeState f = evaluator_->free_state(tau, v_);
    WitnessSample s{SmallVector(4), f.gap};
    s.x(0) = f.theta_m + offset_m_;
    s.x(1) = f.dtheta_m;
    s.x(2) = f.theta_L + offset_L_;
    s.x(3) = f.dtheta_L;
    return s;
  }

  const ValidatedEvaluator* evaluator_ = nullptr;
  double v_ = 0, offset_m_ = 0, offset_L_ = 0;
  int face_ = 0;
  WitnessSample start_;  // evaluated(+0) of a flight from the separation line
  std::optional<LinearFlight> linear_;
};

// A contact segment's closed form from (θo0, θ̇o0): contact_state(τ), with its start (τ = ±0)
// and two more states kept by τ's bits for `state`.  A segment asks for the same τ again: the
// recorder's and the extremes' start after the search's, the separation's state after the search
// found it (a 100 × 100 map's contact evaluations 1,515,158 → 1,386,837, bench/README.md).  The
// closed form is a function of τ alone, so a kept state is the bits an evaluation gives.  The
// search's own samples (`sampled`) are not looked up (they seldom repeat); its start is kept.
// Copies keep their own states (the recorder keeps one).
class ContactArc {
 public:
  ContactArc(const ValidatedEvaluator& evaluator, double theta0, double omega0)
      : evaluator_(&evaluator), theta0_(theta0), omega0_(omega0) {}
  double theta0() const { return theta0_; }
  double omega0() const { return omega0_; }
  /// contact_state(τ), evaluated (the start kept).
  ContactState sampled(double tau) const {
    const ContactState c = evaluator_->contact_state(tau, theta0_, omega0_);
    if (tau == 0) start_ = c, start_bits_ = bits_of(tau), has_start_ = true;
    return c;
  }
  /// contact_state(τ): a kept state, or evaluated and kept.
  ContactState state(double tau) const {
    const std::uint64_t bits = bits_of(tau);
    if (has_start_ && start_bits_ == bits) return start_;
    for (int k = 0; k < kept_; ++k)
      if (bits_[k] == bits) return states_[k];
    const ContactState c = sampled(tau);
    if (tau != 0) keep(tau, c);
    return c;
  }
  /// Keeps contact_state(τ) = c, evaluated elsewhere.
  void keep(double tau, const ContactState& c) const {
    bits_[next_] = bits_of(tau), states_[next_] = c;
    next_ ^= 1, kept_ = std::min(kept_ + 1, 2);
  }

 private:
  static std::uint64_t bits_of(double x) {
    std::uint64_t b = 0;
    std::memcpy(&b, &x, sizeof b);
    return b;
  }
  const ValidatedEvaluator* evaluator_;
  double theta0_, omega0_;
  mutable ContactState start_{}, states_[2]{};
  mutable std::uint64_t start_bits_ = 0, bits_[2] = {0, 0};
  mutable bool has_start_ = false;
  mutable int kept_ = 0, next_ = 0;
};

// A velocity as the angle it sweeps in the servo's time unit √(J/K) (servo_time_unit, 1 s for the
// thesis's cases; the run's constants keep it): the scale of a state's angles for rounding
// tolerances, whatever the gain.
double swept_angle(double time_unit, double velocity) { return velocity * time_unit; }

bool on_separation_line(const ValidatedEvaluator& evaluator, double theta_o, double velocity, double time_unit) {
  const double line = evaluator.evaluator().separation_theta(velocity);
  const double scale = std::max({1.0, std::fabs(theta_o), std::fabs(swept_angle(time_unit, velocity))});
  return std::fabs(theta_o - line) <= 1e-9 * scale;
}

// Extremes of a segment on [0, duration]: its end states and the certified zeros of the
// velocities whose witnesses are `velocity_modes` (θ̇m and θ̇L; in contact both are θ̇o).
// `vector(τ)` is the segment's state x, x' = A x + c.
void segment_extremes(const Parameters& p, const WitnessMode* velocity_modes, int count,
                      FunctionRef<SmallVector(double)> vector, FunctionRef<HybridState(double)> at, double duration,
                      Extremes& x) {
  include_extremes(p, at(0), x);
  include_extremes(p, at(duration), x);
  for (int i = 0; i < count; ++i) {
    const WitnessMode& mode = velocity_modes[i];
    const auto sample = [&vector, &mode](double t) {
      WitnessSample s{vector(t), 0};
      s.value = mode.e.dot(s.x);
      return s;
    };
    double from = 0;
    for (int k = 0; k < 10000; ++k) {
      const auto zero = first_crossing(mode, sample, 0, from, duration);
      if (!zero) break;
      include_extremes(p, at(zero->t), x);
      from = zero->t + 1e-12 * std::max(mode.time_unit, zero->t);
      if (from >= duration) break;
    }
  }
}

// The times of the recent impacts, for the Zeno rule: a ring that grows only when more impacts
// than ever before fall into the window (never per event in a steady motion).
class ImpactWindow {
 public:
  /// Records an impact at t, forgets those before t − window; the count in the window.
  std::size_t add(double t, double window) {
    if (count_ == ring_.size()) grow();
    ring_[(head_ + count_++) % ring_.size()] = t;
    while (count_ > 0 && ring_[head_] < t - window) {
      head_ = (head_ + 1) % ring_.size();
      --count_;
    }
    return count_;
  }

 private:
  void grow() {
    std::vector<double> larger(std::max<std::size_t>(16, 2 * ring_.size()));
    for (std::size_t i = 0; i < count_; ++i) larger[i] = ring_[(head_ + i) % ring_.size()];
    ring_.swap(larger);
    head_ = 0;
  }
  std::vector<double> ring_;
  std::size_t head_ = 0, count_ = 0;
};

}  // namespace

HybridState state_on_face(const Parameters& p, int face, double theta_o, double velocity, bool in_contact) {
  HybridState s;
  s.in_contact = in_contact;
  s.face = face;
  s.dtheta_m = s.dtheta_L = velocity;
  const double x = face * p.backlash / 2;  // θL − θm
  if (p.measured_at == model::MeasuredAt::Motor) {
    s.theta_m = theta_o;
    s.theta_L = theta_o + x;
  } else {
    s.theta_L = theta_o;
    s.theta_m = theta_o - x;
  }
  return s;
}

HybridState step_start(const Parameters& p, double step) {
  // θo = θR − A, at rest, on the face that drives toward θR: for A > 0 the motor pushes
  // forward (x = −b/2), for A < 0 backward (x = +b/2).
  return contact_state_on_face(p, step >= 0 ? -1 : +1, p.theta_R - step, 0);
}

bool inside_backlash(const Parameters& p, const HybridState& s) {
  const double half = p.backlash / 2, x = s.theta_L - s.theta_m;
  const double slack = 1e-12 * std::max({half, std::fabs(s.theta_m), std::fabs(s.theta_L)});  // the rounding of x
  return std::fabs(x) < half - slack;
}

HybridState rigid_start(const Parameters& p, const HybridState& start) {
  if (p.backlash > 0) return start;
  const double omega = start.dtheta_m == start.dtheta_L ? start.dtheta_m
                                                        : recombined_velocity(p, start.dtheta_m, start.dtheta_L);
  const int face = start.face == 0 ? -1 : start.face;
  return contact_state_on_face(p, face, measured(p, start), omega);
}

namespace {

// A sample band (SimulationOptions::sample_band) in a run's frame, and its margin.
using Band = TrajectoryRecorder::BandTest;

// One run of the closed-form hybrid automaton from a start state: contact segments (the
// validated closed form, separation at the first certified zero of Tc) and free flights (the
// first certified gap event), joined by the impact law.
class ClosedFormRun {
 public:
  /// `start_gap`: the gap x = θL − θm of a free start strictly inside the backlash, computed
  /// before any shift of the angles (simulate); none for every other start.
  /// `band`: options.sample_band in this run's frame, with its margin.
  ClosedFormRun(const ValidatedEvaluator& evaluator, const HybridState& start, const SimulationOptions& options,
                std::optional<double> start_gap, std::optional<Band> band)
      : evaluator_(evaluator),
        p_(evaluator.parameters()),
        o_(options),
        recorder_(p_, options, result_),
        constants_(p_),
        cancellation_scale_(4096 * std::numeric_limits<double>::epsilon() * std::fabs(torque_.r(0)) *
                            std::max(1.0, std::fabs(p_.theta_R))),
        rigid_(p_.backlash <= 0),  // a rigid drive: contact for ever, no events
        zeno_window_(zeno_window(p_, o_)),
        state_(rigid_ ? rigid_start(p_, start) : start),
        start_gap_(rigid_ || start.in_contact ? std::nullopt : start_gap),
        band_(band) {}

  SimulationResult run() {
    try {
      return run_events();
    } catch (...) {  // e.g. an event sink ending the run (settle.cpp): its samples so far reach the sink
      flush_samples();
      throw;
    }
  }

 private:
  SimulationResult run_events() {
    try {
      while (t_ < o_.t_end) {
        if (!finite(state_)) return stop(SimulationStatus::NonFinite, "the state is no longer finite");
        if (events_ >= o_.max_events)
          return stop(SimulationStatus::EventLimit, event_limit_reason(o_));
        static const std::string motion = "the motion";
        const double scale = motion_scale(p_, state_.theta_m, state_.theta_L);
        if (!motion_resolved(scale, resolvable_scale_))
          if (auto problem = resolution_problem(p_, scale, motion)) return stop(SimulationStatus::Unresolved, *problem);
        const std::optional<SimulationStatus> end = state_.in_contact ? contact() : flight();
        if (end) return finish(*end);
      }
    } catch (const SearchBudgetExhausted& budget) {
      return stop(SimulationStatus::WorkLimit, budget.what());
    }
    return finish(SimulationStatus::Completed);
  }
  SimulationResult finish(SimulationStatus status) {
    flush_samples();
    result_.status = status;
    result_.t_final = t_;
    result_.final_state = state_;
    result_.theta_o_final = measured(p_, state_);
    return std::move(result_);  // the run ends here: its events are not copied
  }
  SimulationResult stop(SimulationStatus status, std::string reason) {
    result_.stop_reason = std::move(reason);
    return finish(status);
  }
  void push_event(EventKind kind, bool bounce, bool grazing) {
    SimulationEvent e;
    e.t = t_;
    e.kind = kind;
    e.theta_o = measured(p_, state_);
    e.dtheta_o = measured_velocity(p_, state_);
    e.after = state_;
    e.bounce = bounce;
    e.grazing = grazing;
    ++events_;
    if (o_.event_sink) o_.event_sink(e);
    else result_.events.push_back(e);
  }

  std::optional<SimulationStatus> contact();
  WitnessSample torque_sample(double tau, const ContactArc& arc, ContactState* state = nullptr) const;
  std::optional<Crossing> separation(const ContactArc& arc, double remaining, ContactState& at_separation) const;
  std::optional<SimulationStatus> flight();
  SimulationStatus rest(const Flight& flight, double remaining, const HybridState& end);
  std::optional<SimulationStatus> impact(const detail::GapEvent& event, const HybridState& before);
  std::optional<std::string> unresolved_return(const detail::GapEvent& event) const;
  template <class At>
  void record(double upto, const At& at, FunctionRef<int(double, double*, int)> turns);
  template <class At>
  [[gnu::noinline]] void record_in_band(double upto, const At& at, FunctionRef<int(double, double*, int)> turns);
  void flush_samples() {
    if (band_) recorder_.flush(*band_);
  }

  const ValidatedEvaluator& evaluator_;
  const Parameters& p_;
  const SimulationOptions& o_;
  SimulationResult result_;
  TrajectoryRecorder recorder_;
  // The witnesses' constants, once per thread and parameter set (run_constants.hpp):
  // Tc in contact, the gap in flight, and (track_extremes) the velocities.
  const detail::RunConstantsLease constants_;
  const TransmittedTorque& torque_ = constants_->torque;
  const WitnessMode& contact_mode_ = constants_->contact_mode;
  const WitnessMode& gap_mode_ = constants_->gap_mode;
  const double cancellation_scale_;  // see torque_sample
  const bool rigid_;
  const double zeno_window_;  // zeno_window(p_, o_), once per run
  const double resolvable_scale_ = resolvable_scale(p_);  // once per run
  HybridState state_;
  std::optional<double> start_gap_;  // the first flight's gap x(0) when it starts inside the backlash
  const std::optional<Band> band_;  // options.sample_band in this run's frame (band_in_frame)
  double t_ = 0;
  ImpactWindow impacts_;
  long separations_ = 0;
  long events_ = 0;  // events so far (kept or sunk)
};

// Tc = JL θ̈o + FL θ̇o along the contact segment from (θ0, ω0), with the state y = (θo, θ̇o) at τ
// from the same closed-form evaluation: one sample of the certified witness.
WitnessSample ClosedFormRun::torque_sample(double tau, const ContactArc& arc, ContactState* state) const {
  const double theta0 = arc.theta0(), omega0 = arc.omega0();
  const ContactState c = arc.sampled(tau);
  if (state) *state = c;
  WitnessSample s{SmallVector(2), 0};
  s.x << c.theta_o, c.dtheta_o;
  // Tc = (JL K/J)(θR − θo) + (FL − JL F/J) θ̇o without the cancellation θR − θo: by
  // linearity θo − θR = (θo0 − θR)·a(τ) + θ̇o0·b(τ) with the unit responses a, b of the
  // validated closed form, so the rounding error scales with the motion, not with θR.
  // Far from a zero of Tc the cancellation is harmless, so the unit responses are only
  // evaluated where |Tc| is within a few thousand ulps of θR's scale (cancellation_scale_).
  const double direct = torque_.r(0) * (c.theta_o - p_.theta_R) + torque_.r(1) * c.dtheta_o;
  if (std::fabs(direct) > cancellation_scale_) {
    s.value = direct;
    return s;
  }
  const double a = evaluator_.contact_state(tau, p_.theta_R + 1, 0).theta_o - p_.theta_R;
  const double b = evaluator_.contact_state(tau, p_.theta_R, 1).theta_o - p_.theta_R;
  const double deviation = (theta0 - p_.theta_R) * a + omega0 * b;
  s.value = torque_.r(0) * deviation + torque_.r(1) * c.dtheta_o;
  return s;
}

// The next time Tc leaves its holding sign within `remaining` (a grazing touch keeps contact), and
// the contact state there (`at_separation`: one closed-form evaluation for the check below and the event).
std::optional<Crossing> ClosedFormRun::separation(const ContactArc& arc, double remaining,
                                                  ContactState& at_separation) const {
  const double theta0 = arc.theta0(), omega0 = arc.omega0();
  // The last point sampled: the separation's state when the root is a sample (Halley's last step below rounding).
  double last_tau = NAN;
  ContactState last{};
  const auto sample = [this, &arc, &last_tau, &last](double tau) {
    last_tau = tau;
    return torque_sample(tau, arc, &last);
  };
  std::optional<Crossing> separation;
  double from = 0;
  if (std::fabs(transmitted_torque_at(p_, theta0, omega0)) <= 1e-13 * std::max(1.0, std::fabs(omega0))) {
    // Starting on the separation line: certified departure of Tc first.
    if (auto t0 = certified_departure(contact_mode_, sample(0).x, 1e-12)) from = *t0;
  }
  while (!rigid_) {
    separation = detail::certified_first_crossing(contact_mode_, sample, 0, from, remaining);
    if (!separation || !separation->grazing) break;
    from = separation->t + 1e-12 * std::max(contact_mode_.time_unit, separation->t);
  }
  // Tc = r·y + r0 goes through the cancellation θR − θo: once the contact motion has decayed
  // to rounding level its sign is noise, and a "separation" found there is spurious (e.g. an
  // over-damped contact whose Tc = A e^{λ1 t} + B e^{λ2 t} has no zero for t > 0).  The test is
  // on the state, not on Tc's terms: when Fm/Jm = FL/JL the velocity term of Tc vanishes
  // identically and every genuine separation happens at θo = θR, with θ̇o far from zero.
  if (separation) {
    const ContactState& c = at_separation =
        separation->t == last_tau ? last : arc.sampled(separation->t);
    arc.keep(separation->t, c);  // at(separation) of the recorder, the extremes and the event
    const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(p_.theta_R));
    const double rate = std::sqrt(p_.K / (p_.Jm + p_.JL));  // converts a velocity to a displacement scale
    if (std::fabs(c.theta_o - p_.theta_R) <= noise && std::fabs(c.dtheta_o) <= noise * rate) separation.reset();
  }
  return separation;
}

// A contact segment on the face σ held: to the separation, or to t_end.
std::optional<SimulationStatus> ClosedFormRun::contact() {
  const double remaining = o_.t_end - t_;
  const double theta0 = measured(p_, state_), omega0 = state_.dtheta_m;
  const int face = state_.face;
  const ContactArc arc(evaluator_, theta0, omega0);
  ContactState at_separation{};
  const std::optional<Crossing> separated = separation(arc, remaining, at_separation);
  // A copy of the arc after the search (its start and last points kept): record() may keep `at`.
  auto at = [&p = p_, arc, face](double tau) {
    const ContactState c = arc.state(tau);
    return contact_state_on_face(p, face, c.theta_o, c.dtheta_o);
  };
  if (o_.track_extremes) {
    const auto vector = [this, &arc](double tau) { return torque_sample(tau, arc).x; };
    segment_extremes(p_, &constants_->contact_velocity(), 1, vector, at, separated ? separated->t : remaining, result_.extremes);
  }
  const auto turns = [this, theta0, omega0](double duration, double* out, int capacity) {
    return detail::damped_turns((p_.Fm + p_.FL) / (2 * (p_.Jm + p_.JL)), p_.K / (p_.Jm + p_.JL), theta0 - p_.theta_R,
                                omega0, duration, out, capacity);
  };
  record(separated ? t_ + separated->t + 1e-12 : o_.t_end + 1e-12, at, turns);
  if (!separated) {
    state_ = at(remaining);
    t_ = o_.t_end;
    return SimulationStatus::Completed;
  }
  t_ += separated->t;
  state_ = contact_state_on_face(p_, face, at_separation.theta_o, at_separation.dtheta_o);  // at(separated->t)
  state_.in_contact = false;  // face σ is the face just left
  push_event(EventKind::Separation, false, false);
  if (o_.stop_after_separations > 0 && ++separations_ >= o_.stop_after_separations) return SimulationStatus::Completed;
  if (o_.stop_requested && *o_.stop_requested) return SimulationStatus::Completed;
  return std::nullopt;
}

// A free flight: to the first gap event (an impact), or to t_end (at rest, or still moving).
std::optional<SimulationStatus> ClosedFormRun::flight() {
  const double remaining = o_.t_end - t_;
  const double theta_o = measured(p_, state_);
  const bool from_line = std::fabs(state_.dtheta_m - state_.dtheta_L) <= 1e-12 * std::max(1.0, std::fabs(state_.dtheta_m)) &&
                         on_separation_line(evaluator_, theta_o, state_.dtheta_m, constants_->time_unit);
  const Flight flight = from_line ? Flight::from_separation_line(evaluator_, state_) : Flight::from_state(p_, state_);
  const auto at = [flight](double tau) { return flight.at(tau); };  // a copy: record() may keep it
  const double scale = std::max({1.0, std::fabs(theta_o), std::fabs(swept_angle(constants_->time_unit, state_.dtheta_m))});
  const auto sample = [&flight](double tau) { return flight.gap_sample(tau); };
  // Δx'(0) = 0 exactly: the separation line's closed form starts both bodies at one velocity.
  const bool turns_once = constants_->gap_turns_once && (from_line || state_.dtheta_m == state_.dtheta_L);
  const auto event = start_gap_ ? detail::first_gap_event_inside_with(gap_mode_, sample, *start_gap_, state_.face,
                                                                      p_.backlash / 2, remaining)
                                : detail::first_gap_event_with(gap_mode_, sample, -state_.face * p_.backlash, remaining,
                                                               scale, turns_once);
  start_gap_.reset();  // every later flight leaves a face
  if (o_.track_extremes) {
    const auto vector = [&flight](double tau) { return flight.vector(tau); };
    segment_extremes(p_, constants_->free_velocities(), 2, vector, at, event ? event->crossing.t : remaining, result_.extremes);
  }
  const auto turns = [this, &flight](double duration, double* out, int capacity) {
    return flight.turns(p_, duration, out, capacity);
  };
  if (!event) {
    record(o_.t_end + 1e-12, at, turns);
    const HybridState end = flight.at(remaining);
    const double speed = std::max(std::fabs(end.dtheta_m), std::fabs(end.dtheta_L));
    if (speed < o_.rest_velocity) return rest(flight, remaining, end);
    state_ = end;
    t_ = o_.t_end;
    return SimulationStatus::Completed;
  }
  if (auto problem = unresolved_return(*event)) {
    result_.stop_reason = std::move(*problem);
    return SimulationStatus::Unresolved;
  }
  record(t_ + event->crossing.t + 1e-12, at, turns);
  const HybridState before = event->x.size() == 4 ? flight.at(event->x.data()) : flight.at(event->crossing.t);
  t_ += event->crossing.t;
  return impact(*event, before);
}

// The samples of a segment (its state `at(τ)`, τ = t − t_) at the times ≤ upto; with a sample band
// (SimulationOptions::sample_band) none when its θo on [0, upto − t_] certainly lies in the band (at
// both ends and at its turns, `turns`: sample_band.hpp, inside by the margin), else those the last
// sample outside needs (TrajectoryRecorder::defer_last_outside: walked only when no later
// segment ends certainly outside).
template <class At>
void ClosedFormRun::record(double upto, const At& at, FunctionRef<int(double, double*, int)> turns) {
  if (!band_) return recorder_.record(t_, upto, at);
  record_in_band(upto, at, turns);
}

// record() with a sample band: out of line, so that the event loop compiles as without it (issue 19).
template <class At>
void ClosedFormRun::record_in_band(double upto, const At& at, FunctionRef<int(double, double*, int)> turns) {
  const auto keep = [this](double o) { return band_->may_be_outside(o); };  // not inside by the margin
  std::array<double, TrajectoryRecorder::kMaxTurns> times;
  const int count = turns(upto - t_, times.data(), static_cast<int>(times.size()));
  bool skip = count >= 0 && !keep(measured(p_, at(0))) && !keep(measured(p_, at(upto - t_)));
  for (int i = 0; skip && i < count; ++i) skip = !keep(measured(p_, at(times[i])));
  if (skip) recorder_.skip(upto);
  else recorder_.defer_last_outside(t_, upto, at, *band_, times.data(), count);  // `at` kept by value: it owns its segment
}

// A return to the face just left, found within the search's resolution of the certified
// departure t0 (w ≠ 0 on (0, t0]): the exact flight departs as t² or t³ and cannot return there,
// so the search has not resolved the gap from rounding (a flight of no length, which would
// start a burst of events at one instant).  Said, never continued (docs/physics.md, leaving a face).
std::optional<std::string> ClosedFormRun::unresolved_return(const detail::GapEvent& event) const {
  if (event.kind != detail::GapEventKind::FaceLeft || event.from_inside) return std::nullopt;
  const double resolution = CrossingOptions{}.min_interval * servo_time_unit(p_);
  if (event.crossing.t > event.departure + resolution) return std::nullopt;
  char text[256];
  std::snprintf(text, sizeof text,
                "the free flight from t = %.17g s returned to the face it left after %.3g s, within the "
                "search's resolution %.3g s of its certified departure: the gap is not resolved from rounding",
                t_, event.crossing.t, resolution);
  return std::string(text);
}

// Rest: the event at the last time any velocity exceeded the tolerance (bisection on the
// closed form, its points after a certified quiet state not evaluated: rest_search.hpp), then
// the state at t_end.
SimulationStatus ClosedFormRun::rest(const Flight& flight, double remaining, const HybridState& end) {
  const detail::FreeFlightRestBound bound(constants_->free_segment);
  const auto quiet_after = [&](const HybridState& s) {
    return bound.quiet_after(s.theta_m - flight.motor_offset(), s.dtheta_m, s.dtheta_L, o_.rest_velocity);
  };
  const double hi = detail::rest_time([&](double t) { return flight.at(t); }, remaining, o_.rest_velocity, quiet_after);
  const double t_end = t_ + remaining;
  t_ += hi;
  state_ = flight.at(hi);
  push_event(EventKind::Rest, false, false);
  t_ = t_end;
  state_ = end;
  return SimulationStatus::Rest;
}

// Inelastic impact (eq. 24) on the face hit; contact holds if the torque has its holding sign
// there, else the bodies part again at once (a bounce).  Chattering when impacts come denser
// than zeno_impacts in the Zeno window.
std::optional<SimulationStatus> ClosedFormRun::impact(const detail::GapEvent& event, const HybridState& before) {
  const bool opposite = event.kind == detail::GapEventKind::OppositeFace;
  const int face_hit = opposite ? -state_.face : state_.face;
  const double omega = recombined_velocity(p_, before.dtheta_m, before.dtheta_L);
  state_ = contact_state_on_face(p_, face_hit, measured(p_, before), omega);
  const double tc = transmitted_torque_at(p_, measured(p_, state_), omega);
  const bool holds = -face_hit * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
  if (!holds) state_.in_contact = false;  // a bounce: the bodies part again at once
  push_event(opposite ? EventKind::Recombination : EventKind::Recontact, !holds, event.crossing.grazing);
  const double window = zeno_window_;
  if (static_cast<long long>(impacts_.add(t_, window)) >= o_.zeno_impacts) {
    result_.stop_reason = zeno_reason(o_, window);
    return SimulationStatus::Chattering;
  }
  return std::nullopt;
}

// options.sample_band moved by −shift into the run's frame, and its margin: four times the gate's
// tolerance scaled like the gate's errors, max(1, |θ|) in either frame (covering the evaluator's
// error at a sample and at a turn, and the rounding of the shift).
std::optional<Band> band_in_frame(const ValidatedEvaluator& evaluator, const SimulationOptions& options, double shift) {
  if (!options.sample_band) return std::nullopt;
  const auto [low, high] = *options.sample_band;
  const double margin = 4 * evaluator.report().tolerance *
                        std::max({1.0, std::fabs(low), std::fabs(high), std::fabs(low - shift), std::fabs(high - shift)});
  return Band{low - shift, high - shift, margin};
}

SimulationResult simulate_as_given(const ValidatedEvaluator& evaluator, const HybridState& start,
                                   const SimulationOptions& options, std::optional<double> start_gap,
                                   std::optional<Band> band) {
  return ClosedFormRun(evaluator, start, options, start_gap, band).run();
}

void shift_state(HybridState& s, double offset) {
  s.theta_m += offset;
  s.theta_L += offset;
}

}  // namespace

// The numerics run in error coordinates (validation.hpp, in_error_coordinates): the angles are
// shifted by −θR on the way in and by +θR on the way out, so the gap θL − θm keeps its digits
// whatever θR is.  A generated case evaluator (θR folded in) runs as given.
SimulationResult simulate(const ValidatedEvaluator& evaluator, const HybridState& start, const SimulationOptions& options) {
  const std::optional<double> start_gap = !start.in_contact && inside_backlash(evaluator.parameters(), start)
                                              ? std::optional<double>(start.theta_L - start.theta_m)
                                              : std::nullopt;
  const std::optional<ValidatedEvaluator> centred = in_error_coordinates(evaluator);
  if (!centred) return simulate_as_given(evaluator, start, options, start_gap, band_in_frame(evaluator, options, 0));
  const double R = evaluator.parameters().theta_R;
  HybridState from = start;
  shift_state(from, -R);
  SimulationOptions shifted = options;
  auto shift_sample = [R](TrajectorySample& s) {
    s.theta_o += R;
    s.theta_m += R;
    s.theta_L += R;
  };
  if (options.event_sink)
    shifted.event_sink = [&options, R](const SimulationEvent& event) {
      SimulationEvent moved = event;
      moved.theta_o += R;
      shift_state(moved.after, R);
      shift_state(moved.before, R);
      options.event_sink(moved);
    };
  if (options.sample_sink)
    shifted.sample_sink = [&options, &shift_sample](const TrajectorySample& sample) {
      TrajectorySample moved = sample;
      shift_sample(moved);
      options.sample_sink(moved);
    };
  SimulationResult r = simulate_as_given(*centred, from, shifted, start_gap, band_in_frame(evaluator, options, R));
  for (SimulationEvent& e : r.events) {
    e.theta_o += R;
    shift_state(e.after, R);
    shift_state(e.before, R);
  }
  shift_state(r.final_state, R);
  r.theta_o_final += R;
  for (TrajectorySample& s : r.samples) shift_sample(s);
  for (double* angle : {&r.extremes.theta_o_min, &r.extremes.theta_o_max, &r.extremes.theta_m_min, &r.extremes.theta_m_max,
                        &r.extremes.theta_L_min, &r.extremes.theta_L_max})
    *angle += R;  // ±infinity (nothing tracked) stays
  return r;
}

SimulationResult simulate_step(const ValidatedEvaluator& evaluator, double step, const SimulationOptions& options) {
  return simulate(evaluator, step_start(evaluator.parameters(), step), options);
}

}  // namespace backlash::numeric
