// check_api_matches_cli — one route: what the facade writes (json(), csv(), text()) is,
// byte for byte, what the CLI prints for the same request (the CLI's commands will be
// switched onto the facade; until then both must agree).
#include "backlash/api/backlash.hpp"
#include "backlash/api/derive.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace {

using namespace backlash;

/// stdout of `backlash ARGUMENTS` (stderr discarded); fails the test on a non-zero exit.
std::string cli(const std::string& arguments) {
  const std::string command = std::string(BACKLASH_CLI) + " " + arguments + " 2>/dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "backlash " << arguments << " exited with " << WEXITSTATUS(status);
  return out;
}

void expect_same(const std::string& what, const std::string& facade, const std::string& command_line) {
  EXPECT_TRUE(facade == command_line) << what << " returned\n" << facade.substr(0, 2000) << "\ninstead of what `backlash "
                                      << what << "` prints:\n" << command_line.substr(0, 2000);
}

const api::Model& model(const std::string& id) {
  static std::map<std::string, api::Model> models;
  auto found = models.find(id);
  if (found == models.end()) found = models.emplace(id, api::Model(api::load(id))).first;
  return found->second;
}

/// A case file with effects, written once into the test's temporary folder.
std::string effects_case_file() {
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("backlash-api-effects-" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << "name = \"V with effects\"\nmeasured_at = \"load\"\nK = 1\nbacklash = 0.3\nreference = 1\n"
                         "[motor]\nJ = 0.5\nF = 0.1\n[load]\nJ = 0.5\nF = 0.3\n[experiment]\nstep = 0.62\nt_end = 40\n"
                         "[effects]\ncoulomb_load = 0.03\nrestitution = 0.2\n";
  return file.string();
}

TEST(ApiMatchesCli, LimitCycle) {
  for (const std::string id : {"V", "I", "VIII"}) {
    expect_same("limit-cycle " + id + " --json", model(id).limit_cycle().json(), cli("limit-cycle " + id + " --json"));
    expect_same("limit-cycle " + id, model(id).limit_cycle().text(), cli("limit-cycle " + id));
  }
}

TEST(ApiMatchesCli, Simulate) {
  expect_same("simulate I --step 1 --json", model("I").simulate({.step = 1}).json(), cli("simulate I --step 1 --json"));
  expect_same("simulate V", model("V").simulate().text(), cli("simulate V"));
  expect_same("simulate II --step .16 --t-end 20 --csv", model("II").simulate({.step = .16, .t_end = 20, .sample_interval = 0.01}).csv(),
              cli("simulate II --step .16 --t-end 20 --csv"));
}

TEST(ApiMatchesCli, Trace) {
  expect_same("trace V --json", model("V").trace().json(), cli("trace V --json"));
  expect_same("trace I --v0 .9,.5,.13", model("I").trace({.9, .5, .13}).text(), cli("trace I --v0 .9,.5,.13"));
}

TEST(ApiMatchesCli, Effects) {
  const std::string file = effects_case_file();
  const api::Model m(api::load(file));
  expect_same("simulate " + file + " --json", m.simulate().json(), cli("simulate " + file + " --json"));
  expect_same("limit-cycle " + file + " --json", m.limit_cycle().json(), cli("limit-cycle " + file + " --json"));
  std::filesystem::remove(file);
}

TEST(ApiMatchesCli, Sweep) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                    ("backlash-api-sweep-" + std::to_string(::getpid()) + ".csv");
  cli("sweep V --vary FL_over_F --from 0.2 --to 0.9 --points 6 --threads 2 --no-progress --out " + out.string());
  std::ifstream in(out);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(out);
  const api::Sweep sweep =
      api::sweep({.target = "V", .vary = "FL_over_F", .from = 0.2, .to = 0.9, .points = 6, .threads = 1});
  expect_same("sweep V --vary FL_over_F --from 0.2 --to 0.9 --points 6", sweep.csv(), written);
  expect_same("sweep fig31 --points 3", api::sweep({.target = "fig31", .points = 3, .threads = 2}).csv(),
              cli("sweep fig31 --points 3 --no-progress"));
}

TEST(ApiMatchesCli, Validate) {
  const api::Validation v = api::validate(api::load("III"), false);
  EXPECT_TRUE(v.passed());
  expect_same("validate III --json", v.json(), cli("validate III --json"));
  expect_same("validate III", v.text(), cli("validate III"));
}

TEST(ApiMatchesCli, Derive) {
  const api::Derivation d = api::derive(api::load("V"));
  expect_same("derive V --json", d.json, cli("derive V --json"));
  expect_same("derive V --latex", d.latex, cli("derive V --latex"));
  expect_same("derive V", d.text, cli("derive V"));
  // A case given in code derives as its case file does.
  const api::Case from_code = api::Case::from_texts({{"name", "Case IV"}, {"measured_at", "load"}, {"Jm", "0.2"}, {"Fm", "0"},
                                                     {"JL", "0.8"}, {"FL", "0.4"}, {"K", "1"}, {"backlash", "0.2"},
                                                     {"reference", "1"}});
  EXPECT_FALSE(api::derive(from_code).json.empty());
}

}  // namespace
