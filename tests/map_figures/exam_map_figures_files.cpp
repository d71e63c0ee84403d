// What MapFigures::write leaves in a folder, for a synthetic three-parameter grid map with
// a disk-shaped cycle region in (JL_over_Jm, FL_over_F) and exact boundary crossings:
// a figure per pair (SVG with the data drawn: boxes on a log axis, an image on linear ones;
// labelled axes with units, a colour-bar title, a legend, the case named; a PDF), summary.md
// (counts per status, magnitude range, the ranking, the figures linked), the same bytes from
// two writes; without gnuplot the summary says why; bad input is refused with one line naming
// the point and the parameter; the boundary markers stay bounded however many crossings come.
#include "synthetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

namespace {

namespace fs = std::filesystem;
using backlash::map::figures::MapAxis;
using backlash::map::figures::MapBoundaryPoint;
using backlash::map::figures::MapFigures;

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("backlash_map_figures_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// JL/Jm on [0.1, 10] (log, 21 values) × FL/F on [0, 1] (21 values) × K on [1, 2] (3 values):
// a cycle inside the disk of radius 0.6 around (log10 JL/Jm, FL/F) = (0, 0.5) in units of the
// axes' half-widths, divergent at one corner; exact crossings along JL/Jm on every FL/F line.
MapFigures disk_map() {
  MapFigures map("V", {{"JL_over_Jm", 0.1, 10, 21, true}, {"FL_over_F", 0, 1, 21}, {"K", 1, 2, 3}}, "grid");
  std::int64_t index = 0;
  for (int i = 0; i < 21; ++i)
    for (int j = 0; j < 21; ++j)
      for (int k = 0; k < 3; ++k) {
        const double u = -1 + i / 10.0, y = j / 20.0, K = 1 + k / 2.0;
        const std::vector<double> x = {std::pow(10.0, u), y, K};
        const double r = std::hypot(u, (y - 0.5) * 2);
        if (i == 0 && j == 0) {
          backlash::map::figures::MapPoint p = backlash::test::rest_point(index++, x);
          p.status = "divergent";
          map.add(p);
        } else {
          map.add(r < 0.6 ? backlash::test::cycle_point(index++, x, K * 0.01 * (1 - r / 0.6)) : backlash::test::rest_point(index++, x));
        }
      }
  for (int j = 0; j < 21; ++j) {
    const double dy = (j / 20.0 - 0.5) * 2;
    if (std::abs(dy) >= 0.6) continue;
    const double du = std::sqrt(0.36 - dy * dy);
    for (int k = 0; k < 3; ++k)
      for (double u : {-du, du}) map.add_boundary(MapBoundaryPoint{{std::pow(10.0, u), j / 20.0, 1 + k / 2.0}, 0});
  }
  return map;
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// gnuplot's SVG writes each text as <text>, enhanced pieces as <tspan>s; spaces are no-break
// spaces (plot.cpp).  The visible text of the file, pieces joined, NBSP as a space.
std::string visible_text(const std::string& svg) {
  std::string out;
  bool in_tag = false;
  for (std::size_t k = 0; k < svg.size(); ++k) {
    if (svg[k] == '<') in_tag = true;
    else if (svg[k] == '>') in_tag = false;
    else if (!in_tag) out += svg[k];
  }
  return std::regex_replace(std::regex_replace(out, std::regex("\xC2\xA0"), " "), std::regex("\\s+"), " ");
}

TEST(MapFiguresFiles, EveryPairHasAFigureWithDataLabelsAndALegend) {
  const fs::path dir = fresh_folder("pairs");
  const std::string failure = disk_map().write(dir);
  ASSERT_EQ(failure, "") << "returned \"" << failure << "\" instead of drawing the figures";
  for (const std::string stem : {"map_JL_over_Jm_FL_over_F", "map_JL_over_Jm_K", "map_FL_over_F_K"}) {
    const fs::path svg_file = dir / "figures" / (stem + ".svg");
    ASSERT_TRUE(fs::exists(svg_file)) << svg_file;
    ASSERT_TRUE(fs::exists(dir / "figures" / (stem + ".pdf"))) << stem << ".pdf";
    EXPECT_EQ(read(dir / "figures" / (stem + ".pdf")).substr(0, 5), "%PDF-");
    const std::string svg = read(svg_file), text = visible_text(svg);
    EXPECT_NE(text.find("Case V: limit cycles over ("), std::string::npos) << stem << ": no title naming the case in: " << text;
    EXPECT_NE(text.find("mean peak-to-peak swing (rad) of θo, 0 without a cycle"), std::string::npos) << stem << ": no colour-bar title in: " << text;
    EXPECT_NE(text.find("half of the bin's points have a cycle"), std::string::npos) << stem << ": no legend entry for the boundary";
    // the heat map: with JL/Jm on a log axis one filled box per bin (gnuplot draws each as a
    // path with a fill colour); FL/F × K, both linear, a uniform grid: one image, a pixel per bin
    if (stem == std::string("map_FL_over_F_K")) {
      EXPECT_EQ(count(svg, "<image "), 1u) << stem << ": the heat map is not one image";
    } else {
      EXPECT_EQ(count(svg, "<image "), 0u) << stem << ": a log axis drawn as an image";
      EXPECT_GT(count(svg, "fill = 'rgb("), 40u) << stem << ": " << count(svg, "fill = 'rgb(") << " filled shapes";
    }
  }
  const std::string text = visible_text(read(dir / "figures" / "map_JL_over_Jm_FL_over_F.svg"));
  EXPECT_NE(text.find("JL/Jm, inertia ratio, (Jm+JL) kept (dimensionless)"), std::string::npos) << text;
  EXPECT_NE(text.find("FL/F, load share of F, (Fm+FL) kept (dimensionless)"), std::string::npos) << text;
  EXPECT_NE(text.find("boundary found exactly along grid lines"), std::string::npos) << "no legend entry for the markers";
  const std::string k_text = visible_text(read(dir / "figures" / "map_JL_over_Jm_K.svg"));
  EXPECT_NE(k_text.find("K, loop gain (N·m/rad)"), std::string::npos) << k_text;
  fs::remove_all(dir);
}

TEST(MapFiguresFiles, SummaryCountsRanksAndLinks) {
  const fs::path dir = fresh_folder("summary");
  disk_map().write(dir);
  const std::string md = read(dir / "summary.md");
  EXPECT_NE(md.find("# Design-space map of case V"), std::string::npos) << md;
  EXPECT_NE(md.find("1323 points, a grid"), std::string::npos) << md;
  EXPECT_NE(md.find("| divergent | 3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("left out of the bins and figures (answer unknown): 3"), std::string::npos) << md;
  EXPECT_NE(md.find("rad"), std::string::npos);
  for (const std::string stem : {"map_JL_over_Jm_FL_over_F", "map_JL_over_Jm_K", "map_FL_over_F_K"})
    EXPECT_NE(md.find("(figures/" + stem + ".svg)"), std::string::npos) << "summary does not link " << stem;
  // K scales the swing but decides no cycle: JL/Jm and FL/F move the magnitude more
  const auto ranked = disk_map().sensitivities();
  ASSERT_EQ(ranked.size(), 3u);
  EXPECT_EQ(ranked[2].name, "K") << "ranked last: " << ranked[2].name << " instead of K";
  EXPECT_NE(md.find("| 3 | `K` |"), std::string::npos) << md;
  EXPECT_FALSE(fs::exists(dir / ".summary.md.partial"));
  fs::remove_all(dir);
}

TEST(MapFiguresFiles, TwoWritesGiveTheSameBytes) {
  const fs::path a = fresh_folder("first"), b = fresh_folder("second");
  disk_map().write(a);
  disk_map().write(b);
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path other = b / fs::relative(entry.path(), a);
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_TRUE(read(entry.path()) == read(other)) << entry.path().filename() << " differs between two writes";
    ++files;
  }
  EXPECT_EQ(files, 7u) << "summary.md and 3 × (SVG, PDF)";
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(MapFiguresFiles, WithoutGnuplotTheSummarySaysWhy) {
  const fs::path dir = fresh_folder("no_gnuplot");
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", dir.c_str(), 1);
  const std::string failure = disk_map().write(dir);
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(failure, "gnuplot is not installed");
  EXPECT_NE(read(dir / "summary.md").find("The figures were not drawn: gnuplot is not installed."), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "figures" / "map_JL_over_Jm_K.svg"));
  fs::remove_all(dir);
}

// A map without a single known answer, or without a boundary, still draws (gnuplot is given
// no empty colour range) and says so in the title.
TEST(MapFiguresFiles, MapsWithoutAnswersOrWithoutABoundaryStillDraw) {
  for (const std::string status : {"error", "limit_cycle"}) {
    const fs::path dir = fresh_folder("uniform_" + status);
    MapFigures map("V", {{"K", 1, 2, 3}, {"backlash", 0.1, 0.3, 3}}, "grid");
    std::int64_t index = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        backlash::map::figures::MapPoint p = backlash::test::cycle_point(index++, {1 + a / 2.0, 0.1 + b / 10.0}, 0.02);
        p.status = status;
        map.add(p);
      }
    const std::string failure = map.write(dir);
    EXPECT_EQ(failure, "") << status << ": returned \"" << failure << "\" instead of drawing";
    const std::string text = visible_text(read(dir / "figures" / "map_K_backlash.svg"));
    const std::string says = status == "error" ? "no point with a known answer" : "no cycle/no-cycle boundary inside";
    EXPECT_NE(text.find(says), std::string::npos) << status << ": the title does not say \"" << says << "\": " << text;
    const std::string md = read(dir / "summary.md");
    if (status == "error") {
      EXPECT_NE(md.find("No point has a limit cycle."), std::string::npos) << md;
    }
    fs::remove_all(dir);
  }
}

std::string refusal(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(MapFiguresFiles, BadInputIsRefusedNamingThePointAndTheParameter) {
  const std::vector<MapAxis> axes = {{"K", 1, 2, 5}, {"backlash", 0.1, 0.3, 3}};
  EXPECT_EQ(refusal([&] { MapFigures("V", axes, "random"); }), "map figures: sampling 'random' is none of grid, sobol, lhs");
  EXPECT_EQ(refusal([&] { MapFigures("V", {{"K", 0, 2, 5, true}}, "grid"); }),
            "map figures: axis 'K': log scale needs from, to > 0, got 0");
  EXPECT_EQ(refusal([&] { MapFigures("V", {{"K", 1, 2, 0}}, "lhs"); }), "map figures: axis 'K': bins = 0, needs at least 1");
  MapFigures map("V", axes, "grid");
  map.add(backlash::test::rest_point(0, {1, 0.1}));
  EXPECT_EQ(refusal([&] { map.add(backlash::test::rest_point(0, {1, 0.1})); }),
            "map figures: point 0: comes after point 0 (points must come in index order)");
  EXPECT_EQ(refusal([&] { map.add(backlash::test::rest_point(1, {3, 0.1})); }), "map figures: point 1: K = 3 is outside [1, 2]");
  EXPECT_EQ(refusal([&] { map.add(backlash::test::rest_point(1, {1.1, 0.1})); }),
            "map figures: point 1: K = 1.1 is not one of the axis's 5 grid values");
  EXPECT_EQ(refusal([&] { map.add(backlash::test::rest_point(1, {1})); }), "map figures: point 1: 1 values instead of 2");
  EXPECT_EQ(refusal([&] { map.add_boundary({{1, 0.1}, 2}); }), "map figures: boundary point along axis 2 of 2");
  map.add(backlash::test::rest_point(1, {1.25, 0.2}));  // the refusals left the map as it was
}

TEST(MapFiguresFiles, BoundaryMarkersStayBounded) {
  MapFigures map("V", {{"K", 1, 2, 1000}, {"backlash", 0.1, 0.3, 1000}}, "grid");
  const int crossings = 100000;
  for (int i = 0; i < crossings; ++i) map.add_boundary({{1 + i / double(crossings), 0.2}, 0});
  const auto f = map.field(0, 1);
  EXPECT_LE(f.boundary_x.size(), static_cast<std::size_t>(MapFigures::max_boundary_markers));
  EXPECT_GE(f.boundary_x.size(), static_cast<std::size_t>(MapFigures::max_boundary_markers / 2));
  // thinned evenly: the kept crossings are equally spaced, the first one kept
  ASSERT_GE(f.boundary_x.size(), 2u);
  EXPECT_EQ(f.boundary_x[0], 1.0);
  const double step = f.boundary_x[1] - f.boundary_x[0];
  for (std::size_t k = 1; k < f.boundary_x.size(); ++k)
    EXPECT_NEAR(f.boundary_x[k] - f.boundary_x[k - 1], step, 1e-9) << "uneven thinning at marker " << k;
  // a 1000-value grid axis is binned in groups of consecutive values (at most 200 bins)
  EXPECT_EQ(f.x_edges.size(), 201u) << "returned " << f.x_edges.size() - 1 << " bins instead of 200";
}

}  // namespace
