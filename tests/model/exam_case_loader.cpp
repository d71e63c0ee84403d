// exam_case_loader — the strict, exact case-file loader (model/case_spec.hpp).
//
// The eight thesis case files load with exact rationals; every malformed
// variant of a valid file fails with one line "FILE:LINE: KEY: problem" naming
// the right line and key.
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

using backlash::model::CaseFileError;
using backlash::model::CaseSpec;
using backlash::model::MeasuredAt;
using backlash::model::Rational;
using backlash::model::load_case;
using backlash::model::load_case_file;
using backlash::model::to_double;
using backlash::model::to_string;

Rational exact(long numerator, long denominator = 1) { return Rational(numerator, denominator); }

/// EXPECT that `actual` equals `expected` exactly, saying what was read.
void expect_exact(const Rational& actual, const Rational& expected, const std::string& what) {
  EXPECT_TRUE(actual == expected) << what << " returned " << to_string(actual) << " instead of "
                                  << to_string(expected);
}

// ------------------------------------------------------------------ the thesis cases

struct ThesisCaseValues {
  std::string id;
  MeasuredAt measured_at;
  Rational Jm, Fm, JL, FL, backlash, step;
};

/// Each case's own section of the thesis (eqs. 42–44, 56–58, 66–68, 74–76,
/// 82–84, 95–97, 106–108, 118–120) and the first step input it names.
std::vector<ThesisCaseValues> thesis_case_values() {
  return {
      {"I", MeasuredAt::Motor, exact(3, 5), exact(12, 25), exact(2, 5), exact(8, 25), exact(1, 5), exact(1)},
      {"II", MeasuredAt::Motor, exact(1, 2), exact(1, 5), exact(1, 2), exact(0), exact(3, 10), exact(4, 25)},
      {"III", MeasuredAt::Load, exact(1, 2), exact(1, 5), exact(1, 2), exact(0), exact(3, 10), exact(229, 200)},
      {"IV", MeasuredAt::Load, exact(1, 5), exact(1, 5), exact(4, 5), exact(0), exact(3, 10), exact(69, 100)},
      {"V", MeasuredAt::Load, exact(1, 2), exact(1, 10), exact(1, 2), exact(3, 10), exact(3, 10), exact(31, 50)},
      {"VI", MeasuredAt::Load, exact(1, 2), exact(3, 10), exact(1, 2), exact(1, 10), exact(3, 10), exact(11, 20)},
      {"VII", MeasuredAt::Load, exact(1, 5), exact(1, 10), exact(4, 5), exact(3, 10), exact(3, 10), exact(29, 50)},
      {"VIII", MeasuredAt::Load, exact(1, 5), exact(3, 10), exact(4, 5), exact(1, 10), exact(3, 10), exact(53, 200)},
  };
}

TEST(ThesisCases, IdsAreTheEightCasesInThesisOrder) {
  const std::vector<std::string> expected{"I", "II", "III", "IV", "V", "VI", "VII", "VIII"};
  EXPECT_EQ(backlash::model::thesis_case_ids(), expected);
}

TEST(ThesisCases, CasesDirFollowsTheEnvironment) {
  const char* from_environment = std::getenv("BACKLASH_CASES_DIR");
  ASSERT_NE(from_environment, nullptr) << "ctest should set BACKLASH_CASES_DIR";
  EXPECT_EQ(backlash::model::thesis_cases_dir(), std::filesystem::path(from_environment));
}

TEST(ThesisCases, AllEightLoadWithExactValues) {
  for (const ThesisCaseValues& expected : thesis_case_values()) {
    SCOPED_TRACE("case " + expected.id);
    const CaseSpec spec = load_case(expected.id);
    EXPECT_EQ(spec.id, expected.id);
    EXPECT_EQ(spec.name, "Case " + expected.id);
    EXPECT_EQ(spec.source, backlash::model::thesis_cases_dir() / (expected.id + ".toml"));
    EXPECT_EQ(spec.measured_at, expected.measured_at)
        << "measured_at returned " << to_string(spec.measured_at) << " instead of "
        << to_string(expected.measured_at);
    expect_exact(spec.K, exact(1), "K");
    expect_exact(spec.reference, exact(1), "reference");
    expect_exact(spec.backlash, expected.backlash, "backlash");
    expect_exact(spec.Jm, expected.Jm, "motor.J");
    expect_exact(spec.Fm, expected.Fm, "motor.F");
    expect_exact(spec.JL, expected.JL, "load.J");
    expect_exact(spec.FL, expected.FL, "load.F");
    ASSERT_TRUE(spec.experiment.has_value()) << "the [experiment] table was not read";
    expect_exact(spec.experiment->step, expected.step, "experiment.step");
    ASSERT_TRUE(spec.experiment->t_end.has_value()) << "experiment.t_end was not read";
    expect_exact(*spec.experiment->t_end, exact(60), "experiment.t_end");
    // The combined system of every case has unit inertia (eqs. 42, 56, 66, 74, 82, 95, 106, 118).
    expect_exact(spec.Jm + spec.JL, exact(1), "Jm + JL");
  }
}

TEST(ThesisCases, SpotValuesAreExactRationals) {
  expect_exact(load_case("V").FL, exact(3, 10), "case V load.F");
  expect_exact(load_case("I").Jm, exact(3, 5), "case I motor.J");
  expect_exact(load_case("I").Fm, exact(12, 25), "case I motor.F");
}

TEST(ThesisCases, IdsAreCaseInsensitive) {
  const CaseSpec spec = load_case("v");
  EXPECT_EQ(spec.id, "V");
  EXPECT_EQ(spec.source.filename(), "V.toml");
  EXPECT_EQ(load_case("viii").id, "VIII");
}

TEST(ThesisCases, AnUnknownIdFailsNamingIt) {
  try {
    load_case("ix");
    FAIL() << "load_case(\"ix\") returned a case instead of throwing CaseFileError";
  } catch (const CaseFileError& error) {
    EXPECT_EQ(std::string(error.what()), "unknown case 'ix': expected I..VIII or a case file path");
  }
}

TEST(ThesisCases, APathIsLoadedWithItsStemAsId) {
  const CaseSpec spec = load_case((backlash::model::thesis_cases_dir() / "VI.toml").string());
  EXPECT_EQ(spec.id, "VI");
  expect_exact(spec.Fm, exact(3, 10), "case VI motor.F");
}

// ------------------------------------------------------------------ malformed files

/// A valid case file, line by line (line numbers in the comments).
const std::vector<std::string> valid_case_lines{
    "name = \"Test case\"",  // 1
    "measured_at = \"load\"",  // 2
    "K = 1",                 // 3
    "backlash = 0.3",        // 4
    "reference = 1",         // 5
    "",                      // 6
    "[motor]",               // 7
    "J = 0.5",               // 8
    "F = 0.1",               // 9
    "",                      // 10
    "[load]",                // 11
    "J = 0.5",               // 12
    "F = 0.3",               // 13
    "",                      // 14
    "[experiment]",          // 15
    "step = 0.62",           // 16
    "t_end = 60",            // 17
};

class CaseFileVariants : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ = std::filesystem::temp_directory_path() /
              ("backlash-exam-case-loader-" + std::to_string(::getpid()) + "-" + test->name());
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }

  /// Writes `lines` to a fresh file and returns its path.
  std::filesystem::path write(const std::vector<std::string>& lines, const std::string& file_name = "case.toml") {
    const std::filesystem::path file = folder_ / file_name;
    std::ofstream stream(file, std::ios::binary | std::ios::trunc);
    for (const std::string& line : lines) stream << line << '\n';
    return file;
  }

  /// The valid file with line `line_number` (1-based) replaced by `replacement`.
  static std::vector<std::string> with_line(int line_number, const std::string& replacement) {
    std::vector<std::string> lines = valid_case_lines;
    lines.at(static_cast<std::size_t>(line_number - 1)) = replacement;
    return lines;
  }

  /// The valid file with `extra` inserted so that it becomes line `line_number`.
  static std::vector<std::string> with_inserted_line(int line_number, const std::string& extra) {
    std::vector<std::string> lines = valid_case_lines;
    lines.insert(lines.begin() + (line_number - 1), extra);
    return lines;
  }

  /// Loads `lines` and expects exactly "FILE:LINE: KEY: problem".
  void expect_rejected(const std::vector<std::string>& lines, long line, const std::string& key,
                       const std::string& problem) {
    const std::filesystem::path file = write(lines);
    const std::string expected = file.string() + ":" + std::to_string(line) + ": " + key + ": " + problem;
    try {
      const CaseSpec spec = load_case_file(file);
      ADD_FAILURE() << "load_case_file returned a case (" << spec.name << ") instead of the error \"" << expected
                    << "\"";
    } catch (const CaseFileError& error) {
      EXPECT_EQ(std::string(error.what()), expected)
          << "what() returned \"" << error.what() << "\" instead of \"" << expected << "\"";
      EXPECT_EQ(error.file(), file);
      EXPECT_EQ(error.line(), line) << "line() returned " << error.line() << " instead of " << line;
      EXPECT_EQ(error.key(), key) << "key() returned " << error.key() << " instead of " << key;
    }
  }

  CaseSpec load(const std::vector<std::string>& lines) { return load_case_file(write(lines)); }

  std::filesystem::path folder_;
};

TEST_F(CaseFileVariants, TheValidFileLoads) {
  const CaseSpec spec = load(valid_case_lines);
  EXPECT_EQ(spec.id, "case");
  EXPECT_EQ(spec.name, "Test case");
  EXPECT_EQ(spec.measured_at, MeasuredAt::Load);
  expect_exact(spec.backlash, exact(3, 10), "backlash");
  expect_exact(spec.Fm, exact(1, 10), "motor.F");
  ASSERT_TRUE(spec.experiment.has_value());
  expect_exact(spec.experiment->step, exact(31, 50), "experiment.step");
}

// ------------------------------------------------------------------ [effects] (docs/effects.md)

/// The valid file followed by an [effects] table made of `entries` (its header is line 18).
std::vector<std::string> with_effects(const std::vector<std::string>& entries) {
  std::vector<std::string> lines = valid_case_lines;
  lines.push_back("[effects]");  // 18
  lines.insert(lines.end(), entries.begin(), entries.end());
  return lines;
}

TEST_F(CaseFileVariants, NoEffectsTableIsTheNominalModel) {
  const CaseSpec spec = load(valid_case_lines);
  EXPECT_FALSE(spec.effects.any());
  EXPECT_FALSE(spec.effects.saturation.has_value());
  EXPECT_FALSE(spec.effects.mesh_stiffness.has_value());
}

TEST_F(CaseFileVariants, EffectsAreReadExactly) {
  const CaseSpec spec = load(with_effects({"coulomb_motor = 0.05", "coulomb_load = \"3/100\"", "restitution = 0.4",
                                           "saturation = 0.5", "delay = 0.05", "torque_offset = -0.02"}));
  expect_exact(spec.effects.coulomb_motor.value(), exact(1, 20), "effects.coulomb_motor");
  expect_exact(spec.effects.coulomb_load.value(), exact(3, 100), "effects.coulomb_load");
  expect_exact(spec.effects.restitution.value(), exact(2, 5), "effects.restitution");
  ASSERT_TRUE(spec.effects.saturation.has_value());
  expect_exact(*spec.effects.saturation, exact(1, 2), "effects.saturation");
  expect_exact(spec.effects.delay.value(), exact(1, 20), "effects.delay");
  expect_exact(spec.effects.torque_offset.value(), exact(-1, 50), "effects.torque_offset");
  EXPECT_TRUE(spec.effects.any());
}

TEST_F(CaseFileVariants, ComplianceAsInlineOrStandardTable) {
  const CaseSpec inline_table = load(with_effects({"compliance = { stiffness = 400, damping = 4.5 }"}));
  ASSERT_TRUE(inline_table.effects.mesh_stiffness.has_value());
  expect_exact(*inline_table.effects.mesh_stiffness, exact(400), "stiffness");
  expect_exact(*inline_table.effects.mesh_damping, exact(9, 2), "damping");
  std::vector<std::string> lines = valid_case_lines;
  lines.insert(lines.end(), {"[effects.compliance]", "stiffness = 1e4", "damping = 0"});
  const CaseSpec standard = load(lines);
  ASSERT_TRUE(standard.effects.mesh_stiffness.has_value());
  expect_exact(*standard.effects.mesh_stiffness, exact(10000), "stiffness");
}

TEST_F(CaseFileVariants, NeutralValuesAreTheNominalModel) {
  const CaseSpec spec = load(with_effects({"coulomb_motor = 0", "coulomb_load = 0", "restitution = 0", "delay = 0",
                                           "torque_offset = 0"}));
  EXPECT_FALSE(spec.effects.any());
}

TEST_F(CaseFileVariants, BadEffectValuesNameLineAndKey) {
  expect_rejected(with_effects({"coulomb_motor = -0.05"}), 19, "effects.coulomb_motor",
                  "negative Coulomb torque; a friction torque must be >= 0 (got -0.05)");
  expect_rejected(with_effects({"delay = 0", "coulomb_load = -1"}), 20, "effects.coulomb_load",
                  "negative Coulomb torque; a friction torque must be >= 0 (got -1)");
  expect_rejected(with_effects({"restitution = 1"}), 19, "effects.restitution",
                  "coefficient of restitution outside [0, 1): 0 is the inelastic impact, 1 would never settle (got 1)");
  expect_rejected(with_effects({"restitution = -0.1"}), 19, "effects.restitution",
                  "coefficient of restitution outside [0, 1): 0 is the inelastic impact, 1 would never settle (got -0.1)");
  expect_rejected(with_effects({"saturation = 0"}), 19, "effects.saturation",
                  "non-positive saturation limit; the drive torque limit must be > 0 (got 0)");
  expect_rejected(with_effects({"delay = -0.01"}), 19, "effects.delay", "negative delay; tau must be >= 0 (got -0.01)");
  expect_rejected(with_effects({"compliance = { stiffness = 0, damping = 1 }"}), 19, "effects.compliance.stiffness",
                  "non-positive mesh stiffness; a spring must be > 0 (omit the effect for a rigid mesh) (got 0)");
  expect_rejected(with_effects({"compliance = { stiffness = 10, damping = -1 }"}), 19, "effects.compliance.damping",
                  "negative mesh damping; it must be >= 0 (got -1)");
  expect_rejected(with_effects({"compliance = { stiffness = 10 }"}), 19, "effects.compliance.damping", "missing key");
  expect_rejected(with_effects({"compliance = 3"}), 19, "effects.compliance",
                  "expected a table [effects.compliance], got an integer");
  expect_rejected(with_effects({"saturation = \"inf\""}), 19, "effects.saturation", "non-finite number (got \"inf\")");
  expect_rejected(with_effects({"coulomb_motor = true"}), 19, "effects.coulomb_motor", "expected a number, got a boolean");
}

TEST_F(CaseFileVariants, UnknownEffectIsRefusedWithTheVocabulary) {
  expect_rejected(with_effects({"coulomb_load = 0.1", "stiction = 0.2"}), 20, "effects.stiction",
                  "unknown key (allowed: coulomb_motor, coulomb_load, restitution, saturation, compliance, delay, "
                  "torque_offset, stribeck_motor, stribeck_load)");
  expect_rejected(with_effects({"compliance = { stiffness = 10, damping = 1, mass = 2 }"}), 19,
                  "effects.compliance.mass", "unknown key (allowed: stiffness, damping)");
}

TEST_F(CaseFileVariants, RestitutionWithComplianceIsRefused) {
  expect_rejected(with_effects({"restitution = 0.3", "compliance = { stiffness = 400, damping = 4 }"}), 19,
                  "effects.restitution",
                  "restitution and compliance both model the impact (a compliant mesh has its own rebound, set by its "
                  "damping); give one of them");
}

// ------------------------------------------------------------------ measured-drive experiments and [fit]

std::vector<std::string> drive_model(const std::vector<std::string>& experiment, const std::vector<std::string>& rest = {}) {
  std::vector<std::string> lines{"name = \"Drive\"", "measured_at = \"motor\"", "backlash = 0", "reference = 0",
                                 "[motor]", "J = 95", "F = 200", "[load]", "J = 1e-6", "F = 0", "[experiment]"};  // 1..11
  lines.insert(lines.end(), experiment.begin(), experiment.end());
  lines.insert(lines.end(), rest.begin(), rest.end());
  return lines;
}

TEST_F(CaseFileVariants, AMeasuredDriveExperimentOpensTheLoop) {
  const CaseSpec spec = load(drive_model({"kind = \"drive\"", "drive_gain = 35.15", "t_end = 24.8"}));
  ASSERT_TRUE(spec.experiment.has_value());
  EXPECT_EQ(spec.experiment->kind, backlash::model::ExperimentKind::Drive);
  expect_exact(spec.experiment->drive_gain, exact(703, 20), "experiment.drive_gain");
  expect_exact(spec.K, exact(1), "K (absent: unused)");
  expect_exact(spec.backlash, exact(0), "backlash");  // a rigid drive is a valid model
  const CaseSpec default_gain = load(drive_model({"kind = \"drive\""}));
  expect_exact(default_gain.experiment->drive_gain, exact(1), "experiment.drive_gain (default)");
}

TEST_F(CaseFileVariants, BadExperimentKindsNameLineAndKey) {
  expect_rejected(drive_model({"kind = \"ramp\""}), 12, "experiment.kind", "expected \"step\" or \"drive\", got \"ramp\"");
  expect_rejected(drive_model({"kind = \"drive\"", "step = 1"}), 13, "experiment.step",
                  "a measured-drive experiment has no step: the drive comes from the record's drive column");
  expect_rejected(drive_model({"step = 1", "drive_gain = 2"}), 13, "experiment.drive_gain",
                  "only a measured-drive experiment (kind = \"drive\") has a drive gain");
  expect_rejected(drive_model({"kind = \"drive\"", "drive_gain = 0"}), 13, "experiment.drive_gain", "zero drive gain (got 0)");
  expect_rejected(drive_model({"step = 1"}), 1, "K", "missing key");  // a step experiment closes the loop: K is needed
}

TEST_F(CaseFileVariants, FitNamesTheFreeNominalParameters) {
  const CaseSpec spec = load(drive_model({"kind = \"drive\""}, {"[fit]", "free = [\"motor.J\", \"motor.F\"]"}));
  ASSERT_EQ(spec.fit_free.size(), 2u);
  EXPECT_EQ(spec.fit_free[0], "motor.J");
  EXPECT_EQ(spec.fit_free[1], "motor.F");
  expect_rejected(drive_model({"kind = \"drive\""}, {"[fit]", "free = [\"motor.M\"]"}), 14, "fit.free",
                  "unknown parameter \"motor.M\" (allowed: motor.J, motor.F, load.J, load.F, K, backlash, reference)");
  expect_rejected(drive_model({"kind = \"drive\""}, {"[fit]", "free = [\"K\", \"K\"]"}), 14, "fit.free",
                  "\"K\" given twice");
  expect_rejected(drive_model({"kind = \"drive\""}, {"[fit]", "free = \"motor.J\""}), 14, "fit.free",
                  "expected an array of parameter names, got a string");
  expect_rejected(drive_model({"kind = \"drive\""}, {"[fit]", "pinned = []"}), 14, "fit.pinned",
                  "unknown key (allowed: free, fixed)");
  expect_rejected(drive_model({"kind = \"drive\""}, {"[fit]", "free = [\"K\"]", "fixed = [\"K\"]"}), 15, "fit.fixed",
                  "\"K\" is also in fit.free: a parameter is free or fixed, not both");
}

TEST_F(CaseFileVariants, OnlyASmallRegularFileIsRead) {
  for (const char* special : {"/dev/zero", "/dev/null"}) {
    try {
      load_case_file(special);
      ADD_FAILURE() << special << " was read";
    } catch (const CaseFileError& error) {
      EXPECT_NE(std::string(error.what()).find("not a regular file"), std::string::npos) << error.what();
    }
  }
  const std::filesystem::path big = write({std::string(2 << 20, '#')}, "big.toml");
  try {
    load_case_file(big);
    ADD_FAILURE() << "a 2 MiB file was read";
  } catch (const CaseFileError& error) {
    EXPECT_NE(std::string(error.what()).find("case file too large"), std::string::npos) << error.what();
  }
}

TEST_F(CaseFileVariants, UnknownKeyInATable) {
  expect_rejected(with_inserted_line(10, "G = 2"), 10, "motor.G", "unknown key (allowed: J, F)");
}

TEST_F(CaseFileVariants, UnknownTopLevelKey) {
  expect_rejected(with_inserted_line(4, "gain = 2"), 4, "gain",
                  "unknown key (allowed: name, measured_at, K, backlash, reference, motor, load, experiment, effects, fit)");
}

TEST_F(CaseFileVariants, UnknownKeyDifferingOnlyInCaseGetsAHint) {
  expect_rejected(with_line(3, "k = 1"), 3, "k",
                  "unknown key (did you mean 'K'? allowed: name, measured_at, K, backlash, reference, motor, load, "
                  "experiment, effects, fit)");
}

TEST_F(CaseFileVariants, UnknownTable) {
  std::vector<std::string> lines = valid_case_lines;
  lines.push_back("[gearbox]");
  lines.push_back("ratio = 2");
  expect_rejected(lines, 18, "gearbox",
                  "unknown key (allowed: name, measured_at, K, backlash, reference, motor, load, experiment, effects, fit)");
}

TEST_F(CaseFileVariants, MissingKeyInATableNamesTheTableHeaderLine) {
  expect_rejected(with_line(13, ""), 11, "load.F", "missing key");
}

TEST_F(CaseFileVariants, MissingTopLevelKeyNamesLineOne) {
  expect_rejected(with_line(1, ""), 1, "name", "missing key");
}

TEST_F(CaseFileVariants, MissingTable) {
  std::vector<std::string> lines(valid_case_lines.begin(), valid_case_lines.begin() + 10);
  expect_rejected(lines, 1, "load", "missing table [load]");
}

TEST_F(CaseFileVariants, MissingExperimentStep) {
  expect_rejected(with_line(16, ""), 15, "experiment.step", "missing key");
}

TEST_F(CaseFileVariants, ZeroInertia) {
  expect_rejected(with_line(8, "J = 0"), 8, "motor.J", "non-positive inertia (got 0; an inertia must be > 0)");
}

TEST_F(CaseFileVariants, NegativeInertia) {
  expect_rejected(with_line(8, "J = -1"), 8, "motor.J", "non-positive inertia (got -1; an inertia must be > 0)");
}

TEST_F(CaseFileVariants, NegativeFriction) {
  expect_rejected(with_line(13, "F = -0.1"), 13, "load.F",
                  "negative friction (got -0.1; viscous friction must be >= 0)");
}

TEST_F(CaseFileVariants, NegativeBacklash) {
  expect_rejected(with_line(4, "backlash = -0.3"), 4, "backlash",
                  "negative backlash (got -0.3; the total backlash must be >= 0)");
}

TEST_F(CaseFileVariants, NonPositiveGain) {
  expect_rejected(with_line(3, "K = 0"), 3, "K",
                  "non-positive loop gain (got 0; K must be > 0, otherwise the loop does not pull the output toward "
                  "the reference)");
}

TEST_F(CaseFileVariants, NonPositiveEndTime) {
  expect_rejected(with_line(17, "t_end = 0.0"), 17, "experiment.t_end",
                  "non-positive end time (got 0.0; t_end must be > 0)");
}

TEST_F(CaseFileVariants, NotANumber) {
  expect_rejected(with_line(4, "backlash = nan"), 4, "backlash", "non-finite number (got nan)");
}

TEST_F(CaseFileVariants, Infinity) {
  expect_rejected(with_line(12, "J = inf"), 12, "load.J", "non-finite number (got inf)");
  expect_rejected(with_line(5, "reference = -inf"), 5, "reference", "non-finite number (got -inf)");
  expect_rejected(with_line(5, "reference = \"inf\""), 5, "reference", "non-finite number (got \"inf\")");
}

TEST_F(CaseFileVariants, StringThatIsNotANumber) {
  expect_rejected(with_line(8, "J = \"abc\""), 8, "motor.J",
                  "not a number: \"abc\" (expected a digit; write a decimal such as 0.3 or a fraction such as "
                  "\"1/3\")");
}

TEST_F(CaseFileVariants, FractionWithZeroDenominator) {
  expect_rejected(with_line(8, "J = \"1/0\""), 8, "motor.J",
                  "not a number: \"1/0\" (division by zero; write a decimal such as 0.3 or a fraction such as "
                  "\"1/3\")");
}

TEST_F(CaseFileVariants, Boolean) {
  expect_rejected(with_line(9, "F = true"), 9, "motor.F", "expected a number, got a boolean");
}

TEST_F(CaseFileVariants, Array) {
  expect_rejected(with_line(9, "F = [0.1]"), 9, "motor.F", "expected a number, got an array");
}

TEST_F(CaseFileVariants, BadMeasuredAt) {
  expect_rejected(with_line(2, "measured_at = \"shaft\""), 2, "measured_at",
                  "expected \"motor\" or \"load\", got \"shaft\"");
  expect_rejected(with_line(2, "measured_at = 1"), 2, "measured_at",
                  "expected \"motor\" or \"load\", got an integer");
}

TEST_F(CaseFileVariants, NameMustBeAString) {
  expect_rejected(with_line(1, "name = 5"), 1, "name", "expected a string, got an integer");
}

TEST_F(CaseFileVariants, TableWrittenAsAValue) {
  std::vector<std::string> lines(valid_case_lines.begin(), valid_case_lines.begin() + 10);
  lines[5] = "load = 3";
  expect_rejected(lines, 6, "load", "expected a table [load], got an integer");
}

TEST_F(CaseFileVariants, TomlSyntaxErrorUsesTheParsersLine) {
  const std::filesystem::path file = write(with_line(4, "backlash = = 0.3"));
  try {
    load_case_file(file);
    ADD_FAILURE() << "load_case_file returned a case instead of a syntax error";
  } catch (const CaseFileError& error) {
    const std::string message = error.what();
    const std::string expected_prefix = file.string() + ":4: syntax: ";
    EXPECT_EQ(message.substr(0, expected_prefix.size()), expected_prefix)
        << "what() returned \"" << message << "\" instead of starting with \"" << expected_prefix << "\"";
    EXPECT_GT(message.size(), expected_prefix.size()) << "the syntax error has no description";
    EXPECT_EQ(message.find('\n'), std::string::npos) << "what() is not one line: " << message;
    EXPECT_EQ(error.line(), 4);
  }
}

TEST_F(CaseFileVariants, DuplicateKeyIsASyntaxError) {
  const std::filesystem::path file = write(with_inserted_line(10, "J = 0.7"));
  try {
    load_case_file(file);
    ADD_FAILURE() << "load_case_file returned a case instead of a duplicate-key error";
  } catch (const CaseFileError& error) {
    EXPECT_EQ(error.line(), 10) << "line() returned " << error.line() << " instead of 10";
    EXPECT_EQ(error.key(), "syntax");
  }
}

TEST_F(CaseFileVariants, MissingFileIsNamed) {
  const std::filesystem::path file = folder_ / "does-not-exist.toml";
  try {
    load_case_file(file);
    ADD_FAILURE() << "load_case_file returned a case for a missing file";
  } catch (const CaseFileError& error) {
    EXPECT_EQ(std::string(error.what()), file.string() + ": cannot open case file: no such file");
  }
  // load_case treats anything that looks like a path as one.
  EXPECT_THROW(load_case(file.string()), CaseFileError);
}

// ------------------------------------------------------------------ exact numbers

TEST_F(CaseFileVariants, FractionStringsAreAccepted) {
  const CaseSpec spec = load(with_line(4, "backlash = \"1/3\""));
  expect_exact(spec.backlash, exact(1, 3), "backlash \"1/3\"");
  expect_exact(load(with_line(5, "reference = \"-2/5\"")).reference, exact(-2, 5), "reference \"-2/5\"");
  expect_exact(load(with_line(8, "J = \"0.25\"")).Jm, exact(1, 4), "motor.J \"0.25\"");
  expect_exact(load(with_line(8, "J = \"1.5/3\"")).Jm, exact(1, 2), "motor.J \"1.5/3\"");
}

TEST_F(CaseFileVariants, ExponentsAreExact) {
  expect_exact(load(with_line(9, "F = 1e-3")).Fm, exact(1, 1000), "motor.F 1e-3");
  expect_exact(load(with_line(9, "F = 2.5E+2")).Fm, exact(250), "motor.F 2.5E+2");
  expect_exact(load(with_line(9, "F = \"1e-3\"")).Fm, exact(1, 1000), "motor.F \"1e-3\"");
}

TEST_F(CaseFileVariants, UnderscoreSeparatorsAreExact) {
  expect_exact(load(with_line(9, "F = 1_000.000_5")).Fm, exact(10000005, 10000), "motor.F 1_000.000_5");
  expect_exact(load(with_line(9, "F = 1_000")).Fm, exact(1000), "motor.F 1_000");
}

TEST_F(CaseFileVariants, DecimalsNeverPassThroughADouble) {
  // 32 decimals: no double holds this value, the exact decimal does.
  using boost::multiprecision::cpp_int;
  const Rational expected(cpp_int("30000000000000000000000000000001"), boost::multiprecision::pow(cpp_int(10), 32));
  expect_exact(load(with_line(9, "F = 0.30000000000000000000000000000001")).Fm, expected, "motor.F with 32 decimals");
}

TEST_F(CaseFileVariants, NegativeReferenceIsAccepted) {
  expect_exact(load(with_line(5, "reference = -0.5")).reference, exact(-1, 2), "reference -0.5");
}

TEST_F(CaseFileVariants, NegativeStepIsAccepted) {
  const CaseSpec spec = load(with_line(16, "step = -0.62"));
  ASSERT_TRUE(spec.experiment.has_value());
  expect_exact(spec.experiment->step, exact(-31, 50), "experiment.step -0.62");
}

TEST_F(CaseFileVariants, ExperimentIsOptionalAndTEndToo) {
  std::vector<std::string> without_experiment(valid_case_lines.begin(), valid_case_lines.begin() + 13);
  EXPECT_FALSE(load(without_experiment).experiment.has_value());
  const CaseSpec spec = load(with_line(17, ""));
  ASSERT_TRUE(spec.experiment.has_value());
  EXPECT_FALSE(spec.experiment->t_end.has_value());
}

TEST_F(CaseFileVariants, InlineTablesAndCommentsReadTheRightLiteral) {
  std::vector<std::string> lines(valid_case_lines.begin(), valid_case_lines.begin() + 6);
  lines.push_back("motor = { J = 0.125, F = 0.375 }  # a comment 0.9");
  lines.push_back("load = { F = 0.5e1, J = 7.5 }");
  const CaseSpec spec = load(lines);
  expect_exact(spec.Jm, exact(1, 8), "motor.J");
  expect_exact(spec.Fm, exact(3, 8), "motor.F");
  expect_exact(spec.JL, exact(15, 2), "load.J");
  expect_exact(spec.FL, exact(5), "load.F");
}

TEST_F(CaseFileVariants, NonAsciiTextAndInlineTables) {
  std::vector<std::string> lines(valid_case_lines.begin(), valid_case_lines.begin() + 6);
  lines.push_back("motor = { \"J\" = 0.375, F = 0.125 }");
  lines.push_back("load = { J = 0.5, F = 0.25 }");
  lines.push_back("experiment = { t_end = 12.5, step = 0.75 }  # ß — θ");
  lines[0] = "name = \"Fall ß — θ\"";
  const CaseSpec spec = load(lines);
  EXPECT_EQ(spec.name, "Fall ß — θ");
  expect_exact(spec.Jm, exact(3, 8), "motor.J");
  expect_exact(spec.Fm, exact(1, 8), "motor.F");
  ASSERT_TRUE(spec.experiment.has_value());
  expect_exact(spec.experiment->step, exact(3, 4), "experiment.step");
}

// ------------------------------------------------------------------ to_string, to_double

TEST(RationalText, FractionsAndIntegers) {
  EXPECT_EQ(to_string(exact(3, 10)), "3/10");
  EXPECT_EQ(to_string(exact(-2, 5)), "-2/5");
  EXPECT_EQ(to_string(exact(6, 3)), "2");
  EXPECT_EQ(to_string(exact(0)), "0");
  EXPECT_STREQ(to_string(MeasuredAt::Motor), "motor");
  EXPECT_STREQ(to_string(MeasuredAt::Load), "load");
}

/// True if no double is strictly nearer to `value` than `candidate`.
bool is_nearest_double(const Rational& value, double candidate) {
  const Rational error = abs(Rational(candidate) - value);
  for (double neighbour : {std::nextafter(candidate, -std::numeric_limits<double>::infinity()),
                           std::nextafter(candidate, std::numeric_limits<double>::infinity())}) {
    if (abs(Rational(neighbour) - value) < error) return false;
  }
  return true;
}

TEST(RationalToDouble, RoundsToTheNearestDouble) {
  EXPECT_EQ(to_double(exact(1, 3)), 1.0 / 3.0) << "to_double(1/3) returned " << to_double(exact(1, 3));
  EXPECT_EQ(to_double(exact(3, 10)), 0.3) << "to_double(3/10) returned " << to_double(exact(3, 10));
  EXPECT_EQ(to_double(exact(-2, 3)), -2.0 / 3.0);
  EXPECT_EQ(to_double(exact(1, 1000)), 1e-3);
  EXPECT_EQ(to_double(exact(0)), 0.0);

  std::mt19937_64 generator(20240601);
  using boost::multiprecision::cpp_int;
  for (int trial = 0; trial < 2000; ++trial) {
    // Numerators and denominators far beyond 2^53, so a naive num/den in double would round twice.
    cpp_int numerator = cpp_int(generator()) * cpp_int(generator()) + 1;
    cpp_int denominator = cpp_int(generator()) * (trial % 3 == 0 ? cpp_int(generator()) : cpp_int(1)) + 1;
    if (trial % 2 == 1) numerator = -numerator;
    const Rational value(numerator, denominator);
    const double converted = to_double(value);
    EXPECT_TRUE(is_nearest_double(value, converted))
        << "to_double(" << to_string(value) << ") returned " << converted << " which is not the nearest double";
  }
}

}  // namespace
