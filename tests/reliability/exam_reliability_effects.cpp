// Issue 18, items 8, 9, 10, 15 and 16 (part): the effects' numeric limits and work budgets,
// through the built CLI (exit codes, the reason in one line, time and peak memory under a
// kill timeout, so that a hang fails instead of hanging) and, for the odeint gate, the library.
// BACKLASH_CLI_UNDER_TEST=path runs the CLI tests against another binary (e.g. main's).
#include "scratch_folder.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "backlash/numeric/reference.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Child {
  int exit_code = -1;  ///< 128 + signal when killed (SIGKILL at the timeout: 137)
  bool timed_out = false;
  double seconds = 0;
  long max_rss_kb = 0;
  std::string out, err;
};

const fs::path& folder() {
  static const fs::path dir = backlash::testing::scratch_folder("effects-limits");
  return dir;
}

std::string contents(const fs::path& file) { return backlash::testing::slurp(file); }

/// `backlash ARGS...` without a shell, killed after `timeout_s`; stdout, stderr kept unless
/// `keep_stdout` is false (a long CSV goes to /dev/null).
Child backlash(const std::vector<std::string>& args, double timeout_s, bool keep_stdout = true) {
  const char* other = std::getenv("BACKLASH_CLI_UNDER_TEST");
  const std::string program = other && *other ? other : BACKLASH_CLI;
  static int count = 0;
  const fs::path out = folder() / ("stdout" + std::to_string(++count)), err = folder() / ("stderr" + std::to_string(count));
  std::vector<std::string> argv_text{program};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int o = ::open(keep_stdout ? out.c_str() : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  Child c;
  int status = 0;
  struct rusage usage {};
  while (::wait4(pid, &status, WNOHANG, &usage) == 0) {
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (c.seconds > timeout_s && !c.timed_out) {
      c.timed_out = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  c.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  c.max_rss_kb = usage.ru_maxrss;
  if (keep_stdout) c.out = contents(out);
  c.err = contents(err);
  return c;
}

/// Case V's numbers with an [effects] table (and its experiment).
fs::path case_v(const std::string& stem, const std::string& effects, const std::string& changes = "") {
  const fs::path file = folder() / (stem + ".toml");
  std::ofstream(file) << "name = \"" << stem << "\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\n"
                      << (changes.empty() ? "reference = 1\n[motor]\nJ = 0.5\nF = 0.1\n" : changes)
                      << "[load]\nJ = 0.5\nF = 0.3\n"
                      << (effects.empty() ? "" : "[effects]\n" + effects + "\n")
                      << "[experiment]\nstep = 0.62\nt_end = 60\n";
  return file;
}

std::string said(const Child& c) {
  return "exit " + std::to_string(c.exit_code) + (c.timed_out ? " (killed at the timeout)" : "") + " after " +
         std::to_string(c.seconds) + " s, stderr: '" + c.err.substr(0, 400) + "'";
}

/// Refused before any work: exit 2 at once, one line on stderr naming `fragment`, nothing on stdout.
void expect_refusal(const Child& c, const std::string& fragment) {
  EXPECT_EQ(c.exit_code, 2) << said(c);
  EXPECT_LT(c.seconds, 10.0) << said(c);
  EXPECT_TRUE(c.out.empty()) << c.out.substr(0, 200);
  EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << said(c);
  EXPECT_NE(c.err.find(fragment), std::string::npos) << "no '" << fragment << "': " << said(c);
}

// ---------------------------------------------------------------- item 8: no crash

TEST(Item08_EffectScales, StiffOrOverdampedMeshIsRefusedWithItsKey) {
  expect_refusal(backlash({"simulate", case_v("stiff", "compliance = { stiffness = 1e40, damping = 0.5 }").string()}, 30),
                 "compliance.stiffness");
  expect_refusal(backlash({"limit-cycle", case_v("damped", "compliance = { stiffness = 100, damping = 1e16 }").string()}, 30),
                 "compliance.damping");
}

// The gate's reference on a horizon far below odeint's absolute time epsilon (2.2e-16 s):
// y' = −λ y, λ = 1e18, sampled to 2e-18 s, against the exact exp(−λ t).
TEST(Item08_EffectScales, ReferenceTrajectoryOnAnAttosecondHorizon) {
  using namespace backlash::numeric;
  LinearSegment segment;
  segment.A = SmallMatrix::Constant(1, 1, -1e18);
  segment.c = SmallVector::Zero(1);
  const SmallVector start = SmallVector::Constant(1, 1.0);
  std::vector<double> times;
  for (int i = 1; i <= 40; ++i) times.push_back(2e-18 * i / 40);
  const std::vector<SmallVector> z = reference_linear_trajectory(segment, start, times, 1e-12);
  ASSERT_EQ(z.size(), times.size());
  for (std::size_t i = 0; i < times.size(); ++i)
    EXPECT_NEAR(z[i](0), std::exp(-1e18 * times[i]), 1e-10) << "at t = " << times[i];
}

// ---------------------------------------------------------------- item 9: delay

TEST(Item09_Delay, DelayBelowTheResolutionIsRefused) {
  expect_refusal(backlash({"simulate", case_v("delay6", "delay = 1e-6").string()}, 20), "delay = 1e-06");
  expect_refusal(backlash({"limit-cycle", case_v("delay9", "delay = 1e-9").string()}, 20), "delay");
}

// A streamed CSV of a long delayed run: the history is kept only as far back as the delay reaches.
TEST(Item09_Delay, LongStreamedDelayedRunKeepsItsMemory) {
#if BACKLASH_RSS_NOT_THE_PROGRAMS
  GTEST_SKIP() << "under AddressSanitizer the peak RSS is the allocator's";
#endif
  const fs::path file = case_v("delay05", "delay = 0.05");
  const Child c = backlash({"simulate", file.string(), "--t-end", "20000", "--csv", "--dt", "10"}, 40, false);
  EXPECT_EQ(c.exit_code, 0) << said(c);
  // A 20000 s run keeps 400000 steps of history on main (about 130 MB); bounded, the program's
  // own size (about 25 MB) and a segment's 65536 steps (18 MB) remain.
  EXPECT_LT(c.max_rss_kb, 64 * 1024) << said(c) << ", peak " << c.max_rss_kb << " kB";
}

// ---------------------------------------------------------------- item 10: horizons

TEST(Item10_Horizon, EndTimeBeyondTheTimeResolutionIsRefused) {
  expect_refusal(backlash({"simulate", "V", "--t-end", "1e100"}, 20), "t_end");
  expect_refusal(backlash({"simulate", case_v("mesh", "compliance = { stiffness = 100, damping = 0.5 }").string(),
                           "--t-end", "1e100"},
                          20),
                 "t_end");
}

// ---------------------------------------------------------------- item 15: clear errors

// Only θ − θR matters: reference 1e7 gives case V's motion shifted by 1e7.
TEST(Item15_ClearErrors, LargeReferenceIsComputedInErrorCoordinates) {
  const Child shifted =
      backlash({"simulate", case_v("ref7", "", "reference = 1e7\n[motor]\nJ = 0.5\nF = 0.1\n").string(), "--json"}, 30);
  const Child plain =
      backlash({"simulate", case_v("ref1", "", "reference = 1\n[motor]\nJ = 0.5\nF = 0.1\n").string(), "--json"}, 30);
  ASSERT_EQ(shifted.exit_code, 0) << said(shifted);
  ASSERT_EQ(plain.exit_code, 0) << said(plain);
  const auto a = nlohmann::json::parse(shifted.out), b = nlohmann::json::parse(plain.out);
  ASSERT_EQ(a["events"].size(), b["events"].size());
  // The error θo − θR: rounded to ε·1e7 = 2e-9 rad at the reference's size.
  EXPECT_NEAR(a["final"]["error"].get<double>(), b["final"]["error"].get<double>(), 1e-8);
}

TEST(Item15_ClearErrors, MeshTheClosedFormsCannotResolveIsRefused) {
  expect_refusal(backlash({"simulate", case_v("light", "compliance = { stiffness = 3e4, damping = 0.4 }").string()}, 30),
                 "compliance");
}

TEST(Item15_ClearErrors, OverdampedMotorIsRefusedBeforeAnyWork) {
  expect_refusal(backlash({"simulate", case_v("motorF", "", "reference = 1\n[motor]\nJ = 0.5\nF = 1e6\n").string()}, 30),
                 "time scales too far apart");
}

TEST(Item15_ClearErrors, DiscrepancyStepBeyondTheResolutionIsRefused) {
  const fs::path record = folder() / "record.csv";
  {
    std::ofstream out(record);
    out << "t,theta_out\n";
    for (int k = 0; k < 40; ++k) out << 0.01 * k << "," << 0.38 + 1e-3 * k << "\n";
  }
  expect_refusal(backlash({"discrepancy", "--model", case_v("model", "").string(), "--data", record.string(), "--step",
                           "1e300"},
                          30),
                 "--step");
}

// ---------------------------------------------------------------- item 16: the stop says why

TEST(Item16_StopReason, EventLimitWithEffectsSaysWhy) {
  const Child c = backlash(
      {"simulate", case_v("cap", "compliance = { stiffness = 100, damping = 0.5 }").string(), "--t-end", "1e6"}, 30);
  EXPECT_EQ(c.exit_code, 3) << said(c);
  EXPECT_NE(c.err.find("event_limit): the event cap of 100000 events was reached"), std::string::npos) << said(c);
}

}  // namespace
