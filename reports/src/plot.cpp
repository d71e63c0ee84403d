#include "backlash/reports/plot.hpp"

#include <toml++/toml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>
#include <algorithm>
#include <cstdint>

namespace backlash::reports {

namespace {

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += (c == '"' ? std::string("\\\"") : std::string(1, c));
  return out + "\"";
}

}  // namespace

std::optional<std::string> render_svg(const Plot& plot, std::string* why) {
  namespace fs = std::filesystem;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    if (why) *why = "gnuplot is not installed";
    return std::nullopt;
  }
  const fs::path dir = fs::temp_directory_path() / ("backlash-plot-" + std::to_string(::getpid()) + "-" +
                                                      std::to_string(reinterpret_cast<std::uintptr_t>(&plot)));
  fs::create_directories(dir);
  std::ostringstream script;
  script << "set terminal svg size " << plot.width << "," << plot.height << " dynamic enhanced font 'sans,12'\n"
         << "set output " << quoted((dir / "plot.svg").string()) << "\n"
         << "set title " << quoted(plot.title) << " noenhanced\n"
         << "set xlabel " << quoted(plot.x_label) << "\nset ylabel " << quoted(plot.y_label) << "\n"
         << "set grid\nset key outside right top noenhanced\n";
  script << "plot ";
  for (size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    const fs::path data = dir / ("series" + std::to_string(i) + ".dat");
    std::ofstream out(data);
    out.precision(12);
    for (size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) out << s.x[k] << " " << s.y[k] << "\n";
    script << (i ? ", " : "") << quoted(data.string()) << " using 1:2 with " << s.style << " title " << quoted(s.label);
  }
  script << "\n";
  {
    std::ofstream out(dir / "plot.gp");
    out << script.str();
  }
  const int status = std::system(("gnuplot " + quoted((dir / "plot.gp").string()) + " 2> " + quoted((dir / "err.txt").string())).c_str());
  std::optional<std::string> svg;
  if (status == 0) {
    std::ifstream in(dir / "plot.svg");
    std::stringstream buffer;
    buffer << in.rdbuf();
    svg = buffer.str();
  } else if (why) {
    std::ifstream in(dir / "err.txt");
    std::getline(in, *why);
  }
  fs::remove_all(dir);
  return svg;
}

std::string errata_markdown(const std::string& errata_directory) {
  namespace fs = std::filesystem;
  std::ostringstream md;
  md << "# Errata ledger\n\nEvery number printed in the thesis that differs from the exact value beyond its printed "
        "precision, with the exact value and a likely cause.  Source: `reports/errata/*.toml`; each entry is checked "
        "by the test named after its place (tests/symbolic, tests/numeric).\n";
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(errata_directory))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    const toml::table t = toml::parse_file(file.string());
    const toml::array* list = t["erratum"].as_array();
    md << "\n## " << file.filename().string() << " (" << (list ? list->size() : 0) << " entries)\n\n"
       << "| where | case | quantity | printed | exact | likely cause |\n|---|---|---|---|---|---|\n";
    if (!list) continue;
    for (const toml::node& node : *list) {
      const toml::table& e = *node.as_table();
      std::string exact = e["exact"].value_or(std::string());
      const std::string decimal = e["exact_decimal"].value_or(std::string());
      if (exact.empty()) exact = decimal; else if (!decimal.empty()) exact += " = " + decimal;
      std::string cause = e["cause"].value_or(std::string());
      for (char& c : cause) if (c == '|') c = '/';
      md << "| " << e["where"].value_or(std::string()) << " | " << e["case"].value_or(std::string()) << " | "
         << e["quantity"].value_or(std::string()) << " | " << e["printed"].value_or(std::string()) << " | `" << exact << "` | "
         << cause << " |\n";
    }
  }
  return md.str();
}

}  // namespace backlash::reports
