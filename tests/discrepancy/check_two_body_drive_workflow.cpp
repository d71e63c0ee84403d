// Issue 22: backlash from a logged drive.  The measured-drive workflow on the two-body model
// with its gap (`[experiment] kind = "drive"`, `backlash > 0`; docs/discrepancy.md,
// "Measured-drive records"), run through the command line
//   backlash discrepancy --model M.toml --data D.csv --json
// on records of an INDEPENDENT generator (two_body_generator.hpp: two inertias with a gap,
// rigid teeth or a compliant mesh, Coulomb friction with sticking on either body, a P/PI
// position loop on the quantised motor or load encoder, the logged current with noise,
// integrated by Boost.Odeint with its own event logic — nothing of numeric/ or discrepancy/).
//
// TwoBodyGenerator: the generator itself — contact and flight times of a hand-solved
// free-flight case, a hand-solved Coulomb stop and stick, the energy balance of closed-loop runs (rigid impacts, a compliant mesh,
// Coulomb friction on both bodies), the gap held within its faces, the log's form
// (encoder counts, reversals, the CSV's columns, the model file), a bad spec refused.
//
// TwoBodyDriveWorkflow: the model file states the nominal plant with the backlash (and, where
// a correction is tested, the load's J and F) off and lists them in [fit] free; the record has
// both encoders or the motor encoder alone.  Recovered, with their reported σ:
//   item1_backlash_*        the backlash, 0.1° to 20° and the thesis's 0.3 rad, within
//                           max(5 %, 3σ) with both encoders and with the motor encoder alone
//                           (with both encoders and the loop on the load: 5° and 20°);
//   item3_load_*            the load's inertia and viscous friction within 10 %;
//   item3_mesh_stiffness    a compliant mesh named (`compliance`) with its stiffness within 10 %
//                           (both encoders; with the motor encoder alone not fitted, documented,
//                           and the backlash still within max(5 %, 3σ));
//   item3_coulomb_each_side Coulomb friction on the motor and on the load named, each within 10 %;
//   item1_rigid_drive       a record without a gap (backlash 0 in the generator) against a model
//                           with one: the backlash fitted ≈ 0 (within 3σ or 2 encoder counts);
//   item1_missing_columns   a model with a gap and a record without the columns it needs
//                           (the rigid `t,theta_out,drive`; no drive) refused: exit 2, one line
//                           naming the file, the line and the column, nothing written.
// The default set runs a few records per item (≤ ~60 s in Release); BACKLASH_TWO_BODY_MATRIX=1
// runs every backlash size with both encoder setups and both loops (bench/two_body_drive_matrix.sh
// prints the table).
#include "two_body_generator.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace backlash::generated_data;
using nlohmann::json;

constexpr double kDegree = M_PI / 180;

// ------------------------------------------------------------------ the generator

// Rigid teeth, no friction, the load at rest in the middle of the gap, a constant torque u on
// the motor: it crosses half the gap in t1 = sqrt(b·Jm/u) (θm = u·t²/(2Jm) = b/2) and hits the
// load, both then move at ω = u·t1/(Jm + JL); the torque reversed at t2 parts them at once
// (the motor pulls away from the face) and the motor crosses the whole gap relative to the
// coasting load in sqrt(2·b·Jm/u).
TEST(TwoBodyGenerator, HandSolvedFreeFlight) {
  TwoBodyPlant p;
  p.Jm = 0.01, p.JL = 0.03, p.Fm = 0, p.FL = 0, p.backlash = 0.05;
  const double u = 0.2, t2 = 0.2;
  std::vector<double> t, torque;
  for (int k = 0; k <= 400; ++k) t.push_back(1e-3 * k), torque.push_back(k < 200 ? u : -u);
  const TwoBodyRun run = simulate_two_body(p, t, torque, {});
  const double t1 = std::sqrt(p.backlash * p.Jm / u), w1 = u * t1 / (p.Jm + p.JL);
  const double t3 = t2 + std::sqrt(2 * p.backlash * p.Jm / u);
  ASSERT_EQ(run.events.contact_times.size(), 2u) << "expected an impact at " << t1 << " s and one at " << t3 << " s";
  ASSERT_EQ(run.events.separation_times.size(), 1u);
  EXPECT_NEAR(run.events.contact_times[0], t1, 1e-12);
  EXPECT_NEAR(run.events.separation_times[0], t2, 1e-15);
  EXPECT_NEAR(run.events.contact_times[1], t3, 1e-12);
  // Just before t2: in contact, ω = w1 + u·(t − t1)/(Jm + JL), the gap on face −b/2.
  const TwoBodyState& s = run.state[199];
  EXPECT_NEAR(s.omega_m, w1 + u * (t[199] - t1) / (p.Jm + p.JL), 1e-12);
  EXPECT_NEAR(s.omega_l, s.omega_m, 1e-15);
  EXPECT_NEAR(s.theta_l - s.theta_m, -p.backlash / 2, 1e-15);
  // Losses: the two impacts' ½·Jm·JL/(Jm + JL)·Δω², the rest the kinetic energy.
  EXPECT_NEAR(run.energy.work, run.energy.kinetic + run.energy.impact_losses, 1e-12 * run.energy.work);
  EXPECT_NEAR(run.energy.impact_losses - 0.5 * p.Jm * p.JL / (p.Jm + p.JL) * (u * t1 / p.Jm) * (u * t1 / p.Jm),
              0.5 * p.Jm * p.JL / (p.Jm + p.JL) * std::pow(u * (t3 - t2) / p.Jm, 2), 1e-12);
}

// Coulomb friction on the load alone: the motor (torque u until t2, then none) hits the stuck
// load at t1 = sqrt(b·Jm/u), pushes it (J·ω' = u − CL), then coasts pushing it (the load's
// friction keeps the contact: J·ω' = −CL) until both stop and stick at t2 + ω2·J/CL, where they
// stay (no torque): θ = θ(t2) + ω2²·J/(2·CL).
TEST(TwoBodyGenerator, HandSolvedCoulombStop) {
  TwoBodyPlant p;
  p.Jm = 0.01, p.JL = 0.03, p.Fm = 0, p.FL = 0, p.backlash = 0.05, p.coulomb_load = 0.03;
  const double u = 0.2, t2 = 0.2, J = p.Jm + p.JL, CL = p.coulomb_load;
  std::vector<double> t, torque;
  for (int k = 0; k <= 1500; ++k) t.push_back(1e-3 * k), torque.push_back(k < 200 ? u : 0);
  const TwoBodyRun run = simulate_two_body(p, t, torque, {});
  const double t1 = std::sqrt(p.backlash * p.Jm / u), w2 = u * t1 / J + (u - CL) * (t2 - t1) / J;
  const double stop = t2 + w2 * J / CL;
  ASSERT_EQ(run.events.impacts, 1);
  EXPECT_EQ(run.events.sticks, 1);
  EXPECT_EQ(run.events.separations, 0);
  EXPECT_NEAR(run.state[200].omega_m, w2, 1e-12);
  const std::size_t before = static_cast<std::size_t>(std::floor(stop * 1e3));
  EXPECT_NEAR(run.state[before].omega_l, w2 - CL / J * (t[before] - t2), 1e-12);
  EXPECT_EQ(run.state.back().omega_m, 0.0);
  EXPECT_EQ(run.state.back().omega_l, 0.0);
  EXPECT_NEAR(run.state.back().theta_m - run.state[200].theta_m, w2 * w2 * J / (2 * CL), 1e-12);
  EXPECT_NEAR(run.energy.work, run.energy.kinetic + run.energy.dissipated + run.energy.impact_losses, 1e-8 * run.energy.work);  // ∫CL·|ω| at odeint's tolerance
}

// Every run: the motor's work = the kinetic and spring energy gained + the viscous, Coulomb
// and mesh-damping losses + the impacts' + what a released overlapping mesh leaves behind.
TEST(TwoBodyGenerator, EnergyBalances) {
  struct Case {
    const char* name;
    double stiffness, damping, coulomb_motor, coulomb_load;
    bool on_load;
  };
  for (const Case& c : {Case{"rigid teeth", kRigid, 0, 0, 0, false}, Case{"rigid, Coulomb both", kRigid, 0, 0.05, 0.08, false},
                        Case{"compliant mesh", 2000, 3, 0, 0, false}, Case{"compliant, Coulomb both", 2000, 3, 0.05, 0.08, false},
                        Case{"compliant, loop on the load", 5000, 2, 0.02, 0.03, true}}) {
    TwoBodyRecordSpec spec = standard_record_spec(3 * kDegree);
    spec.plant.stiffness = c.stiffness, spec.plant.damping = c.damping;
    spec.plant.coulomb_motor = c.coulomb_motor, spec.plant.coulomb_load = c.coulomb_load;
    spec.loop.on_load = c.on_load;
    const TwoBodyRecord r = generate_two_body_record(spec);
    const TwoBodyEnergy& e = r.energy;
    const double balance = e.work - e.kinetic - e.dissipated - e.impact_losses - e.release_losses;
    std::printf("%-28s work %.6f J, kinetic+spring %.3g, dissipated %.6f, impacts %.6f, releases %.3g: off by %.2g J; "
                "%d impacts, %d engagements, %d sticks, %d breakaways, %d reversals, %ld steps\n",
                c.name, e.work, e.kinetic, e.dissipated, e.impact_losses, e.release_losses, balance, r.events.impacts,
                r.events.engagements, r.events.sticks, r.events.breakaways, r.reversals, r.events.steps);
    EXPECT_LE(std::fabs(balance), 1e-7 * e.work) << c.name;  // odeint at 1e-11 over ~1e4 steps
    EXPECT_GT(r.events.impacts + r.events.engagements, r.reversals) << c.name << ": the teeth did not meet at every reversal";
    EXPECT_GE(r.reversals, 5) << c.name;
    if (c.coulomb_motor > 0) {
      EXPECT_GT(r.events.sticks + r.events.breakaways, 0) << c.name << ": no body ever stuck";
    }
  }
}

// The gap stays between its faces (rigid teeth), the bodies cross it at every reversal, the
// encoders give whole counts, the record has its reversals, and it is the same every time.
TEST(TwoBodyGenerator, GapLogAndReversals) {
  TwoBodyRecordSpec spec = standard_record_spec(5 * kDegree);
  spec.plant.coulomb_load = 0.05;
  const TwoBodyRecord a = generate_two_body_record(spec), b = generate_two_body_record(spec);
  EXPECT_EQ(a.drive, b.drive);
  EXPECT_EQ(a.theta_load, b.theta_load);
  const double q = 2 * M_PI / spec.counts_per_rev, half = spec.plant.backlash / 2;
  double low = 0, high = 0;
  for (std::size_t k = 0; k < a.t.size(); ++k) {
    const double x = a.state[k].theta_l - a.state[k].theta_m;
    low = std::min(low, x), high = std::max(high, x);
    ASSERT_LE(std::fabs(x), half * (1 + 1e-12)) << "the gap left its faces at t = " << a.t[k];
    for (double y : {a.theta_motor[k], a.theta_load[k]}) {
      ASSERT_NEAR(y / q, std::round(y / q), 1e-6);
    }
    ASSERT_LE(std::fabs(a.theta_motor[k] - a.state[k].theta_m), q / 2 * (1 + 1e-9));
  }
  EXPECT_NEAR(low, -half, 1e-12) << "the motor never pushed forward";
  EXPECT_NEAR(high, half, 1e-12) << "the motor never pushed backward";
  EXPECT_GE(a.reversals, 5);
  EXPECT_EQ(a.reversals, spec.reference.moves - 1);
  const std::string both = two_body_csv(a, true), motor = two_body_csv(a, false);
  EXPECT_EQ(both.substr(0, both.find('\n')), "t,theta_motor,theta_load,drive");
  EXPECT_EQ(motor.substr(0, motor.find('\n')), "t,theta_motor,drive");
  EXPECT_EQ(static_cast<std::size_t>(std::count(motor.begin(), motor.end(), '\n')), a.t.size() + 1);
  TwoBodyCase model;
  model.nominal = spec.plant;
  model.nominal.stiffness = 3000;
  model.free = {"backlash", "load.J"};
  const std::string toml = two_body_case_toml(model);
  for (const char* line : {"kind = \"drive\"", "backlash = 0.08726646259971647", "coulomb_load = 0.05",
                           "compliance = { stiffness = 3000, damping = 0 }", "free = [\"backlash\", \"load.J\"]"})
    EXPECT_NE(toml.find(line), std::string::npos) << "the model file lacks " << line << ":\n" << toml;
}

TEST(TwoBodyGenerator, RefusesWhatItCannotSimulate) {
  auto refused = [](auto change) {
    TwoBodyRecordSpec spec = standard_record_spec(kDegree);
    change(spec);
    EXPECT_THROW(generate_two_body_record(spec), std::invalid_argument);
  };
  refused([](TwoBodyRecordSpec& s) { s.plant.Jm = 0; });
  refused([](TwoBodyRecordSpec& s) { s.plant.JL = -1; });
  refused([](TwoBodyRecordSpec& s) { s.plant.backlash = -1e-3; });
  refused([](TwoBodyRecordSpec& s) { s.plant.stiffness = 0; });
  refused([](TwoBodyRecordSpec& s) { s.plant.coulomb_load = -1; });
  refused([](TwoBodyRecordSpec& s) { s.loop.period = 0; });
  refused([](TwoBodyRecordSpec& s) { s.gain = 0; });
  refused([](TwoBodyRecordSpec& s) { s.reference.moves = 0; });
  refused([](TwoBodyRecordSpec& s) { s.reference.amplitude = 0.01; });  // shorter than its ramps
}

// ------------------------------------------------------------------ the workflow, by the command line

struct CommandRun {
  int exit_code;
  std::string out, err;
};

CommandRun run_command(const std::string& arguments) {
  const std::string err_file =
      (fs::temp_directory_path() / ("backlash-two-body-" + std::to_string(::getpid()) + ".err")).string();
  const std::string command = std::string(BACKLASH_CLI) + " " + arguments + " 2> " + err_file;
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  std::ifstream in(err_file);
  std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(err_file);
  return {WEXITSTATUS(status), out, err};
}

class Folder {
 public:
  Folder() {
    std::random_device entropy;
    path_ = fs::temp_directory_path() / ("backlash-two-body-" + std::to_string(::getpid()) + "-" + std::to_string(entropy()));
    fs::create_directory(path_);
  }
  ~Folder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

struct Drive {
  std::string label;
  TwoBodyRecordSpec spec;
  TwoBodyCase model;
  bool both_encoders = true;
};

// The workflow's JSON on the drive (exit 0 expected).
json run_workflow(const Drive& d) {
  Folder folder;
  const TwoBodyRecord record = generate_two_body_record(d.spec);
  const fs::path data = folder / "record.csv", model = folder / "model.toml";
  write_text_file(data, two_body_csv(record, d.both_encoders));
  write_text_file(model, two_body_case_toml(d.model));
  const CommandRun r = run_command("discrepancy --model " + model.string() + " --data " + data.string() + " --json");
  EXPECT_EQ(r.exit_code, 0) << d.label << ": exit " << r.exit_code << ", stderr: " << r.err;
  if (r.exit_code != 0) return json();
  return json::parse(r.out, nullptr, false);
}

struct Estimate {
  bool found = false;
  double value = 0, sigma = 0;
};

Estimate correction(const json& result, const std::string& key) {
  if (!result.is_object() || !result.contains("parameter_corrections")) return {};
  for (const json& c : result["parameter_corrections"])
    if (c.value("key", "") == key) return {true, c.value("fitted", 0.0), c.value("sigma", 0.0)};
  return {};
}

Estimate effect(const json& result, const std::string& name, const std::string& parameter) {
  if (!result.is_object() || !result.contains("effects")) return {};
  for (const json& e : result["effects"])
    if (e.value("effect", "") == name && e["parameters"].contains(parameter))
      return {true, e["parameters"][parameter].get<double>(), e["uncertainty"].value(parameter, 0.0)};
  return {};
}

std::string status(const json& result) { return result.is_object() ? result.value("status", "") : ""; }

// A drive: the truth in the generator, the model file with the backlash `backlash_off` times the
// truth, free to be fitted; the loop on the motor or the load encoder.
Drive drive(double backlash, bool both_encoders, bool on_load = false, std::uint64_t seed = 1) {
  Drive d;
  d.spec = standard_record_spec(backlash);
  d.spec.loop.on_load = on_load;
  d.spec.seed = seed;
  if (backlash > 0.2) d.spec.reference.amplitude = 1.2;  // the moves well beyond the gap
  d.model.nominal = d.spec.plant;
  d.model.nominal.backlash = (seed % 2 == 1 ? 1.4 : 0.7) * backlash;
  d.model.free = {"backlash"};
  d.both_encoders = both_encoders;
  char label[160];
  std::snprintf(label, sizeof label, "backlash %.4g deg, %s, loop on the %s", backlash / kDegree,
                both_encoders ? "both encoders" : "motor encoder", on_load ? "load" : "motor");
  d.label = label;
  return d;
}

// |fitted − truth| ≤ max(5 % of the truth, 3σ): the criterion.
void expect_backlash_recovered(const Drive& d, double truth) {
  const json result = run_workflow(d);
  const Estimate b = correction(result, "backlash");
  std::printf("%-52s true %.6g rad, fitted %.6g ± %.2g rad (%+.2f %%), status %s\n", d.label.c_str(), truth, b.value, b.sigma,
              100 * (b.value / truth - 1), status(result).c_str());
  ASSERT_TRUE(b.found) << d.label << ": no backlash among the parameter corrections";
  EXPECT_GT(b.sigma, 0) << d.label << ": the backlash has no uncertainty";
  EXPECT_LE(std::fabs(b.value - truth), std::max(0.05 * truth, 3 * b.sigma))
      << d.label << ": fitted " << b.value << " ± " << b.sigma << " rad, the truth " << truth << " rad";
}

bool full_matrix() {
  const char* v = std::getenv("BACKLASH_TWO_BODY_MATRIX");
  return v != nullptr && std::string(v) == "1";
}

const std::vector<double>& backlash_sizes() {
#ifdef BACKLASH_REDUCED_SUITE  // sanitizer builds: the smallest and the thesis's (the full set runs in Release)
  static const std::vector<double> all{0.1 * kDegree, 0.3};
#else
  static const std::vector<double> all{0.1 * kDegree, 1 * kDegree, 5 * kDegree, 20 * kDegree, 0.3};
#endif
  return all;
}

TEST(TwoBodyDriveWorkflow, item1_backlash_both_encoders) {
  for (double b : backlash_sizes()) expect_backlash_recovered(drive(b, true), b);
  if (full_matrix())
    for (double b : backlash_sizes()) expect_backlash_recovered(drive(b, true, true, 2), b);
}

// Both encoders, the position loop closed on the LOAD encoder: the loop hunts in the gap, the
// motor pushing the load in strokes (60–90 ms) shorter than the filter's length (about 100 ms at
// the spectrum's 82 Hz cut-off), so no contact stretch outlasts the filter.  Read on the filtered
// gap, from 5° up the steady samples lay on one face only: the backlash came out 0 at 5° and the
// record was refused at 20° and 0.3 rad ("shows no contact plateau").  Now read on the raw gap
// (docs/discrepancy.md, "Both encoders: the gap is observed").  5° and 20° here (a few seconds
// each); every size with BACKLASH_TWO_BODY_MATRIX=1.
TEST(TwoBodyDriveWorkflow, item1_backlash_both_encoders_loop_on_load) {
  for (double b : {5 * kDegree, 20 * kDegree}) expect_backlash_recovered(drive(b, true, true, 2), b);
}

// With the motor encoder alone every size, 1° included (it was +6.35 %, about 8 σ, before the
// observer read its separations on the logged drive and its impacts on the encoder's counts).
TEST(TwoBodyDriveWorkflow, item1_backlash_motor_encoder_alone) {
  for (double b : backlash_sizes()) expect_backlash_recovered(drive(b, false), b);
  if (full_matrix())
    for (double b : backlash_sizes()) expect_backlash_recovered(drive(b, false, true, 2), b);
}

// The load's inertia and viscous friction 30 % high and 25 % low in the model, free.
TEST(TwoBodyDriveWorkflow, item3_load_inertia_and_friction) {
  for (bool both : {true, false}) {
    Drive d = drive(2 * kDegree, both);
    d.model.nominal.JL *= 1.3;
    d.model.nominal.FL *= 0.75;
    d.model.free = {"backlash", "load.J", "load.F"};
    const json result = run_workflow(d);
    for (const auto& [key, truth] : {std::pair<std::string, double>{"load.J", d.spec.plant.JL}, {"load.F", d.spec.plant.FL}}) {
      const Estimate e = correction(result, key);
      std::printf("%-52s %s true %.6g, fitted %.6g ± %.2g\n", d.label.c_str(), key.c_str(), truth, e.value, e.sigma);
      ASSERT_TRUE(e.found) << d.label << ": no correction of " << key;
      EXPECT_LE(std::fabs(e.value / truth - 1), 0.10) << d.label << ": " << key << " fitted " << e.value << ", the truth " << truth;
    }
  }
}

// A compliant mesh (≈ 80 Hz engaged, damping ratio ≈ 0.4) the rigid model lacks: with both
// encoders named, with its stiffness.  With the motor encoder alone the stiffness is not fitted
// (docs/discrepancy.md: the load observer's contact is rigid and the band is cut below the
// mesh's resonance, where the deflection's signature, ~(f/f_mesh)² of the load's inertial
// torque, is absorbed by the load's inertia); there the backlash is still recovered within the
// issue's criterion (the deflection widens the lost motion by 2·R/kc at most).
TEST(TwoBodyDriveWorkflow, item3_mesh_stiffness) {
  for (bool both : {true, false}) {
    Drive d = drive(2 * kDegree, both);
    d.spec.plant.stiffness = 2000, d.spec.plant.damping = 3;
    const json result = run_workflow(d);
    const Estimate k = effect(result, "compliance", "stiffness");
    std::printf("%-52s stiffness true %.6g, fitted %.6g ± %.2g, status %s\n", d.label.c_str(), d.spec.plant.stiffness, k.value,
                k.sigma, status(result).c_str());
    if (!both) {
      EXPECT_FALSE(k.found) << d.label << ": a stiffness named with the motor encoder alone (documented as not fitted)";
      const Estimate b = correction(result, "backlash");
      ASSERT_TRUE(b.found) << d.label << ": no backlash among the parameter corrections";
      EXPECT_LE(std::fabs(b.value - d.spec.plant.backlash), std::max(0.05 * d.spec.plant.backlash, 3 * b.sigma))
          << d.label << ": backlash fitted " << b.value << " ± " << b.sigma << " on a compliant mesh";
      continue;
    }
    ASSERT_TRUE(k.found) << d.label << ": no compliance named (status " << status(result) << ")";
    EXPECT_LE(std::fabs(k.value / d.spec.plant.stiffness - 1), 0.10) << d.label << ": stiffness fitted " << k.value;
  }
}

// Coulomb friction on the motor and on the load (the model has none): both named, each within 10 %.
TEST(TwoBodyDriveWorkflow, item3_coulomb_each_side) {
  Drive d = drive(2 * kDegree, true);
  d.spec.plant.coulomb_motor = 0.06, d.spec.plant.coulomb_load = 0.1;
  const json result = run_workflow(d);
  for (const auto& [name, truth] : {std::pair<std::string, double>{"coulomb_motor", 0.06}, {"coulomb_load", 0.1}}) {
    const Estimate c = effect(result, name, "torque");
    std::printf("%-52s %s true %.4g, fitted %.6g ± %.2g, status %s\n", d.label.c_str(), name.c_str(), truth, c.value, c.sigma,
                status(result).c_str());
    ASSERT_TRUE(c.found) << d.label << ": " << name << " not named";
    EXPECT_LE(std::fabs(c.value / truth - 1), 0.10) << d.label << ": " << name << " fitted " << c.value;
  }
}

// No gap in the drive, one of 1° in the model: the backlash fitted ≈ 0 — within 3σ of 0 or two
// encoder counts (the resolution of the lost motion the data can show).
TEST(TwoBodyDriveWorkflow, item1_rigid_drive_reported_rigid) {
  for (bool both : {true, false}) {
    Drive d = drive(0, both);
    d.model.nominal.backlash = 1 * kDegree;
    const json result = run_workflow(d);
    const Estimate b = correction(result, "backlash");
    const double counts = 2 * (2 * M_PI / d.spec.counts_per_rev);
    std::printf("%-52s fitted %.4g ± %.2g rad, status %s\n", d.label.c_str(), b.value, b.sigma, status(result).c_str());
    ASSERT_TRUE(b.found) << d.label << ": the model's 1° backlash was not corrected";
    EXPECT_LE(b.value, std::max(3 * b.sigma, counts)) << d.label << ": a rigid drive given a backlash of " << b.value << " rad";
  }
}

// A model with a gap and a record without the columns it needs: exit 2, one line naming the file,
// the line (the header, 1) and the missing column; nothing written into --out.
TEST(TwoBodyDriveWorkflow, item1_missing_columns_refused) {
  Folder folder;
  Drive d = drive(2 * kDegree, true);
  d.spec.reference.moves = 1;
  const TwoBodyRecord record = generate_two_body_record(d.spec);
  const fs::path model = folder / "model.toml";
  write_text_file(model, two_body_case_toml(d.model));
  std::string rigid = "t,theta_out,drive\n", no_drive = "t,theta_motor,theta_load\n";
  for (std::size_t k = 0; k < record.t.size(); ++k) {
    rigid += std::to_string(record.t[k]) + "," + std::to_string(record.theta_motor[k]) + "," + std::to_string(record.drive[k]) + "\n";
    no_drive += std::to_string(record.t[k]) + "," + std::to_string(record.theta_motor[k]) + "," +
                std::to_string(record.theta_load[k]) + "\n";
  }
  for (const auto& [name, text, column] : {std::tuple<std::string, std::string, std::string>{"rigid.csv", rigid, "theta_motor"},
                                           {"no_drive.csv", no_drive, "drive"}}) {
    const fs::path data = folder / name, out = folder / ("out_" + name);
    write_text_file(data, text);
    const CommandRun r = run_command("discrepancy --model " + model.string() + " --data " + data.string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << name << ": exit " << r.exit_code << ", stderr: " << r.err;
    EXPECT_EQ(r.out, "") << name;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << name << ": not one line: " << r.err;
    EXPECT_NE(r.err.find(data.string() + ":1:"), std::string::npos) << name << ": the file and line 1 not named: " << r.err;
    EXPECT_NE(r.err.find(column), std::string::npos) << name << ": the column " << column << " not named: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << name << ": left " << out << " behind";
  }
}

}  // namespace
