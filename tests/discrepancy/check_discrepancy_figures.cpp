// The discrepancy pages' figures go through the project's one plotting route
// (backlash/reports/plot.hpp: gnuplot): each .svg of report_files() is gnuplot's SVG, carries
// its title, legend and candidate names, and is the same bytes from run to run; the page
// links every figure.  Without gnuplot the figures are left out and the page says why.
#include "backlash/reports/discrepancy_pages.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>  // getpid

namespace {

using namespace backlash;
namespace fs = std::filesystem;

// A small made-up result: a step response, a model a little off, one free-flight region,
// two candidates (one of them failed).
discrepancy::DiscrepancyResult made_up_result() {
  discrepancy::DiscrepancyResult r;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.01 * i;
    r.t.push_back(t);
    r.theta_measured.push_back(0.62 * (1 - std::exp(-3 * t)) + 0.002 * std::sin(40 * t));
    r.theta_nominal.push_back(0.62 * (1 - std::exp(-3.5 * t)));
    r.theta_corrected.push_back(0.62 * (1 - std::exp(-3 * t)));
  }
  r.noise = 0.0015;
  r.rms_before = 0.02, r.rms_after = 0.0016;
  r.regions = {{0, 0.4, "contact", 40, 0.01, 0.001}, {0.4, 1.1, "free", 70, 0.03, 0.002}, {1.1, 2, "contact", 91, 0.01, 0.001}};
  discrepancy::Candidate coulomb, failed;
  coulomb.effect = "coulomb_load", coulomb.parameters = {{"torque", 0.01, 0.001}}, coulomb.rms = 0.0016;
  failed.effect = "torque_offset", failed.parameters = {{"torque", 0, NAN}}, failed.rms = NAN;
  r.effects = {coulomb};
  r.rounds = {{coulomb, failed}};
  r.status = discrepancy::Status::EffectFound;
  return r;
}

std::map<std::string, std::string> files_of(const model::CaseSpec& spec, const discrepancy::DiscrepancyResult& r) {
  std::map<std::string, std::string> out;
  for (auto& [name, text] : discrepancy::report_files(spec, "made_up.csv", r, 0.62)) out[name] = text;
  return out;
}

bool gnuplot_installed() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

}  // namespace

TEST(DiscrepancyFigures, AreGnuplotsSvgWithTheirContentAndTheSameBytesEveryTime) {
  if (!gnuplot_installed()) GTEST_SKIP() << "gnuplot is not installed";
  const model::CaseSpec spec = model::load_case("V");
  const auto r = made_up_result();
  const auto a = files_of(spec, r), b = files_of(spec, r);
  ASSERT_EQ(a.size(), b.size());
  const std::map<std::string, std::vector<std::string>> content{
      {"measured_vs_models.svg", {"Measured", "measured", "nominal", "model", "corrected", "[s]"}},
      {"residual.svg", {"Residual", "free", "flight", "noise", "band", "±3σ", "[rad]"}},
      {"candidates.svg", {"First", "round:", "coulomb_load", "torque_offset", "failed", "nominal"}}};
  for (const auto& [name, words] : content) {
    ASSERT_TRUE(a.count(name)) << name << " was not drawn";
    const std::string& svg = a.at(name);
    EXPECT_EQ(svg, b.at(name)) << name << " differs between two runs";
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u) << name;
    EXPECT_NE(svg.find("<desc>Produced by GNUPLOT"), std::string::npos) << name << " is not gnuplot's SVG";
    EXPECT_EQ(svg.find("<text>"), std::string::npos) << name << ": a <text> that collapses its spaces";
    for (const std::string& word : words) EXPECT_NE(svg.find(word), std::string::npos) << name << " has no \"" << word << "\"";
    EXPECT_NE(a.at("discrepancy.md").find("](" + name + ")"), std::string::npos) << "the page does not show " << name;
  }
  EXPECT_NE(a.at("residual.svg").find("fill-opacity"), std::string::npos) << "the free-flight region is not shaded";
}

TEST(DiscrepancyFigures, WithoutGnuplotThePageSaysSoAndHasNoFigures) {
  const model::CaseSpec spec = model::load_case("V");
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  const fs::path empty = fs::temp_directory_path() / ("backlash-no-gnuplot-" + std::to_string(::getpid()));
  fs::create_directories(empty);
  ::setenv("PATH", empty.c_str(), 1);
  const auto files = files_of(spec, made_up_result());
  ::setenv("PATH", saved.c_str(), 1);
  fs::remove_all(empty);
  for (const auto& [name, text] : files) EXPECT_NE(fs::path(name).extension(), ".svg") << name << " drawn without gnuplot";
  ASSERT_TRUE(files.count("discrepancy.md"));
  const std::string& md = files.at("discrepancy.md");
  EXPECT_NE(md.find("The figures were not drawn: gnuplot is not installed."), std::string::npos);
  EXPECT_EQ(md.find(".svg)"), std::string::npos) << "the page links a figure that was not drawn";
  EXPECT_TRUE(files.count("discrepancy.json") && files.count("corrected.toml"));
}
