// Issue 18, the inputs' bounds, item by item (test names carry the item number):
//   10  a case file's number with many digits: 17 (a double printed in full) derives and
//       generates code fast; beyond model::largest_significant_digits it is refused at its
//       line, before any work (docs/design.md, "Case files").
//   10  a simulation's samples: the spacing must be > 0 and the count at most
//       api::largest_sample_count, checked by the facade for the CLI and Python alike.
//   16  every numeric flag of the command line read by one strict reader (cli/flags.hpp): hex,
//       inf, nan, trailing garbage, signs and exponents where a key is wanted are refused with
//       the flag named, exit 2, nothing on stdout.
// Times are the child's CPU time (getrusage), not the wall clock: the machine may be busy.
#include "backlash/api/backlash.hpp"
#include "backlash/model/case_spec.hpp"

#include "scratch_folder.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace backlash;

#ifdef BACKLASH_INPUTS_SANITIZED
constexpr double kSlowdown = 10;  // every call is ~10x slower under the sanitizers
#else
constexpr double kSlowdown = 1;
#endif

struct CliRun {
  int exit_code = -1;
  std::string out, err;
  double cpu_seconds = 0;  ///< the child's user + system time
};

fs::path scratch() { return backlash::testing::scratch_folder("inputs"); }

using backlash::testing::slurp;

/// Runs `backlash ARGUMENTS`, at most `limit` seconds of wall time (`timeout` ends it with 124)
/// and 8 MiB per output file (ulimit -f: a run that writes without end is killed by SIGXFSZ).
CliRun run(const std::string& arguments, int limit = 60) {
  static int counter = 0;
  const std::string tag = std::to_string(++counter);
  const fs::path out = scratch() / ("out" + tag), err = scratch() / ("err" + tag);
  const std::string command = "ulimit -f 16384; timeout " + std::to_string(limit) + " " + std::string(BACKLASH_CLI) + " " + arguments +
                              " > " + out.string() + " 2> " + err.string();
  const pid_t child = ::fork();
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  struct rusage usage {};
  ::wait4(child, &status, 0, &usage);
  struct rusage children {};
  ::getrusage(RUSAGE_CHILDREN, &children);  // the sh's children (timeout, backlash) are counted here
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  static double before = 0;
  const double total = static_cast<double>(children.ru_utime.tv_sec + children.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(children.ru_utime.tv_usec + children.ru_stime.tv_usec);
  r.cpu_seconds = total - before;
  before = total;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// Case V's file with line `K = ...` replaced by `k_line`.
fs::path case_with_K(const std::string& stem, const std::string& k_line) {
  std::ifstream in(fs::path(BACKLASH_SOURCE_CASES) / "V.toml");
  std::stringstream text;
  for (std::string line; std::getline(in, line);) text << (line.rfind("K = ", 0) == 0 ? k_line : line) << "\n";
  const fs::path file = scratch() / (stem + ".toml");
  std::ofstream(file) << text.str();
  return file;
}

/// The line number of `K = ` in case V's file.
int line_of_K() {
  std::ifstream in(fs::path(BACKLASH_SOURCE_CASES) / "V.toml");
  int number = 0;
  for (std::string line; std::getline(in, line);)
    if (++number, line.rfind("K = ", 0) == 0) return number;
  return 0;
}

// ---------------------------------------------------------------- 10: digits of a parameter

TEST(Item10_Digits, SeventeenDigitGainDerivesAndGeneratesCodeFast) {
  // 12.8 s of CPU in derive and 11 s in codegen before: the trial division of each radicand
  // went over every d < 2^16 with big-number arithmetic, for every radical printed.
  const fs::path file = case_with_K("K17", "K = 0.30000000000000004");
  const CliRun derive = run("derive " + file.string() + " --json");
  ASSERT_EQ(derive.exit_code, 0) << derive.err;
  EXPECT_LT(derive.cpu_seconds, 3 * kSlowdown) << "derive of a 17-digit K";
  EXPECT_NE(derive.out.find("7500000000000001/25000000000000000"), std::string::npos) << "K read exactly";
  const CliRun codegen = run("codegen " + file.string() + " --out " + (scratch() / "K17-code").string());
  ASSERT_EQ(codegen.exit_code, 0) << codegen.err;
  EXPECT_LT(codegen.cpu_seconds, 3 * kSlowdown) << "codegen of a 17-digit K";
}

TEST(Item10_Digits, ThousandsOfDigitsAreRefusedAtTheirLineBeforeAnyWork) {
  // More than 60 s before (GiNaC factoring polynomials with 4000-digit coefficients).
  const fs::path file = case_with_K("K4000", "K = \"0.3" + std::string(3998, '0') + "1\"");
  for (const std::string command : {"derive", "codegen", "simulate"}) {
    const CliRun r = run(command + " " + file.string() + (command == "codegen" ? " --out " + (scratch() / "x").string() : ""), 30);
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.err;
    EXPECT_EQ(r.err, "backlash: error: " + file.string() + ":" + std::to_string(line_of_K()) +
                         ": K: too many significant digits (4000; at most 100 are read, a double printed in full has "
                         "17)\n")
        << command;
    EXPECT_EQ(r.out, "") << command;
    EXPECT_LT(r.cpu_seconds, 1 * kSlowdown) << command;
    EXPECT_FALSE(fs::exists(scratch() / "x")) << "codegen wrote its folder";
  }
}

TEST(Item10_Digits, TheBoundIsOnSignificantDigitsOfEachNumberAndFractionPart) {
  const std::size_t n = model::largest_significant_digits;
  ASSERT_EQ(n, 100u) << "docs/design.md, \"Case files\" states the bound";
  auto parsed = [](const std::string& k_value) {
    std::ifstream in(fs::path(BACKLASH_SOURCE_CASES) / "V.toml");
    std::stringstream text;
    for (std::string line; std::getline(in, line);) text << (line.rfind("K = ", 0) == 0 ? "K = " + k_value : line) << "\n";
    try {
      (void)model::parse_case(text.str(), "digits.toml");
      return std::string("ok");
    } catch (const model::CaseFileError& e) {
      return std::string(e.what());
    }
  };
  const std::string digits_100 = "1" + std::string(98, '2') + "3";  // 100 significant digits
  EXPECT_EQ(parsed("\"0." + digits_100 + "\""), "ok");
  EXPECT_EQ(parsed("\"0.000" + digits_100 + "000\""), "ok") << "leading and trailing zeros are not significant";
  EXPECT_EQ(parsed("0." + digits_100), "ok") << "a TOML float";
  EXPECT_NE(parsed("\"" + digits_100 + "/" + digits_100 + "1\"").find(": K: too many significant digits (101;"), std::string::npos)
      << "a fraction's denominator";
  EXPECT_NE(parsed("\"" + digits_100 + "4/3\"").find(": K: too many significant digits (101;"), std::string::npos) << "a numerator";
  EXPECT_NE(parsed("0." + digits_100 + "4").find(": K: too many significant digits (101;"), std::string::npos) << "a TOML float";
  EXPECT_EQ(parsed("\"1" + std::string(200, '0') + "e-200\""), "ok") << "1 significant digit";
}

// ---------------------------------------------------------------- 10: the samples of a simulation

TEST(Item10_Samples, TheSpacingMustBePositiveAndTheCountBounded) {
  EXPECT_THROW(api::check_sample_interval(0), api::BadInput);
  EXPECT_THROW(api::check_sample_interval(-1), api::BadInput);
  EXPECT_THROW(api::check_sample_interval(std::nan("")), api::BadInput);
  EXPECT_NO_THROW(api::check_sample_interval(1e-300)) << "the count is judged with the end time";
  const api::Model v(api::Case::load("V"));
  try {
    (void)v.simulate({.step = 0.62, .t_end = 60, .sample_interval = 1e-7});
    ADD_FAILURE() << "6e8 samples (38 GB) were not refused";
  } catch (const api::BadInput& e) {
    EXPECT_EQ(e.argument(), "sample_interval");
    EXPECT_EQ(e.problem(), "1e-07 s over t_end = 60 s gives 6e+08 samples; at most 1e+07 are recorded (use a larger "
                           "interval or a shorter t_end)");
  }
  const double largest_interval_refused = 60 / (api::largest_sample_count - 1) * (1 - 1e-9);
  EXPECT_THROW((void)v.simulate({.step = 0.62, .t_end = 60, .sample_interval = largest_interval_refused}), api::BadInput);
  EXPECT_EQ(v.simulate({.step = 0.62, .t_end = 60, .sample_interval = 0.01}).result.samples.size(), 6001u);
}

TEST(Item10_Samples, TheCliRefusesTheSameCountBeforeWriting) {
  // Before: 6e8 rows streamed (about 80 GB of text) and, with --dt 1e-300, rows without end.
  for (const std::string dt : {"1e-7", "1e-300"}) {
    const CliRun r = run("simulate V --csv --dt " + dt, 20);
    EXPECT_EQ(r.exit_code, 2) << dt << ": " << r.err.substr(0, 200);
    EXPECT_EQ(r.err.rfind("backlash: error: --dt: " + std::string(dt == "1e-7" ? "1e-07" : "1e-300") + " s over t_end = 60 s gives ", 0), 0u)
        << r.err.substr(0, 200);
    EXPECT_EQ(r.out, "") << "nothing on stdout before the input is known good";
  }
  const CliRun zero = run("simulate V --dt 0");
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_EQ(zero.err, "backlash: error: --dt: must be > 0, got 0\n");
}

// ---------------------------------------------------------------- 16: strict numbers on the command line

struct Refusal {
  std::string arguments, message;
};

TEST(Item16_StrictFlags, EveryNumericFlagRefusesHexInfNanAndTrailingGarbage) {
  // Before: map's --step, --points, --threads, --block, --seed, --stop-after and validate's
  // --tolerance were read by CLI11, which takes 0x10 as 16 and wraps -1 into 2^64 - 1.
  const std::string map = "map V --vary K=1:1.1:2 --no-boundary ";
  const std::vector<Refusal> refusals{
      {map + "--step 0x10", "--step: '0x10' is not a number"},
      {map + "--step inf", "--step: 'inf' is not finite"},
      {map + "--step 1abc", "--step: '1abc' is not a number"},
      {map + "--threads 0x1", "--threads: '0x1' is not a number"},
      {map + "--threads 1.5", "--threads: expected a whole number, got '1.5'"},
      {map + "--block 0x2", "--block: '0x2' is not a number"},
      {map + "--sample lhs --points 0x2", "--points: '0x2' is not a number"},
      {map + "--sample lhs --points nan", "--points: 'nan' is not finite"},
      {map + "--stop-after 1e400 --out " + (scratch() / "m").string(),
       "--stop-after: '1e400' is too large for double precision (beyond 1.8e308)"},
      {map + "--sample lhs --points 2 --seed -1",
       "--seed: expected the digits of a whole number from 0 to 18446744073709551615, got '-1'"},
      {map + "--sample lhs --points 2 --seed 1e23",
       "--seed: expected the digits of a whole number from 0 to 18446744073709551615, got '1e23'"},
      {map + "--sample lhs --points 2 --seed 0x10",
       "--seed: expected the digits of a whole number from 0 to 18446744073709551615, got '0x10'"},
      {map + "--sample lhs --points 2 --seed 18446744073709551616",
       "--seed: '18446744073709551616' is too large (at most 18446744073709551615)"},
      {"validate V --tolerance 0x1p-30", "--tolerance: '0x1p-30' is not a number"},
      {"validate V --tolerance 1e-9x", "--tolerance: '1e-9x' is not a number"},
      {"simulate V --step 0x10", "--step: '0x10' is not a number"},
      {"simulate V --t-end 60s", "--t-end: '60s' is not a number"},
      {"sweep V --vary K --from 0x1 --to 2 --points 2", "--from: '0x1' is not a number"},
      {"sweep V --vary K --from 1 --to 2 --points 0x2", "--points: '0x2' is not a number"},
      {"trace V --v0 0x1", "--v0: '0x1' is not a number"},
  };
  for (const Refusal& r : refusals) {
    const CliRun out = run(r.arguments, 30);
    EXPECT_EQ(out.exit_code, 2) << r.arguments;
    EXPECT_EQ(out.err, "backlash: error: " + r.message + "\n") << r.arguments;
    EXPECT_EQ(out.out, "") << r.arguments;
  }
  EXPECT_FALSE(fs::exists(scratch() / "m"));
}

TEST(Item16_StrictFlags, TheLargestSeedIsAKeyOfItsOwn) {
  // Before, --seed -1 and 18446744073709551615 were the same key (and 1e23 was read as a
  // double, then converted): now only the digits of 0 … 2^64 − 1 are keys, each its own.
  const std::string map = "map V --vary K=1:1.1:2 --no-boundary --sample lhs --points 2 --seed ";
  const CliRun largest = run(map + "18446744073709551615");
  const CliRun other = run(map + "18446744073709551614");
  ASSERT_EQ(largest.exit_code, 0) << largest.err;
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_NE(largest.out, other.out) << "two keys, one sample";
}

}  // namespace
