// Issue 18, the outputs through the built CLI: nothing lost, nothing left behind, no corrupt
// map — resume checked against its files (item 6), the boundary phase stopped by signals
// (11), write errors on stdout (12), no litter after signals, full disks and killed runs (13),
// one map run per --out (14), sloppy map/sweep flags refused (16).  Test names carry the item.
// The binary is BACKLASH_CLI (the build's); the environment variable BACKLASH_CLI_UNDER_TEST
// points them at another one (how each was seen failing on the old code).
#include "scratch_folder.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

fs::path scratch() { return backlash::testing::scratch_folder("outputs"); }

std::string cli() {
  const char* other = std::getenv("BACKLASH_CLI_UNDER_TEST");
  return other && *other ? other : BACKLASH_CLI;
}

using backlash::testing::slurp;

int lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

/// Where the child's stdout goes: a file of the scratch folder, /dev/full, or nowhere (closed).
enum class Stdout { file, full, closed };

struct Child {
  pid_t pid = -1;
  fs::path out, err;
};

/// Starts `backlash ARGUMENTS…` in `folder` (fork/exec, no shell).
Child start(const std::vector<std::string>& arguments, const fs::path& folder, Stdout mode = Stdout::file) {
  static int counter = 0;
  const std::string tag = std::to_string(++counter);
  Child c{-1, scratch() / ("out" + tag), scratch() / ("err" + tag)};
  const std::string program = cli();
  std::vector<char*> argv{const_cast<char*>(program.c_str())};
  for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  c.pid = ::fork();
  if (c.pid == 0) {
    if (::chdir(folder.c_str()) != 0) ::_exit(126);
    const int err = ::open(c.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(err, STDERR_FILENO);
    if (mode == Stdout::closed) {
      ::close(STDOUT_FILENO);
    } else {
      const int out = mode == Stdout::full ? ::open("/dev/full", O_WRONLY) : ::open(c.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, STDOUT_FILENO);
    }
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  return c;
}

struct CliRun {
  int exit_code = -1;  ///< the exit status, or 128 + the signal that ended the process
  std::string out, err;
};

CliRun finish(const Child& c) {
  int status = 0;
  ::waitpid(c.pid, &status, 0);
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(c.out);
  r.err = slurp(c.err);
  return r;
}

CliRun run(const std::vector<std::string>& arguments, const fs::path& folder = scratch(), Stdout mode = Stdout::file) {
  return finish(start(arguments, folder, mode));
}

/// Waits (up to 60 s) until `ready()` holds; false if the time ran out.
template <class Ready>
bool wait_for(Ready ready) {
  const auto limit = Clock::now() + std::chrono::seconds(60);
  while (!ready()) {
    if (Clock::now() > limit) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

std::vector<std::string> litter(const fs::path& folder, const std::string& fragment) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().filename().string().find(fragment) != std::string::npos) found.push_back(entry.path().filename());
  return found;
}

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = scratch() / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

void expect_one_line_error(const CliRun& r, int exit_code, const std::string& fragment) {
  EXPECT_EQ(r.exit_code, exit_code) << "returned exit " << r.exit_code << " instead of " << exit_code << ": " << r.err;
  EXPECT_EQ(lines(r.err), 1) << "returned " << lines(r.err) << " lines on stderr instead of 1: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << "returned '" << r.err << "' instead of a line with '" << fragment << "'";
}

// A 90-point grid on case V with 5 boundary points: about a second.
const std::vector<std::string> small_map = {"map", "V", "--vary", "Fm=0.05:0.4:10", "--vary", "K=0.5:2:9",
                                            "--out", "m",   "--no-figures"};

std::vector<std::string> with(std::vector<std::string> arguments, std::initializer_list<std::string> more) {
  arguments.insert(arguments.end(), more);
  return arguments;
}

// ---------------------------------------------------------------- item 6: resume

TEST(Item06_Resume, StoppedAfterEveryPointResumesToExactlyItsRows) {
  const fs::path folder = fresh_folder("resume_all");
  // --stop-after 90 stops once all 90 points are kept: the state a run killed in the boundary phase leaves.
  const CliRun stopped = run(with(small_map, {"--stop-after", "90"}), folder);
  ASSERT_EQ(stopped.exit_code, 1) << stopped.err;
  const CliRun resumed = run(with(small_map, {"--resume"}), folder);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  std::istringstream rows(slurp(folder / "m" / "points.csv"));
  std::string row;
  std::getline(rows, row);
  long count = 0;
  for (; std::getline(rows, row); ++count)
    EXPECT_EQ(row.rfind(std::to_string(count) + ",", 0), 0u) << "row " << count << " is '" << row.substr(0, 60) << "'";
  EXPECT_EQ(count, 90) << "returned " << count << " rows for 90 points";
}

TEST(Item06_Resume, FilesThatDoNotMatchTheCheckpointAreRefused) {
  const fs::path folder = fresh_folder("resume_short");
  const fs::path partial = folder / ".m.map-partial";
  for (const char* file : {"points.csv", "points.bin"}) {
    ASSERT_EQ(run(with(small_map, {"--stop-after", "64"}), folder).exit_code, 1);
    fs::resize_file(partial / file, fs::file_size(partial / file) / 3);  // shorter than its checkpoint
    const CliRun r = run(with(small_map, {"--resume"}), folder);
    expect_one_line_error(r, 2, file);
    EXPECT_FALSE(fs::exists(folder / "m")) << "wrote a map from " << file << " shorter than its checkpoint";
  }
  // Rows out of order (a points.csv of another run's block): refused too.
  ASSERT_EQ(run(with(small_map, {"--stop-after", "64"}), folder).exit_code, 1);
  std::string text = slurp(partial / "points.csv");
  const std::size_t row1 = text.find("\n1,"), row2 = text.find("\n2,");
  ASSERT_NE(row2, std::string::npos);
  text.replace(row1 + 1, 2, "5,");
  std::ofstream(partial / "points.csv", std::ios::binary) << text;
  expect_one_line_error(run(with(small_map, {"--resume"}), folder), 2, "row 1");
  EXPECT_FALSE(fs::exists(folder / "m"));
}

// ---------------------------------------------------------------- item 11: signals in the boundary phase

TEST(Item11_MapSignals, SigtermInTheBoundaryPhaseStopsPromptlyAndResumes) {
  const fs::path folder = fresh_folder("boundary_signal");
  // 360 points, 21 boundary points: about 3 s of boundary phase.
  const std::vector<std::string> map = {"map", "V", "--vary", "Fm=0.05:0.4:60", "--vary", "K=0.5:2:6", "--out", "b", "--no-figures"};
  const Child child = start(map, folder);
  // map.h5 is created when the points are done and the boundary phase begins.
  ASSERT_TRUE(wait_for([&] { return fs::exists(folder / ".b.map-partial" / "map.h5"); }));
  const auto signalled = Clock::now();
  ::kill(child.pid, SIGTERM);
  const CliRun r = finish(child);
  const double seconds = std::chrono::duration<double>(Clock::now() - signalled).count();
  expect_one_line_error(r, 1, "--resume");
  EXPECT_LT(seconds, 5.0) << "ran " << seconds << " s after SIGTERM";  // it stops before the next boundary point
  EXPECT_FALSE(fs::exists(folder / "b"));
  ASSERT_TRUE(fs::exists(folder / ".b.map-partial" / "checkpoint"));
  const CliRun resumed = run(with(map, {"--resume"}), folder);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(lines(slurp(folder / "b" / "points.csv")), 361);
  EXPECT_EQ(lines(slurp(folder / "b" / "boundary.csv")), 22);
}

// ---------------------------------------------------------------- item 12: stdout

TEST(Item12_Stdout, WriteErrorsOnStdoutExitOne) {
  const std::vector<std::vector<std::string>> commands = {
      {"map", "V", "--vary", "Fm=0.05:0.4:3"},
      {"limit-cycle", "V", "--json"},
      {"simulate", "V"},
      {"trace", "V"},
      {"validate", "V"},
      {"sweep", "V", "--vary", "K", "--from", "1", "--to", "2", "--points", "2", "--no-progress"}};
  for (const auto& command : commands)
    for (const Stdout mode : {Stdout::full, Stdout::closed}) {
      const CliRun r = run(command, scratch(), mode);
      SCOPED_TRACE(command.front() + (mode == Stdout::full ? " > /dev/full" : " >&-"));
      EXPECT_EQ(r.exit_code, 1) << r.err;
      EXPECT_NE(r.err.find("cannot write the output to stdout"), std::string::npos) << r.err;
      EXPECT_EQ(lines(r.err), 1) << r.err;
    }
}

// ---------------------------------------------------------------- item 13: litter

TEST(Item13_Litter, KilledReportsStagingIsRemovedBySigtermAndByTheNextRun) {
  const fs::path folder = fresh_folder("report_signal");
  const Child killed = start({"report", "--no-pdf", "--out", "rep"}, folder);
  ASSERT_TRUE(wait_for([&] { return !litter(folder, ".rep.tmp-").empty(); }));
  ::kill(killed.pid, SIGKILL);
  finish(killed);
  const std::vector<std::string> left = litter(folder, ".rep.tmp-");
  ASSERT_EQ(left.size(), 1u);  // SIGKILL: nothing can clean up
  // The next run onto the same --out removes it (before making its own); SIGTERM to that run
  // removes its own staging folder.
  const Child next = start({"report", "--no-pdf", "--out", "rep"}, folder);
  ASSERT_TRUE(wait_for([&] {
    const std::vector<std::string> now = litter(folder, ".rep.tmp-");
    return std::any_of(now.begin(), now.end(), [&](const std::string& name) { return name != left.front(); });
  }));
  ::kill(next.pid, SIGTERM);
  const CliRun r = finish(next);
  EXPECT_EQ(r.exit_code, 128 + SIGTERM) << r.err;
  EXPECT_EQ(litter(folder, ".rep."), std::vector<std::string>{}) << "left behind after SIGKILL, then SIGTERM";
  EXPECT_FALSE(fs::exists(folder / "rep"));
}

TEST(Item13_Litter, FullDiskLeavesNothing) {
  const fs::path disk = fresh_folder("full_disk");
  if (::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=4k") != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs here (" << std::strerror(errno) << "; needs root): no full disk to test on";
  struct Unmount {
    fs::path at;
    ~Unmount() { ::umount(at.c_str()); }
  } unmount{disk};
  {
    std::ofstream fill(disk / "fill", std::ios::binary);
    fill << std::string(64 * 1024, 'x');  // more than fits: the disk is full
  }
  // (report stages through the same StagedDirectory as discrepancy and the report test above; it is slow.)
  const std::string record = std::string(BACKLASH_SOURCE_DIR) + "/examples/case_V_with_hidden_friction.csv";
  for (const auto& command : std::vector<std::vector<std::string>>{
           {"codegen", "V", "--out", "cg"},
           {"sweep", "fig31", "--points", "3", "--no-progress", "--out", "s.csv"},
           {"discrepancy", "--model", "V", "--step", "0.62", "--data", record, "--no-progress", "--out", "d"}}) {
    const CliRun r = run(command, disk);
    SCOPED_TRACE(command.front());
    expect_one_line_error(r, 1, "cannot");
    EXPECT_EQ(litter(disk, ""), std::vector<std::string>{"fill"}) << "left behind on a full disk";
  }
}

// A cycle whose bodies part only by bouncing (restitution, with a delay: the period-3 case of
// exam_delayed_period_three) has no separation velocity: the text says so, never "nan".
TEST(Item16_Texts, CycleWithoutSeparationSaysSoInsteadOfNan) {
  const fs::path folder = fresh_folder("bouncing_cycle");
  std::ofstream(folder / "bouncing.toml") << slurp(fs::path(BACKLASH_SOURCE_DIR) / "cases" / "I.toml")
                                          << "\n[effects]\ndelay = 0.725\nrestitution = 0.5\n";
  const CliRun text = run({"limit-cycle", "bouncing.toml"}, folder);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("period-3 cycle"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("nan"), std::string::npos) << "returned " << text.out << " with a nan";
  EXPECT_NE(text.out.find("separation velocity  none (the bodies part only by bouncing"), std::string::npos) << text.out;
  const CliRun json = run({"limit-cycle", "bouncing.toml", "--json"}, folder);
  EXPECT_NE(json.out.find("\"separation_velocity\": null"), std::string::npos) << json.out;
}

// ---------------------------------------------------------------- item 14: one map per --out

TEST(Item14_MapLock, SecondMapOnTheSameOutIsRefusedInOneLine) {
  const fs::path folder = fresh_folder("two_maps");
  const std::vector<std::string> map = {"map", "V", "--vary", "Fm=0.05:0.4:20", "--vary", "K=0.5:2:12", "--out", "c", "--no-figures"};
  const Child first = start(map, folder);
  ASSERT_TRUE(wait_for([&] { return fs::exists(folder / ".c.map-partial" / "checkpoint"); }));
  for (const auto& second : {map, with(map, {"--resume"})})
    expect_one_line_error(run(second, folder), 2, "another backlash run is writing it");
  const CliRun r = finish(first);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(slurp(folder / "c" / "points.csv")), 241);
  EXPECT_EQ(litter(folder, ".c."), std::vector<std::string>{});
}

TEST(Item14_MapLock, HdfFailureIsOneLineWithoutHdfDiagnostics) {
  const fs::path folder = fresh_folder("hdf5_failure");
  ASSERT_EQ(run(with(small_map, {"--stop-after", "90"}), folder).exit_code, 1);
  fs::create_directories(folder / ".m.map-partial" / "map.h5" / "in_the_way");  // H5Fcreate must fail
  expect_one_line_error(run(with(small_map, {"--resume"}), folder), 1, "map.h5");
}

// ---------------------------------------------------------------- item 16: sloppy flags

TEST(Item16_SloppyFlags, GridWithoutCountBadSeedsAndEmptyOutAreRefused) {
  const CliRun no_count = run({"map", "V", "--vary", "K=0.5:1"});
  expect_one_line_error(no_count, 2, "--vary");
  EXPECT_EQ(no_count.out, "");
  for (const char* seed : {"-1", "1e23", "18446744073709551616", "0x10", ""}) {
    const CliRun r = run({"map", "V", "--vary", "K=0.5:1", "--sample", "lhs", "--points", "3", "--seed", seed});
    SCOPED_TRACE(std::string("--seed '") + seed + "'");
    expect_one_line_error(r, 2, "--seed");
    EXPECT_EQ(r.out, "");
  }
  const CliRun largest = run({"map", "V", "--vary", "K=0.5:1", "--sample", "lhs", "--points", "3", "--seed", "18446744073709551615"});
  EXPECT_EQ(largest.exit_code, 0) << largest.err;
  EXPECT_EQ(lines(largest.out), 4);
  const CliRun empty_out = run({"sweep", "V", "--vary", "K", "--from", "1", "--to", "2", "--points", "2", "--out", ""});
  expect_one_line_error(empty_out, 2, "--out");
  EXPECT_EQ(empty_out.out, "");
}

}  // namespace
