// The discrepancy workflow on real measurements: the EMPS servo drive (tests/data/emps/).
//
// Known answers from outside this project: the benchmark's authors (Janot, Gautier,
// Brunot 2019) publish, with the data, a reference model identified on the estimation
// record by IDIM-LS (their Simulation_EMPS.m: M = 95.1089 kg, Fv = 203.5034 N·s/m,
// Fc = 20.3935 N, OF = −3.1648 N in force = M·q'' + Fv·q' + Fc·sgn q' + OF, with a
// 100 Hz Butterworth).  Our workflow, starting from a careless mass and viscous friction,
// must name the two effects the authors' model has, and land on their values within our
// own reported uncertainty (the same data, another filter, another fit: they are two
// estimates, not one number).  Then the validation record, with its force pulses, which
// nothing was fitted on, must confirm the corrected model.
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/reports/discrepancy_pages.hpp"
#include "backlash/measurements/emps.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

using namespace backlash;

const std::filesystem::path data_dir = BACKLASH_EMPS_DATA_DIR;

// A mass and viscous friction, deliberately off (80 kg, 300 N·s/m), both free.
model::CaseSpec emps_model() {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("emps_model_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << "name = \"EMPS: mass and viscous friction\"\nmeasured_at = \"motor\"\nbacklash = 0\nreference = 0\n"
                         "[motor]\nJ = 80\nF = 300\n[load]\nJ = 1\nF = 0\n"
                         "[experiment]\nkind = \"drive\"\ndrive_gain = 1\n[fit]\nfree = [\"motor.J\", \"motor.F\"]\n";
  model::CaseSpec spec = model::load_case(file.string());
  std::filesystem::remove(file);
  return spec;
}

struct EmpsRun {
  model::CaseSpec model = emps_model();
  measurements::MeasuredRecord estimation = measurements::to_measured_record(measurements::read_emps(data_dir / "DATA_EMPS.mat"));
  measurements::MeasuredRecord validation =
      measurements::to_measured_record(measurements::read_emps(data_dir / "DATA_EMPS_PULSES.mat"));
  discrepancy::DriveDiscrepancyResult result = discrepancy::find_drive_discrepancy(model, estimation, {}, &validation);
};

const EmpsRun& run() {
  static const EmpsRun r;
  return r;
}

const discrepancy::Parameter& parameter(const std::vector<discrepancy::Parameter>& ps, const std::string& name) {
  for (const discrepancy::Parameter& p : ps)
    if (p.name == name) return p;
  throw std::runtime_error("no parameter " + name);
}

void expect_within_sigmas(double value, double sigma, double reference, double sigmas, const std::string& what) {
  EXPECT_TRUE(std::isfinite(sigma) && sigma > 0) << what << ": uncertainty " << sigma;
  EXPECT_LE(std::fabs(value - reference), sigmas * sigma)
      << what << " returned " << value << " ± " << sigma << " instead of the published " << reference << " (within "
      << sigmas << " σ)";
}

TEST(EmpsWorkflow, exam_NamesCoulombFrictionThenTheOffsetAndNothingElse) {
  const auto& r = run().result;
  EXPECT_EQ(r.status, discrepancy::Status::EffectFound);
  ASSERT_EQ(r.effects.size(), 2u) << "named " << r.effects.size() << " effects instead of 2";
  EXPECT_EQ(r.effects[0].effect, "coulomb_motor") << "returned " << r.effects[0].effect << " instead of coulomb_motor";
  EXPECT_EQ(r.effects[1].effect, "torque_offset") << "returned " << r.effects[1].effect << " instead of torque_offset";
  // The third round looked at the delay and the saturation and found neither decisive: the
  // amplifier's limit (10 V, 351 N) is far beyond the record's 152 N.
  ASSERT_EQ(r.rounds.size(), 3u);
  for (const discrepancy::Candidate& c : r.rounds[2]) EXPECT_FALSE(c.decisive) << c.effect << " decisive in round 3";
  // A saturation far below the drive mimics a Coulomb term (sat at a small limit ≈ L·sgn):
  // its limit sits at the bottom of its range, and the edge rule keeps it out.
  for (const discrepancy::Candidate& c : r.rounds[0])
    if (c.effect == "saturation") {
      EXPECT_TRUE(c.at_range_edge || !c.decisive);
    }
}

TEST(EmpsWorkflow, exam_FittedValuesAgreeWithThePublishedReferenceModel) {
  const auto& r = run().result;
  ASSERT_EQ(r.effects.size(), 2u);
  const discrepancy::Parameter& J = parameter(r.corrected_nominal, "motor.J");
  const discrepancy::Parameter& F = parameter(r.corrected_nominal, "motor.F");
  // motor.J is the mass less the load's 1 kg of the model file.
  expect_within_sigmas(J.value + 1, J.uncertainty, 95.1089, 2, "M = motor.J + load.J");
  expect_within_sigmas(F.value, F.uncertainty, 203.5034, 2, "Fv");
  expect_within_sigmas(r.effects[0].parameters[0].value, r.effects[0].parameters[0].uncertainty, 20.3935, 2, "Fc");
  // Their OF is on the side of the needed force; our offset is added to the drive: T0 = −OF.
  expect_within_sigmas(r.effects[1].parameters[0].value, r.effects[1].parameters[0].uncertainty, 3.1648, 2, "T0");
  // The uncertainties are honest for correlated residuals, not the naive ones (√τ_int ≈ 15×
  // smaller): each is a few per cent of its value, not a few per mille.
  EXPECT_GT(r.tau_int_after, 50);
  EXPECT_GT(r.effects[0].parameters[0].uncertainty / r.effects[0].parameters[0].value, 0.005);
}

TEST(EmpsWorkflow, exam_TheBestNominalModelIsFittedBeforeAnyEffect) {
  const auto& r = run().result;
  ASSERT_EQ(r.nominal_fit.size(), 2u);
  // Without Coulomb friction the viscous term absorbs it: about twice the true Fv.
  EXPECT_GT(parameter(r.nominal_fit, "motor.F").value, 350);
  EXPECT_LT(r.rms_before, r.rms_given) << "the refitted nominal model is no better than the careless one";
}

TEST(EmpsWorkflow, exam_TheGapShrinksInTorqueAndInPosition) {
  const auto& r = run().result;
  EXPECT_LT(r.rms_after, 0.35 * r.rms_before) << "torque RMS " << r.rms_before << " -> " << r.rms_after;
  EXPECT_LT(r.estimation.position_rms_corrected, 0.5 * r.estimation.position_rms_nominal)
      << "position RMS over windows " << r.estimation.position_rms_nominal << " -> " << r.estimation.position_rms_corrected;
  // Where the residual was: opposite means forward and backward (Coulomb's signature), gone after.
  const auto& forward = r.classes[0];
  const auto& backward = r.classes[1];
  ASSERT_EQ(forward.kind, "forward");
  ASSERT_EQ(backward.kind, "backward");
  EXPECT_GT(forward.mean_before - backward.mean_before, 5) << "no Coulomb signature before";
  EXPECT_LT(std::fabs(forward.mean_after - backward.mean_after), 1);
}

TEST(EmpsWorkflow, exam_TheValidationRecordWhichNothingWasFittedOnConfirmsTheCorrectedModel) {
  const auto& r = run().result;
  ASSERT_TRUE(r.validation.has_value());
  EXPECT_EQ(r.validation->samples, 24841);
  EXPECT_LT(r.validation->torque_rms_corrected, 0.5 * r.validation->torque_rms_nominal)
      << "validation torque RMS " << r.validation->torque_rms_nominal << " -> " << r.validation->torque_rms_corrected;
  EXPECT_LT(r.validation->position_rms_corrected, 0.5 * r.validation->position_rms_nominal)
      << "validation position RMS " << r.validation->position_rms_nominal << " -> " << r.validation->position_rms_corrected;
}

TEST(EmpsWorkflow, exam_TheCutOffComesFromTheSpectrum) {
  const auto& r = run().result;
  EXPECT_TRUE(r.cutoff_from_spectrum);
  EXPECT_NEAR(r.cutoff, 84.9609375, 1e-9) << "returned " << r.cutoff << " Hz instead of 84.96 (see inverse_dynamics_signals)";
  EXPECT_NEAR(r.sample_rate, 1000, 1e-3) << "returned " << r.sample_rate << " Hz instead of 1000";
}

TEST(EmpsWorkflow, exam_FilesAreTheSameBytesEveryTimeAndTheCorrectedModelLoads) {
  const EmpsRun& first = run();
  const auto again = discrepancy::find_drive_discrepancy(first.model, first.estimation, {}, &first.validation);
  const auto a = discrepancy::drive_report_files(first.model, "DATA_EMPS.mat", "DATA_EMPS_PULSES.mat", first.result);
  const auto b = discrepancy::drive_report_files(first.model, "DATA_EMPS.mat", "DATA_EMPS_PULSES.mat", again);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].second, b[i].second) << a[i].first << " differs between runs";
  const nlohmann::json json = nlohmann::json::parse(discrepancy::drive_to_json(first.model, first.result));
  for (const char* key : {"status", "effect", "parameters", "effects", "rms_before", "rms_after", "noise", "candidates", "regions"})
    EXPECT_TRUE(json.contains(key)) << "JSON has no " << key;
  EXPECT_EQ(json["effect"], "coulomb_motor");
  // The corrected model loads, and fitting it again names nothing more.
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("emps_corrected_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << discrepancy::drive_corrected_case_file(first.model, first.result);
  const model::CaseSpec corrected = model::load_case(file.string());
  std::filesystem::remove(file);
  EXPECT_EQ(model::to_double(corrected.effects.coulomb_motor.value()), first.result.corrected_effects.coulomb_motor);
  EXPECT_EQ(model::to_double(corrected.effects.torque_offset.value()), first.result.corrected_effects.torque_offset);
  const auto refit = discrepancy::find_drive_discrepancy(corrected, first.estimation);
  EXPECT_TRUE(refit.effects.empty()) << "the corrected model still misses " << (refit.effects.empty() ? "" : refit.effects[0].effect);
  EXPECT_NEAR(refit.rms_before, first.result.rms_after, 1e-6 * first.result.rms_after);
}

}  // namespace
