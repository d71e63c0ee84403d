// `backlash map` through the built CLI: bad input (one line, exit 2, nothing written), the
// folder's files the same bytes for any thread count and any number of MPI ranks (1 and 2,
// when the build has MPI), an interrupted run (a signal) resumed to the same bytes, and memory
// flat in the number of points (peak RSS; skipped under AddressSanitizer).
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code = -1;
  std::string out, err;
  long max_rss_kb = 0;
};

fs::path scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("backlash-map-cli-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    fs::remove_all(fs::temp_directory_path() / ("backlash-map-cli-" + std::to_string(::getpid())), ignored);
  }
} cleanup;

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

pid_t start(const std::string& command) {
  const pid_t child = ::fork();
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return child;
}

CliRun finish(pid_t child, const fs::path& out, const fs::path& err) {
  int status = 0;
  struct rusage usage {};
  ::wait4(child, &status, 0, &usage);
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.max_rss_kb = usage.ru_maxrss;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// `PREFIX backlash ARGUMENTS` through /bin/sh, stdout and stderr to files.
CliRun run(const std::string& arguments, const std::string& prefix = "") {
  static int counter = 0;
  const std::string tag = std::to_string(++counter);
  const fs::path out = scratch() / ("out" + tag), err = scratch() / ("err" + tag);
  const pid_t child =
      start(prefix + std::string(BACKLASH_CLI) + " " + arguments + " > " + out.string() + " 2> " + err.string());
  return finish(child, out, err);
}

const char* files[] = {"points.csv", "boundary.csv", "map.h5", "map.json"};
const char* figures[] = {"summary.md", "figures/map_JL_over_Jm_FL_over_F.svg"};

void expect_same_folders(const fs::path& a, const fs::path& b) {
  for (const char* f : figures)  // drawn when the build has the figures (and gnuplot)
    if (fs::exists(a / f)) {
      EXPECT_EQ(slurp(a / f), slurp(b / f)) << f << ": " << b << " returned other bytes than " << a;
    }
  for (const char* f : files) {
    ASSERT_TRUE(fs::exists(a / f)) << (a / f);
    EXPECT_EQ(slurp(a / f), slurp(b / f)) << f << ": " << b << " returned other bytes than " << a;
  }
}

const std::string grid = "map V --vary JL_over_Jm=0.5:2:4 --vary FL_over_F=0.1:0.9:12 --no-figures";

TEST(MapCli, exam_bad_input_is_one_line_exit_2_and_nothing_written) {
  const fs::path out = scratch() / "bad";
  for (const std::string& arguments :
       {std::string("map V --vary K=1:x:3 --out ") + out.string(), "map V --vary Q=1:2:3 --out " + out.string(),
        "map V --vary K=-1:2:3 --out " + out.string(), "map V --vary K=1:2:3 --sample sobol --out " + out.string(),
        "map V --vary K=1:2:3 --threads 0 --out " + out.string(), "map V --vary K=1:2:3 --resume --out " + out.string(),
        "map nosuchcase.toml --vary K=1:2:3 --out " + out.string()}) {
    const CliRun r = run(arguments);
    EXPECT_EQ(r.exit_code, 2) << arguments << ": returned exit " << r.exit_code << " instead of 2: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << arguments << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << arguments << ": " << r.out;
    EXPECT_FALSE(fs::exists(out)) << arguments;
    EXPECT_FALSE(fs::exists(scratch() / ".bad.map-partial")) << arguments;
  }
}

TEST(MapCli, check_files_do_not_depend_on_the_thread_count) {
  const CliRun one = run(grid + " --threads 1 --out " + (scratch() / "t1").string());
  const CliRun two = run(grid + " --threads 2 --out " + (scratch() / "t2").string());
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(two.exit_code, 0) << two.err;
  expect_same_folders(scratch() / "t1", scratch() / "t2");
}

#ifdef BACKLASH_MPIRUN
TEST(MapCli, check_files_do_not_depend_on_the_number_of_mpi_ranks) {
  const std::string mpirun = std::string(BACKLASH_MPIRUN) + " " + BACKLASH_MPIRUN_FLAGS;
  const std::string with_figures = grid.substr(0, grid.find(" --no-figures"));
  const CliRun serial = run(with_figures + " --threads 1 --out " + (scratch() / "r0").string());
  const CliRun one = run(with_figures + " --threads 1 --out " + (scratch() / "r1").string(), mpirun + " -n 1 ");
  const CliRun two = run(with_figures + " --threads 2 --out " + (scratch() / "r2").string(), mpirun + " -n 2 ");
  ASSERT_EQ(serial.exit_code, 0) << serial.err;
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_NE(two.err.find("x 2 ranks"), std::string::npos) << "returned '" << two.err << "' instead of a 2-rank run";
  expect_same_folders(scratch() / "r0", scratch() / "r1");
  expect_same_folders(scratch() / "r0", scratch() / "r2");
}
#endif

TEST(MapCli, exam_a_signal_stops_the_map_and_resume_finishes_it_to_the_same_bytes) {
  const std::string big = "map V --vary JL_over_Jm=0.5:2:8 --vary FL_over_F=0.1:0.9:64 --no-figures --block 8";
  const CliRun whole = run(big + " --threads 1 --out " + (scratch() / "whole").string());
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const fs::path out = scratch() / "stopped", checkpoint = scratch() / ".stopped.map-partial" / "checkpoint";
  const fs::path o = scratch() / "stopped.out", e = scratch() / "stopped.err";
  const pid_t child = start(std::string(BACKLASH_CLI) + " " + big + " --threads 1 --out " + out.string() + " > " + o.string() + " 2> " +
                            e.string());
  // Wait until some block is done (the checkpoint says "done N" with N > 0), then SIGTERM.
  for (int k = 0; k < 6000; ++k) {
    const std::string text = slurp(checkpoint);
    const std::size_t at = text.rfind("done ");
    if (at != std::string::npos && text.compare(at, 7, "done 0\n") != 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(child, SIGTERM);
  const CliRun stopped = finish(child, o, e);
  if (stopped.exit_code == 0) GTEST_SKIP() << "the map finished before the signal arrived";
  EXPECT_EQ(stopped.exit_code, 1) << stopped.err;
  EXPECT_NE(stopped.err.find("--resume"), std::string::npos) << stopped.err;
  EXPECT_FALSE(fs::exists(out));
  const CliRun resumed = run(big + " --resume --threads 2 --out " + out.string());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  expect_same_folders(scratch() / "whole", out);
}

TEST(MapCli, check_memory_is_flat_in_the_number_of_points) {
#if BACKLASH_RSS_NOT_THE_PROGRAMS
  GTEST_SKIP() << "under AddressSanitizer the peak RSS is the allocator's (freed blocks are held in its quarantine), "
                  "not the program's: checked in the uninstrumented build";
#endif
  const CliRun small = run("map V --vary K=0.5:2:64 --step 0");
  const CliRun large = run("map V --vary K=0.5:2:4096 --step 0");
  ASSERT_EQ(small.exit_code, 0) << small.err;
  ASSERT_EQ(large.exit_code, 0) << large.err;
  EXPECT_EQ(std::count(large.out.begin(), large.out.end(), '\n'), 4097);
  EXPECT_LT(large.max_rss_kb - small.max_rss_kb, 8 * 1024)
      << "returned " << large.max_rss_kb << " kB instead of about " << small.max_rss_kb << " kB for 64x the points";
}

}  // namespace
