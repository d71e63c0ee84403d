// The measured-drive discrepancy workflow (discrepancy/measured_drive.hpp) on records of a
// servo like EMPS made by an INDEPENDENT generator (drive_generator.hpp: a digital P/PI
// position controller on the quantised encoder around a rigid carriage, integrated by
// Boost.Odeint with its own stick/slip handling) — never by the closed-form simulator the
// workflow's position check uses, nor by anything of discrepancy/.
//
// DriveGenerator: the generator itself — it agrees with the project's exact simulator
// (discrepancy/measured_drive_simulation.hpp, an independent implementation) fed its own logged drive, it is
// deterministic, its positions are encoder counts, its records have EMPS's scale, a saturated
// record's logged drive exceeds the limit, a bad spec is refused.
//
// DriveWorkflow: the model file (a temporary TOML read by model::load_case_file) has J and F
// 25–35 % off (low or high) and marks them free; the record hides
//   CoulombAndOffset  Fc and T0: EMPS's sizes (20 N, 3.2 N), weak (8 N, −4.5 N), strong (35 N, 1.5 N);
//   Coulomb, Offset   each alone;
//   Delay             a transport delay of 3.2 or 6.8 ms (not a multiple of the 1 ms period);
//   Saturation        the amplifier clipping at 90 or 75 N while the logged drive exceeds it;
//   Clean             nothing but J and F (two trajectories);
//   EndsInMotion      a clean record whose log stops in the middle of a move;
// each at two noise levels: "fine" (EMPS's encoder quantum 5e-8 m, no other noise) and
// "coarse" (a 1e-6 m quantum — 20× EMPS's — plus an unlogged force noise of 0.3 N and 0.2 N of
// noise on the logged drive), the drive column in newtons (gain 1) or in volts (35.15 N/V),
// every run on its own trajectory (12 s estimation, 8 s validation), 24 runs in all.
// Per scenario:
//   ...Named         the named effects are exactly the hidden ones (either order), status
//                    effect_found; on a clean record none (no_discrepancy or unexplained, as
//                    the noise-level rule says);
//   ...Fitted        every fitted parameter — J, F (the corrected model's, or the best nominal
//                    one's when nothing is named) and each named effect's — within kSigmas = 4
//                    reported standard deviations of the truth (a named effect that is not
//                    hidden has the truth 0, or ∞ for a limit).  No bias allowance: none is
//                    justified — the filter and the differences are linear and act on both
//                    sides alike, the quantisation and the noises are zero-mean — and a
//                    workflow with the fixes listed below meets it with room (its largest
//                    error over the fitted parameters is 1.56σ);
//   ...Improves      the torque RMS shrinks at least kTorqueShrink = 2× (measured ≥ 12× in
//                    every scenario with a hidden effect), the position-window RMS
//                    at least kPositionShrink = 3×, and on the validation record (another
//                    trajectory, fitted on neither) the corrected model beats the best
//                    nominal one by the same factors;
//   ...MatchesTruth  the corrected model is as good as the TRUE model scored the same way
//                    (the truth as the model file, nothing free, no candidate): torque RMS
//                    within 5 % of the truth's, position-window RMS at most 2× the truth's on
//                    the estimation and on the validation record.
//
// Found with this generator and fixed in the workflow (drive_workflow.cpp; docs/discrepancy.md,
// "Measured-drive records"), each guarded by the tests below:
//   1. the zero-order hold: logged drive sample k acts on [t_k + τ, t_{k+1} + τ), on average
//      half a period after the instant it was compared at — every record showed a "delay" of
//      T/2 (named on a clean record, ΔBIC ≈ −500), a hidden τ was fitted as τ + T/2 (≈ 200σ
//      off).  Now the drive is compared as the hold's exact effect on the second difference of
//      the position (the quadratic B-spline weights of the held samples), through the filter;
//   2. the Coulomb term Tc·sgn(v̂) was not filtered like the rest of the equation (Tc low and F
//      high by 5–12σ); now its column goes through the same filter, at rest the friction holds
//      the drive, and samples within a filter length of a start, a stop or a reversal are not
//      compared;
//   3. the filter's end transients: samples within the filter's effective length of each end
//      are not compared (a record that stops in motion biased J by 7–9σ);
//   4. a weak pair (Fc = 8 N, T0 = −4.5 N) is named although each effect alone misses the
//      decisive rule: when no single candidate is decisive, pairs are tried by the same rule
//      with two parameters' BIC penalty.
#include "drive_generator.hpp"

#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/discrepancy/measured_drive_simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace backlash;
using generated_data::DriveRecord;
using generated_data::DriveRecordSpec;

constexpr double kMass = 95, kViscous = 204;       // EMPS's published values [kg, N·s/m]
constexpr double kVoltsGain = 35.150651882485469;  // EMPS's gtau [N/V]
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kSigmas = 4;
constexpr double kTorqueShrink = 2, kPositionShrink = 3;
constexpr double kTruthTorque = 1.05, kTruthPosition = 2;

// ------------------------------------------------------------------ the generator

DriveRecordSpec emps_like(const std::uint64_t trajectory) {
  DriveRecordSpec spec;
  spec.plant.mass = kMass;
  spec.plant.viscous = kViscous;
  spec.trajectory.seed = trajectory;
  return spec;
}

// The logged drive fed to the exact closed-form simulator (an implementation independent of
// the generator's odeint one) from the generator's true initial state gives the generator's
// true motion: both follow the same semantics (zero-order hold, delay, clipping, sticking).
TEST(DriveGenerator, AgreesWithTheExactSimulator) {
  struct Case {
    const char* name;
    double coulomb, offset, saturation, delay, gain;
  };
  for (const Case& c : {Case{"Coulomb, offset, saturation, delay", 20, 3.2, 100, 0.0043, kVoltsGain},
                        Case{"clean", 0, 0, kInfinity, 0, 1}, Case{"strong Coulomb", 40, -2, kInfinity, 0.001, 1}}) {
    DriveRecordSpec spec = emps_like(7);
    spec.plant.coulomb = c.coulomb, spec.plant.offset = c.offset, spec.plant.saturation = c.saturation, spec.plant.delay = c.delay;
    spec.gain = c.gain;
    spec.trajectory.duration = 6;
    const DriveRecord r = generated_data::generate_drive_record(spec);
    discrepancy::RigidDrive model;
    model.J = kMass, model.F = kViscous, model.coulomb = c.coulomb, model.offset = c.offset;
    model.saturation = c.saturation, model.delay = c.delay, model.gain = c.gain;
    const discrepancy::MeasuredDriveRun exact = discrepancy::simulate_measured_drive(
        model, r.record.t, *r.record.drive, 0, r.record.size() - 1, r.position.front(), r.velocity.front());
    double dx = 0, dv = 0;
    for (std::size_t k = 0; k < r.record.size(); ++k)
      dx = std::max(dx, std::fabs(exact.x[k] - r.position[k])), dv = std::max(dv, std::fabs(exact.v[k] - r.velocity[k]));
    std::printf("%-36s %zu samples, %d sticks, %d slips, %d reversals, %ld odeint steps: max |dx| %.2g m, max |dv| %.2g m/s\n", c.name,
                r.record.size(), r.sticks, r.slips, r.reversals, r.steps, dx, dv);
    // odeint at 1e-12 on a linear ODE, each zero located to 52 bits: measured 1e-14 m and 4e-15 m/s.
    EXPECT_LE(dx, 1e-11) << c.name << ": the generator's position differs from the exact simulator's by " << dx << " m";
    EXPECT_LE(dv, 1e-10) << c.name << ": the generator's velocity differs from the exact simulator's by " << dv << " m/s";
    if (c.coulomb > 0) {
      EXPECT_GT(r.sticks + r.slips, 0) << c.name << ": no stick or slip in the record";
    }
  }
}

TEST(DriveGenerator, IsDeterministicAndCountsQuanta) {
  DriveRecordSpec spec = emps_like(3);
  spec.plant.coulomb = 20;
  spec.trajectory.duration = 4;
  spec.force_noise = 0.3;
  spec.log_noise = 0.2;
  const DriveRecord a = generated_data::generate_drive_record(spec), b = generated_data::generate_drive_record(spec);
  EXPECT_EQ(a.record.theta_out, b.record.theta_out) << "the same spec returned another position";
  EXPECT_EQ(*a.record.drive, *b.record.drive) << "the same spec returned another drive";
  spec.seed = 4;
  const DriveRecord c = generated_data::generate_drive_record(spec);
  EXPECT_NE(*a.record.drive, *c.record.drive) << "another noise seed returned the same drive";
  for (std::size_t k = 0; k < a.record.size(); ++k) {
    const double counts = a.record.theta_out[k] / spec.quantum;
    ASSERT_LE(std::fabs(counts - std::round(counts)), 1e-6) << "theta_out[" << k << "] = " << a.record.theta_out[k]
                                                            << " is not a multiple of the quantum " << spec.quantum;
    ASSERT_LE(std::fabs(a.record.theta_out[k] - a.position[k]), 0.5 * spec.quantum * (1 + 1e-9))
        << "theta_out[" << k << "] is not the nearest count to the true position";
    ASSERT_DOUBLE_EQ(a.record.t[k], static_cast<double>(k) * 1e-3);
  }
}

// EMPS's scale: positions within 0–0.25 m, speeds up to 0.13 m/s, forces within ±150 N, a
// controller that tracks to a fraction of a millimetre; the record starts and ends at rest.
TEST(DriveGenerator, HasEmpsScale) {
  for (std::uint64_t trajectory : {1, 2, 3, 4, 5, 6}) {
    DriveRecordSpec spec = emps_like(trajectory);
    spec.plant.coulomb = 20, spec.plant.offset = 3.2;
    const DriveRecord r = generated_data::generate_drive_record(spec);
    const auto [low, high] = std::minmax_element(r.record.theta_out.begin(), r.record.theta_out.end());
    std::printf("trajectory %d: %.2f s, x in [%.4f, %.4f] m, |v| <= %.3f m/s, |u| <= %.1f N, tracking error <= %.2g m\n",
                static_cast<int>(trajectory), r.record.t.back(), *low, *high, r.max_speed, r.max_force, r.max_tracking_error);
    EXPECT_GE(*low, 0.0) << "trajectory " << trajectory;
    EXPECT_LE(*high, 0.25) << "trajectory " << trajectory;
    EXPECT_GE(*high - *low, 0.15) << "trajectory " << trajectory << ": the moves span only " << *high - *low << " m";
    EXPECT_GE(r.max_speed, 0.06) << "trajectory " << trajectory;
    EXPECT_LE(r.max_speed, 0.14) << "trajectory " << trajectory;
    EXPECT_LE(r.max_force, 160) << "trajectory " << trajectory;
    EXPECT_LE(r.max_tracking_error, 1e-3) << "trajectory " << trajectory;
    EXPECT_GE(r.record.t.back(), spec.trajectory.duration - spec.trajectory.final_rest) << "trajectory " << trajectory;
    EXPECT_LE(std::fabs(r.velocity.back()), 1e-4) << "trajectory " << trajectory << ": the record ends in motion";  // 2 counts/ms
  }
  DriveRecordSpec cut = emps_like(1);
  cut.trajectory.end_in_motion = true;
  const DriveRecord r = generated_data::generate_drive_record(cut);
  EXPECT_DOUBLE_EQ(r.record.t.back(), cut.trajectory.duration);
  EXPECT_GT(std::fabs(r.velocity.back()), 0.01) << "a record cut at " << cut.trajectory.duration << " s ends at rest";
}

// The saturation scenarios' records: the controller asks for more than the amplifier gives.
TEST(DriveGenerator, SaturatedRecordsLogMoreThanTheLimit) {
  for (const double limit : {90.0, 75.0}) {
    for (const double gain : {1.0, kVoltsGain}) {
      DriveRecordSpec spec = emps_like(11);
      spec.plant.saturation = limit;
      spec.gain = gain;
      const DriveRecord r = generated_data::generate_drive_record(spec);
      double logged = 0;
      std::size_t beyond = 0;
      for (double u : *r.record.drive) {
        logged = std::max(logged, std::fabs(gain * u));
        beyond += std::fabs(gain * u) > limit;
      }
      std::printf("limit %.0f N, gain %.4g: the logged drive reaches %.1f N, %zu samples beyond the limit\n", limit, gain, logged, beyond);
      EXPECT_GE(logged, 1.2 * limit) << "limit " << limit << ": the logged drive reaches only " << logged << " N";
      EXPECT_GE(beyond, 100u) << "limit " << limit << ": only " << beyond << " samples beyond it";
    }
  }
}

TEST(DriveGenerator, RefusesWhatItCannotSimulate) {
  auto refused = [](auto change) {
    DriveRecordSpec spec = emps_like(1);
    spec.trajectory.duration = 1;
    change(spec);
    EXPECT_THROW(generated_data::generate_drive_record(spec), std::invalid_argument);
  };
  refused([](DriveRecordSpec& s) { s.plant.mass = 0; });
  refused([](DriveRecordSpec& s) { s.plant.viscous = -1; });
  refused([](DriveRecordSpec& s) { s.plant.coulomb = -1; });
  refused([](DriveRecordSpec& s) { s.plant.saturation = 0; });
  refused([](DriveRecordSpec& s) { s.plant.delay = -1e-3; });
  refused([](DriveRecordSpec& s) { s.controller.period = 0; });
  refused([](DriveRecordSpec& s) { s.gain = 0; });
  refused([](DriveRecordSpec& s) { s.trajectory.high = s.trajectory.low; });
}

// ------------------------------------------------------------------ the workflow's runs

struct Level {
  std::string name;
  double quantum, force_noise, log_noise;  // [m], [N], [N] (divided by the gain in the log)
};

const std::vector<Level>& levels() {
  static const std::vector<Level> all{{"fine", 5e-8, 0, 0}, {"coarse", 1e-6, 0.3, 0.2}};
  return all;
}

struct Hidden {
  double coulomb = 0, offset = 0, saturation = kInfinity, delay = 0;
};

struct Scenario {
  std::string name;
  std::vector<Hidden> variants;       // one record per variant and level
  std::vector<std::string> expected;  // the effects to be named
  bool end_in_motion = false;
  std::vector<std::size_t> trajectories;  // if given: the first variant on each of these k at each level
};

const Scenario& scenario(const std::string& name) {
  static const std::map<std::string, Scenario> all = [] {
    std::map<std::string, Scenario> s;
    auto add = [&](const Scenario& x) { s[x.name] = x; };
    Hidden emps, weak, strong, coulomb, offset, delay_short, delay_long, saturation_high, saturation_low;
    emps.coulomb = 20, emps.offset = 3.2;  // EMPS's Fc and −OFF
    weak.coulomb = 8, weak.offset = -4.5;
    strong.coulomb = 35, strong.offset = 1.5;
    coulomb.coulomb = 15;
    offset.offset = -3.5;
    delay_short.delay = 0.0032, delay_long.delay = 0.0068;
    saturation_high.saturation = 90, saturation_low.saturation = 75;
    add({"CoulombAndOffset", {emps, strong}, {"coulomb_motor", "torque_offset"}, false, {}});
    add({"WeakCoulombAndOffset", {weak}, {"coulomb_motor", "torque_offset"}, false, {0, 1, 2, 3, 4}});
    add({"Coulomb", {coulomb}, {"coulomb_motor"}, false, {}});
    add({"Offset", {offset}, {"torque_offset"}, false, {}});
    add({"Delay", {delay_short, delay_long}, {"delay"}, false, {}});
    add({"Saturation", {saturation_high, saturation_low}, {"saturation"}, false, {}});
    add({"Clean", {Hidden{}, Hidden{}}, {}, false, {}});
    add({"EndsInMotion", {Hidden{}}, {}, true, {}});
    return s;
  }();
  return all.at(name);
}

struct Run {
  std::string label;
  Hidden truth;
  DriveRecord estimation, validation;
  discrepancy::DriveDiscrepancyResult result;      // the workflow, from the nominal model
  discrepancy::DriveDiscrepancyResult true_model;  // the truth scored the same way (nothing fitted, no candidate)
};

// A model file: J and F, the effects given, [fit] free = J and F or nothing.
model::CaseSpec drive_model(double J, double F, double gain, const Hidden& effects, bool free) {
  static std::atomic<int> counter{0};
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("backlash_check_drive_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + ".toml");
  {
    std::ofstream out(file);
    char text[1024];
    std::snprintf(text, sizeof text,
                  "name = \"generated drive\"\nmeasured_at = \"motor\"\nbacklash = 0\nreference = 0\n"
                  "[motor]\nJ = %.17g\nF = %.17g\n[load]\nJ = 1e-9\nF = 0\n[experiment]\nkind = \"drive\"\ndrive_gain = %.17g\n"
                  "[effects]\ncoulomb_motor = %.17g\ntorque_offset = %.17g\ndelay = %.17g\n",
                  J, F, gain, effects.coulomb, effects.offset, effects.delay);
    out << text;
    if (std::isfinite(effects.saturation)) {
      std::snprintf(text, sizeof text, "saturation = %.17g\n", effects.saturation);
      out << text;
    }
    if (free) out << "[fit]\nfree = [\"motor.J\", \"motor.F\"]\n";
  }
  model::CaseSpec spec = model::load_case_file(file);
  std::filesystem::remove(file);
  return spec;
}

// `k` picks the trajectory, the noise, the gain (even: N, odd: V) and the nominal error
// (even: J 30 % and F 25 % low; odd: J 30 % and F 35 % high).
Run make_run(const Scenario& s, std::size_t variant, const Level& level, std::size_t k) {
  Run run;
  run.truth = s.variants[variant];
  DriveRecordSpec spec = emps_like(11 + k);
  spec.plant.coulomb = run.truth.coulomb;
  spec.plant.offset = run.truth.offset;
  spec.plant.saturation = run.truth.saturation;
  spec.plant.delay = run.truth.delay;
  spec.trajectory.duration = 12;
  spec.trajectory.end_in_motion = s.end_in_motion;
  spec.gain = k % 2 == 0 ? 1 : kVoltsGain;
  spec.quantum = level.quantum;
  spec.force_noise = level.force_noise;
  spec.log_noise = level.log_noise / spec.gain;
  spec.seed = 101 + k;
  run.estimation = generated_data::generate_drive_record(spec);
  DriveRecordSpec other = spec;  // the validation record: another trajectory, other noise
  other.trajectory.seed += 1000;
  other.trajectory.duration = 8;
  other.trajectory.end_in_motion = false;
  other.seed += 1000;
  run.validation = generated_data::generate_drive_record(other);
  const double J = (k % 2 == 0 ? 0.7 : 1.3) * kMass, F = (k % 2 == 0 ? 0.75 : 1.35) * kViscous;
  run.label = s.name + " #" + std::to_string(variant) + " " + level.name + " k" + std::to_string(k) + (spec.gain == 1 ? " (N)" : " (V)");
  run.result = discrepancy::find_drive_discrepancy(drive_model(J, F, spec.gain, Hidden{}, true), run.estimation.record, {},
                                                   &run.validation.record);
  discrepancy::DriveOptions nothing;
  nothing.candidates = {};
  run.true_model = discrepancy::find_drive_discrepancy(drive_model(kMass, kViscous, spec.gain, run.truth, false),
                                                       run.estimation.record, nothing, &run.validation.record);
  return run;
}

// The runs of a scenario, made once per process.
const std::vector<Run>& runs_of(const std::string& name) {
  static std::map<std::string, std::vector<Run>> cache;
  const auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  const Scenario& s = scenario(name);
  std::vector<std::size_t> level_indices{0, 1}, variants;
  for (std::size_t v = 0; v < s.variants.size(); ++v) variants.push_back(v);
#ifdef BACKLASH_REDUCED_SUITE  // sanitizer builds: the first variant at the coarse level (the full suite runs in Release)
  level_indices = {1};
  variants = {0};
#endif
  std::vector<Run> runs;
  for (std::size_t l : level_indices) {
    if (!s.trajectories.empty()) {
#ifdef BACKLASH_REDUCED_SUITE
      runs.push_back(make_run(s, 0, levels()[l], s.trajectories.front()));
#else
      for (std::size_t k : s.trajectories) runs.push_back(make_run(s, 0, levels()[l], k));
#endif
      continue;
    }
    for (std::size_t v : variants) runs.push_back(make_run(s, v, levels()[l], v + 3 * l));
  }
  return cache[name] = std::move(runs);
}

// ------------------------------------------------------------------ what was fitted

struct Fitted {
  std::string name;
  double truth, value, sigma;
};

// J and F (the corrected model's when an effect was named, else the best nominal one's) and
// every named effect's parameter, against the truth.
std::vector<Fitted> fitted_parameters(const Run& run) {
  const discrepancy::DriveDiscrepancyResult& r = run.result;
  std::vector<Fitted> out;
  for (const discrepancy::Parameter& p : r.effects.empty() ? r.nominal_fit : r.corrected_nominal) {
    if (p.name == "motor.J") out.push_back({"J", kMass, p.value + 1e-9, p.uncertainty});  // + the load's J
    if (p.name == "motor.F") out.push_back({"F", kViscous, p.value, p.uncertainty});
  }
  for (const discrepancy::Candidate& c : r.effects) {
    const discrepancy::Parameter& p = c.parameters.front();
    if (c.effect == "coulomb_motor") out.push_back({"Tc", run.truth.coulomb, p.value, p.uncertainty});
    if (c.effect == "torque_offset") out.push_back({"T0", run.truth.offset, p.value, p.uncertainty});
    if (c.effect == "delay") out.push_back({"tau", run.truth.delay, p.value, p.uncertainty});
    if (c.effect == "saturation") out.push_back({"L", run.truth.saturation, p.value, p.uncertainty});
  }
  return out;
}

std::vector<std::string> named(const Run& run) {
  std::vector<std::string> out;
  for (const discrepancy::Candidate& c : run.result.effects) out.push_back(c.effect);
  std::sort(out.begin(), out.end());
  return out;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "(none)" : out;
}

// One run as rows of the report's table; BACKLASH_DRIVE_ROUNDS=1 adds every candidate.
void print(const Run& run) {
  const discrepancy::DriveDiscrepancyResult& r = run.result;
  const discrepancy::DriveDiscrepancyResult& t = run.true_model;
  std::printf("%-34s %-14s named %s\n", run.label.c_str(), discrepancy::to_string(r.status), joined(named(run)).c_str());
  std::printf("    torque RMS %.3g -> %.3g (truth %.3g, noise %.3g); position RMS %.3g -> %.3g (truth %.3g)\n", r.rms_before, r.rms_after,
              t.rms_before, r.noise, r.estimation.position_rms_nominal, r.estimation.position_rms_corrected,
              t.estimation.position_rms_nominal);
  std::printf("    validation: torque RMS %.3g -> %.3g (truth %.3g); position RMS %.3g -> %.3g (truth %.3g)\n",
              r.validation->torque_rms_nominal, r.validation->torque_rms_corrected, t.validation->torque_rms_nominal,
              r.validation->position_rms_nominal, r.validation->position_rms_corrected, t.validation->position_rms_nominal);
  if (std::getenv("BACKLASH_DRIVE_ROUNDS"))
    for (std::size_t i = 0; i < r.rounds.size(); ++i)
      for (const discrepancy::Candidate& c : r.rounds[i])
        std::printf("    round %zu %-14s %s = %-10.4g dBIC %-8.1f rms %.3g holdout %.3g%s%s %s\n", i, c.effect.c_str(),
                    c.parameters.empty() ? "-" : c.parameters[0].name.c_str(), c.parameters.empty() ? NAN : c.parameters[0].value,
                    c.delta_bic, c.rms, c.rms_holdout, c.decisive ? " decisive" : "", c.at_range_edge ? " at-edge" : "", c.failure.c_str());
  for (const Fitted& f : fitted_parameters(run))
    std::printf("    %-4s truth %-10.6g fitted %-11.6g ± %-9.3g |error|/sigma %.2f\n", f.name.c_str(), f.truth, f.value, f.sigma,
                std::fabs(f.value - f.truth) / f.sigma);
}

// ------------------------------------------------------------------ the checks

void expect_named(const std::string& scenario_name) {
  std::vector<std::string> expected = scenario(scenario_name).expected;
  std::sort(expected.begin(), expected.end());
  for (const Run& run : runs_of(scenario_name)) {
    print(run);
    EXPECT_EQ(named(run), expected) << run.label << ": named " << joined(named(run)) << " instead of " << joined(expected);
    if (expected.empty())
      EXPECT_NE(run.result.status, discrepancy::Status::EffectFound)
          << run.label << ": returned " << discrepancy::to_string(run.result.status) << " instead of no_discrepancy or unexplained";
    else
      EXPECT_EQ(run.result.status, discrepancy::Status::EffectFound)
          << run.label << ": returned " << discrepancy::to_string(run.result.status) << " instead of effect_found";
  }
}

void expect_fitted(const std::string& scenario_name) {
  for (const Run& run : runs_of(scenario_name)) {
    print(run);
    const std::vector<Fitted> fitted = fitted_parameters(run);
    EXPECT_GE(fitted.size(), 2u) << run.label << ": J and F were not fitted";
    for (const Fitted& f : fitted) {
      EXPECT_TRUE(std::isfinite(f.sigma) && f.sigma > 0) << run.label << ": " << f.name << " returned the uncertainty " << f.sigma;
      EXPECT_LE(std::fabs(f.value - f.truth), kSigmas * f.sigma)
          << run.label << ": " << f.name << " returned " << f.value << " ± " << f.sigma << " instead of " << f.truth << " (within "
          << kSigmas << " sigma)";
    }
  }
}

void expect_improves(const std::string& scenario_name) {
  for (const Run& run : runs_of(scenario_name)) {
    print(run);
    const discrepancy::DriveDiscrepancyResult& r = run.result;
    ASSERT_TRUE(r.validation.has_value()) << run.label;
    EXPECT_GE(r.rms_before, kTorqueShrink * r.rms_after) << run.label << ": the torque RMS returned " << r.rms_after
                                                         << " instead of at most " << r.rms_before / kTorqueShrink;
    EXPECT_GE(r.estimation.position_rms_nominal, kPositionShrink * r.estimation.position_rms_corrected)
        << run.label << ": the position-window RMS returned " << r.estimation.position_rms_corrected << " instead of at most "
        << r.estimation.position_rms_nominal / kPositionShrink;
    EXPECT_GE(r.validation->torque_rms_nominal, kTorqueShrink * r.validation->torque_rms_corrected)
        << run.label << ": on the validation record the torque RMS returned " << r.validation->torque_rms_corrected
        << " instead of at most " << r.validation->torque_rms_nominal / kTorqueShrink;
    EXPECT_GE(r.validation->position_rms_nominal, kPositionShrink * r.validation->position_rms_corrected)
        << run.label << ": on the validation record the position-window RMS returned " << r.validation->position_rms_corrected
        << " instead of at most " << r.validation->position_rms_nominal / kPositionShrink;
  }
}

void expect_matches_truth(const std::string& scenario_name) {
  for (const Run& run : runs_of(scenario_name)) {
    print(run);
    const discrepancy::DriveDiscrepancyResult& r = run.result;
    const discrepancy::DriveDiscrepancyResult& t = run.true_model;
    EXPECT_LE(r.rms_after, kTruthTorque * t.rms_before)
        << run.label << ": the torque RMS returned " << r.rms_after << " instead of at most " << kTruthTorque << " x the truth's "
        << t.rms_before;
    EXPECT_LE(r.estimation.position_rms_corrected, kTruthPosition * t.estimation.position_rms_nominal)
        << run.label << ": the position-window RMS returned " << r.estimation.position_rms_corrected << " instead of at most "
        << kTruthPosition << " x the truth's " << t.estimation.position_rms_nominal;
    EXPECT_LE(r.validation->position_rms_corrected, kTruthPosition * t.validation->position_rms_nominal)
        << run.label << ": on the validation record the position-window RMS returned " << r.validation->position_rms_corrected
        << " instead of at most " << kTruthPosition << " x the truth's " << t.validation->position_rms_nominal;
  }
}

// ------------------------------------------------------------------ the tests

TEST(DriveWorkflow, CoulombAndOffsetNamed) { expect_named("CoulombAndOffset"); }
TEST(DriveWorkflow, CoulombAndOffsetFitted) { expect_fitted("CoulombAndOffset"); }
TEST(DriveWorkflow, CoulombAndOffsetImproves) { expect_improves("CoulombAndOffset"); }
TEST(DriveWorkflow, CoulombAndOffsetMatchesTruth) { expect_matches_truth("CoulombAndOffset"); }

TEST(DriveWorkflow, WeakCoulombAndOffsetNamed) { expect_named("WeakCoulombAndOffset"); }
TEST(DriveWorkflow, WeakCoulombAndOffsetFitted) { expect_fitted("WeakCoulombAndOffset"); }
TEST(DriveWorkflow, WeakCoulombAndOffsetImproves) { expect_improves("WeakCoulombAndOffset"); }
TEST(DriveWorkflow, WeakCoulombAndOffsetMatchesTruth) { expect_matches_truth("WeakCoulombAndOffset"); }

TEST(DriveWorkflow, CoulombNamed) { expect_named("Coulomb"); }
TEST(DriveWorkflow, CoulombFitted) { expect_fitted("Coulomb"); }
TEST(DriveWorkflow, CoulombImproves) { expect_improves("Coulomb"); }
TEST(DriveWorkflow, CoulombMatchesTruth) { expect_matches_truth("Coulomb"); }

TEST(DriveWorkflow, OffsetNamed) { expect_named("Offset"); }
TEST(DriveWorkflow, OffsetFitted) { expect_fitted("Offset"); }
TEST(DriveWorkflow, OffsetImproves) { expect_improves("Offset"); }
TEST(DriveWorkflow, OffsetMatchesTruth) { expect_matches_truth("Offset"); }

TEST(DriveWorkflow, DelayNamed) { expect_named("Delay"); }
TEST(DriveWorkflow, DelayFitted) { expect_fitted("Delay"); }
TEST(DriveWorkflow, DelayImproves) { expect_improves("Delay"); }
TEST(DriveWorkflow, DelayMatchesTruth) { expect_matches_truth("Delay"); }

TEST(DriveWorkflow, SaturationNamed) { expect_named("Saturation"); }
TEST(DriveWorkflow, SaturationFitted) { expect_fitted("Saturation"); }
TEST(DriveWorkflow, SaturationImproves) { expect_improves("Saturation"); }
TEST(DriveWorkflow, SaturationMatchesTruth) { expect_matches_truth("Saturation"); }

TEST(DriveWorkflow, CleanNamesNothing) { expect_named("Clean"); }
TEST(DriveWorkflow, CleanFitted) { expect_fitted("Clean"); }
TEST(DriveWorkflow, CleanMatchesTruth) { expect_matches_truth("Clean"); }

TEST(DriveWorkflow, EndsInMotionNamesNothing) { expect_named("EndsInMotion"); }
TEST(DriveWorkflow, EndsInMotionFitted) { expect_fitted("EndsInMotion"); }

}  // namespace
