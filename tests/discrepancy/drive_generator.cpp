#include "drive_generator.hpp"

#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace backlash::generated_data {

namespace {

// ------------------------------------------------------------------ the reference trajectory

// One piece of the reference velocity: from v0 to v1 along the quintic smoothstep
// s(u) = 10u³ − 15u⁴ + 6u⁵ over `duration` (v0 == v1: a cruise or a rest).
struct Segment {
  double t0, duration, x0, v0, v1;
};

class Reference {
 public:
  void add(double duration, double v1) {
    if (!(duration > 0)) return;
    segments_.push_back({t_, duration, x_, v_, v1});
    x_ += duration * (v_ + 0.5 * (v1 - v_));  // ∫s over [0, 1] is 1/2
    t_ += duration;
    v_ = v1;
  }
  double end_time() const { return t_; }
  double end_position() const { return x_; }
  void start_at(double x) { x_ = x; }

  // Position and velocity at t (after the last segment: at rest where it ended).
  std::array<double, 2> at(double t) const {
    if (segments_.empty() || t >= t_) return {x_, v_};
    auto it = std::upper_bound(segments_.begin(), segments_.end(), t, [](double value, const Segment& s) { return value < s.t0; });
    const Segment& s = *(it == segments_.begin() ? it : it - 1);
    const double u = std::clamp((t - s.t0) / s.duration, 0.0, 1.0);
    const double smooth = u * u * u * (10 - 15 * u + 6 * u * u);
    const double integral = u * u * u * u * (2.5 - 3 * u + u * u);  // ∫₀ᵘ smooth
    return {s.x0 + s.duration * (s.v0 * u + (s.v1 - s.v0) * integral), s.v0 + (s.v1 - s.v0) * smooth};
  }

 private:
  std::vector<Segment> segments_;
  double t_ = 0, x_ = 0, v_ = 0;
};

// Back-and-forth moves from near `low` to near `high` and back, each with a trapezoid velocity
// profile (quintic ramps), half of them in two speed levels (half speed first, as EMPS's), rests
// between them.
Reference make_reference(const DriveTrajectory& spec) {
  std::mt19937_64 random(spec.seed);
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(random); };
  const double margin = std::min(0.04, 0.25 * (spec.high - spec.low));
  Reference r;
  r.start_at(spec.low + 0.5 * margin);
  r.add(0.2, 0);
  auto ramp = [&](double dv) { return std::max(spec.min_ramp, 1.875 * std::fabs(dv) / spec.max_acceleration); };
  int direction = 1;
  while (r.end_time() < spec.duration) {
    if (!spec.end_in_motion && r.end_time() + spec.final_rest >= spec.duration) break;
    const double target = direction > 0 ? uniform(spec.high - margin, spec.high) : uniform(spec.low, spec.low + margin);
    const double distance = std::fabs(target - r.end_position());
    double v = uniform(spec.min_speed, spec.max_speed);
    const bool two_levels = uniform(0, 1) < 0.5;
    const double first_cruise = uniform(0.1, 0.4);
    // Two levels: 0 → v/2 (cruise c1) → v (cruise c2) → 0; c2 from the distance.
    const double fixed_two = ramp(v / 2) * v / 4 + v / 2 * first_cruise + ramp(v / 2) * 0.75 * v + ramp(v) * v / 2;
    if (two_levels && distance - fixed_two > 0) {
      const double d = direction;
      r.add(ramp(v / 2), d * v / 2);
      r.add(first_cruise, d * v / 2);
      r.add(ramp(v / 2), d * v);
      r.add((distance - fixed_two) / v, d * v);
      r.add(ramp(v), 0);
    } else {
      while (distance - ramp(v) * v < 0) v *= 0.8;  // one level: 0 → v → 0
      r.add(ramp(v), direction * v);
      r.add((distance - ramp(v) * v) / v, direction * v);
      r.add(ramp(v), 0);
    }
    r.add(uniform(0, spec.max_rest), 0);
    direction = -direction;
  }
  if (!spec.end_in_motion) r.add(spec.final_rest, 0);
  return r;
}

// ------------------------------------------------------------------ the plant

using State = std::array<double, 2>;  // x, v

struct Plant {
  const DrivePlant& p;
  double x = 0, v = 0;
  bool moving = false;  // false: at rest (v == 0), held while |f + T0| ≤ Fc
  int s = 0;            // the sign of the motion while moving
  double tolerance;
  DriveRecord* out;

  // From t0 to t1 under the constant force f (+ T0).
  void advance(double t0, double t1, double f) {
    if (!(t1 > t0)) return;
    const double net = f + p.offset;
    double t = t0;
    if (moving && v == 0) moving = false;  // stopped exactly at a boundary: decided with this piece's force
    if (!moving) {
      if (std::fabs(net) <= p.coulomb) return;  // held by friction (x unchanged)
      s = net > 0 ? 1 : -1;
      moving = true;
      if (p.coulomb > 0) ++out->slips;
    }
    namespace odeint = boost::numeric::odeint;
    while (true) {
      const int sign = s;
      auto rhs = [&](const State& y, State& dy, double) {
        dy[0] = y[1];
        dy[1] = (net - p.viscous * y[1] - p.coulomb * sign) / p.mass;
      };
      auto stepper = odeint::make_dense_output(tolerance, tolerance, odeint::runge_kutta_dopri5<State>());
      stepper.initialize(State{x, v}, t, t1 - t);
      bool zero = false;
      while (stepper.current_time() < t1) {
        const auto [previous, now] = stepper.do_step(rhs);
        ++out->steps;
        const double end = std::min(now, t1);
        State y;
        stepper.calc_state(end, y);
        if (y[1] * sign > 0) continue;
        // The velocity reached 0 in (previous, end]: locate it on the dense output.
        auto speed = [&](double time) {
          State z;
          stepper.calc_state(time, z);
          return z[1] * sign;
        };
        double root = end;
        const double at_previous = speed(previous);
        if (y[1] != 0 && at_previous > 0) {
          std::uintmax_t iterations = 200;
          const auto bracket = boost::math::tools::toms748_solve(speed, previous, end, at_previous, y[1] * sign,
                                                                 boost::math::tools::eps_tolerance<double>(52), iterations);
          root = 0.5 * (bracket.first + bracket.second);
        }
        State z;
        stepper.calc_state(root, z);
        x = z[0];
        v = 0;
        t = root;
        zero = true;
        break;
      }
      if (!zero) {
        State y;
        stepper.calc_state(t1, y);
        x = y[0];
        v = y[1];
        return;
      }
      // At v = 0 with the force of this piece: stick, or reverse at once.
      if (std::fabs(net) <= p.coulomb) {
        moving = false;
        s = 0;
        if (p.coulomb > 0) ++out->sticks;
        return;
      }
      const int next = net > 0 ? 1 : -1;
      if (p.coulomb > 0 && next != sign) ++out->reversals;
      s = next;
      if (!(t1 > t)) return;
    }
  }
};

}  // namespace

DriveRecord generate_drive_record(const DriveRecordSpec& spec) {
  const DrivePlant& p = spec.plant;
  const DriveController& c = spec.controller;
  if (!(p.mass > 0) || !(p.viscous >= 0) || !(p.coulomb >= 0) || !(p.saturation > 0) || !(p.delay >= 0) ||
      !std::isfinite(p.offset))
    throw std::invalid_argument("drive generator: the plant needs M > 0, Fv >= 0, Fc >= 0, L > 0, delay >= 0, a finite offset");
  if (!(c.period > 0) || !(spec.trajectory.duration > 0) || !(spec.trajectory.high > spec.trajectory.low) || !(spec.gain != 0))
    throw std::invalid_argument("drive generator: period, duration, high - low and gain must be > 0 (gain != 0)");
  const Reference reference = make_reference(spec.trajectory);

  DriveRecord out;
  Plant plant{p, reference.at(0)[0], 0, false, 0, spec.tolerance, &out};
  std::mt19937_64 random(spec.seed);
  std::normal_distribution<double> gaussian(0, 1);
  const double T = c.period;
  const double duration = spec.trajectory.end_in_motion ? spec.trajectory.duration : reference.end_time();
  const std::size_t n = static_cast<std::size_t>(std::floor(duration / T + 1e-9)) + 1;
  std::vector<double> outputs;  // c_k, waiting for their switch time
  outputs.reserve(n);
  std::vector<double> noise(n);
  for (double& w : noise) w = spec.force_noise * gaussian(random);
  auto quantise = [&](double x) { return spec.quantum > 0 ? spec.quantum * std::round(x / spec.quantum) : x; };

  double time = 0, force = 0;  // nothing acts before the first output does
  double integral = 0, previous_y = quantise(plant.x);
  std::size_t k = 0, j = 0;  // the next tick, the next switch
  while (k < n) {
    const double tick = static_cast<double>(k) * T;
    const double change = static_cast<double>(j) * T + p.delay;
    if (j >= k || tick <= change) {  // the controller's tick (first when they coincide: it computes c_k)
      plant.advance(time, tick, force);
      time = std::max(time, tick);
      const double y = quantise(plant.x);
      const auto [r, r_dot] = reference.at(tick);
      const double velocity_command = c.kp * (r - y) + (c.feed_forward ? r_dot : 0);
      const double velocity_error = velocity_command - (k == 0 ? 0 : (y - previous_y) / T);
      integral += c.kv * velocity_error * T / c.ti;
      const double u = c.kv * velocity_error + integral;
      previous_y = y;
      outputs.push_back(u);
      out.record.t.push_back(tick);
      out.record.theta_out.push_back(y);
      out.reference.push_back(r);
      out.position.push_back(plant.x);
      out.velocity.push_back(plant.v);
      out.max_force = std::max(out.max_force, std::fabs(u));
      out.max_speed = std::max(out.max_speed, std::fabs(plant.v));
      out.max_tracking_error = std::max(out.max_tracking_error, std::fabs(r - plant.x));
      if (!(std::fabs(r - plant.x) < 0.05))
        throw std::runtime_error("drive generator: the carriage is " + std::to_string(r - plant.x) + " m from the reference at t = " +
                                 std::to_string(tick) + " s (an unstable loop?)");
      ++k;
    } else {  // output j starts to act
      plant.advance(time, change, force);
      time = std::max(time, change);
      force = std::clamp(outputs[j], -p.saturation, p.saturation) + noise[j];
      ++j;
    }
  }
  out.record.drive = std::vector<double>(n);
  for (std::size_t i = 0; i < n; ++i) (*out.record.drive)[i] = outputs[i] / spec.gain + spec.log_noise * gaussian(random);
  out.record.source = "generated_drive.csv";
  return out;
}

}  // namespace backlash::generated_data
