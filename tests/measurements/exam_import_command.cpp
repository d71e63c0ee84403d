// exam_import_command — `backlash import FILE.mat --out FILE.csv [--format emps]`,
// run as the built binary.
//
// A published EMPS record becomes a CSV (t, theta_out = qm, drive = gtau·vir)
// that the strict reader reads back bit for bit, with a summary on stdout; bad
// input exits 2 with one line on stderr, nothing on stdout and no file written
// or left behind.
#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/measured_record.hpp"

#include "mat_files.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include <sys/wait.h>

namespace {

using backlash::measurements::EmpsRecord;
using backlash::measurements::MeasuredRecord;
using backlash::measurements::read_emps;
using backlash::measurements::read_measured_csv;
using backlash::measurements::testing::TemporaryFolder;
using backlash::measurements::testing::emps_variables;
using backlash::measurements::testing::expect_same_bits;
using backlash::measurements::testing::read_text;
using backlash::measurements::testing::variable_named;
using backlash::measurements::testing::write_mat;
using backlash::measurements::testing::write_text;

const std::filesystem::path data_dir = BACKLASH_EMPS_DATA_DIR;

struct CommandRun {
  int exit_code;
  std::string out, err;
};

std::string shell_quoted(const std::string& argument) {
  std::string quoted = "'";
  for (const char character : argument) quoted += character == '\'' ? std::string("'\\''") : std::string(1, character);
  return quoted + "'";
}

/// Runs the built backlash with `arguments`; stderr goes through a file in `scratch`.
CommandRun run(const std::vector<std::string>& arguments, const std::filesystem::path& scratch) {
  const std::filesystem::path err_file = scratch / "stderr.txt";
  std::string command = shell_quoted(BACKLASH_CLI);
  for (const std::string& argument : arguments) {
    command += ' ';
    command += shell_quoted(argument);
  }
  command += " 2> ";
  command += shell_quoted(err_file.string());
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "", "popen failed"};
  std::string out;
  std::array<char, 4096> buffer;
  while (const std::size_t count = std::fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), count);
  const int status = ::pclose(pipe);
  std::string err = read_text(err_file);
  std::filesystem::remove(err_file);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out, err};
}

TEST(ImportCommand, EstimationRecordBecomesACsvTheReaderReadsBackExactly) {
  TemporaryFolder folder;
  const auto input = data_dir / "DATA_EMPS.mat";
  const auto output = folder / "emps.csv";
  const CommandRun result = run({"import", input.string(), "--out", output.string()}, folder.path());
  ASSERT_EQ(result.exit_code, 0) << "returned exit code " << result.exit_code << " instead of 0: " << result.err;
  EXPECT_EQ(result.err, "") << "printed on stderr";
  for (const std::string fragment :
       {"samples      24841", "duration     24.84 s", "sample rate  1000 Hz", "gtau         35.15065188248547 N/V",
        "drive = gtau*vir [N]", "pulses_N     none", "[experiment]\nkind = \"drive\"\ndrive_gain = 1\n"})
    EXPECT_NE(result.out.find(fragment), std::string::npos) << "the summary lacks \"" << fragment << "\":\n" << result.out;

  const std::string text = read_text(output);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,theta_out,drive") << "the header returned something else";
  const MeasuredRecord record = read_measured_csv(output);
  const EmpsRecord emps = read_emps(input);
  expect_same_bits(record.t, emps.t, "t");
  expect_same_bits(record.theta_out, emps.qm, "theta_out");
  ASSERT_TRUE(record.drive.has_value()) << "drive returned absent instead of present";
  std::vector<double> force(emps.size());
  for (std::size_t k = 0; k < emps.size(); ++k) force[k] = emps.gtau * emps.vir[k];
  expect_same_bits(*record.drive, force, "drive");
  EXPECT_FALSE(record.theta_motor || record.theta_load) << "returned columns the import must not write";
  EXPECT_EQ(folder.entries(), std::vector<std::string>{"emps.csv"}) << "the import left other files behind";
}

TEST(ImportCommand, ValidationRecordPulsesAreNotCountedTwice) {
  TemporaryFolder folder;
  const auto input = data_dir / "DATA_EMPS_PULSES.mat";
  const auto output = folder / "pulses.csv";
  write_text(output, "an older import");  // replaced
  const CommandRun result = run({"import", input.string(), "--out", output.string(), "--format", "emps"}, folder.path());
  ASSERT_EQ(result.exit_code, 0) << "returned exit code " << result.exit_code << " instead of 0: " << result.err;
  EXPECT_NE(result.out.find("pulses_N     already contained in vir"), std::string::npos) << result.out;
  const MeasuredRecord record = read_measured_csv(output);
  const EmpsRecord emps = read_emps(input);
  std::vector<double> force(emps.size());
  for (std::size_t k = 0; k < emps.size(); ++k) force[k] = emps.gtau * emps.vir[k];
  ASSERT_TRUE(record.drive.has_value());
  expect_same_bits(*record.drive, force, "drive");
}

struct BadImport {
  std::string name;
  std::vector<std::string> arguments;
  std::string expected_error;  ///< after "backlash: error: "; empty: only check it is one line
};

TEST(ImportCommand, BadInputExitsTwoWithOneLineAndWritesNothing) {
  TemporaryFolder folder;
  const std::string good = (data_dir / "DATA_EMPS.mat").string();
  const std::string output = (folder / "out.csv").string();
  const auto text = folder / "notes.mat";
  write_text(text, "not a mat file\n");
  const auto short_qm = folder / "short.mat";
  std::vector<backlash::measurements::testing::MatVariableSpec> variables = emps_variables();
  variable_named(variables, "qm").values.pop_back();
  ASSERT_TRUE(write_mat(short_qm, variables));
  std::filesystem::create_directory(folder / "existing-folder");
  const auto own_copy = folder / "copy.mat";
  std::filesystem::copy_file(good, own_copy);

  const std::vector<BadImport> cases{
      {"text file named .mat", {"import", text.string(), "--out", output}, text.string() + ": not a MATLAB .mat file"},
      {"mismatched lengths", {"import", short_qm.string(), "--out", output}, short_qm.string() + ": qm: 9 samples, but t has 10"},
      {"missing input", {"import", (folder / "absent.mat").string(), "--out", output},
       (folder / "absent.mat").string() + ": cannot read: no such file"},
      {"output is /dev/null", {"import", good, "--out", "/dev/null"},
       "/dev/null: refusing to replace it: not a regular file (a character device)"},
      {"output is a folder", {"import", good, "--out", (folder / "existing-folder").string()},
       (folder / "existing-folder").string() + ": refusing to replace it: not a regular file (a directory)"},
      {"output folder missing", {"import", good, "--out", (folder / "absent" / "out.csv").string()},
       (folder / "absent" / "out.csv").string() + ": cannot write: directory " + (folder / "absent").string() +
           " does not exist"},
      {"output is the input", {"import", own_copy.string(), "--out", own_copy.string()},
       "--out: " + own_copy.string() + " is the input file"},
      {"unknown format", {"import", good, "--out", output, "--format", "csv"}, "--format: unknown format 'csv' (known: emps)"},
      {"no --out", {"import", good}, "--out is required (run with --help for usage)"},
  };
  const std::string own_copy_before = read_text(own_copy);
  for (const BadImport& bad : cases) {
    SCOPED_TRACE(bad.name);
    const CommandRun result = run(bad.arguments, folder.path());
    EXPECT_EQ(result.exit_code, 2) << "returned exit code " << result.exit_code << " instead of 2";
    EXPECT_EQ(result.out, "") << "printed on stdout";
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << "stderr is not one line: " << result.err;
    const std::string expected = "backlash: error: " + bad.expected_error + "\n";
    EXPECT_EQ(result.err, expected) << "returned \"" << result.err << "\" instead of \"" << expected << "\"";
    const std::vector<std::string> left{"copy.mat", "existing-folder", "notes.mat", "short.mat"};
    EXPECT_EQ(folder.entries(), left) << "the import wrote or left a file";
  }
  EXPECT_EQ(read_text(own_copy), own_copy_before) << "the input was changed";
  EXPECT_TRUE(std::filesystem::is_empty(folder / "existing-folder"));
}

}  // namespace
