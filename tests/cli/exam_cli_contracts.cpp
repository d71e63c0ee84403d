// The command-line contracts of docs/design.md: JSON keys others script against,
// one-line errors with a non-zero exit for bad input, and no output written
// when a command fails.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <unistd.h>
#include <sys/wait.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

struct CommandRun {
  int exit_code;
  std::string out, err;
};

CommandRun run(const std::string& arguments) {
  const std::string err_file = std::filesystem::temp_directory_path() / ("backlash-cli-test-" + std::to_string(::getpid()) + ".err");
  const std::string command = std::string(BACKLASH_CLI) + " " + arguments + " 2> " + err_file;
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  std::ifstream in(err_file);
  std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(err_file);
  return {WEXITSTATUS(status), out, err};
}

void expect_one_line_error(const CommandRun& r, const std::string& fragment) {
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(r.out.empty()) << "printed to stdout: " << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "error is not one line: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << "error '" << r.err << "' does not mention '" << fragment << "'";
}

TEST(DeriveCommand, JsonHasSolutionsSeparationLineIsoclinesAndVerification) {
  const CommandRun r = run("derive V --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["case"], "V");
  for (const char* state : {"theta_m", "dtheta_m", "theta_L", "dtheta_L"}) {
    EXPECT_TRUE(j["free"][state].contains("exact")) << state;
    EXPECT_TRUE(j["free"][state].contains("decimal")) << state;
  }
  EXPECT_EQ(j["separation_line"]["cot_phi"]["exact"], "1/5");
  EXPECT_FALSE(j["isoclines"].empty());
  EXPECT_EQ(j["verification"]["status"], "verified");
}

TEST(DeriveCommand, LatexOutput) {
  const CommandRun r = run("derive III --latex");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\\theta_m"), std::string::npos);
}

TEST(TraceCommand, JsonKeysOfDesign) {
  const CommandRun r = run("trace V --v0 1,0.5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["case"], "V");
  EXPECT_DOUBLE_EQ(j["cot_phi"].get<double>(), 0.2);
  ASSERT_EQ(j["points"].size(), 2u);
  for (const char* key : {"v0", "t", "theta_m", "dtheta_m", "theta_L", "dtheta_L", "theta_o", "dtheta_o"})
    EXPECT_TRUE(j["points"][0].contains(key)) << key;
}

TEST(SimulateCommand, JsonKeysOfDesign) {
  const CommandRun r = run("simulate I --step 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_FALSE(j["events"].empty());
  for (const char* key : {"t", "kind", "theta_o", "dtheta_o"}) EXPECT_TRUE(j["events"][0].contains(key)) << key;
  EXPECT_EQ(j["events"][0]["kind"], "separation");
  for (const char* key : {"theta_o", "theta_m", "theta_L"}) EXPECT_TRUE(j["final"].contains(key)) << key;
}

TEST(LimitCycleCommand, JsonKeysOfDesign) {
  const CommandRun r = run("limit-cycle VI --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "limit_cycle");
  for (const char* key : {"case", "amplitude", "peak_to_peak", "period", "separation_velocity", "multiplier"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(nlohmann::json::parse(run("limit-cycle I --json").out)["status"], "none");
}

TEST(BadInput, FlagsAndCasesFailWithOneLine) {
  expect_one_line_error(run("trace V --v0 1,,2"), "--v0");
  expect_one_line_error(run("trace V --v0 abc"), "--v0");
  expect_one_line_error(run("trace V --v0 ''"), "--v0");
  expect_one_line_error(run("simulate V --step 0.5 --t-end 0"), "--t-end");
  expect_one_line_error(run("simulate V --step 0.5 --t-end -3"), "--t-end");
  expect_one_line_error(run("simulate V --step x"), "--step");
  expect_one_line_error(run("simulate IX --step 1"), "IX");
  expect_one_line_error(run("derive nonexistent_case.toml"), "nonexistent_case.toml");
  expect_one_line_error(run("sweep fig31 --points 0"), "--points");
}

TEST(BadInput, BadCaseFileNamesFileLineAndKey) {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "backlash_bad_case.toml";
  std::ofstream(file) << "name = \"bad\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\nreference = 1\n[motor]\nJ = 0\nF = 0.1\n[load]\nJ = 0.5\nF = 0.3\n";
  const CommandRun r = run("derive " + file.string());
  expect_one_line_error(r, file.string() + ":7: motor.J");
  std::filesystem::remove(file);
}

TEST(BadInput, NothingWrittenOnFailure) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "backlash_sweep_must_not_exist.csv";
  std::filesystem::remove(out);
  const CommandRun r = run("sweep fig31 --points 3 --threads 0 --out " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::filesystem::path codegen_out = std::filesystem::temp_directory_path() / "backlash_codegen_must_not_exist";
  std::filesystem::remove_all(codegen_out);
  EXPECT_NE(run("codegen IX --out " + codegen_out.string()).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(codegen_out));
}

}  // namespace
