// The closed-form hybrid simulator with effects (effects_simulation.hpp,
// docs/effects.md): each segment is a mode's closed-form flow (effect_modes.cpp)
// and the first certified exit among its witnesses; the event loop, the static
// rules and the impacts are the engine's (effects_engine.cpp).
#include "backlash/numeric/effects_simulation.hpp"

#include "effects/effects_engine.hpp"
#include "hybrid/certified_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

namespace backlash::numeric {

namespace {

using detail::Exit;
using detail::Functional;
using detail::Guard;
using detail::Witness;

Functional of(const ModeFlow::Functional& f) { return {f.row, f.constant, f.magnitude, 0}; }

// The closed-form mode's coordinates as functionals: θo − θR, the gap, and the drive folded in.
detail::ModeFunctionals functionals_of(const Parameters& p, const Effects& e, const ModeFlow& flow, int left_zone) {
  detail::ModeFunctionals f;
  f.left_zone = left_zone;
  f.theta_o_error = of(flow.theta_o_error());
  f.gap = of(flow.gap_functional());
  f.dimension = static_cast<int>(flow.segment().A.rows());
  if (flow.mode().regime == 0)
    f.drive = f.theta_o_error.scaled(-p.K).shifted(drive_constant(e, 0));
  else
    f.drive = Functional{SmallRow::Zero(f.dimension), drive_constant(e, flow.mode().regime), drive_constant_bound(e), 0};
  return f;
}

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// A witness on its boundary at τ = 0 leaves it toward w > 0 (its first derivative that is not
// rounding noise is positive): the largest τ0 = horizon/2^i where the Taylor lower bound
//   w(τ) ≥ w_K τ^K/K! − Σ_{j<K} |w_j| τ^j/j! − sup|w^{(K+1)}| τ^{K+1}/(K+1)!
// is positive, sup|w^{(K+1)}| ≤ ‖e A^K‖₁ e^{‖A‖τ} ‖ż(0)‖∞.  0 when none is found.
// e A^K and ‖A‖∞ are the witness's mode's own (WitnessMode: eA = e·A, eA2 = eA·A, eA3 = eA2·A and
// ‖A‖∞ formed as here, the same bits), not formed again per departure.
double departure_time(const WitnessMode& mode, const SmallVector& zdot0, const std::array<double, 4>& w, int K,
                      double horizon) {
  const std::array<const SmallRow*, 4> rows{&mode.e, &mode.eA, &mode.eA2, &mode.eA3};  // e A^K
  const SmallRow& eAK = *rows[static_cast<std::size_t>(K)];
  const double norm_A = mode.norm_A_plain, norm_z = zdot0.cwiseAbs().maxCoeff();
  const double norm_eAK = K == 1 ? mode.norm_eA : eAK.cwiseAbs().sum();
  double tau = horizon;
  int i = 0;
  // The remainder's term alone (e^{‖A‖τ} ≥ 1) is at least twice the leading one, so the bound is
  // negative, while τ > 4(K+1)·w_K/(‖e A^K‖₁‖ż(0)‖∞) (twice that far, for the rounding): those τ are
  // passed over without evaluating it (the departure is found on the mode's own time scale, not
  // by halving down from the horizon; the same τ as halving, which is exact).
  const double remainder_rate = norm_eAK * norm_z;
  if (remainder_rate > 0 && std::isfinite(remainder_rate)) {
    const double beyond = 4 * (K + 1) * w[K] / remainder_rate;
    for (; i < 400 && tau > 0 && tau > beyond; ++i) tau *= 0.5;
  }
  for (; i < 400 && tau > 0; ++i, tau *= 0.5) {
    std::array<double, 5> power{1, tau, tau * tau, tau * tau * tau, tau * tau * tau * tau};
    double lower = w[K] * power[K] / factorial(K) -
                   norm_eAK * std::exp(norm_A * tau) * norm_z * power[K + 1] / factorial(K + 1);
    for (int j = 0; j < K; ++j) lower -= std::fabs(w[j]) * power[j] / factorial(j);
    if (lower > 0) return tau;
  }
  return 0;
}

// r·x and |r|·|x| for the modes' sizes, unrolled with Eigen's own order of operations for a
// dynamic dot product (pairwise for 4: (r0x0 + r2x2) + (r1x1 + r3x3)), so the same bits as
// r.dot(x) without its loop; Eigen for other sizes.
double dot(const SmallRow& r, const SmallVector& x) {
  if (r.size() == 4 && x.size() == 4) return (r(0) * x(0) + r(2) * x(2)) + (r(1) * x(1) + r(3) * x(3));
  if (r.size() == 2 && x.size() == 2) return r(0) * x(0) + r(1) * x(1);
  return r.dot(x.transpose());
}
double abs_dot(const SmallRow& r, const SmallVector& x) {
  const auto a = [](double v) { return std::fabs(v); };
  if (r.size() == 4 && x.size() == 4)
    return (a(r(0)) * a(x(0)) + a(r(2)) * a(x(2))) + (a(r(1)) * a(x(1)) + a(r(3)) * a(x(3)));
  if (r.size() == 2 && x.size() == 2) return a(r(0)) * a(x(0)) + a(r(1)) * a(x(1));
  return r.cwiseAbs().dot(x.cwiseAbs().transpose());
}

enum class StartKind { Inside, ExitNow, Never };
struct Start {
  StartKind kind = StartKind::Inside;
  double from = 0;
  bool departs = false;  ///< on the boundary, leaving toward w > 0, certified w(from) > 0 (departure_time)
};

// The start's rate ż(0) = A z0 + c, the same for every witness of a segment, and the size of the
// terms that form it, |A|(|z0| + z0's rounding) + c's terms (its rounding scale): formed once per
// segment, the latter only when a witness starts on its boundary (classify_start).
class SegmentStartRate {
 public:
  explicit SegmentStartRate(const ModeFlow& flow)
      : flow_(flow), zdot_(flow.segment().A * flow.local_start() + flow.segment().c) {}
  const SmallVector& zdot() const { return zdot_; }
  const SmallVector& scale() const {
    if (!scaled_) {
      scale_ = flow_.segment().A.cwiseAbs() * (flow_.local_start().cwiseAbs() + flow_.local_start_noise()) +
               flow_.forcing_magnitude();
      scaled_ = true;
    }
    return scale_;
  }

 private:
  const ModeFlow& flow_;
  SmallVector zdot_;
  mutable SmallVector scale_;
  mutable bool scaled_ = false;
};

// Where the search for a witness's exit starts.  Rounding scales come from the size of the
// terms that formed each quantity (a deviation or a forcing can cancel): w(0) is on its
// boundary when within the rounding of its terms, or within what the previous event's time
// tolerance (toms748: 1e-14 of t) moves it; a derivative is noise below 1e-9 of its terms'.
// (A looser on-boundary rule — 1e-11 of the terms — took a real 1e-11 gap for a contact.)
// On the boundary, the first derivative that is not noise decides: leaving the valid side is
// an exit at once, entering it starts the search after a certified departure time.
// The witness's mode holds eᵀA, eᵀA² (the products formed here, the same bits), so they are not
// formed again; the higher derivatives and their rounding scales only on the boundary.
// `rates`: the start's rate and its rounding scale, the same for every witness of the segment.
// w^{(K)} and its scale are formed for K up to the first that decides (the same bits as all of them).
Start classify_start(const ModeFlow& flow, const WitnessMode& mode, double level, const SegmentStartRate& rates,
                     double magnitude, double horizon, double t_global) {
  const SmallVector& zdot = rates.zdot();
  const SmallVector& z0 = flow.local_start();
  const SmallVector& z0_noise = flow.local_start_noise();
  const SmallRow& e = mode.e;
  std::array<double, 4> w{};
  w[0] = dot(e, z0) - level;
  w[1] = dot(e, zdot);
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double tolerance = 64 * eps * (abs_dot(e, z0) + magnitude) + 32 * abs_dot(e, z0_noise) +
                           std::fabs(w[1]) * 4e-14 * std::max(1.0, std::fabs(t_global));
  if (w[0] > tolerance) return {StartKind::Inside, 0};
  if (w[0] < -tolerance) return {StartKind::ExitNow, 0};
  const std::array<const SmallRow*, 4> rows{nullptr, &e, &mode.eA, &mode.eA2};  // e A^{k−1} for w^{(k)}
  for (int K = 1; K <= 3; ++K) {
    if (K > 1) w[K] = rows[K]->dot(zdot);
    const double scale = rows[K]->cwiseAbs().dot(rates.scale().transpose());
    if (std::fabs(w[K]) <= 1e-9 * scale) continue;
    if (w[K] < 0) return {StartKind::ExitNow, 0};
    const double from = departure_time(mode, zdot, w, K, horizon);
    if (from > 0) return {StartKind::Inside, from, true};
    return {StartKind::Inside, std::min(horizon, 1e-12 * std::max(1.0, horizon))};
  }
  return {StartKind::Never, 0};
}

bool grazing_is_event(Guard g) { return g == Guard::GapOpposite || g == Guard::GapSame; }

// The rounding-level rule of the nominal simulators: a zero of Tc where the contact motion has
// decayed to rounding level about its equilibrium is not a separation.
bool spurious_separation(const Parameters& p, const ModeFlow& flow, double tau) {
  const Mode& m = flow.mode();
  if (m.kind != ModeKind::Contact || m.regime != 0) return false;
  const SmallVector z = flow.local(tau);
  const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(p.theta_R));
  return std::fabs(z(0)) <= noise && std::fabs(z(1)) <= noise * std::sqrt(p.K / (p.Jm + p.JL));
}

}  // namespace

// Only c, eᵀc, eᵀA c and eᵀA² c depend on the forcing c (which moves with the start: the drive
// folded in): WitnessMode::set_forcing; the others (eᵀA^k, the balancing, μ∞, the norms) come
// from A and e alone.  Exact comparison of A and e.  Building the
// constants per search was a third of a closed-form segment's cost (issue 19).  The entry kept
// for (A, e) is given the forcing c and returned as it is.  The least recently used entry is the
// one replaced, so an entry stays where it is (and keeps its forcing) for the next capacity − 1
// calls on this thread: a segment's searches (a few witnesses) hold their entries by reference.
// A segment's witnesses share A: A is compared once per segment (kept_mode_group), each entry
// carrying the group of its A's value, and a witness's entry is found by its group and e.
namespace {

// x == y element by element (exact, as Eigen's ==: +0 == −0, a NaN equals nothing): for the
// modes' sizes (4 × 4, 2 × 2 and their rows) every element compared without a branch (vector
// compares), otherwise stopping at the first difference.
template <int N>
bool same_values_of(const double* x, const double* y) {
  bool same = true;
  for (int i = 0; i < N; ++i) same &= x[i] == y[i];
  return same;
}
bool same_values(const double* x, const double* y, Eigen::Index n) {
  if (n == 16) return same_values_of<16>(x, y);
  if (n == 4) return same_values_of<4>(x, y);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!(x[i] == y[i])) return false;
  return true;
}

struct KeptModes {
  static constexpr std::size_t capacity = 32;
  struct Entry {
    WitnessMode mode;
    std::uint64_t used;
    std::uint64_t group;  // every entry of a group has the same A (==); groups are never reused
  };
  KeptModes() { entries.reserve(capacity); }
  std::vector<Entry> entries;
  std::uint64_t clock = 0, groups = 0;
  std::size_t last = 0;  // the entry found or made by the last call
};

KeptModes& kept_modes() {
  thread_local KeptModes kept;
  return kept;
}

}  // namespace

std::uint64_t detail::kept_mode_group(const SmallMatrix& A) {
  KeptModes& kept = kept_modes();
  std::uint64_t other = 0;  // a group whose A is not A (no group is 0): a group's entries are mostly made together
  for (const KeptModes::Entry& entry : kept.entries) {
    if (entry.group == other) continue;
    if (entry.mode.A.rows() == A.rows() && entry.mode.A.cols() == A.cols() &&
        same_values(entry.mode.A.data(), A.data(), A.size()))
      return entry.group;
    other = entry.group;
  }
  return ++kept.groups;  // A's value is in no entry: a new group
}

const WitnessMode& detail::kept_witness_mode(std::uint64_t group, const SmallMatrix& A, const SmallVector& c,
                                             const SmallRow& e) {
  KeptModes& kept = kept_modes();
  std::vector<KeptModes::Entry>& cache = kept.entries;
  ++kept.clock;
  const auto same = [&](const KeptModes::Entry& entry) {
    return entry.group == group && entry.mode.e.size() == e.size() && same_values(entry.mode.e.data(), e.data(), e.size());
  };
  const auto found = [&](std::size_t i) -> const WitnessMode& {
    cache[i].mode.set_forcing(c);
    cache[i].used = kept.clock;
    kept.last = i;
    return cache[i].mode;
  };
  // At most one entry matches (one is made only when none does), so the order the entries are
  // tried in does not change the answer: the one after the last found first (a mode's witnesses
  // come in the same order each time it is entered, and their entries were made in that order).
  if (kept.last + 1 < cache.size() && same(cache[kept.last + 1])) return found(kept.last + 1);
  for (std::size_t i = 0; i < cache.size(); ++i)
    if (same(cache[i])) return found(i);
  if (cache.size() < KeptModes::capacity) {
    cache.push_back({WitnessMode(A, c, e), kept.clock, group});
    kept.last = cache.size() - 1;
    return cache.back().mode;
  }
  const auto oldest = std::min_element(cache.begin(), cache.end(), [](const auto& a, const auto& b) { return a.used < b.used; });
  *oldest = {WitnessMode(A, c, e), kept.clock, group};
  kept.last = static_cast<std::size_t>(oldest - cache.begin());
  return oldest->mode;
}

const WitnessMode& detail::kept_witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e) {
  return kept_witness_mode(kept_mode_group(A), A, c, e);
}

WitnessMode detail::witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e) {
  return kept_witness_mode(A, c, e);
}

namespace {

// The closed-form samples of one segment, shared by its witnesses' searches: every witness is
// searched over the same windows, each search's windows start where its last one ended, and the
// first window is the mode's own (WitnessMode::first_window: A alone), so the same τ is asked for
// again and again.  Evaluations are kept and given again (an exact match of τ's bits: the same τ
// gives the same bits), each in the slot its τ's bits hash to (one comparison per look-up; a
// later τ with the same slot replaces it, which costs only an evaluation again).
class SampleMemo {
 public:
  explicit SampleMemo(const ModeFlow& flow) : flow_(flow) {}
  const SmallVector& local(double tau) const {
    std::uint64_t key;
    std::memcpy(&key, &tau, sizeof key);
    const auto at = static_cast<unsigned>(((key ^ (key >> 32)) * 0x9E3779B97F4A7C15ull) >> (64 - bits));
    const unsigned bit = 1u << at;
    if ((filled_ & bit) && keys_[at] == key) return z_[at];
    filled_ |= bit;
    keys_[at] = key;
    z_[at] = flow_.local(tau);
    return z_[at];
  }

 private:
  static constexpr int bits = 5, capacity = 1 << bits;
  const ModeFlow& flow_;
  mutable std::array<std::uint64_t, capacity> keys_;
  mutable std::array<SmallVector, capacity> z_;
  mutable unsigned filled_ = 0;  // the slots that hold an evaluation
};

// The certified search for one witness's first exit, advanced window by window.
class ExitSearch {
 public:
  ExitSearch(const Parameters& p, const ModeFlow& flow, const SampleMemo& memo, const SegmentStartRate& rates,
             std::uint64_t group, const Witness& witness, double horizon, double t_global)
      : p_(p), flow_(flow), memo_(memo), witness_(witness) {
    level_ = -witness.f.constant;
    // The search on a mode built once (kept per thread: its entry stays put while this segment's
    // searches run) is the LinearWitness search, bit for bit — with a stiff bound (the mesh modes)
    // as without one: the search's constants are WitnessMode(A, c, e) either way, so they are not
    // built again for each window of each witness (issue 19: the mesh's searches).
    bound_ = flow.derivative_bound(witness.f.row, 3);
    mode_ = &detail::kept_witness_mode(group, flow.segment().A, flow.segment().c, witness.f.row);
    const Start start = classify_start(flow, *mode_, level_, rates, witness.f.magnitude, horizon, t_global);
    if (start.kind == StartKind::Never) finished_ = true;
    if (start.kind == StartKind::ExitNow) immediate_ = true;
    from_ = start.from;
    departs_ = start.departs;
  }

  bool immediate() const { return immediate_; }
  /// The witness's rate w'(τ) = eᵀA z(τ) + eᵀc is positive beyond the closed form's rounding
  /// (kSampleNoise of its terms, as the search's own allowance): the exact rate is positive too.
  bool rising_at(double tau) const {
    const SmallVector& z = memo_.local(tau);
    const double rate = dot(mode_->eA, z) + mode_->ec;
    return rate > detail::kSampleNoise * (abs_dot(mode_->eA, z) + std::fabs(mode_->ec));
  }
  /// The search passed up to `until` without asking it, where it is known to find nothing.
  void pass_until(double until) {
    if (!finished_ && from_ < until) from_ = until;
  }
  /// The witness starts on its boundary and leaves it toward w > 0, w(τ) > 0 certified where its
  /// search starts (classify_start).
  bool departs() const { return departs_; }

  /// The first exit in (from, until], or nothing there (the search then resumes at `until`).
  std::optional<Exit> search_until(double until) {
    while (!finished_ && from_ < until) {
      const std::optional<Crossing> crossing = search(until);
      if (!crossing) {
        from_ = until;
        return std::nullopt;
      }
      const bool spurious = witness_.guard == Guard::ContactTorque && spurious_separation(p_, flow_, crossing->t);
      if (spurious && !crossing->grazing) {  // the contact motion has decayed to rounding: contact holds to the end
        finished_ = true;
        return std::nullopt;
      }
      if (!spurious && (!crossing->grazing || grazing_is_event(witness_.guard)))
        return Exit{crossing->t, witness_, crossing->grazing};
      from_ = crossing->t + 1e-12 * std::max(1.0, crossing->t);
    }
    return std::nullopt;
  }

 private:
  std::optional<Crossing> search(double until) const {
    // The memo's state itself, not a copy (the same bits as WitnessSample's).
    struct StateSample {
      const SmallVector& x;
      double value;
    };
    const auto sample = [this](double tau) {
      const SmallVector& x = memo_.local(tau);
      return StateSample{x, dot(mode_->e, x)};
    };
    return detail::search(detail::Sampler<decltype(sample)>(*mode_, sample, level_), bound_ ? &bound_ : nullptr, from_,
                          until, CrossingOptions{});
  }
  const Parameters& p_;
  const ModeFlow& flow_;
  const SampleMemo& memo_;
  Witness witness_;
  double level_ = 0;
  std::function<double(double, double)> bound_;  // the stiff flow's bound on |w'''| (mesh modes), or empty
  const WitnessMode* mode_ = nullptr;  // the witness's constants
  double from_ = 0;
  bool finished_ = false, immediate_ = false, departs_ = false;
};

// Whether a free flight's return to the face left is not searched where it is proved to find
// nothing (detail::OneTurn, first_exit_one_turn): the mode's gap rate has at most two real zeros
// (free_gap_turns_once), one of them the start (both bodies at one velocity in the flow's own
// start, so the gap rate is exactly 0 there), and the flight leaves the face toward the opposite
// one; the opposite face's guard is searched first in every window (docs/effects.md).
bool one_turn_applies(detail::OneTurn one_turn, const Parameters& p, const Effects& e, const ModeFlow& flow,
                      const std::vector<Witness>& witnesses, const std::vector<ExitSearch>& searches) {
  if (one_turn == detail::OneTurn::Off || witnesses.size() < 2) return false;
  if (witnesses[0].guard != Guard::GapOpposite || witnesses[1].guard != Guard::GapSame || !searches[1].departs())
    return false;
  if (one_turn == detail::OneTurn::Forced) return true;
  const SmallVector& z0 = flow.local_start();  // (Δm, θ̇m, ΔL, θ̇L)
  return detail::free_gap_turns_once(p, e, flow.mode()) && z0(1) == z0(3);
}

// The first exit of a free flight whose gap turns at most once (one_turn_applies), as the
// segment's loop over the windows finds it (ClosedFormSegment), the windows in the loop's order:
// searches[0], the opposite face's guard, first; the return's guard searches[1] is not asked where
// it is proved to find nothing (docs/effects.md, "A flight whose gap turns at most once") — in
// the window where the opposite face is crossed (every range it would be asked lies before the
// crossing), and in a window at whose end its witness still rises (the gap has not turned yet).
[[gnu::noinline]] std::optional<Exit> first_exit_one_turn(std::vector<ExitSearch>& searches, double horizon,
                                                          double first_window) {
  std::optional<Exit> exit;
  double window = first_window;
  for (double a = 0; a < horizon && !exit; a += window, window *= 2) {
    const double b = std::min(horizon, a + window);
    exit = searches[0].search_until(b);
    if (!exit) {
      if (searches[1].rising_at(b)) searches[1].pass_until(b);
      else exit = searches[1].search_until(b);
    }
    for (std::size_t i = 2; i < searches.size(); ++i) {
      const std::optional<Exit> candidate = searches[i].search_until(exit ? exit->tau : b);
      if (candidate && (!exit || candidate->tau < exit->tau)) exit = candidate;
    }
  }
  return exit;
}

class ClosedFormSegment final : public detail::Segment {
 public:
  ClosedFormSegment(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start, double horizon,
                    double t_global, int left_zone, const std::vector<Witness>& extra = {},
                    detail::OneTurn one_turn = detail::OneTurn::Proved)
      : params_(p), flow_(p, e, m, start) {
    duration = horizon;
    if (m.kind == ModeKind::Contact ? m.slip_motor == 0 : (m.slip_motor == 0 && m.slip_load == 0)) {
      rest = true;  // everything stuck and no delay: the drive cannot change
      return;
    }
    // Every witness searched window by window, the windows doubling from an eighth of the servo
    // period: the search stops at the first window that holds an exit, never far beyond it.
    // The witnesses and their searches in storage kept per thread (no allocation per segment); a
    // segment's searches are all done here, before the next segment is built.
    thread_local std::vector<Witness> witnesses;
    thread_local std::vector<ExitSearch> searches;
    searches.clear();
    detail::mode_witnesses(p, e, m, functionals_of(p, e, flow_, left_zone), true, witnesses);
    witnesses.insert(witnesses.end(), extra.begin(), extra.end());
    const SampleMemo memo(flow_);
    const SegmentStartRate rates(flow_);  // ż(0), and its rounding scale when a witness starts on its boundary
    searches.reserve(witnesses.size());
    const std::uint64_t group = detail::kept_mode_group(flow_.segment().A);  // the witnesses' A, compared once
    for (const Witness& w : witnesses) {
      searches.emplace_back(p, flow_, memo, rates, group, w, horizon, t_global);
      if (searches.back().immediate()) {
        duration = 0;
        if (w.guard != Guard::Handover) exit = Exit{0, w, false};  // a handover at once: an empty segment
        return;
      }
    }
    double window = std::min(horizon, 0.125 * servo_period(p));
    if (one_turn_applies(one_turn, p, e, flow_, witnesses, searches)) exit = first_exit_one_turn(searches, horizon, window);
    for (double a = 0; a < horizon && !exit; a += window, window *= 2) {
      const double b = std::min(horizon, a + window);
      for (ExitSearch& search : searches) {
        const std::optional<Exit> candidate = search.search_until(exit ? exit->tau : b);
        if (candidate && (!exit || candidate->tau < exit->tau)) exit = candidate;
      }
    }
    if (exit) duration = exit->tau;
    if (exit && exit->witness.guard == Guard::Handover) exit.reset();  // the segment ends there, the mode goes on
  }

  HybridState state(double tau) const override { return flow_.state(tau); }
  double measured_at(const Parameters&, double tau) const override { return flow_.measured_at(tau); }

  // The exact extremes: the ends and the certified zeros of each moving velocity.
  void extremes(double until, Extremes& x) const override {
    include(flow_.state(0), x);
    include(flow_.state(until), x);
    const Mode& m = flow_.mode();
    std::vector<ModeFlow::Functional> velocities;
    if (m.slip_motor != 0) velocities.push_back(flow_.motor_velocity());
    if (m.kind != ModeKind::Contact && m.slip_load != 0) velocities.push_back(flow_.load_velocity());
    for (const ModeFlow::Functional& v : velocities) {
      LinearWitness w;
      w.A = flow_.segment().A;
      w.c = flow_.segment().c;
      w.e = v.row;
      w.level = -v.constant;
      w.state = [this](double tau) { return flow_.local(tau); };
      w.third_derivative_bound = flow_.derivative_bound(w.e, 3);
      double from = 0;
      for (int k = 0; k < 10000 && from < until; ++k) {
        const auto zero = first_crossing(w, from, until);
        if (!zero) break;
        include(flow_.state(zero->t), x);
        from = zero->t + 1e-12 * std::max(1.0, zero->t);
      }
    }
  }

 private:
  void include(const HybridState& h, Extremes& x) const { include_extremes(params_, h, x); }
  Parameters params_;
  ModeFlow flow_;
};

class ClosedFormEngine final : public detail::Engine {
 public:
  using Engine::Engine;

 protected:
  double drive_now() const override {
    return drive_torque_in_regime(p_, e_, measured(p_, state_), state_.drive_regime);
  }
  std::unique_ptr<detail::Segment> next_segment(const Mode& mode, double remaining) override {
    return std::make_unique<ClosedFormSegment>(p_, e_, mode, state_, remaining, t_, left_zone());
  }
};

}  // namespace

std::unique_ptr<detail::Segment> detail::closed_form_segment(const Parameters& p, const Effects& e, const Mode& m,
                                                             const HybridState& start, double horizon,
                                                             double t_global, int left_zone,
                                                             const std::vector<Witness>& extra, detail::OneTurn one_turn) {
  return std::make_unique<ClosedFormSegment>(p, e, m, start, horizon, t_global, left_zone, extra, one_turn);
}

SimulationResult simulate_effects(const ValidatedEffectModel& model, const HybridState& start,
                                  const SimulationOptions& options, const EffectsEngineOptions& engine) {
  const Effects& e = model.effects();
  if (!e.any() && !engine.general_engine) return simulate(model.nominal(), start, options);
  if (e.stribeck()) return detail::simulate_stribeck(model.parameters(), e, start, options, engine);
  if (e.delayed()) return detail::simulate_delayed(model.parameters(), e, start, options, engine);
  return ClosedFormEngine(model.parameters(), e, options, engine).run(start);
}

SimulationResult simulate_effects_step(const ValidatedEffectModel& model, double step, const SimulationOptions& options,
                                       const EffectsEngineOptions& engine) {
  return simulate_effects(model, effects_step_start(model.parameters(), model.effects(), step), options, engine);
}

}  // namespace backlash::numeric
