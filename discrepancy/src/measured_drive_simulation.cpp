#include "backlash/discrepancy/measured_drive_simulation.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace backlash::discrepancy {

namespace {

constexpr const char* who = "simulate_measured_drive: ";

// A double as its shortest round-trip text (0.4, not 0.40000000000000002).
struct Shortest {
  double value;
};
std::ostream& operator<<(std::ostream& out, Shortest s) {
  std::array<char, 32> text{};
  const auto end = std::to_chars(text.data(), text.data() + text.size(), s.value).ptr;
  return out.write(text.data(), end - text.data());
}
template <class Part>
auto printable(const Part& part) {
  if constexpr (std::is_same_v<Part, double>)
    return Shortest{part};
  else
    return part;
}

template <class... Parts>
[[noreturn]] void refuse(const char* prefix, const Parts&... parts) {
  std::ostringstream out;
  out << prefix;
  (out << ... << printable(parts));
  throw std::invalid_argument(out.str());
}

// 1/(j+2)!, j = 0…10: the series of φ2.
constexpr std::array<double, 11> phi2_coefficients = [] {
  std::array<double, 11> c{};
  double f = 2;  // 2!
  for (int j = 0; j < 11; ++j) {
    c[j] = 1.0 / f;
    f *= j + 3;
  }
  return c;
}();

struct Kernels {
  double exp_z, phi1, phi2;
};

// e^z, φ1(z), φ2(z) for z ≤ 0 (z = −F·h/J; −∞ gives 0, 0, 0).  |z| < 1/8: φ2 by its
// series (8 terms to 2^-56 for |z| ≤ 1/64, else 11), φ1 = 1 + zφ2, e^z = 1 + zφ1; above:
// one libm call, φ2 = (φ1 − 1)/z (at most a factor 16 of cancellation).
Kernels kernels(double z) {
  if (z > -0.125) {
    const int terms = z >= -1.0 / 64 ? 8 : 11;
    double phi2 = phi2_coefficients[terms - 1];
    for (int j = terms - 2; j >= 0; --j) phi2 = phi2 * z + phi2_coefficients[j];
    const double phi1 = 1.0 + z * phi2;
    return {1.0 + z * phi1, phi1, phi2};
  }
  double e, em1;
  if (z < -1.0) {
    e = std::exp(z);
    em1 = e - 1.0;
  } else {
    em1 = std::expm1(z);
    e = em1 + 1.0;
  }
  const double phi1 = em1 / z;
  return {e, phi1, (phi1 - 1.0) / z};
}

class Simulation {
 public:
  Simulation(const RigidDrive& m, MeasuredDriveRun& run, std::size_t max_events)
      : J_(m.J), rate_(m.F / m.J), Tc_(m.coulomb), run_(run), max_events_(max_events) {}

  double x = 0, v = 0;
  bool stuck = false;
  int came_from = 0;  ///< with v == 0 and not stuck: the direction of the motion that ended (0: from rest)

  /// Advances over [t0, t0 + h) under the net drive a.
  void piece(double a, double t0, double h) {
    if (!(h > 0)) return;
    if (Tc_ == 0) {  // no sticking: v passes through 0, no events
      move(a / J_, h);
      return;
    }
    for (;;) {  // at most two passes: a zero inside the piece ends the first one
      int s;
      if (v == 0) {
        if (std::fabs(a) <= Tc_) {
          if (!stuck && came_from != 0) record(t0, DriveEventKind::Stick);
          stuck = true;
          return;
        }
        s = a > 0 ? 1 : -1;
        if (stuck || came_from == 0)
          record(t0, DriveEventKind::Slip);
        else if (s != came_from)
          record(t0, DriveEventKind::Reversal);
        stuck = false;
        came_from = 0;
      } else {
        s = v > 0 ? 1 : -1;
      }
      const double q = (a - Tc_ * s) / J_;  // the acceleration at v = 0 (and the forcing c/J)
      if (q * s < 0) {                      // decelerating: the velocity reaches 0 at h*
        const double h_zero = time_to_zero(q);
        if (h_zero < h) {
          move(q, h_zero);
          v = 0;
          came_from = s;
          t0 += h_zero;
          h -= h_zero;
          continue;
        }
      }
      move(q, h);
      if (v * s <= 0) {  // the zero falls on the piece's end within rounding (or v underflowed)
        v = 0;
        came_from = s;
      }
      return;
    }
  }

 private:
  void move(double q, double h) {
    const Kernels k = kernels(-rate_ * h);
    x += h * (v * k.phi1 + q * h * k.phi2);
    v = v * k.exp_z + q * h * k.phi1;
  }

  // v(h) = 0 for v·q < 0: h* = (1/k)·log1p(k·w), w = −v/q, as w·log1p(kw)/(kw) (→ w for F → 0).
  double time_to_zero(double q) const {
    const double w = -v / q;
    if (!(w < std::numeric_limits<double>::infinity())) return w;  // q underflowed: never
    const double kw = rate_ * w;
    if (kw == 0) return w;
    if (std::isinf(kw)) return (std::log(rate_) + std::log(w)) / rate_;
    return w * (std::log1p(kw) / kw);
  }

  void record(double t, DriveEventKind kind) {
    if (run_.events.size() < max_events_) run_.events.push_back({t, kind, x});
    ++run_.event_count;
  }

  double J_, rate_, Tc_;
  MeasuredDriveRun& run_;
  std::size_t max_events_;
};

void check_model(const RigidDrive& m) {
  auto finite = [](const char* name, double value) {
    if (!std::isfinite(value)) refuse(who, name, " = ", value, " is not finite");
  };
  finite("J", m.J);
  finite("F", m.F);
  finite("the Coulomb torque Tc", m.coulomb);
  finite("the torque offset T0", m.offset);
  finite("the delay tau", m.delay);
  finite("the drive gain", m.gain);
  if (!(m.J > 0)) refuse(who, "J = ", m.J, " must be > 0 (the total inertia)");
  if (m.F < 0) refuse(who, "F = ", m.F, " must be >= 0 (the total viscous friction)");
  if (m.coulomb < 0) refuse(who, "the Coulomb torque Tc = ", m.coulomb, " must be >= 0");
  if (!(m.saturation > 0)) refuse(who, "the saturation L = ", m.saturation, " must be > 0 (infinity: no limit)");
  if (m.delay < 0) refuse(who, "the delay tau = ", m.delay, " must be >= 0");
}

}  // namespace

double applied_torque(const RigidDrive& model, double drive) {
  return std::clamp(model.gain * drive, -model.saturation, model.saturation) + model.offset;
}

RigidDrive rigid_drive_of(const numeric::Parameters& p, const numeric::Effects& e, double drive_gain) {
  constexpr const char* prefix = "rigid_drive_of: ";
  if (p.backlash > 0)
    refuse(prefix, "backlash = ", p.backlash, ": a rigid drive has no gap (the measured-drive simulator needs backlash 0)");
  for (const model::EffectInfo& effect : model::effects_table)  // the effects the table says need the gap
    if (effect.needs_gap && e.has(effect))
      refuse(prefix, effect.single() ? "" : std::string(effect.key) + ": ", effect.primary().name, " = ",
             model::field(e, effect.primary().id), " needs a gap to close (backlash > 0); a rigid drive has none");
  if (e.stribeck())
    refuse(prefix, "Stribeck friction (", e.describe(), ") is not simulated on a rigid measured drive; use coulomb_motor");
  RigidDrive m;
  m.J = p.Jm + p.JL;
  m.F = p.Fm + p.FL;
  m.coulomb = e.coulomb_motor + e.coulomb_load;
  m.offset = e.torque_offset;
  m.saturation = e.saturation;
  m.delay = e.delay;
  m.gain = drive_gain;
  check_model(m);
  return m;
}

const char* to_string(DriveEventKind kind) {
  switch (kind) {
    case DriveEventKind::Stick: return "stick";
    case DriveEventKind::Slip: return "slip";
    case DriveEventKind::Reversal: return "reversal";
  }
  return "?";
}

MeasuredDriveRun simulate_measured_drive(const RigidDrive& model, std::span<const double> t,
                                         std::span<const double> drive, std::size_t first, std::size_t last,
                                         double x0, double v0, bool start_stuck, std::size_t max_events) {
  check_model(model);
  if (t.size() != drive.size())
    refuse(who, "t and drive differ in length (", t.size(), " and ", drive.size(), " samples)");
  if (last >= t.size()) refuse(who, "last = ", last, " is out of range (", t.size(), " samples)");
  if (first > last) refuse(who, "first = ", first, " > last = ", last);
  if (!std::isfinite(x0)) refuse(who, "x0 = ", x0, " is not finite");
  if (!std::isfinite(v0)) refuse(who, "v0 = ", v0, " is not finite");
  if (start_stuck && v0 != 0) refuse(who, "start_stuck with v0 = ", v0, " (a stuck body is at rest: v0 must be 0)");
  auto finite_time = [&](std::size_t i) {
    if (!std::isfinite(t[i])) refuse(who, "t[", i, "] = ", t[i], " is not finite");
  };
  auto increasing_at = [&](std::size_t i) {  // i ≥ 1, both finite
    if (!(t[i] > t[i - 1]))
      refuse(who, "t is not strictly increasing at sample ", i, " (t[", i - 1, "] = ", t[i - 1], ", t[", i, "] = ", t[i], ")");
  };
  finite_time(first);
  for (std::size_t i = first + 1; i <= last; ++i) {
    finite_time(i);
    increasing_at(i);
  }
  const double tau = model.delay;
  // The sample acting at t[first]: the last k with t_k + τ ≤ t[first] (the first sample before
  // any), found stepping back from `first` (about τ/period steps; only these samples are used).
  std::size_t k = first;
  while (k > 0 && t[k] + tau > t[first]) {
    finite_time(k - 1);
    increasing_at(k);
    --k;
  }
  for (std::size_t i = k; i <= last; ++i)
    if (!std::isfinite(drive[i])) refuse(who, "drive[", i, "] = ", drive[i], " is not finite (it acts from t = ", t[i] + tau, ")");

  MeasuredDriveRun run;
  const std::size_t n = last - first + 1;
  run.x.resize(n);
  run.v.resize(n);
  run.x[0] = x0;
  run.v[0] = v0;
  Simulation body(model, run, max_events);
  body.x = x0;
  body.v = v0;
  body.stuck = start_stuck && model.coulomb > 0;

  double now = t[first];
  double a = applied_torque(model, drive[k]);
  for (std::size_t j = first + 1; j <= last; ++j) {
    const double target = t[j];
    while (k + 1 <= last && t[k + 1] + tau <= target) {  // sample k+1 takes over before the output
      const double boundary = t[k + 1] + tau;
      body.piece(a, now, boundary - now);
      now = boundary;
      a = applied_torque(model, drive[++k]);
    }
    body.piece(a, now, target - now);
    now = target;
    if (!std::isfinite(body.x) || !std::isfinite(body.v)) {
      std::ostringstream out;
      out << who << "the state overflowed at t = " << Shortest{target} << " (x = " << body.x << ", v = " << body.v
          << "): the parameters' magnitudes exceed a double's range";
      throw std::overflow_error(out.str());
    }
    run.x[j - first] = body.x;
    run.v[j - first] = body.v;
  }
  run.stuck_at_end = body.stuck;
  return run;
}

}  // namespace backlash::discrepancy
