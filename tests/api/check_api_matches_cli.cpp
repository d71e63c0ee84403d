// check_api_matches_cli — one route: what the facade writes (json(), csv(), text(), the
// streamed CSVs, error messages) is, byte for byte, what the CLI prints for the same request
// (the CLI's commands are shells over the facade; these hold them to it).
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

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// stdout of `backlash ARGUMENTS`, and its stderr into `err` when asked for; fails the test
/// when the exit code is not `exit_code`.
std::string cli(const std::string& arguments, int exit_code = 0, std::string* err = nullptr) {
  const std::filesystem::path err_file =
      std::filesystem::temp_directory_path() / ("backlash-api-cli-" + std::to_string(::getpid()) + ".err");
  const std::string command = std::string(BACKLASH_CLI) + " " + arguments + " 2>" + err_file.string();
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), exit_code) << "backlash " << arguments << " exited with " << WEXITSTATUS(status)
                                            << " instead of " << exit_code;
  if (err) *err = slurp(err_file);
  std::filesystem::remove(err_file);
  return out;
}

/// A case file in the test's temporary folder.
std::string case_file(const std::string& stem, const std::string& text) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("backlash-api-" + std::to_string(::getpid()) + "-" + stem + ".toml");
  std::ofstream(file) << text;
  return file.string();
}

std::string case_text(const std::string& K, const std::string& F) {
  return "name = \"t\"\nmeasured_at = \"load\"\nK = " + K + "\nbacklash = 0.3\nreference = 1\n[motor]\nJ = 0.5\nF = " +
         F + "\n[load]\nJ = 0.5\nF = " + F + "\n";
}

/// The text a sink is handed, joined.
struct Collected {
  std::string text;
  api::TextSink sink() {
    return [this](std::string_view piece) { text += piece; };
  }
};

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

TEST(ApiMatchesCli, StreamedCsvIsTheWholeCsv) {
  const api::SimulationRequest request{.step = .16, .t_end = 20, .sample_interval = 0.01};
  Collected streamed;
  const api::Simulation run = model("II").simulate_csv(request, streamed.sink());
  expect_same("simulate_csv(II, step .16, t_end 20)", streamed.text, model("II").simulate(request).csv());
  EXPECT_TRUE(run.result.samples.empty()) << "simulate_csv kept " << run.result.samples.size() << " samples instead of 0";

  const api::SweepRequest sweep{.target = "fig32", .points = 5, .threads = 2};
  Collected rows;
  long seen = 0;
  const api::Sweep done = api::sweep(sweep, rows.sink(), [&](const numeric::SweepRow&) { ++seen; });
  expect_same("sweep(fig32, 5 points, streamed)", rows.text, api::sweep(sweep).csv());
  EXPECT_EQ(seen, 15) << "the row callback saw " << seen << " rows instead of 15";
  EXPECT_EQ(done.points, 15) << "the streamed sweep counted " << done.points << " points instead of 15";
  expect_same("sweep fig32 --points 5", rows.text, cli("sweep fig32 --points 5 --no-progress"));
}

TEST(ApiMatchesCli, EarlyStop) {
  // Undamped, the cycle grows; the event cap ends the run long before t_end (exit 3).
  const std::string file = case_file("grows", case_text("1", "0"));
  const api::Model m(api::load(file));
  const api::Simulation run = m.simulate({.step = 0.62, .t_end = 2e5});
  ASSERT_TRUE(run.stopped_early()) << "simulate() returned " << numeric::to_string(run.result.status)
                                   << " instead of an early stop";
  std::string err;
  expect_same("simulate --json (stopped early)", run.json(), cli("simulate " + file + " --step 0.62 --t-end 2e5 --json", 3, &err));
  expect_same("the early-stop line on stderr", "backlash: " + run.stop_message() + "\n", err);
  expect_same("simulate (stopped early)", run.text(), cli("simulate " + file + " --step 0.62 --t-end 2e5", 3));
  Collected csv;
  m.simulate_csv({.step = 0.62, .t_end = 2e5, .sample_interval = 1000}, csv.sink());
  expect_same("simulate --csv (stopped early)", csv.text,
              cli("simulate " + file + " --step 0.62 --t-end 2e5 --dt 1000 --csv", 3));
  std::filesystem::remove(file);
}

TEST(ApiMatchesCli, RefusalsAreTheSameLine) {
  // The scale check before any work: the facade's exception is the CLI's line.
  const std::string file = case_file("K1e90", case_text("1e90", "0.1"));
  std::string facade = "(no error)", err;
  try {
    api::Model m(api::load(file));
  } catch (const std::exception& error) {
    facade = error.what();
    EXPECT_TRUE(api::is_bad_input(error)) << "the scale check returned an error that is not bad input: " << facade;
  }
  cli("limit-cycle " + file, 2, &err);
  expect_same("limit-cycle (K = 1e90)", "backlash: error: " + facade + "\n", err);
  std::filesystem::remove(file);
  // A BadInput is named by its flag.
  try {
    model("V").simulate({.step = 0.5, .t_end = -3});
    ADD_FAILURE() << "simulate(t_end = -3) returned a result instead of BadInput";
  } catch (const api::BadInput& error) {
    cli("simulate V --step 0.5 --t-end -3", 2, &err);
    expect_same("simulate --t-end -3", "backlash: error: --t-end: " + error.problem() + "\n", err);
  }
}

TEST(ApiMatchesCli, SweepSeriesIsQuoted) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("backlash-api-quoted-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  const std::string file = (folder / "a,b.toml").string();
  std::ofstream(file) << case_text("1", "0.2");
  const api::Sweep sweep = api::sweep({.target = file, .vary = "K", .from = 1, .to = 2, .points = 2, .threads = 1});
  EXPECT_NE(sweep.csv().find("\n\"a,b:K\","), std::string::npos) << "csv() returned " << sweep.csv() << " instead of a quoted series";
  expect_same("sweep a,b.toml --vary K", sweep.csv(),
              cli("sweep \"" + file + "\" --vary K --from 1 --to 2 --points 2 --threads 1 --no-progress"));
  std::filesystem::remove_all(folder);
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
