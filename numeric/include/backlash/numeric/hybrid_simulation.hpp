// backlash/numeric/hybrid_simulation.hpp — the hybrid automaton, event by event.
//
// One frame throughout (docs/physics.md): the gap x = θL − θm is centred, the
// contact faces are x = ±b/2, and the measured shaft θo is continuous through
// every event.  Modes and guards:
//   contact on face σ (x = σ b/2)   θo from the validated closed form (eq. 25);
//                                   holds while −σ·Tc ≥ 0, Tc = JL θ̈o + FL θ̇o;
//   separation                      Tc leaves its holding sign (the state is then on the
//                                   separation line θo = θR + cot φ θ̇o);
//   free                            from the separation line: the validated closed form
//                                   (t, θ̇m0); from any other state (after a bounce): the
//                                   exact matrix exponential of the segment's linear ODE;
//   recombination                   x reaches the opposite face −σ b/2;
//   recontact                       x returns to the face σ b/2 it left;
//   impact (eq. 24)                 inelastic: (Jm+JL) θ̇ = Jm θ̇m + JL θ̇L; contact on the
//                                   face hit holds if the torque has its holding sign there,
//                                   else the bodies part again at once (a bounce);
//   rest                            free flight that can never close the gap again and whose
//                                   velocities have decayed below `rest_velocity`.
// Every event time is the first zero of a certified witness (first_crossing.hpp):
// no fixed steps, nothing skipped.  Outcomes that are not errors come back as
// statuses: completed (t_end reached), rest, chattering (Zeno: too many impacts in
// a vanishing time), event_limit, non_finite, unresolved (the motion grew so large that
// double precision no longer resolves the backlash: scales.hpp), work_limit (a certified
// search ran out of its interval budget) — never a hang or a NaN.
// No backlash (b = 0) is a rigid drive (docs/physics.md): the gear transmits a torque of
// either sign, so the bodies never separate and the motion is the contact mode alone.
#pragma once

#include "backlash/numeric/validation.hpp"

#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace backlash::numeric {

/// Events.  The nominal model has the first four; the effects (effects.hpp,
/// docs/effects.md) add sticking and breaking away (Coulomb friction) and the drive
/// entering or leaving its limit (saturation).
enum class EventKind { Separation, Recombination, Recontact, Rest, Stick, Slip, Saturation, Desaturation };
const char* to_string(EventKind kind);

/// Which body a stick/slip event concerns.
enum class Body { None, Motor, Load, Both };
const char* to_string(Body body);

struct HybridState {
  double theta_m = 0, dtheta_m = 0, theta_L = 0, dtheta_L = 0;
  bool in_contact = true;  ///< rigid contact, or (compliance) the mesh engaged
  int face = -1;  ///< σ: contact face x = σ b/2 (contact), or the face last left (free)
  // Effects only (the nominal simulators leave them at their defaults):
  bool motor_stuck = false, load_stuck = false;  ///< Coulomb sticking (a stuck pair in contact: both)
  int drive_regime = 0;  ///< saturation: 0 linear, +1 clipped at +L, −1 clipped at −L
};

struct SimulationEvent {
  double t = 0;
  EventKind kind = EventKind::Separation;
  double theta_o = 0, dtheta_o = 0;  ///< measured shaft, velocity after the event
  HybridState after;
  HybridState before;                ///< (effects engine) the state just before an impact
  bool bounce = false;               ///< impact after which contact did not hold
  bool grazing = false;
  Body body = Body::None;            ///< stick / slip: which body
  bool accumulation = false;         ///< the end of a summed series of bounces (restitution)
};

enum class SimulationStatus { Completed, Rest, Chattering, EventLimit, NonFinite, Unresolved, WorkLimit };
const char* to_string(SimulationStatus status);
/// True for the statuses that end a simulation before t_end without the model having
/// stopped by itself (chattering, event_limit, non_finite, unresolved, work_limit): the
/// result is correct up to t_final and says nothing beyond it.
bool stopped_early(SimulationStatus status);

struct TrajectorySample {
  double t, theta_o, dtheta_o, theta_m, dtheta_m, theta_L, dtheta_L;
  bool in_contact;
};

struct SimulationOptions {
  double t_end = 60;
  double sample_interval = 0;   ///< > 0: record the trajectory at k·sample_interval, k = 0, 1, … (for CSV)
  /// Set: every trajectory sample goes here, in time order, as soon as it is computed, and
  /// SimulationResult::samples stays empty (memory does not grow with the output's length).
  std::function<void(const TrajectorySample&)> sample_sink;
  /// Non-empty: record the trajectory at these times instead (ascending; a measured record's
  /// own grid; times before 0 give the start state, the system at rest before the step).
  std::vector<double> sample_times;
  /// Set: every event goes here as it happens, in time order, and SimulationResult::events
  /// stays empty (memory does not grow with the number of events).  Honoured by simulate() (the
  /// closed-form simulator, which also runs simulate_effects without effects); the simulators
  /// with effects and the odeint ones keep their list.
  std::function<void(const SimulationEvent&)> event_sink;
  long max_events = 100000;     ///< event_limit after this many events (kept or sunk)
  double rest_velocity = 1e-9;  ///< rest when every velocity is below this (and no event can follow)
  int zeno_impacts = 100;       ///< chattering when this many impacts happen within the Zeno window
  /// The Zeno window in seconds; 0: `zeno_time_scales` of the system's fastest time scale
  /// (zeno_window(p, options)), so that the rule means the same for K = 1 and K = 1e12.
  double zeno_window = 0;
  long stop_after_separations = 0;  ///< > 0: stop (status completed) right after this many separations
  /// Set: read right after each separation's event has reached event_sink; true stops the run
  /// there (status completed), as stop_after_separations does — for a sink that decides at an
  /// event whether the run goes on (settle.cpp).  Honoured by simulate().
  const bool* stop_requested = nullptr;
  bool track_extremes = false;      ///< record the exact extremes of θo, θm, θL (zeros of the velocities)
  /// Set (θo in the caller's frame): for a caller that needs only the last sample outside
  /// [low, high] (settle.hpp), the closed-form simulator leaves out samples (counted in
  /// SimulationResult::samples_left_out): all of a segment whose θo at its ends and at its turns
  /// (the zeros of θ̇o, in closed form: hybrid/sample_band.hpp) lies inside the band by a margin
  /// of four times the evaluator's validated tolerance (scaled like the gate's: max(1, |θ|)); of
  /// the other segments, those inside by the margin and those before the segment's last sample
  /// outside by the margin (found from its end backwards), or before a later segment's last
  /// sample when that one is outside by the margin (then this segment is not walked at all).  So the last sample outside the band,
  /// and every sample within the margin of its edges, reach the sink, in time order, each with
  /// its own time, as computed without the band.  Other simulators ignore it.
  struct SampleBand {
    double low, high;
  };
  std::optional<SampleBand> sample_band;
  /// Set: the samples carry t and θo alone (the other fields NaN, in_contact false), for a sink
  /// that reads nothing else (a fit to a record of θo); a closed-form free flight then forms only
  /// the measured shaft's terms, with the bits of the full state's θo.  Honoured by the effects
  /// engine; the other simulators fill every field.
  bool sample_theta_o_only = false;
};

/// Exact extremes over the simulated time: at event states and at the certified
/// zeros of each shaft's velocity inside every segment.
struct Extremes {
  double theta_o_min = INFINITY, theta_o_max = -INFINITY;
  double theta_m_min = INFINITY, theta_m_max = -INFINITY;
  double theta_L_min = INFINITY, theta_L_max = -INFINITY;
};

struct SimulationResult {
  SimulationStatus status = SimulationStatus::Completed;
  std::vector<SimulationEvent> events;
  double t_final = 0;
  HybridState final_state;
  double theta_o_final = 0;
  std::vector<TrajectorySample> samples;  ///< (without a sample_sink)
  Extremes extremes;  ///< when options.track_extremes
  std::string stop_reason;  ///< for an early stop (stopped_early): what happened, in words
  long long samples_left_out = 0;  ///< samples not recorded (SimulationOptions::sample_band)
};

/// The default Zeno window in units of the fastest time scale 1/fastest_mode_rate(p)
/// (scales.hpp): 1e-6 of it is 1e-6 s for the thesis's cases (rates about 1/s).  A hundred
/// impacts within a millionth of the fastest mode's time scale are an accumulation of impacts
/// (Zeno), not a motion the modes resolve; a fixed window in seconds would call the ordinary
/// impacts of a stiff servo (K = 1e12: time scale 1e-6 s) chattering.
inline constexpr double zeno_time_scales = 1e-6;
/// The Zeno window of a run in seconds: options.zeno_window when set (> 0), else
/// zeno_time_scales / fastest_mode_rate(p).
double zeno_window(const Parameters& p, const SimulationOptions& options);
/// The stop reason of a chattering run: the impact count and the window.
std::string zeno_reason(const SimulationOptions& options, double window);
/// The stop reason of a run that reached options.max_events.
std::string event_limit_reason(const SimulationOptions& options);

/// The measured shaft of a state, and its velocity.
double measured(const Parameters& p, const HybridState& s);
double measured_velocity(const Parameters& p, const HybridState& s);

/// Widens `x` to include the angles θo, θm, θL of the state `s`: the one update of the running
/// extremes, for every simulator (bookkeeping only, no dynamics).
void include_extremes(const Parameters& p, const HybridState& s, Extremes& x);

/// Records the trajectory at k·`options.sample_interval` (for CSV output) or at
/// `options.sample_times`, into the result or into options.sample_sink; shared by the
/// closed-form and the odeint simulators (bookkeeping only, no dynamics).  The times are
/// k·interval with an integer k, never a running sum: no drift, and no stall where adding the
/// interval no longer changes t.
class TrajectoryRecorder {
 public:
  TrajectoryRecorder(const Parameters& p, const SimulationOptions& o, SimulationResult& r) : p_(p), o_(o), r_(r) {}
  /// Samples at the global times ≤ t_upto of a segment that starts at t0; `at(τ)` is its state at
  /// τ = t − t0 (a HybridState), or its θo alone (a double: SimulationOptions::sample_theta_o_only).
  template <class At>
  void record(double t0, double t_upto, const At& at) {
    if (!o_.sample_times.empty()) {
      const std::vector<double>& times = o_.sample_times;
      for (; index_ < times.size() && times[index_] <= t_upto; ++index_) push(times[index_], at(std::max(0.0, times[index_] - t0)));
      return;
    }
    if (o_.sample_interval <= 0) return;
    for (double next = static_cast<double>(k_) * o_.sample_interval; next <= t_upto;
         next = static_cast<double>(++k_) * o_.sample_interval)
      push(next, at(next - t0));
  }
  /// Passes over the sample times ≤ t_upto without recording them (SimulationOptions::sample_band).
  void skip(double t_upto) {
    if (!o_.sample_times.empty()) {
      for (; index_ < o_.sample_times.size() && o_.sample_times[index_] <= t_upto; ++index_) ++r_.samples_left_out;
      return;
    }
    if (o_.sample_interval <= 0) return;
    for (; static_cast<double>(k_) * o_.sample_interval <= t_upto; ++k_) ++r_.samples_left_out;
  }
  /// The test of SimulationOptions::sample_band in a run's frame: θo in [low, high], decided
  /// only outside a `margin` about its edges (hybrid_simulation.hpp, SampleBand).
  struct BandTest {
    double low, high, margin;
    /// θo perhaps outside the band: not inside it by the margin (a sample to keep).
    bool may_be_outside(double theta_o) const { return !(theta_o >= low + margin && theta_o <= high - margin); }
    /// θo certainly outside the band: outside it by the margin (no earlier sample is needed).
    bool outside(double theta_o) const { return theta_o < low - margin || theta_o > high + margin; }
  };
  /// The most turns of θo a pending segment keeps (defer_last_outside).
  static constexpr int kMaxTurns = 8;
  /// record() for a caller that needs only the last θo outside a band (SimulationOptions::sample_band):
  /// the segment's samples from its last backwards, keeping those that may be outside
  /// (BandTest::may_be_outside) and stopping at the first certainly outside (BandTest::outside);
  /// the kept ones are recorded in time order, the others counted as left out.  Deferred (issue 19):
  /// only the last sample now; the walk waits, `at` kept, until a later segment's last sample is
  /// certainly outside (then the samples before it are not needed: all left out) or the run ends
  /// (flush).  `turns`: the times τ in (0, t_upto − t0) where the segment's θo may turn, ascending
  /// (`turn_count` of them, < 0: not known, or more than kMaxTurns): between them θo is monotone,
  /// which the walk uses (walk_back).  With sample_times: record().
  template <class At>
  void defer_last_outside(double t0, double t_upto, const At& at, const BandTest& band, const double* turns = nullptr,
                          int turn_count = -1) {
    if (!o_.sample_times.empty() || o_.sample_interval <= 0) return record(t0, t_upto, at);
    const long long first = k_;
    while (static_cast<double>(k_) * o_.sample_interval <= t_upto) ++k_;
    if (k_ == first) return;
    const double t = static_cast<double>(k_ - 1) * o_.sample_interval;
    const HybridState end = at(t - t0);
    if (!band.outside(measured(p_, end))) return defer(first, t0, end, at, band, turns, turn_count);
    for (const Pending& p : pending_) r_.samples_left_out += p.end - p.first;
    pending_.clear();
    r_.samples_left_out += k_ - 1 - first;
    if (band.may_be_outside(measured(p_, end))) push(t, end);
  }
  /// The walks defer_last_outside left pending, newest first, to the first sample certainly
  /// outside; every one of the run's samples is then recorded or counted as left out.
  void flush(const BandTest& band);

 private:
  void push(double t, double theta_o) {  // SimulationOptions::sample_theta_o_only
    emit({t, theta_o, NAN, NAN, NAN, NAN, NAN, false});
  }
  void push(double t, const HybridState& h) {
    emit({t, measured(p_, h), measured_velocity(p_, h), h.theta_m, h.dtheta_m, h.theta_L, h.dtheta_L, h.in_contact});
  }
  void emit(const TrajectorySample& sample) {
    if (o_.sample_sink) o_.sample_sink(sample);
    else r_.samples.push_back(sample);
  }
  const Parameters& p_;
  const SimulationOptions& o_;
  SimulationResult& r_;
  long long k_ = 0;
  std::size_t index_ = 0;
  std::vector<std::pair<double, HybridState>> kept_;  // flush's, reused
  struct Pending {  // a segment's samples k in [first, end) waiting for flush
    long long first, end;
    double t0;
    HybridState last;  // at(end − 1), already computed
    std::function<HybridState(double)> at;
    std::array<double, kMaxTurns> turns;  // where θo may turn (defer_last_outside), ascending
    int turn_count;                       // < 0: not known
  };
  std::vector<Pending> pending_;
  // The segment's samples [first, k_) made pending (out of line, with walk_back: the closed-form
  // event loop's code is not the band's, issue 19).
  [[gnu::noinline]] void defer(long long first, double t0, const HybridState& last, std::function<HybridState(double)> at,
                               const BandTest& band, const double* turns, int turn_count);
  // One pending segment's samples from its last backwards (trajectory_recorder.cpp); true at the
  // first certainly outside.
  bool walk_back(const Pending& p, const BandTest& band);
};

/// The state with the measured shaft at θo, both shafts moving at `velocity`, and the
/// gap at the face σ (x = σ b/2): in contact on it, or just leaving it.
HybridState state_on_face(const Parameters& p, int face, double theta_o, double velocity, bool in_contact);

/// Start at rest, in contact on the face that drives toward θR, with θo = θR − step.
HybridState step_start(const Parameters& p, double step);

/// A start state made rigid for b = 0: in contact on its face, the two velocities merged by
/// the impact law (eq. 24) when they differ.  Other states are returned unchanged.
HybridState rigid_start(const Parameters& p, const HybridState& start);

/// True for a free state strictly inside the backlash: |x| < b/2 for the gap x = θL − θm beyond
/// its rounding 1e-12·max(b/2, |θm|, |θL|) (a state within it is on the face x = ±b/2).
bool inside_backlash(const Parameters& p, const HybridState& s);

/// The closed-form run from `start`.  A free start leaves its face σ (the face last left), or —
/// inside_backlash — starts strictly inside: its first flight ends at the first arrival of the gap
/// at either face, found by the same certified search as a flight from a face (docs/physics.md,
/// "Gap, faces, events"): a recontact on σ (for a start inside: the nearer face, x > 0: +b/2),
/// a recombination on −σ.
SimulationResult simulate(const ValidatedEvaluator& evaluator, const HybridState& start, const SimulationOptions& options);
SimulationResult simulate_step(const ValidatedEvaluator& evaluator, double step, const SimulationOptions& options);

/// How many sets of a run's parameter-set constants (the contact and free segments, the witnesses'
/// WitnessMode constants) this process has built: simulate() builds them once per thread and
/// parameter set, not per run (issue 19: once per map point for its ~5 runs).  A count for tests
/// and benchmarks.
long run_constants_built();

}  // namespace backlash::numeric
