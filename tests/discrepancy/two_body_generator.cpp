#include "two_body_generator.hpp"

#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>

namespace backlash::generated_data {

namespace {

// θm, ωm, θL, ωL, then the energy accumulators W = ∫u·ωm and D = ∫(losses).
using Y = std::array<double, 6>;

int sign_of(double v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

// The event functions: each is > 0 while its mode lasts and its zero is the event.
enum class Kind {
  touch,        // a face reached from inside the gap: −δσ (rigid: impact; compliant: engagement)
  reengage,     // a released but still overlapping compliant mesh pushes again: −Pσ
  overlap_end,  // the overlap of a released compliant mesh ends: δσ (bookkeeping only)
  release,      // the transmitted torque leaves its holding sign: P (rigid: separation)
  stop,         // a body with Coulomb friction stops: s·ω (body 0 motor, 1 load, 2 both in contact)
  breakaway     // a stuck body's torque leaves the friction band: C − |N|
};

struct Event {
  Kind kind;
  int arg;  // the face σ, or the body
};

// The mode: `contact` the face σ the bodies are in contact on (rigid) or engaged on
// (compliant), 0 in flight; s the direction of motion of each body, 0 while stuck (only a body
// with Coulomb friction is ever stuck; without, s is irrelevant and kept at ±1).
struct Mode {
  int contact = 0;
  std::array<int, 2> s{1, 1};
};

struct Forces {
  std::array<double, 2> a;  // accelerations of motor and load
  std::array<double, 2> N;  // the torque on each body besides its friction (u + Rm, RL)
  double P;                 // the torque transmitted across the contact face (holding: ≥ 0)
};

class Plant {
 public:
  Plant(const TwoBodyPlant& p, double tolerance, TwoBodyEvents& events, TwoBodyEnergy& energy)
      : p_(p), rigid_(std::isinf(p.stiffness)), locked_(rigid_ && p.backlash == 0), tolerance_(tolerance),
        events_(events), energy_(energy) {}

  void start(const TwoBodyState& s0) {
    y_ = {s0.theta_m, s0.omega_m, s0.theta_l, s0.omega_l, 0, 0};
    if (locked_) {
      mode_.contact = 1;
      y_[2] = y_[0], y_[3] = y_[1];
    }
    for (int sigma : {-1, 1}) {
      if (rigid_ && !locked_ && std::fabs(overlap(y_, sigma)) <= 1e-15 && y_[1] == y_[3]) mode_.contact = sigma;
      if (!rigid_ && overlap(y_, sigma) > 0 && mesh_torque(y_, sigma) > 0) mode_.contact = sigma;
    }
    for (int body : {0, 1}) set_direction(body, velocity(y_, body));
    if (rigid_ && mode_.contact != 0) mode_.s[1] = mode_.s[0];
    initial_energy_ = kinetic(y_) + spring(y_);
  }

  TwoBodyState state() const { return {y_[0], y_[1], y_[2], y_[3]}; }

  // From t0 to t1 under the motor torque u.
  void advance(double t0, double t1, double u) {
    u_ = u;
    double t = t0;
    time_ = t0;
    int events_here = 0;
    settle();
    while (t < t1) {
      t = segment(t, t1);
      if (t < t1 && ++events_here > 10000)
        throw std::runtime_error("two-body generator: more than 10000 events in one controller period at t = " + std::to_string(t) +
                                 " s (the events do not resolve)");
    }
    energy_.work = y_[4];
    energy_.dissipated = y_[5];
    energy_.kinetic = kinetic(y_) + spring(y_) - initial_energy_;
    energy_.spring = spring(y_);
  }

 private:
  // ---------------------------------------------------------------- the physics

  static double velocity(const Y& y, int body) { return body == 0 ? y[1] : y[3]; }
  double inertia(int body) const { return body == 0 ? p_.Jm : p_.JL; }
  double viscous(int body) const { return body == 0 ? p_.Fm : p_.FL; }
  double coulomb(int body) const { return body == 0 ? p_.coulomb_motor : p_.coulomb_load; }
  // δσ = σ·x − b/2, x = θL − θm: > 0 when the teeth overlap beyond face σ.
  double overlap(const Y& y, int sigma) const { return sigma * (y[2] - y[0]) - 0.5 * p_.backlash; }
  double mesh_torque(const Y& y, int sigma) const {
    return p_.stiffness * overlap(y, sigma) + p_.damping * sigma * (y[3] - y[1]);
  }
  double kinetic(const Y& y) const { return 0.5 * (p_.Jm * y[1] * y[1] + p_.JL * y[3] * y[3]); }
  double spring(const Y& y) const {
    if (rigid_ || mode_.contact == 0) return 0;
    const double d = overlap(y, mode_.contact);
    return 0.5 * p_.stiffness * d * d;
  }

  Forces forces(const Y& y) const {
    Forces f{};
    const int sigma = mode_.contact;
    if (rigid_ && sigma != 0) {  // one body
      const int s = mode_.s[0];
      const double J = p_.Jm + p_.JL, w = y[1];
      const double a = s == 0 ? 0 : (u_ - (p_.Fm + p_.FL) * w - (p_.coulomb_motor + p_.coulomb_load) * s) / J;
      const double RL = p_.JL * a + p_.FL * w + p_.coulomb_load * s;  // what the load needs
      f.a = {a, a};
      f.N = {u_ - RL, RL};
      f.P = locked_ ? 1 : -sigma * RL;
      return f;
    }
    f.P = (!rigid_ && sigma != 0) ? mesh_torque(y, sigma) : 0;
    f.N = {u_ + sigma * f.P, -sigma * f.P};
    for (int body : {0, 1}) {
      const int s = mode_.s[body];
      f.a[body] = s == 0 ? 0 : (f.N[body] - viscous(body) * velocity(y, body) - coulomb(body) * s) / inertia(body);
    }
    return f;
  }

  void rhs(const Y& y, Y& dy) const {
    const Forces f = forces(y);
    dy[0] = y[1], dy[1] = f.a[0], dy[2] = y[3], dy[3] = f.a[1];
    dy[4] = u_ * y[1];
    double loss = p_.Fm * y[1] * y[1] + p_.FL * y[3] * y[3];
    loss += p_.coulomb_motor * std::fabs(y[1]) + p_.coulomb_load * std::fabs(y[3]);
    if (!rigid_ && mode_.contact != 0) loss += p_.damping * (y[3] - y[1]) * (y[3] - y[1]);
    dy[5] = loss;
  }

  // ---------------------------------------------------------------- the events of a mode

  std::vector<Event> events_of_mode() const {
    std::vector<Event> out;
    const int sigma = mode_.contact;
    if (rigid_ && sigma != 0) {
      if (mode_.s[0] != 0 && !locked_) out.push_back({Kind::release, sigma});
      if (mode_.s[0] != 0 && p_.coulomb_motor + p_.coulomb_load > 0) out.push_back({Kind::stop, 2});
      return out;
    }
    if (sigma != 0) {
      out.push_back({Kind::release, sigma});
    } else {
      for (int face : {-1, 1}) {
        if (rigid_ || overlap(y_, face) <= 0) {
          out.push_back({Kind::touch, face});
        } else {
          out.push_back({Kind::reengage, face});
          out.push_back({Kind::overlap_end, face});
        }
      }
    }
    for (int body : {0, 1}) {
      if (coulomb(body) <= 0) continue;
      out.push_back({mode_.s[body] == 0 ? Kind::breakaway : Kind::stop, body});
    }
    return out;
  }

  double value(const Event& e, const Y& y) const {
    switch (e.kind) {
      case Kind::touch: return -overlap(y, e.arg);
      case Kind::reengage: return -mesh_torque(y, e.arg);
      case Kind::overlap_end: return overlap(y, e.arg);
      case Kind::release: return forces(y).P;
      case Kind::stop: return mode_.s[e.arg == 2 ? 0 : e.arg] * velocity(y, e.arg == 2 ? 0 : e.arg);
      case Kind::breakaway: return coulomb(e.arg) - std::fabs(forces(y).N[e.arg]);
    }
    return 1;
  }

  // Integrates from t to at most t1 in the current mode; returns the time reached (t1, or the
  // earliest event, after which the mode has changed).
  double segment(double t, double t1) {
    namespace odeint = boost::numeric::odeint;
    const std::vector<Event> watched = events_of_mode();
    std::vector<char> armed(watched.size());
    for (std::size_t j = 0; j < watched.size(); ++j) {  // a face exactly touched counts (the gap closes from 0)
      const double g = value(watched[j], y_);
      armed[j] = g > 0 || (g == 0 && watched[j].kind == Kind::touch);
    }
    auto system = [this](const Y& y, Y& dy, double) { rhs(y, dy); };
    auto stepper = odeint::make_dense_output(tolerance_, tolerance_, t1 - t, odeint::runge_kutta_dopri5<Y>());
    stepper.initialize(y_, t, std::min(1e-4, t1 - t));
    while (true) {
      const auto [previous, now] = stepper.do_step(system);
      ++events_.steps;
      const double end = std::min(now, t1);
      Y y;
      stepper.calc_state(end, y);
      double earliest = end;
      int which = -1;
      for (std::size_t j = 0; j < watched.size(); ++j) {
        const double g = value(watched[j], y);
        if (!armed[j]) {
          armed[j] = g > 0;
          continue;
        }
        if (g > 0) continue;
        auto g_at = [&](double time) {
          Y z;
          stepper.calc_state(time, z);
          return value(watched[j], z);
        };
        double root = end;
        const double g_previous = g_at(previous);
        if (g < 0 && g_previous > 0) {
          std::uintmax_t iterations = 200;
          const auto bracket = boost::math::tools::toms748_solve(g_at, previous, end, g_previous, g,
                                                                 boost::math::tools::eps_tolerance<double>(52), iterations);
          root = bracket.second;  // the side where the event has happened
        } else if (g_previous <= 0) {
          root = previous;
        }
        if (root < earliest || which < 0) earliest = root, which = static_cast<int>(j);
      }
      if (which >= 0) {
        stepper.calc_state(earliest, y_);
        time_ = earliest;
        transition(watched[which], earliest);
        settle();
        return earliest;
      }
      if (end >= t1) {
        y_ = y;
        return t1;
      }
    }
  }

  // ---------------------------------------------------------------- the transitions

  void set_direction(int body, double w) {
    if (w != 0 || coulomb(body) <= 0) {
      mode_.s[body] = w < 0 ? -1 : 1;
    } else {
      mode_.s[body] = 0;  // at rest with friction: settle() decides
    }
  }

  void part() {
    mode_.contact = 0;
    ++(rigid_ ? events_.separations : events_.releases);
    events_.separation_times.push_back(time_);
    for (int body : {0, 1}) set_direction(body, velocity(y_, body));
  }

  void transition(const Event& e, double time) {
    switch (e.kind) {
      case Kind::touch:
        if (rigid_) {
          impact(e.arg, time);
        } else {
          mode_.contact = e.arg;
          ++events_.engagements;
          events_.contact_times.push_back(time);
        }
        return;
      case Kind::reengage: {
        const double d = overlap(y_, e.arg);
        energy_.release_losses -= 0.5 * p_.stiffness * d * d;
        mode_.contact = e.arg;
        ++events_.engagements;
        events_.contact_times.push_back(time);
        return;
      }
      case Kind::overlap_end: return;
      case Kind::release: {
        if (!rigid_) {
          const double d = overlap(y_, mode_.contact);
          energy_.release_losses += 0.5 * p_.stiffness * d * d;
        }
        part();
        return;
      }
      case Kind::stop: stop(e.arg); return;
      case Kind::breakaway: {
        mode_.s[e.arg] = sign_of(forces(y_).N[e.arg]);
        ++events_.breakaways;
        return;
      }
    }
  }

  // Rigid teeth reach face σ: the inelastic impact (momentum conserved), then one body.
  void impact(int sigma, double time) {
    const double J = p_.Jm + p_.JL, w = (p_.Jm * y_[1] + p_.JL * y_[3]) / J;
    const double loss = kinetic(y_) - 0.5 * J * w * w;
    energy_.impact_losses += loss;
    y_[2] = y_[0] + sigma * 0.5 * p_.backlash;
    y_[1] = y_[3] = w;
    mode_.contact = sigma;
    set_direction(0, w);
    if (p_.coulomb_motor + p_.coulomb_load <= 0 && w == 0) mode_.s[0] = 1;
    mode_.s[1] = mode_.s[0];
    ++events_.impacts;
    events_.contact_times.push_back(time);
  }

  void stop(int body) {
    if (body == 2) {  // both, in rigid contact
      y_[1] = y_[3] = 0;
      mode_.s = {0, 0};
      ++events_.sticks;
      return;  // settle() decides: stuck, reversal, or the motor leaving the face
    }
    (body == 0 ? y_[1] : y_[3]) = 0;
    const double N = forces(y_).N[body];
    if (std::fabs(N) <= coulomb(body)) {
      mode_.s[body] = 0;
      ++events_.sticks;
    } else {
      mode_.s[body] = sign_of(N);
    }
  }

  // The rest and contact rules at the current state and torque: stuck bodies that break away,
  // rigid contact whose transmitted torque has lost its holding sign (after an impact, or
  // under a new torque).
  void settle() {
    const int sigma = mode_.contact;
    if (rigid_ && sigma != 0) {
      if (mode_.s[0] == 0) {  // stuck together: into the face both frictions hold, away from it the motor's
        const int into = locked_ ? sign_of(u_) : -sigma;
        const bool pushing = sign_of(u_) == into || u_ == 0;
        const double band = pushing ? p_.coulomb_motor + p_.coulomb_load : p_.coulomb_motor;
        if (std::fabs(u_) <= band) return;
        ++events_.breakaways;
        if (pushing) {
          mode_.s = {into, into};
          return;
        }
        mode_.contact = 0;
        ++events_.separations;
        events_.separation_times.push_back(time_);
        mode_.s[0] = sign_of(u_);
        set_direction(1, 0);
        settle();
        return;
      }
      if (!locked_ && forces(y_).P < 0) part();
      return;
    }
    const Forces f = forces(y_);
    for (int body : {0, 1}) {
      if (mode_.s[body] != 0 || std::fabs(f.N[body]) <= coulomb(body)) continue;
      mode_.s[body] = sign_of(f.N[body]);
      ++events_.breakaways;
    }
  }

  const TwoBodyPlant& p_;
  const bool rigid_, locked_;
  const double tolerance_;
  TwoBodyEvents& events_;
  TwoBodyEnergy& energy_;
  Y y_{};
  Mode mode_;
  double u_ = 0, initial_energy_ = 0, time_ = 0;
};

void check_plant(const TwoBodyPlant& p) {
  if (!(p.Jm > 0) || !(p.JL > 0) || !(p.Fm >= 0) || !(p.FL >= 0) || !(p.backlash >= 0) || !(p.stiffness > 0) ||
      !(p.damping >= 0) || !(p.coulomb_motor >= 0) || !(p.coulomb_load >= 0) || !std::isfinite(p.backlash))
    throw std::invalid_argument("two-body generator: the plant needs Jm, JL, k > 0 and Fm, FL, b, c, Cm, CL >= 0");
}

// ------------------------------------------------------------------ the reference

// A trapezoid between −A and +A: rest, then `moves` moves (ramp up over `ramp` with the
// quintic smoothstep velocity, cruise at V, ramp down), each followed by a rest.
struct Trapezoid {
  TwoBodyReference spec;
  double move_time() const { return 2 * spec.amplitude / spec.speed + spec.ramp; }
  double duration() const { return spec.rest + spec.moves * (move_time() + spec.rest); }

  std::array<double, 2> at(double t) const {  // r, ṙ
    const double A = spec.amplitude, V = spec.speed, R = spec.ramp, cycle = move_time() + spec.rest;
    double tau = t - spec.rest;
    if (tau <= 0) return {-A, 0};
    const int move = std::min(static_cast<int>(tau / cycle), spec.moves - 1);
    tau -= move * cycle;
    const double from = move % 2 == 0 ? -A : A, d = move % 2 == 0 ? 1 : -1;
    if (tau >= move_time()) return {-from, 0};
    auto ramp_up = [&](double s) {  // position covered and speed after s of a ramp from 0 to V
      const double u = std::clamp(s / R, 0.0, 1.0);
      return std::array<double, 2>{R * V * u * u * u * u * (2.5 - 3 * u + u * u), V * u * u * u * (10 - 15 * u + 6 * u * u)};
    };
    const double cruise = move_time() - 2 * R;
    if (tau < R) {
      const auto [x, v] = ramp_up(tau);
      return {from + d * x, d * v};
    }
    if (tau < R + cruise) return {from + d * (0.5 * V * R + V * (tau - R)), d * V};
    const auto [x, v] = ramp_up(move_time() - tau);  // the ramp down mirrors the ramp up
    return {-from - d * x, d * v};
  }
};

std::string number(double v) {
  std::array<char, 64> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace

TwoBodyRun simulate_two_body(const TwoBodyPlant& plant, const std::vector<double>& t, const std::vector<double>& torque,
                             const TwoBodyState& start, double tolerance) {
  check_plant(plant);
  if (t.size() != torque.size() || t.empty())
    throw std::invalid_argument("two-body generator: t and torque need the same, non-zero length");
  TwoBodyRun run;
  Plant body(plant, tolerance, run.events, run.energy);
  body.start(start);
  run.state.push_back(body.state());
  for (std::size_t k = 1; k < t.size(); ++k) {
    body.advance(t[k - 1], t[k], torque[k - 1]);
    run.state.push_back(body.state());
  }
  return run;
}

TwoBodyRecordSpec standard_record_spec(double backlash) {
  TwoBodyRecordSpec spec;
  spec.plant.backlash = backlash;
  spec.reference.amplitude = 0.8;
  spec.current_noise = 0.002;
  return spec;
}

TwoBodyRecord generate_two_body_record(const TwoBodyRecordSpec& spec) {
  check_plant(spec.plant);
  const TwoBodyLoop& loop = spec.loop;
  const Trapezoid reference{spec.reference};
  const TwoBodyReference& r = spec.reference;
  if (!(loop.period > 0) || !(r.amplitude > 0) || !(r.speed > 0) || !(r.ramp > 0) || !(r.rest >= 0) || r.moves < 1 ||
      !(spec.gain != 0) || spec.counts_per_rev < 0 || !(spec.current_noise >= 0))
    throw std::invalid_argument("two-body generator: T, A, V, ramp > 0, rest >= 0, moves >= 1, gain != 0 needed");
  if (2 * r.amplitude < r.speed * r.ramp)
    throw std::invalid_argument("two-body generator: a move of 2A is shorter than its two ramps at speed V");

  TwoBodyRecord out;
  Plant plant(spec.plant, spec.tolerance, out.events, out.energy);
  const double start = reference.at(0)[0];
  plant.start({start, 0, start, 0});
  const double quantum = spec.counts_per_rev > 0 ? 2 * M_PI / static_cast<double>(spec.counts_per_rev) : 0;
  auto encoder = [&](double theta) { return quantum > 0 ? quantum * std::round(theta / quantum) : theta; };
  std::mt19937_64 random(spec.seed);
  std::normal_distribution<double> gaussian(0, 1);
  const double T = loop.period;
  const std::size_t n = static_cast<std::size_t>(std::floor(reference.duration() / T + 1e-9)) + 1;
  double integral = 0, previous = 0, u = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * T;
    if (k > 0) plant.advance(t - T, t, u);
    const TwoBodyState s = plant.state();
    const auto [ref, ref_rate] = reference.at(t);
    const double ym = encoder(s.theta_m), yl = encoder(s.theta_l), y = loop.on_load ? yl : ym;
    if (k == 0) previous = ym;
    integral += loop.ki * T * (ref - y);
    u = loop.kp * (ref - y) + loop.kv * (ref_rate - (ym - previous) / T) + integral;
    previous = ym;
    if (!(std::fabs(s.theta_m - ref) < 10 * r.amplitude + M_PI) || !(std::fabs(s.theta_l - ref) < 10 * r.amplitude + M_PI))
      throw std::runtime_error("two-body generator: the loop ran away at t = " + std::to_string(t) + " s");
    out.t.push_back(t);
    out.theta_motor.push_back(ym);
    out.theta_load.push_back(yl);
    out.reference.push_back(ref);
    out.torque.push_back(u);
    out.state.push_back(s);
  }
  for (double c : out.torque) out.drive.push_back(c / spec.gain + spec.current_noise * gaussian(random));
  int direction = 0;
  for (const TwoBodyState& s : out.state) {
    const int now = std::fabs(s.omega_m) > 0.3 * r.speed ? sign_of(s.omega_m) : 0;
    if (now != 0 && direction != 0 && now != direction) ++out.reversals;
    if (now != 0) direction = now;
  }
  return out;
}

std::string two_body_csv(const TwoBodyRecord& record, bool both_encoders) {
  std::string csv = both_encoders ? "t,theta_motor,theta_load,drive\n" : "t,theta_motor,drive\n";
  for (std::size_t k = 0; k < record.t.size(); ++k) {
    csv += number(record.t[k]) + ',' + number(record.theta_motor[k]) + ',';
    if (both_encoders) csv += number(record.theta_load[k]) + ',';
    csv += number(record.drive[k]) + '\n';
  }
  return csv;
}

std::string two_body_case_toml(const TwoBodyCase& model) {
  const TwoBodyPlant& p = model.nominal;
  std::string toml;
  std::size_t from = 0;
  while (!model.comment.empty() && from <= model.comment.size()) {
    const std::size_t end = std::min(model.comment.find('\n', from), model.comment.size());
    toml += "# " + model.comment.substr(from, end - from) + "\n";
    from = end + 1;
  }
  toml += "name = \"" + model.name + "\"\nmeasured_at = \"motor\"\nbacklash = " + number(p.backlash) +
                     "\nreference = 0\n\n[motor]\nJ = " + number(p.Jm) + "\nF = " + number(p.Fm) + "\n\n[load]\nJ = " +
                     number(p.JL) + "\nF = " + number(p.FL) + "\n\n[experiment]\nkind = \"drive\"\ndrive_gain = " +
                     number(model.drive_gain) + "\n";
  std::string effects;
  if (p.coulomb_motor > 0) effects += "coulomb_motor = " + number(p.coulomb_motor) + "\n";
  if (p.coulomb_load > 0) effects += "coulomb_load = " + number(p.coulomb_load) + "\n";
  if (std::isfinite(p.stiffness))
    effects += "compliance = { stiffness = " + number(p.stiffness) + ", damping = " + number(p.damping) + " }\n";
  if (!effects.empty()) toml += "\n[effects]\n" + effects;
  if (!model.free.empty()) {
    toml += "\n[fit]\nfree = [";
    for (std::size_t i = 0; i < model.free.size(); ++i) toml += (i ? ", \"" : "\"") + model.free[i] + "\"";
    toml += "]\n";
  }
  return toml;
}

void write_text_file(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("two-body generator: cannot write " + file.string());
}

}  // namespace backlash::generated_data
