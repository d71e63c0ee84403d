// Issue 18, measured records and import, through the built CLI: a record that does not start
// at the step (item 4), a truncated .mat (5), a sample beyond what the model computes with (7),
// a record with a gap and an import whose write fails (15), the progress of a long discrepancy
// run (17).  Test names carry the item number.  BACKLASH_RECORDS_CLI, when set, runs another
// binary (e.g. main's, to see each test fail there).
#include "scratch_folder.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

fs::path scratch() { return backlash::testing::scratch_folder("records"); }

std::string cli() {
  const char* other = std::getenv("BACKLASH_RECORDS_CLI");
  return other && *other ? other : BACKLASH_CLI;
}

using backlash::testing::slurp;

/// Runs `PREFIX backlash ARGUMENTS` through /bin/sh, stdout and stderr to files.
CliRun run(const std::string& arguments, const std::string& prefix = "") {
  static int counter = 0;
  const std::string tag = std::to_string(++counter);
  const fs::path out = scratch() / ("out" + tag), err = scratch() / ("err" + tag);
  const std::string command = prefix + cli() + " " + arguments + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(command.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// One line on stderr (the project's one-line error), containing every `part`.
void expect_one_line_error(const CliRun& r, const std::vector<std::string>& parts) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  for (const std::string& part : parts) EXPECT_NE(r.err.find(part), std::string::npos) << "missing '" << part << "' in " << r.err;
}

/// The README's step record (examples/case_V_with_hidden_friction.csv), its first `rows` rows,
/// times shifted by `shift`; row `changed` (0-based data row) gets `theta_out` = `value`, and
/// from row `gap_at` on every time gets `gap` added.
struct RecordEdit {
  std::size_t rows = 600;
  double shift = 0;
  long changed = -1;
  std::string value = "";
  long gap_at = -1;
  double gap = 0;
};

fs::path step_record(const std::string& stem, const RecordEdit& edit) {
  std::ifstream in(fs::path(BACKLASH_SOURCE_DIR) / "examples" / "case_V_with_hidden_friction.csv");
  std::string line;
  std::getline(in, line);
  std::ostringstream text;
  text.precision(17);
  text << line << "\n";
  for (std::size_t row = 0; row < edit.rows && std::getline(in, line); ++row) {
    const std::size_t comma = line.find(',');
    double t = std::stod(line.substr(0, comma)) + edit.shift;
    if (edit.gap_at >= 0 && static_cast<long>(row) >= edit.gap_at) t += edit.gap;
    text << t << "," << (static_cast<long>(row) == edit.changed ? edit.value : line.substr(comma + 1)) << "\n";
  }
  const fs::path file = scratch() / (stem + ".csv");
  std::ofstream(file) << text.str();
  return file;
}

/// Case V (cases/V.toml) with `extra` appended to its [experiment] table.
fs::path case_v(const std::string& stem, const std::string& extra) {
  std::string text = slurp(fs::path(BACKLASH_SOURCE_DIR) / "cases" / "V.toml");
  text += extra;
  const fs::path file = scratch() / (stem + ".toml");
  std::ofstream(file) << text;
  return file;
}

// ------------------------------------------------------------------ item 4

TEST(RecordsItem4, item4_record_not_starting_at_the_step_refused) {
  // The README's record with 100 s added to every time, against a model whose step is at 0.
  const fs::path shifted = step_record("shifted", {.shift = 100});
  const CliRun r = run("discrepancy --model V --data " + shifted.string());
  expect_one_line_error(r, {shifted.string() + ":2: t:", "starts at t = 100", "step_time"});
}

TEST(RecordsItem4, item4_step_time_reads_the_shifted_record_as_the_original) {
  const fs::path original = step_record("original", {});
  const fs::path shifted = step_record("shifted", {.shift = 100});
  const fs::path model = case_v("V_at_100", "step_time = 100\n");
  const CliRun a = run("discrepancy --model V --json --data " + original.string());
  const CliRun b = run("discrepancy --model " + model.string() + " --json --data " + shifted.string());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const nlohmann::json x = nlohmann::json::parse(a.out), y = nlohmann::json::parse(b.out);
  // The same answer: (t + 100) − 100 differs from t by rounding (ulp(100) = 1.4e-14 s), which
  // moves the fitted numbers at that relative level, far below 1e-9.
  EXPECT_EQ(x["status"], "effect_found");
  EXPECT_EQ(x["status"], y["status"]);
  EXPECT_NEAR(x["rms_before"].get<double>(), y["rms_before"].get<double>(), 1e-9 * x["rms_before"].get<double>());
  EXPECT_NEAR(x["rms_after"].get<double>(), y["rms_after"].get<double>(), 1e-9 * x["rms_after"].get<double>());
  ASSERT_EQ(x["effects"].size(), y["effects"].size());
  for (std::size_t i = 0; i < x["effects"].size(); ++i) {
    EXPECT_EQ(x["effects"][i]["effect"], y["effects"][i]["effect"]);
    for (const auto& [name, value] : x["effects"][i]["parameters"].items())
      EXPECT_NEAR(value.get<double>(), y["effects"][i]["parameters"][name].get<double>(), 1e-9 * std::abs(value.get<double>()));
  }
}

// ------------------------------------------------------------------ item 5

TEST(RecordsItem5, item5_truncated_mat_refused) {
  const std::string whole = slurp(fs::path(BACKLASH_SOURCE_DIR) / "tests" / "data" / "emps" / "DATA_EMPS.mat");
  ASSERT_GT(whole.size(), 1000u);
  const fs::path cut = scratch() / "cut.mat", csv = scratch() / "cut.csv";
  std::ofstream(cut, std::ios::binary) << whole.substr(0, whole.size() - 63);
  const CliRun r = run("import " + cut.string() + " --out " + csv.string());
  expect_one_line_error(r, {cut.string() + ":", "truncated"});
  EXPECT_FALSE(fs::exists(csv)) << "a truncated file was imported";
}

// ------------------------------------------------------------------ item 7

TEST(RecordsItem7, item7_sample_beyond_the_computable_scale_refused_with_its_line) {
  const fs::path huge = step_record("huge", {.changed = 300, .value = "1e300"});
  const CliRun r = run("discrepancy --model V --data " + huge.string());
  expect_one_line_error(r, {huge.string() + ":302: theta_out:", "1e+300", "1e+100"});
}

// ------------------------------------------------------------------ item 15

TEST(RecordsItem15, item15_record_with_a_gap_refused_with_its_line) {
  const fs::path gap = step_record("gap", {.gap_at = 300, .gap = 1e6});
  const CliRun r = run("discrepancy --model V --data " + gap.string());
  expect_one_line_error(r, {gap.string() + ":302: t:", "gap of 1000000"});
}

TEST(RecordsItem15, item15_import_whose_write_fails_exits_1) {
  // A file-size limit makes the write fail as a full disk does (EFBIG instead of ENOSPC);
  // the signal it raises is ignored so that write() returns the error.
  const fs::path mat = fs::path(BACKLASH_SOURCE_DIR) / "tests" / "data" / "emps" / "DATA_EMPS.mat";
  const fs::path folder = scratch() / "small-disk";
  fs::create_directories(folder);
  const CliRun r = run("import " + mat.string() + " --out " + (folder / "out.csv").string(), "trap '' XFSZ; ulimit -f 64; ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find((folder / "out.csv").string() + ": cannot write"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(folder)) << "the failed write left something behind";
}

// ------------------------------------------------------------------ item 17

/// Runs `backlash ARGUMENTS` with stderr on a pseudo-terminal; returns what it wrote there.
std::string stderr_on_a_terminal(const std::string& arguments, int& exit_code) {
  int terminal = -1;
  const pid_t child = ::forkpty(&terminal, nullptr, nullptr, nullptr);
  if (child == 0) {
    const std::string command = cli() + " " + arguments + " > /dev/null";
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::string seen;
  char buffer[4096];
  for (ssize_t n; (n = ::read(terminal, buffer, sizeof buffer)) > 0;) seen.append(buffer, static_cast<std::size_t>(n));
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(terminal);
  exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return seen;
}

TEST(RecordsItem17, item17_discrepancy_shows_progress_on_a_terminal) {
  const fs::path record = step_record("progress", {});
  int exit_code = -1;
  const std::string seen = stderr_on_a_terminal("discrepancy --model V --data " + record.string(), exit_code);
  EXPECT_EQ(exit_code, 0) << seen;
  EXPECT_NE(seen.find("[####"), std::string::npos) << seen;
  EXPECT_NE(seen.find("100%"), std::string::npos) << seen;
  // Not on a pipe, and not with --no-progress.
  const CliRun piped = run("discrepancy --model V --data " + record.string());
  EXPECT_EQ(piped.err, "");
  const std::string quiet = stderr_on_a_terminal("discrepancy --no-progress --model V --data " + record.string(), exit_code);
  EXPECT_EQ(quiet.find('['), std::string::npos) << quiet;
}

}  // namespace
