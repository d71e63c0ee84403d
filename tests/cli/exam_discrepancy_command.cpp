// `backlash discrepancy`: bad input fails with one line naming the file (and line and
// column where there is one), exit 2, and nothing written into --out; a measured-drive
// model runs on an EMPS record given as CSV or .mat, and its --out folder is the same
// bytes every time.
#include "../measurements/mat_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using backlash::measurements::testing::emps_variables;
using backlash::measurements::testing::variable_named;
using backlash::measurements::testing::write_mat;

const fs::path emps_dir = BACKLASH_EMPS_DATA_DIR;

struct CommandRun {
  int exit_code;
  std::string out, err;
};

// A shell command line; stdout and stderr apart.
CommandRun run_shell(const std::string& line) {
  const std::string err_file = fs::temp_directory_path() / ("backlash-discrepancy-test-" + std::to_string(::getpid()) + ".err");
  const std::string command = "(" + line + ") 2> " + err_file;
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

CommandRun run(const std::string& arguments) { return run_shell(std::string(BACKLASH_CLI) + " " + arguments); }

class Folder {
 public:
  Folder() {
    std::random_device entropy;
    path_ = fs::temp_directory_path() / ("backlash-discrepancy-" + std::to_string(::getpid()) + "-" + std::to_string(entropy()));
    fs::create_directory(path_);
  }
  ~Folder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream(path_ / name, std::ios::binary) << content;
    return (path_ / name).string();
  }

 private:
  fs::path path_;
};

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A smooth record of 40 samples (the step workflow's CSV) with one line replaced.
std::string step_record(int broken_line = -1, const std::string& replacement = "") {
  std::string csv = "t,theta_out\n";
  for (int i = 0; i < 40; ++i) {
    const int line = i + 2;
    if (line == broken_line) {
      csv += replacement + "\n";
      continue;
    }
    csv += std::to_string(0.05 * i) + "," + std::to_string(0.5 - 0.5 * std::exp(-0.3 * i)) + "\n";
  }
  return csv;
}

const char* const drive_model =
    "name = \"EMPS\"\nmeasured_at = \"motor\"\nbacklash = 0\nreference = 0\n[motor]\nJ = 80\nF = 300\n[load]\nJ = 1\nF = 0\n"
    "[experiment]\nkind = \"drive\"\n[fit]\nfree = [\"motor.J\", \"motor.F\"]\n";

struct BadCase {
  std::string name, arguments, expected;  ///< expected: the whole line after "backlash: error: ", or a fragment
  bool exact = true;
};

void expect_refused(const BadCase& bad, const fs::path& out) {
  SCOPED_TRACE(bad.name);
  const CommandRun r = run(bad.arguments + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << "returned exit code " << r.exit_code << " instead of 2; stderr: " << r.err;
  EXPECT_EQ(r.out, "") << "printed on stdout";
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr is not one line: " << r.err;
  if (bad.exact)
    EXPECT_EQ(r.err, "backlash: error: " + bad.expected + "\n")
        << "returned \"" << r.err << "\" instead of \"backlash: error: " << bad.expected << "\"";
  else
    EXPECT_NE(r.err.find(bad.expected), std::string::npos) << "returned \"" << r.err << "\", which does not name \"" << bad.expected << "\"";
  EXPECT_FALSE(fs::exists(out)) << "left " << out << " behind";
}

TEST(DiscrepancyCommand, exam_BadStepRecordsAreRefusedWithOneLineNamingFileLineAndColumn) {
  Folder folder;
  const fs::path out = folder / "out";
  const std::string model = " --model V --step 0.5 --data ";
  const std::string no_header = folder.write("no_header.csv", "0,0.1\n0.05,0.2\n");
  const std::string missing = folder.write("missing.csv", "t,theta_motor\n0,1\n");
  const std::string backwards = folder.write("backwards.csv", step_record(7, "0.1,0.3"));
  const std::string duplicate = folder.write("duplicate.csv", step_record(7, "0.2,0.3"));
  const std::string nan = folder.write("nan.csv", step_record(9, "0.35,nan"));
  const std::string text = folder.write("text.csv", step_record(5, "0.15,abc"));
  const std::string empty = folder.write("empty.csv", "");
  const std::string few = folder.write("few.csv", "t,theta_out\n0,0\n0.1,0.1\n0.2,0.15\n");
  const std::string no_step_model = folder.write("no_step.toml",
                                                 "name = \"no step\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\nreference = 1\n"
                                                 "[motor]\nJ = 0.5\nF = 0.1\n[load]\nJ = 0.5\nF = 0.3\n");
  const std::string good = folder.write("good.csv", step_record());
  const std::vector<BadCase> cases{
      {"no header", "discrepancy" + model + no_header, no_header + ":1: ", false},
      {"no theta_out column", "discrepancy" + model + missing, missing + ":1: theta_out", false},
      {"time going backwards", "discrepancy" + model + backwards, backwards + ":7: t", false},
      {"a repeated time", "discrepancy" + model + duplicate, duplicate + ":7: t", false},
      {"NaN", "discrepancy" + model + nan, nan + ":9: theta_out", false},
      {"not a number", "discrepancy" + model + text, text + ":5: theta_out", false},
      {"empty file", "discrepancy" + model + empty, empty, false},
      {"too few samples", "discrepancy" + model + few, few + ": too few samples: 3 data rows, at least 10 required"},
      {"no step anywhere", "discrepancy --model " + no_step_model + " --data " + good, no_step_model + ":1: experiment.step", false},
      {"a step of 0", "discrepancy --model V --step 0 --data " + good, "--step: must not be 0"},
      {"drive options on a step model", "discrepancy" + model + good + " --cutoff 50",
       "--cutoff: only for a measured-drive model ([experiment] kind = \"drive\")"},
      {"absent record", "discrepancy" + model + (folder / "absent.csv").string(), (folder / "absent.csv").string(), false},
  };
  for (const BadCase& bad : cases) expect_refused(bad, out);
}

TEST(DiscrepancyCommand, exam_BadMeasuredDriveInputIsRefusedWithOneLine) {
  Folder folder;
  const fs::path out = folder / "out";
  const std::string model = folder.write("emps.toml", drive_model);
  const std::string estimation = (emps_dir / "DATA_EMPS.mat").string();
  // .mat files: a variable missing, lengths that differ, time going backwards.
  auto variables = emps_variables(300);
  variables.erase(std::remove_if(variables.begin(), variables.end(), [](const auto& v) { return v.name == "vir"; }), variables.end());
  const std::string no_vir = (folder / "no_vir.mat").string();
  ASSERT_TRUE(write_mat(no_vir, variables));
  variables = emps_variables(300);
  variable_named(variables, "qm").values.pop_back();
  const std::string short_qm = (folder / "short_qm.mat").string();
  ASSERT_TRUE(write_mat(short_qm, variables));
  variables = emps_variables(300);
  std::swap(variable_named(variables, "t").values[100], variable_named(variables, "t").values[101]);
  const std::string backwards = (folder / "backwards.mat").string();
  ASSERT_TRUE(write_mat(backwards, variables));
  const std::string no_drive = folder.write("no_drive.csv", step_record());
  const std::string gap_model =
      folder.write("gap.toml", std::string(drive_model).replace(std::string(drive_model).find("backlash = 0"), 12, "backlash = 0.001"));
  const std::string k_model = folder.write(
      "k.toml", std::string(drive_model).replace(std::string(drive_model).find("\"motor.F\"]"), 10, "\"K\"]"));
  const std::string both_model = folder.write(
      "both.toml", std::string(drive_model).replace(std::string(drive_model).find("\"motor.F\"]"), 10, "\"load.J\"]"));
  const std::string d = "discrepancy --model " + model + " --data ";
  const std::vector<BadCase> cases{
      {"no vir in the .mat", d + no_vir, no_vir + ": vir: ", false},
      {"qm shorter than t", d + short_qm, short_qm + ": qm: 299 samples, but t has 300"},
      {"time going backwards in the .mat", d + backwards, backwards + ": t: ", false},
      {"a CSV without a drive column", d + no_drive, no_drive + ": no drive column: a measured-drive model needs the logged drive"},
      {"a step for a drive", d + estimation + " --step 0.5", "--step: the model's experiment is a measured drive, which has no step"},
      {"a cut-off at Nyquist", d + estimation + " --cutoff 500", "500", false},
      {"a negative window", d + estimation + " --window -1", "--window: expected a duration > 0 [s], got '-1'"},
      // Issue 22: a drive with a gap runs on the motor encoder; EMPS logs only the measured shaft.
      {"a drive model with a backlash", "discrepancy --model " + gap_model + " --data " + estimation, "DATA_EMPS.mat: theta_motor: missing column", false},
      {"K free", "discrepancy --model " + k_model + " --data " + estimation,
       "k.toml: fit.free: K is not part of a measured-drive model (the loop is open)"},
      {"motor.J and load.J free", "discrepancy --model " + both_model + " --data " + estimation,
       "both.toml: fit.free: motor.J and load.J cannot both be free: on a rigid drive only their sum shows"},
      {"a bad validation record", d + estimation + " --validate " + short_qm, short_qm + ": qm: 299 samples, but t has 300"},
  };
  for (const BadCase& bad : cases) expect_refused(bad, out);
}

TEST(DiscrepancyCommand, exam_EmpsFromTheMatFileNamesCoulombAndOffsetAndWritesTheSameBytesTwice) {
  Folder folder;
  const std::string model = folder.write("emps.toml", drive_model);
  const std::string args = "discrepancy --model " + model + " --data " + (emps_dir / "DATA_EMPS.mat").string() + " --validate " +
                           (emps_dir / "DATA_EMPS_PULSES.mat").string();
  const CommandRun json = run(args + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["status"], "effect_found");
  ASSERT_EQ(j["effects"].size(), 2u);
  EXPECT_EQ(j["effects"][0]["effect"], "coulomb_motor");
  EXPECT_EQ(j["effects"][1]["effect"], "torque_offset");
  EXPECT_LT(j["validation"]["torque_rms_corrected"].get<double>(), j["validation"]["torque_rms_nominal"].get<double>());
  std::vector<std::string> first;
  for (const char* out : {"a", "b"}) {
    const CommandRun r = run(args + " --out " + (folder / out).string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder / "a")) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  for (const char* expected : {"discrepancy.md", "discrepancy.json", "corrected.toml", "torque_residual_vs_velocity.svg",
                               "torque_over_time.svg", "position_window.svg", "validation_position_window.svg", "candidates.svg"})
    EXPECT_TRUE(std::find(names.begin(), names.end(), expected) != names.end()) << "no " << expected << " in --out";
  for (const std::string& name : names)
    EXPECT_EQ(read(folder / "a" / name), read(folder / "b" / name)) << name << " differs between two runs";
}

// The README's discrepancy commands, as printed there, run from the source folder (the --out
// folder moved to a temporary one), and say what the README says they say.
TEST(DiscrepancyCommand, exam_TheReadmeExamplesRunAndSayWhatTheReadmeSays) {
  std::ifstream readme(fs::path(BACKLASH_SOURCE_DIR) / "README.md");
  std::vector<std::string> commands;
  for (std::string line; std::getline(readme, line);)
    if (line.rfind("build/bin/backlash discrepancy", 0) == 0) commands.push_back(line);
  ASSERT_EQ(commands.size(), 5u) << "the README has " << commands.size() << " discrepancy examples instead of 5";
  Folder folder;
  int k = 0;
  for (std::string command : commands) {
    SCOPED_TRACE(command);
    const std::size_t out = command.find(" --out ");
    const std::size_t end = out == std::string::npos ? command.size() : out;
    command = command.substr(std::string("build/bin/backlash ").size(), end - std::string("build/bin/backlash ").size()) +
              " --no-progress --out " + (folder / ("out" + std::to_string(k++))).string();
    const CommandRun r = run_shell("cd " + std::string(BACKLASH_SOURCE_DIR) + " && " + BACKLASH_CLI + " " + command);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    if (command.find("heavier_load") != std::string::npos) {  // a wrong nominal number, not an effect
      EXPECT_NE(r.out.find(": parameters_corrected ("), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("load.J          0.5 -> 0.574989 ± 1.1e-05  (x1.15)"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("(128.44 and 0.99 noise sigmas)"), std::string::npos) << r.out;
      continue;
    }
    if (command.find("two_body_drive") != std::string::npos) {  // a drive with a gap, both encoders
      EXPECT_NE(r.out.find(": parameters_corrected ("), std::string::npos) << r.out;  // the residual at its noise (issue 22)
      EXPECT_NE(r.out.find("(noise level 0.035)"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("backlash        0.0261799 -> 0.0349 ± 1.9e-06"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("load.J          0.0375 -> 0.0298961 ± 9.3e-05"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("load.F          0.05 -> 0.0500209"), std::string::npos) << r.out;
      continue;
    }
    EXPECT_NE(r.out.find("effect_found"), std::string::npos) << r.out;
    if (command.find("hidden_friction") != std::string::npos) {
      EXPECT_NE(r.out.find("coulomb_load    torque = 0.0200002"), std::string::npos) << r.out;
    } else if (command.find("friction_and_delay") != std::string::npos) {  // a pair: the best single plus one
      EXPECT_NE(r.out.find("delay           tau = 0.188432 ± 5.6e-05"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("coulomb_load    torque = 0.0309826 ± 1.5e-05"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("(81.51 and 1.04 noise sigmas)"), std::string::npos) << r.out;
    } else {
      EXPECT_NE(r.out.find("coulomb_motor   torque = 20.3941"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("torque_offset   torque = 3.25104"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("torque RMS: 9.451 before (best nominal), 2.065 after"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("torque RMS 9.695 before, 2.609 after"), std::string::npos) << r.out;
    }
  }
}

}  // namespace
