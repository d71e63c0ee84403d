// How plot.hpp draws a heat map (HeatMap's rule): a uniform grid on linear axes as an image,
// one pixel per cell (the SVG's embedded PNG decoded here: its size, the palette's end colours
// at the colour range's ends, a transparent pixel for a cell with a NaN value and for a grid
// position without a cell), marked to be drawn with sharp pixels; log axes, non-uniform cells,
// a single row and a cell given twice as one filled box per cell.
#include "backlash/reports/plot.hpp"

#include <gtest/gtest.h>

#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

namespace {

using backlash::reports::HeatMap;
using backlash::reports::Plot;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

bool have_gnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

// A 4 × 3 grid of unit cells from (10, -1), value i + 4 j at column i, row j, on [0, 11]; the
// cell (1, 1) has a NaN value and the cell (2, 2) is left out.
Plot grid_plot() {
  Plot plot;
  plot.name = "heat";
  plot.title = "heat map";
  HeatMap h;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) {
      if (i == 2 && j == 2) continue;
      h.x_low.push_back(10 + i), h.x_high.push_back(11 + i), h.y_low.push_back(-1 + j), h.y_high.push_back(j);
      h.value.push_back(i == 1 && j == 1 ? nan : i + 4 * j);
    }
  h.colour_label = "value";
  h.value_range = std::pair{0.0, 11.0};
  plot.heat_map = h;
  plot.series.push_back({"line", {10, 14}, {-1, 2}});
  return plot;
}

std::string svg_of(const Plot& plot) {
  std::vector<std::string> svgs;
  const auto failure = backlash::reports::render_svgs({plot}, svgs);
  EXPECT_FALSE(failure) << *failure;
  return svgs.empty() ? "" : svgs[0];
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

std::vector<unsigned char> base64(const std::string& text) {
  const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  std::uint32_t bits = 0;
  int have = 0;
  for (char c : text) {
    const std::size_t d = digits.find(c);
    if (d == std::string::npos) continue;  // '=' padding
    bits = (bits << 6) | static_cast<std::uint32_t>(d);
    if ((have += 6) >= 8) out.push_back(static_cast<unsigned char>(bits >> (have -= 8)));
  }
  return out;
}

struct Rgba {
  std::size_t width = 0, height = 0;
  std::vector<std::array<int, 4>> pixel;  // rows from the top
};

// An 8-bit RGBA PNG (what gnuplot embeds): its chunks, the IDAT inflated and unfiltered.
Rgba decode_png(const std::vector<unsigned char>& png) {
  const auto u32 = [&](std::size_t at) {
    return (std::uint32_t{png[at]} << 24) | (std::uint32_t{png[at + 1]} << 16) | (std::uint32_t{png[at + 2]} << 8) | png[at + 3];
  };
  Rgba image;
  std::vector<unsigned char> packed;
  for (std::size_t at = 8; at + 8 <= png.size();) {
    const std::size_t n = u32(at);
    const std::string type(png.begin() + static_cast<std::ptrdiff_t>(at + 4), png.begin() + static_cast<std::ptrdiff_t>(at + 8));
    if (type == "IHDR") {
      image.width = u32(at + 8), image.height = u32(at + 12);
      EXPECT_EQ(png[at + 16], 8) << "bit depth";
      EXPECT_EQ(png[at + 17], 6) << "colour type (RGBA)";
    }
    if (type == "IDAT") packed.insert(packed.end(), png.begin() + static_cast<std::ptrdiff_t>(at + 8), png.begin() + static_cast<std::ptrdiff_t>(at + 8 + n));
    at += 12 + n;
  }
  const std::size_t stride = 4 * image.width;
  std::vector<unsigned char> raw(image.height * (stride + 1));
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &size, packed.data(), packed.size()), Z_OK);
  EXPECT_EQ(size, raw.size());
  std::vector<unsigned char> row(stride), above(stride, 0);
  for (std::size_t y = 0; y < image.height; ++y) {
    const unsigned char filter = raw[y * (stride + 1)];
    for (std::size_t k = 0; k < stride; ++k) {
      const int a = k >= 4 ? row[k - 4] : 0, b = above[k], c = k >= 4 ? above[k - 4] : 0;
      const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
      const int predictor = filter == 1 ? a : filter == 2 ? b : filter == 3 ? (a + b) / 2
                          : filter == 4 ? (pa <= pb && pa <= pc ? a : pb <= pc ? b : c) : 0;
      row[k] = static_cast<unsigned char>(raw[y * (stride + 1) + 1 + k] + predictor);
    }
    for (std::size_t x = 0; x < image.width; ++x) image.pixel.push_back({row[4 * x], row[4 * x + 1], row[4 * x + 2], row[4 * x + 3]});
    above = row;
  }
  return image;
}

TEST(PlotHeatMap, AUniformGridIsAnImageWithBlankPixelsForCellsWithoutAValue) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const std::string svg = svg_of(grid_plot());
  ASSERT_EQ(count(svg, "<image "), 1u) << "the heat map is not drawn as one image";
  EXPECT_EQ(count(svg, "<image style='image-rendering:pixelated' image-rendering='optimizeSpeed' "), 1u)
      << "the image is not marked to be drawn with sharp pixels";
  const std::string head = "xlink:href='data:image/png;base64,";
  const std::size_t from = svg.find(head) + head.size();
  ASSERT_NE(from, std::string::npos + head.size());
  const Rgba image = decode_png(base64(svg.substr(from, svg.find('\'', from) - from)));
  ASSERT_EQ(image.width, 4u);
  ASSERT_EQ(image.height, 3u);
  const auto at = [&](int i, int j) { return image.pixel[static_cast<std::size_t>(i) + 4 * static_cast<std::size_t>(2 - j)]; };
  EXPECT_EQ(at(0, 0), (std::array<int, 4>{0x44, 0x01, 0x54, 255})) << "value 0: the palette's first colour";
  EXPECT_EQ(at(3, 2), (std::array<int, 4>{0xfd, 0xe7, 0x25, 255})) << "value 11: the palette's last colour";
  EXPECT_EQ(at(1, 1)[3], 0) << "a NaN value is not blank";
  EXPECT_EQ(at(2, 2)[3], 0) << "a grid position without a cell is not blank";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i)
      if (!(i == 1 && j == 1) && !(i == 2 && j == 2)) {
        EXPECT_EQ(at(i, j)[3], 255) << "cell " << i << ", " << j << " is not opaque";
      }
}

// Without an image, the boxes: the value-0 cell's colour is a filled shape of the SVG.
void expect_boxes(const Plot& plot, const std::string& what) {
  const std::string svg = svg_of(plot);
  EXPECT_EQ(count(svg, "<image"), 0u) << what << ": drawn as an image";
  EXPECT_GE(count(svg, "fill = 'rgb( 68,   1,  84)'"), 1u) << what << ": the value-0 cell is not a filled box";
}

TEST(PlotHeatMap, LogAxesNonUniformCellsASingleRowAndACellTwiceAreBoxes) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  Plot log_x = grid_plot();
  log_x.x_log = true;
  expect_boxes(log_x, "log x axis");
  Plot log_y = grid_plot();
  for (double& y : log_y.heat_map->y_low) y += 2;
  for (double& y : log_y.heat_map->y_high) y += 2;
  log_y.y_log = true;
  log_y.series.clear();
  expect_boxes(log_y, "log y axis");
  Plot wider = grid_plot();
  for (std::size_t k = 0; k < wider.heat_map->x_low.size(); ++k)  // column 3 twice as wide
    if (wider.heat_map->x_low[k] == 13) wider.heat_map->x_high[k] = 15;
  expect_boxes(wider, "non-uniform columns");
  Plot shifted = grid_plot();
  shifted.heat_map->x_low[0] += 1e-3, shifted.heat_map->x_high[0] += 1e-3;  // off the grid by 1e-3 of a cell
  expect_boxes(shifted, "a cell off the grid");
  Plot row = grid_plot();
  for (std::size_t k = 0; k < row.heat_map->y_low.size(); ++k) row.heat_map->y_low[k] = -1, row.heat_map->y_high[k] = 0;
  row.heat_map->x_low.resize(4), row.heat_map->x_high.resize(4), row.heat_map->y_low.resize(4), row.heat_map->y_high.resize(4);
  row.heat_map->value.resize(4);
  expect_boxes(row, "a single row");
  Plot twice = grid_plot();
  twice.heat_map->x_low.push_back(10), twice.heat_map->x_high.push_back(11);
  twice.heat_map->y_low.push_back(-1), twice.heat_map->y_high.push_back(0), twice.heat_map->value.push_back(5);
  expect_boxes(twice, "a cell twice");
}

// Rounding in the edges (a grid's edges computed as from + k · step) still gives the image.
TEST(PlotHeatMap, EdgesWithinRoundingOfAUniformGridAreAnImage) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  Plot plot;
  plot.name = "rounded";
  HeatMap h;
  const int n = 30;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      h.x_low.push_back(0.25 + (i - 0.5) * (3.75 / 99)), h.x_high.push_back(0.25 + (i + 0.5) * (3.75 / 99));
      h.y_low.push_back((j - 0.5) / 99.0), h.y_high.push_back((j + 0.5) / 99.0);
      h.value.push_back(std::sin(i * 0.3) * std::cos(j * 0.2));
    }
  plot.heat_map = h;
  EXPECT_EQ(count(svg_of(plot), "<image "), 1u);
}

}  // namespace
