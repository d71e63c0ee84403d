#include "backlash/reports/plot.hpp"

#include "backlash/output/text.hpp"
#include "backlash/symbolic/escape.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include <stdlib.h>  // mkdtemp (POSIX)

namespace backlash::reports {

namespace {

// A gnuplot single-quoted string ('' for a quote; no other escapes exist there).  Spaces
// become no-break spaces: gnuplot's SVG splits enhanced text into <tspan>s and some
// renderers drop a tspan's leading space ("θ_{o} vs" would read "θovs").
std::string quoted(const std::string& text, bool keep_spaces = false) {
  std::string out = "'";
  for (char c : symbolic::escape::valid_utf8(text)) {
    if (c == '\'') out += "''";
    else if (c == ' ' && !keep_spaces) out += "\xC2\xA0";
    else if (static_cast<unsigned char>(c) < 0x20) out += ' ';
    else out += c;
  }
  return out + "'";
}

// "%.10g" (output::printf_g: printf's bytes without printf's cost — a map's figures write
// tens of thousands of numbers).
std::string number(double v) { return output::printf_g(v, 10); }

// cairo stamps its PDFs with the time of day: overwrite the digits in place (same length,
// so the cross-reference offsets stay valid) with the epoch, for byte-reproducible files.
void fix_pdf_dates(const std::filesystem::path& file) {
  std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
  if (!io) return;
  std::string bytes((std::istreambuf_iterator<char>(io)), std::istreambuf_iterator<char>());
  bool changed = false;
  for (const std::string key : {"/CreationDate (D:", "/ModDate (D:"}) {
    for (std::size_t at = bytes.find(key); at != std::string::npos; at = bytes.find(key, at + 1)) {
      const std::size_t digits = at + key.size();
      std::size_t n = 0;
      while (digits + n < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[digits + n])) && n < 14) ++n;
      const std::string epoch = std::string("19700101000000").substr(0, n);
      bytes.replace(digits, n, epoch);
      changed = true;
    }
  }
  if (!changed) return;
  io.seekp(0);
  io.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// True where `from` was found in `bytes` (every occurrence then replaced by `to`).
bool replace_all(std::string& bytes, const std::string& from, const std::string& to) {
  std::string edited;
  std::size_t start = 0;
  for (std::size_t at = bytes.find(from); at != std::string::npos; at = bytes.find(from, start)) {
    if (edited.empty()) edited.reserve(bytes.size() + bytes.size() / 16);
    edited.append(bytes, start, at - start).append(to);
    start = at + from.size();
  }
  if (start == 0) return false;
  edited.append(bytes, start, std::string::npos);
  bytes = std::move(edited);
  return true;
}

// Two edits of gnuplot's SVG, in one read and one write.
// (1) gnuplot splits enhanced text into <tspan>s ("θ_{m} and" gives "θ", "m", " and"), and
// librsvg (and other SVG renderers) collapse the space that starts a tspan, even a
// no-break space, unless the text element preserves white space: "θmand".  Every
// <text> gets xml:space="preserve" (gnuplot writes no white space between the tspans).
// (2) A heat map drawn as an image (one PNG pixel per cell) is scaled up by the viewer,
// which blurs it unless told to keep the pixels sharp: every <image> gets image-rendering
// (CSS `pixelated` in the style, the SVG 1.1 `optimizeSpeed` as attribute for viewers that
// know only that; librsvg 2.54 ignores both and smooths).
void edit_svg(const std::filesystem::path& file) {
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) return;
    std::ostringstream all;  // in one read, not a character at a time (a map's SVG can be a megabyte)
    all << in.rdbuf();
    bytes = std::move(all).str();
  }
  const bool text = replace_all(bytes, "<text>", "<text xml:space=\"preserve\">");
  const bool image = replace_all(bytes, "<image ", "<image style='image-rendering:pixelated' image-rendering='optimizeSpeed' ");
  if (!text && !image) return;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// "%.6g": the value written at a bar's end.
std::string short_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

}  // namespace

std::string literal(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::string("_^{}@&~\\").find(c) != std::string::npos) out += '\\';
    out += c;
  }
  return out;
}

bool has_data(const Plot& plot) {
  if (plot.series.empty()) return false;
  for (const Series& s : plot.series) {
    bool finite = false;
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) finite = finite || (std::isfinite(s.x[k]) && std::isfinite(s.y[k]));
    if (!finite) return false;
  }
  return true;
}

std::string figure_csv(const Plot& plot) {
  std::ostringstream out;
  out << "series,x,y\n";
  for (const Series& s : plot.series)
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k)
      if (std::isfinite(s.x[k]) && std::isfinite(s.y[k]))
        out << symbolic::escape::csv_field(s.label) << "," << number(s.x[k]) << "," << number(s.y[k]) << "\n";
  return out.str();
}

namespace {

// The inline data blocks of figure f: $d<f>_<i> per series (a blank line where a point is
// not finite: a break in the line), $b<f> for the bars; $h<f> (the heat map) below.
// number(v) for values seen before, by their bits: a direct-mapped table of texts (a heat map
// writes each grid edge and centre once per cell).  A number's text depends on its bits alone.
class NumberTexts {
 public:
  const std::string& of(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    Slot& s = slots_[(bits * 0x9e3779b97f4a7c15ULL) >> 54];  // 1024 slots
    if (!s.used || s.bits != bits) s.text = number(v), s.bits = bits, s.used = true;
    return s.text;
  }

 private:
  struct Slot {
    std::uint64_t bits = 0;
    bool used = false;
    std::string text;
  };
  std::vector<Slot> slots_ = std::vector<Slot>(1024);
};

void write_data_blocks(std::ostringstream& script, const Plot& plot, std::size_t f) {
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    script << "$d" << f << "_" << i << " << EOD\n";
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) script << "\n";
      else script << number(s.x[k]) << " " << number(s.y[k]) << "\n";
    }
    script << "EOD\n";
  }
  if (plot.bars && !plot.bars->values.empty()) {  // $b<f>: value row 0 value row-0.35 row+0.35 (a NaN: an empty bar)
    script << "$b" << f << " << EOD\n";
    for (std::size_t k = 0; k < plot.bars->values.size(); ++k) {
      const double v = std::isfinite(plot.bars->values[k]) ? plot.bars->values[k] : 0.0, row = static_cast<double>(k);
      script << number(v) << " " << number(row) << " 0 " << number(v) << " " << number(row - 0.35) << " " << number(row + 0.35) << "\n";
    }
    script << "EOD\n";
  }
}

// The heat map's cells as an image (HeatMap's rule in plot.hpp): the pixel of each cell in
// gnuplot's scan order (x fastest, rows upwards), NaN where the grid has no cell or its value
// is NaN (gnuplot leaves a NaN pixel transparent: blank, as a cell without a box).
struct HeatImage {
  std::size_t nx = 0, ny = 0;
  double x0 = 0, dx = 0, y0 = 0, dy = 0;
  std::vector<double> pixel;
};

// The column of each cell [low, high] on a uniform grid of at least 2 columns from min(low)
// to max(high), within rounding (1e-6 of a column); the number of columns; nothing if the
// cells do not form one.
struct UniformColumns {
  std::vector<std::size_t> column;  // of each cell
  std::size_t count = 0;
  double from = 0, step = 0;  // the grid's first edge and its column width
};
std::optional<UniformColumns> uniform_columns(const std::vector<double>& low, const std::vector<double>& high) {
  if (low.empty()) return std::nullopt;
  const double from = *std::min_element(low.begin(), low.end()), to = *std::max_element(high.begin(), high.end());
  const double width = high[0] - low[0], columns = std::round((to - from) / width);
  if (!std::isfinite(from) || !std::isfinite(to) || !(width > 0) || !(columns >= 2 && columns <= 1e6)) return std::nullopt;
  const double step = (to - from) / columns, tolerance = 1e-6 * step;
  std::vector<std::size_t> column(low.size());
  for (std::size_t k = 0; k < low.size(); ++k) {
    const double i = std::round((low[k] - from) / step);
    if (!(std::abs(low[k] - (from + i * step)) <= tolerance && std::abs(high[k] - (from + (i + 1) * step)) <= tolerance) ||
        !(i >= 0 && i < columns))
      return std::nullopt;
    column[k] = static_cast<std::size_t>(i);
  }
  return UniformColumns{std::move(column), static_cast<std::size_t>(columns), from, step};
}

std::optional<HeatImage> heat_image(const Plot& plot) {
  if (!plot.heat_map || plot.x_log || plot.y_log) return std::nullopt;  // gnuplot draws images linearly only
  const HeatMap& h = *plot.heat_map;
  std::vector<double> x_low, x_high, y_low, y_high, value;  // the cells with a value
  for (std::size_t k = 0; k < h.value.size() && k < h.x_low.size() && k < h.x_high.size() && k < h.y_low.size() && k < h.y_high.size(); ++k)
    if (std::isfinite(h.value[k])) {
      x_low.push_back(h.x_low[k]), x_high.push_back(h.x_high[k]), y_low.push_back(h.y_low[k]), y_high.push_back(h.y_high[k]);
      value.push_back(h.value[k]);
    }
  const auto columns = uniform_columns(x_low, x_high), rows = uniform_columns(y_low, y_high);
  if (!columns || !rows || columns->count * rows->count > 4 * value.size()) return std::nullopt;  // at most 4 pixels per cell
  HeatImage image;
  image.nx = columns->count, image.ny = rows->count;
  image.x0 = columns->from, image.dx = columns->step;
  image.y0 = rows->from, image.dy = rows->step;
  image.pixel.assign(image.nx * image.ny, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k < value.size(); ++k) {
    double& pixel = image.pixel[columns->column[k] + image.nx * rows->column[k]];
    if (!std::isnan(pixel)) return std::nullopt;  // a cell twice
    pixel = value[k];
  }
  return image;
}

// $h<f>: the heat map, as an image (x y value per pixel, NaN for a blank one) or as cells
// (x y xlow xhigh ylow yhigh value; the cells with a value).  Returns true for an image.
bool write_heat_map_block(std::ostringstream& script, const Plot& plot, std::size_t f) {
  if (!plot.heat_map) return false;
  const HeatMap& h = *plot.heat_map;
  NumberTexts texts;  // a grid's cells repeat their edges and centres
  const auto number = [&texts](double v) -> const std::string& { return texts.of(v); };
  script << "$h" << f << " << EOD\n";
  const std::optional<HeatImage> image = heat_image(plot);
  if (image) {
    for (std::size_t j = 0; j < image->ny; ++j) {
      const std::string y = number(image->y0 + (static_cast<double>(j) + 0.5) * image->dy);
      for (std::size_t i = 0; i < image->nx; ++i) {
        const double v = image->pixel[i + image->nx * j];
        script << number(image->x0 + (static_cast<double>(i) + 0.5) * image->dx) << " " << y << " ";
        if (std::isnan(v)) script << "NaN\n";
        else script << number(v) << "\n";
      }
    }
  }
  for (std::size_t k = 0; !image && k < h.value.size() && k < h.x_low.size() && k < h.x_high.size() && k < h.y_low.size() && k < h.y_high.size(); ++k) {
    if (!std::isfinite(h.value[k])) continue;
    const double xc = plot.x_log ? std::sqrt(h.x_low[k] * h.x_high[k]) : (h.x_low[k] + h.x_high[k]) / 2;
    const double yc = plot.y_log ? std::sqrt(h.y_low[k] * h.y_high[k]) : (h.y_low[k] + h.y_high[k]) / 2;
    script << number(xc) << " " << number(yc) << " " << number(h.x_low[k]) << " " << number(h.x_high[k]) << " "
           << number(h.y_low[k]) << " " << number(h.y_high[k]) << " " << number(h.value[k]) << "\n";
  }
  script << "EOD\n";
  return image.has_value();
}

// The settings a heat map and log axes add (none for a plain plot: its script is unchanged).
void write_heat_map_settings(std::ostringstream& body, const Plot& plot) {
  if (plot.x_log) body << "set logscale x\n";
  if (plot.y_log) body << "set logscale y\n";
  if (!plot.heat_map) return;
  // a perceptually uniform palette (viridis's end and middle colours), readable in grey
  body << "set palette defined (0 '#440154', 1 '#3b528b', 2 '#21918c', 3 '#5ec962', 4 '#fde725')\n"
       << "set cblabel " << quoted(plot.heat_map->colour_label) << "\nset colorbox\n";
  if (const auto& r = plot.heat_map->value_range) body << "set cbrange [" << number(r->first) << ":" << number(r->second) << "]\n";
}

// The settings shades and bars add (none without them: the script of a plain plot is unchanged).
void write_shade_and_bar_settings(std::ostringstream& body, const Plot& plot) {
  for (std::size_t k = 0; k < plot.shades.size(); ++k) {
    const Shade& s = plot.shades[k];
    body << "set object " << (k + 1) << " rect from " << number(s.x_low) << ", graph 0 to " << number(s.x_high)
         << ", graph 1 behind fc rgb " << quoted(s.colour, true) << " fs transparent solid " << number(s.opacity) << " noborder\n";
  }
  if (!plot.bars) return;
  const Bars& b = *plot.bars;
  if (b.values.empty()) {
    body << "unset ytics\nset yrange [0.6:-0.6]\n";
    return;
  }
  body << "set ytics (";
  for (std::size_t k = 0; k < b.names.size(); ++k) body << (k ? ", " : "") << quoted(literal(b.names[k])) << " " << k;
  body << ")\nset grid noytics\n";
  if (!plot.x_range) body << "set xrange [0:*]\n";
  if (!plot.y_range) body << "set yrange [" << number(static_cast<double>(b.values.size()) - 0.4) << ":-0.6]\n";
  for (std::size_t k = 0; k < b.values.size(); ++k) {
    const double v = b.values[k];
    body << "set label " << (plot.labels.size() + k + 1) << " " << quoted(std::isfinite(v) ? short_number(v) : "failed")
         << " at " << number(std::isfinite(v) ? v : 0.0) << "," << k << " offset 0.6,0 font ',10'\n";
  }
}

// The gnuplot commands that draw figure f (the same for the SVG and the PDF).
std::string figure_body(const Plot& plot, std::size_t f, bool heat_image) {
  std::ostringstream body;
  body << "reset\nset encoding utf8\n"
       << "set title " << quoted(plot.title) << "\n"
       << "set xlabel " << quoted(plot.x_label) << "\nset ylabel " << quoted(plot.y_label) << "\n"
       << "set grid lc rgb '#dddddd'\nset key " << plot.key << " spacing 1.1\n"
       << "set border lw 1\nset tics nomirror\nset xtics mirror\nset ytics mirror\n";
  write_heat_map_settings(body, plot);
  write_shade_and_bar_settings(body, plot);
  if (plot.x_range) body << "set xrange [" << number(plot.x_range->first) << ":" << number(plot.x_range->second) << "]\n";
  if (plot.y_range) body << "set yrange [" << number(plot.y_range->first) << ":" << number(plot.y_range->second) << "]\n";
  for (std::size_t l = 0; l < plot.labels.size(); ++l)
    body << "set label " << (l + 1) << " " << quoted(plot.labels[l].text) << " at " << number(plot.labels[l].x) << ","
         << number(plot.labels[l].y) << " font ',9' tc rgb '#555555'\n";
  body << "plot ";
  if (plot.heat_map && heat_image) body << "$h" << f << " using 1:2:3 with image notitle";
  else if (plot.heat_map) body << "$h" << f << " using 1:2:3:4:5:6:7 with boxxyerror fs solid 1.0 noborder lc palette notitle";
  if (plot.heat_map) body << (plot.series.empty() && !(plot.bars && !plot.bars->values.empty()) ? "" : ", \\\n     ");
  if (plot.bars && !plot.bars->values.empty())
    body << "$b" << f << " using 1:2:3:4:5:6 with boxxyerror fs solid 1.0 noborder lc rgb " << quoted(plot.bars->colour, true)
         << " notitle" << (plot.series.empty() ? "" : ", \\\n     ");
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    body << (i ? ", \\\n     " : "") << "$d" << f << "_" << i << " using 1:2 with " << s.style
         << (s.in_key ? " title " + quoted(s.label) : std::string(" notitle"));
  }
  body << "\n";
  return body.str();
}

// Runs gnuplot once in `directory` on every plot: figures/NAME.svg, and with `pdf`
// figures/NAME.pdf (date-fixed).  The script and gnuplot's log are removed.
std::optional<std::string> run_gnuplot(const std::vector<Plot>& plots, const std::filesystem::path& directory, bool pdf) {
  namespace fs = std::filesystem;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) return std::string("gnuplot is not installed");
  std::ostringstream script;
  script << "set encoding utf8\n";
  for (std::size_t f = 0; f < plots.size(); ++f) {
    const Plot& plot = plots[f];
    write_data_blocks(script, plot, f);
    const bool heat_image = write_heat_map_block(script, plot, f);
    const std::string body = figure_body(plot, f, heat_image);
    const fs::path stem = fs::path("figures") / plot.name;
    script << "set terminal svg size " << plot.width << "," << plot.height << " enhanced font 'DejaVu Sans,12' background '#ffffff'\n"
           << "set output " << quoted(stem.string() + ".svg", true) << "\n"
           << body << "set output\n";
    if (!pdf) continue;
    script << "set terminal pdfcairo size " << number(plot.width / 130.0) << "in," << number(plot.height / 130.0)
           << "in enhanced font 'DejaVu Sans,8.5' background '#ffffff'\n"
           << "set output " << quoted(stem.string() + ".pdf", true) << "\n"
           << body << "set output\n";
  }
  const fs::path script_file = directory / "figures.gp";
  {
    std::ofstream out(script_file, std::ios::binary);
    out << script.str();
    if (!out) return std::string("cannot write the gnuplot script");
  }
  fs::create_directories(directory / "figures");
  const fs::path log = directory / "figures.log";
  const std::string command = "cd " + output::shell_word(directory.string()) + " && gnuplot figures.gp > figures.log 2>&1";
  const int status = std::system(command.c_str());
  std::optional<std::string> failure;
  if (status != 0) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line))
      if (!line.empty()) last = line;
    failure = "gnuplot failed: " + last;
  }
  std::error_code ignored;
  fs::remove(script_file, ignored);
  fs::remove(log, ignored);
  if (!failure)
    for (const Plot& plot : plots) {
      if (pdf) fix_pdf_dates(directory / "figures" / (plot.name + ".pdf"));
      edit_svg(directory / "figures" / (plot.name + ".svg"));
    }
  return failure;
}

}  // namespace

std::optional<std::string> render_figures(const std::vector<Plot>& plots, const std::filesystem::path& directory) {
  return run_gnuplot(plots, directory, true);
}

std::optional<std::string> render_svgs(const std::vector<Plot>& plots, std::vector<std::string>& svgs) {
  namespace fs = std::filesystem;
  svgs.clear();
  std::error_code error;
  const fs::path temp = fs::temp_directory_path(error);
  if (error) return "no temporary folder: " + error.message();
  std::string folder = (temp / "backlash-plot-XXXXXX").string();
  if (mkdtemp(folder.data()) == nullptr) return "cannot make a temporary folder in " + temp.string();
  std::optional<std::string> failure = run_gnuplot(plots, folder, false);
  for (std::size_t f = 0; !failure && f < plots.size(); ++f) {
    std::ifstream in(fs::path(folder) / "figures" / (plots[f].name + ".svg"), std::ios::binary);
    if (!in) failure = "gnuplot drew no " + plots[f].name + ".svg";
    else svgs.emplace_back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  fs::remove_all(folder, error);
  if (failure) svgs.clear();
  return failure;
}

}  // namespace backlash::reports
