// Issue 19, gnuplot started beside the caller's work (start_gnuplot_early, plot.hpp): the
// figures it draws are the bytes of a gnuplot started when they are drawn (SVG and PDF), and
// the waiting one is the one used — it draws even when PATH no longer finds gnuplot.
#include "backlash/reports/plot.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <stdlib.h>

namespace {

using backlash::reports::Plot;
namespace fs = std::filesystem;

bool have_gnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

std::vector<Plot> plots() {
  Plot plot;
  plot.name = "line";
  plot.title = "a line and a parabola";
  plot.x_label = "t (s)";
  plot.y_label = "θ (rad)";
  backlash::reports::Series line{"θ = t", {}, {}};
  backlash::reports::Series parabola{"θ = t²", {}, {}};
  for (int i = 0; i <= 20; ++i) {
    line.x.push_back(i / 10.0), line.y.push_back(i / 10.0);
    parabola.x.push_back(i / 10.0), parabola.y.push_back(i * i / 100.0);
  }
  plot.series = {line, parabola};
  return {plot};
}

std::string bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path fresh(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() / ("backlash-early-" + std::to_string(getpid()) + "-" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

}  // namespace

TEST(PlotStartedEarly, SameFiguresFromTheWaitingGnuplot) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path now = fresh("now"), early = fresh("early");
  ASSERT_FALSE(backlash::reports::render_figures(plots(), now));
  backlash::reports::start_gnuplot_early();
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", "/nonexistent", 1);  // only the waiting gnuplot can draw now
  const auto failure = backlash::reports::render_figures(plots(), early);
  setenv("PATH", path.c_str(), 1);
  ASSERT_FALSE(failure) << *failure;
  for (const char* file : {"figures/line.svg", "figures/line.pdf"}) {
    EXPECT_FALSE(bytes(now / file).empty()) << file;
    EXPECT_EQ(bytes(now / file), bytes(early / file)) << file;
  }
  EXPECT_FALSE(fs::exists(early / "figures.gp"));
  EXPECT_FALSE(fs::exists(early / "figures.log"));
  fs::remove_all(now), fs::remove_all(early);
}
