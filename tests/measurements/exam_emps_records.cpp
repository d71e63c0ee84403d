// exam_emps_records — EMPS .mat records read through matio (measurements/emps.hpp).
//
// The two published records read with their known shape, sampling and gains;
// the validation record's pulses are found already contained in vir (the
// evidence is pinned here); malformed .mat files written with matio, a text
// file named .mat, truncated and non-regular files give one-line errors naming
// file and variable, and matio prints nothing.
#include "backlash/measurements/emps.hpp"

#include "mat_files.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace {

using backlash::measurements::EmpsPulses;
using backlash::measurements::EmpsRecord;
using backlash::measurements::MeasuredDataError;
using backlash::measurements::MeasuredRecord;
using backlash::measurements::emps_drive_force;
using backlash::measurements::emps_pulses_in_vir;
using backlash::measurements::read_emps;
using backlash::measurements::to_measured_record;
using backlash::measurements::testing::MatVariableSpec;
using backlash::measurements::testing::TemporaryFolder;
using backlash::measurements::testing::bits;
using backlash::measurements::testing::emps_variables;
using backlash::measurements::testing::expect_same_bits;
using backlash::measurements::testing::variable_named;
using backlash::measurements::testing::write_mat;
using backlash::measurements::testing::write_text;

const std::filesystem::path data_dir = BACKLASH_EMPS_DATA_DIR;
const std::filesystem::path estimation_file = data_dir / "DATA_EMPS.mat";
const std::filesystem::path validation_file = data_dir / "DATA_EMPS_PULSES.mat";

template <class Action>
std::string error_of(Action&& action) {
  try {
    action();
  } catch (const MeasuredDataError& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("<not a MeasuredDataError: ") + error.what() + ">";
  }
  return "<no error>";
}

void expect_error(const std::string& actual, const std::string& expected) {
  EXPECT_EQ(actual, expected) << "returned \"" << actual << "\" instead of \"" << expected << "\"";
}

constexpr std::size_t published_samples = 24841;
constexpr double published_gtau = 35.150651882485469;

void expect_published_layout(const EmpsRecord& record) {
  EXPECT_EQ(record.size(), published_samples) << "returned " << record.size() << " samples instead of " << published_samples;
  EXPECT_EQ(record.qm.size(), published_samples);
  EXPECT_EQ(record.qg.size(), published_samples);
  EXPECT_EQ(record.vir.size(), published_samples);
  EXPECT_EQ(record.t.front(), 0.0) << "t(1) returned " << record.t.front() << " instead of 0";
  EXPECT_EQ(record.t.back(), 24.84) << "t(end) returned " << record.t.back() << " instead of 24.84";
  // 1 kHz: every step within 1e-7 s of 1 ms (the files show 2e-8 at most), and strictly increasing.
  double shortest_step = 1, longest_step = 0;
  for (std::size_t k = 1; k < record.size(); ++k) {
    shortest_step = std::min(shortest_step, record.t[k] - record.t[k - 1]);
    longest_step = std::max(longest_step, record.t[k] - record.t[k - 1]);
  }
  EXPECT_GT(shortest_step, 1e-3 - 1e-7) << "the shortest step returned " << shortest_step << " instead of about 1e-3";
  EXPECT_LT(longest_step, 1e-3 + 1e-7) << "the longest step returned " << longest_step << " instead of about 1e-3";
  const double rate = static_cast<double>(record.size() - 1) / (record.t.back() - record.t.front());
  EXPECT_NEAR(rate, 1000.0, 1e-9) << "the sample rate returned " << rate << " Hz instead of 1000";
  EXPECT_EQ(bits(record.gtau), bits(published_gtau)) << "gtau returned " << record.gtau << " instead of 35.150651882485469";
  EXPECT_EQ(record.kp, 160.18) << "kp returned " << record.kp << " instead of 160.18";
  EXPECT_EQ(record.kv, 243.45) << "kv returned " << record.kv << " instead of 243.45";
}

// ------------------------------------------------------------------ the published records

TEST(EmpsRecords, EstimationRecordHasTheKnownShapeSamplingAndGains) {
  const EmpsRecord record = read_emps(estimation_file);
  expect_published_layout(record);
  EXPECT_EQ(record.source, estimation_file);
  EXPECT_FALSE(record.pulses_N.has_value()) << "pulses_N returned present instead of absent";
  EXPECT_EQ(record.qm.front(), 7.45e-06) << "qm(1) returned " << record.qm.front() << " instead of 7.45e-06";
  EXPECT_EQ(emps_pulses_in_vir(record), EmpsPulses::none);
}

TEST(EmpsRecords, ValidationRecordPulsesAreAlreadyContainedInVir) {
  const EmpsRecord record = read_emps(validation_file);
  expect_published_layout(record);
  ASSERT_TRUE(record.pulses_N.has_value()) << "pulses_N returned absent instead of present";
  const std::vector<double>& pulses = *record.pulses_N;
  EXPECT_TRUE(std::all_of(pulses.begin(), pulses.end(), [](double p) { return p == 0 || p == 5; }))
      << "pulses_N holds values other than 0 and 5";
  // The evidence: vir steps with every edge of pulses_N, 1:1, and hardly moves otherwise.
  std::size_t rising = 0, falling = 0;
  double worst_edge_mismatch = 0, largest_other_step = 0;
  double first_rise = -1;
  for (std::size_t k = 1; k < record.size(); ++k) {
    const double pulse_step = pulses[k] - pulses[k - 1];
    const double vir_step = record.vir[k] - record.vir[k - 1];
    if (pulse_step == 0) {
      largest_other_step = std::max(largest_other_step, std::abs(vir_step));
      continue;
    }
    ++(pulse_step > 0 ? rising : falling);
    if (pulse_step > 0 && first_rise < 0) first_rise = record.t[k];
    worst_edge_mismatch = std::max(worst_edge_mismatch, std::abs(vir_step - pulse_step));
  }
  EXPECT_EQ(rising, 25u) << "returned " << rising << " rising edges instead of 25";
  EXPECT_EQ(falling, 24u) << "returned " << falling << " falling edges instead of 24";
  EXPECT_NEAR(first_rise, 0.344, 1e-6) << "the first pulse starts at " << first_rise << " instead of 0.344";
  EXPECT_LT(worst_edge_mismatch, 0.2) << "at an edge vir stepped by " << worst_edge_mismatch
                                      << " more or less than pulses_N instead of < 0.2";
  EXPECT_LT(largest_other_step, 0.75) << "between edges vir stepped by " << largest_other_step << " instead of < 0.75";
  EXPECT_EQ(emps_pulses_in_vir(record), EmpsPulses::contained)
      << "returned " << to_string(emps_pulses_in_vir(record)) << " instead of contained";
}

TEST(EmpsRecords, DriveForceIsGtauTimesVirOnBothRecords) {
  for (const auto& file : {estimation_file, validation_file}) {
    SCOPED_TRACE(file.filename().string());
    const EmpsRecord record = read_emps(file);
    std::vector<double> expected(record.size());
    for (std::size_t k = 0; k < record.size(); ++k) expected[k] = record.gtau * record.vir[k];
    expect_same_bits(emps_drive_force(record), expected, "drive");
    const MeasuredRecord measured = to_measured_record(record);
    expect_same_bits(measured.t, record.t, "t");
    expect_same_bits(measured.theta_out, record.qm, "theta_out");
    ASSERT_TRUE(measured.drive.has_value());
    expect_same_bits(*measured.drive, expected, "drive");
    EXPECT_FALSE(measured.theta_motor || measured.theta_load) << "returned columns EMPS does not measure";
    EXPECT_EQ(measured.source, file);
  }
}

// ------------------------------------------------------------------ the pulses decision

EmpsRecord synthetic_record(bool pulses_in_vir, bool one_edge_wrong = false) {
  EmpsRecord record;
  record.gtau = 35;
  std::vector<double> pulses;
  for (int k = 0; k < 2000; ++k) {
    record.t.push_back(k / 1000.0);
    record.qm.push_back(0);
    record.qg.push_back(0);
    const double pulse = (k / 250) % 2 == 1 ? 5.0 : 0.0;  // 0.25 s on, 0.25 s off
    pulses.push_back(pulse);
    record.vir.push_back(0.5 * std::sin(k / 100.0) + (pulses_in_vir ? pulse : 0.0));
  }
  if (one_edge_wrong) record.vir[250] -= 5;  // the first edge no longer steps
  record.pulses_N = pulses;
  record.source = "synthetic.mat";
  return record;
}

TEST(EmpsPulsesDecision, PulsesOnTopOfASmoothVirAreAdded) {
  const EmpsRecord record = synthetic_record(false);
  EXPECT_EQ(emps_pulses_in_vir(record), EmpsPulses::added)
      << "returned " << to_string(emps_pulses_in_vir(record)) << " instead of added";
  const std::vector<double> drive = emps_drive_force(record);
  for (std::size_t k = 0; k < record.size(); ++k)
    ASSERT_EQ(bits(drive[k]), bits(record.gtau * record.vir[k] + (*record.pulses_N)[k]))
        << "drive[" << k << "] returned " << drive[k] << " instead of gtau*vir + pulses_N";
}

TEST(EmpsPulsesDecision, PulsesInsideVirAreNotAddedAgain) {
  const EmpsRecord record = synthetic_record(true);
  EXPECT_EQ(emps_pulses_in_vir(record), EmpsPulses::contained)
      << "returned " << to_string(emps_pulses_in_vir(record)) << " instead of contained";
}

TEST(EmpsPulsesDecision, MixedEvidenceIsRefused) {
  const EmpsRecord record = synthetic_record(true, true);
  expect_error(error_of([&] { emps_pulses_in_vir(record); }),
               "synthetic.mat: pulses_N: cannot tell from the data whether the pulses are already in vir: of 7 edges, "
               "vir steps with 6 (as contained) and stays put at 1 (as added on top)");
  expect_error(error_of([&] { emps_drive_force(record); }),
               "synthetic.mat: pulses_N: cannot tell from the data whether the pulses are already in vir: of 7 edges, "
               "vir steps with 6 (as contained) and stays put at 1 (as added on top)");
}

// ------------------------------------------------------------------ bad .mat files

struct BadMat {
  std::string name;
  std::vector<MatVariableSpec> variables;
  std::string expected;  ///< after "FILE: "
};

std::vector<BadMat> bad_mats() {
  std::vector<BadMat> cases;
  const auto with = [&](const std::string& name, auto change, const std::string& expected) {
    std::vector<MatVariableSpec> variables = emps_variables();
    change(variables);
    cases.push_back({name, variables, expected});
  };
  with("missing variable", [](auto& v) { v.pop_back(); }, "kv: missing variable (the file has: gtau, kp, qg, qm, t, vir)");
  with("missing time", [](auto& v) { v.erase(v.begin()); }, "t: missing variable (the file has: gtau, kp, kv, qg, qm, vir)");
  with("shorter qm", [](auto& v) { variable_named(v, "qm").values.pop_back(); }, "qm: 9 samples, but t has 10");
  with("longer vir", [](auto& v) { variable_named(v, "vir").values.push_back(1); }, "vir: 11 samples, but t has 10");
  with("shorter pulses", [](auto& v) { v.push_back({"pulses_N", std::vector<double>(9, 0.0)}); },
       "pulses_N: 9 samples, but t has 10");
  with("repeated time", [](auto& v) { variable_named(v, "t").values[4] = variable_named(v, "t").values[3]; },
       "t: not strictly increasing: t(5) = 0.003 after t(4) = 0.003");
  with("time going back", [](auto& v) { variable_named(v, "t").values[9] = 0.0005; },
       "t: not strictly increasing: t(10) = 0.0005 after t(9) = 0.008");
  with("NaN in vir", [](auto& v) { variable_named(v, "vir").values[2] = std::nan(""); },
       "vir: vir(3) is NaN (t = 0.002 s): not finite");
  with("infinity in qm", [](auto& v) { variable_named(v, "qm").values[0] = -HUGE_VAL; },
       "qm: qm(1) is -inf (t = 0 s): not finite");
  with("NaN time", [](auto& v) { variable_named(v, "t").values[1] = std::nan(""); }, "t: t(2) is NaN: not finite");
  with("NaN gain", [](auto& v) { variable_named(v, "gtau").values[0] = std::nan(""); }, "gtau: is NaN: not finite");
  with("zero gain", [](auto& v) { variable_named(v, "gtau").values[0] = 0; },
       "gtau: is 0: the drive force gtau*vir would vanish");
  with("complex qm", [](auto& v) { variable_named(v, "qm").kind = MatVariableSpec::Kind::complex; },
       "qm: complex, expected real numbers");
  with("text qg", [](auto& v) { variable_named(v, "qg") = {"qg", {}, {}, MatVariableSpec::Kind::text, "reference"}; },
       "qg: not numeric: it is a char array");
  with("logical vir", [](auto& v) { variable_named(v, "vir").kind = MatVariableSpec::Kind::logical; },
       "vir: logical, expected numeric values");
  with("matrix time", [](auto& v) { variable_named(v, "t").dims = {5, 2}; },
       "t: not a vector: it is 5x2 (expected Nx1 or 1xN)");
  with("vector gain", [](auto& v) { variable_named(v, "gtau").values = {35, 36}; }, "gtau: not a scalar: it is 2x1");
  with("one sample", [](auto& v) { for (auto& s : v) if (s.values.size() == 10) s.values.resize(1); },
       "t: 1 sample, at least 2 required");
  return cases;
}

TEST(EmpsBadFiles, EachMalformedRecordGivesItsOneLineMessage) {
  TemporaryFolder folder;
  int index = 0;
  for (const BadMat& bad : bad_mats()) {
    SCOPED_TRACE(bad.name);
    const auto file = folder / ("bad-" + std::to_string(index++) + ".mat");
    ASSERT_TRUE(write_mat(file, bad.variables));
    ::testing::internal::CaptureStderr();
    const std::string actual = error_of([&] { read_emps(file); });
    const std::string printed = ::testing::internal::GetCapturedStderr();
    expect_error(actual, file.string() + ": " + bad.expected);
    EXPECT_EQ(printed, "") << "matio printed on stderr";
  }
}

TEST(EmpsBadFiles, FilesThatAreNotMatFilesAreRefused) {
  TemporaryFolder folder;
  const auto text = folder / "notes.mat";
  write_text(text, "t,qm,vir\n0,1,2\n");
  const auto empty = folder / "empty.mat";
  write_text(empty, "");
  const auto truncated = folder / "truncated.mat";
  {
    const std::string whole = backlash::measurements::testing::read_text(estimation_file);
    write_text(truncated, whole.substr(0, 3000));
  }
  const auto version4 = folder / "version4.mat";
  ASSERT_TRUE(write_mat(version4, emps_variables(), MAT_FT_MAT4));

  ::testing::internal::CaptureStderr();
  expect_error(error_of([&] { read_emps(text); }), text.string() + ": not a MATLAB .mat file");
  expect_error(error_of([&] { read_emps(empty); }),
               empty.string() + ": not a MATLAB v5 or v7.3 .mat file (EMPS records are v5)");
  expect_error(error_of([&] { read_emps(version4); }),
               version4.string() + ": not a MATLAB v5 or v7.3 .mat file (EMPS records are v5)");
  const std::string truncated_error = error_of([&] { read_emps(truncated); });
  // Issue 18, item 5: the data element cut short is named before matio reads it (as zeros).
  const std::string prefix = truncated.string() + ": cannot read: the file is truncated or corrupt (data element ";
  EXPECT_EQ(truncated_error.rfind(prefix, 0), 0u) << "returned \"" << truncated_error << "\" instead of \"" << prefix << "...)\"";
  EXPECT_EQ(truncated_error.find('\n'), std::string::npos);
  expect_error(error_of([&] { read_emps(folder / "absent.mat"); }), (folder / "absent.mat").string() + ": cannot read: no such file");
  expect_error(error_of([&] { read_emps(folder.path()); }), folder.path().string() + ": cannot read: it is a directory");
  expect_error(error_of([&] { read_emps("/dev/zero"); }), "/dev/zero: cannot read: not a regular file (a character device)");
  expect_error(error_of([&] { read_emps(estimation_file, 1000); }),
               estimation_file.string() + ": file too large: 626039 bytes (the limit is 1000 bytes)");
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "") << "matio printed on stderr";
}

// ------------------------------------------------------------------ other valid encodings

TEST(EmpsEncodings, RowVectorsSinglesIntegersAndExtraVariablesRead) {
  TemporaryFolder folder;
  std::vector<MatVariableSpec> variables = emps_variables();
  variable_named(variables, "qm").dims = {1, 10};
  variable_named(variables, "qg").kind = MatVariableSpec::Kind::single;
  variable_named(variables, "kp").kind = MatVariableSpec::Kind::int32;
  variables.push_back({"comment", {}, {}, MatVariableSpec::Kind::text, "not used"});
  const auto file = folder / "variants.mat";
  ASSERT_TRUE(write_mat(file, variables));
  const EmpsRecord record = read_emps(file);
  expect_same_bits(record.qm, variable_named(variables, "qm").values, "qm");
  std::vector<double> singles;
  for (double value : variable_named(variables, "qg").values) singles.push_back(static_cast<float>(value));
  expect_same_bits(record.qg, singles, "qg");
  EXPECT_EQ(record.kp, 160.0) << "kp returned " << record.kp << " instead of 160";
  EXPECT_EQ(record.gtau, 35.0) << "gtau returned " << record.gtau << " instead of 35";
}

TEST(EmpsEncodings, Version73FilesRead) {
  TemporaryFolder folder;
  const auto file = folder / "v73.mat";
  if (!write_mat(file, emps_variables(), MAT_FT_MAT73)) GTEST_SKIP() << "this matio cannot write v7.3 files";
  const EmpsRecord record = read_emps(file);
  std::vector<MatVariableSpec> written = emps_variables();
  expect_same_bits(record.t, variable_named(written, "t").values, "t");
  expect_same_bits(record.vir, variable_named(written, "vir").values, "vir");
}

}  // namespace
