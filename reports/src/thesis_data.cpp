#include "backlash/reports/thesis_data.hpp"

#include "backlash/model/data_dir.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace backlash::reports {

namespace fs = std::filesystem;

DataPaths default_data_paths() {
  const fs::path share = model::data_dir();
  return {share / "errata", share / "data", share / "data" / "thesis_dividing_line_tables.toml"};
}

namespace {

toml::table parse(const fs::path& file) {
  try {
    return toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw std::runtime_error(file.string() + ": " + std::string(e.description()));
  }
}

std::string str(const toml::table& t, const char* key, const fs::path& file, bool required = true) {
  const auto value = t[key].value<std::string>();
  if (!value && required) throw std::runtime_error(file.string() + ": missing string '" + key + "'");
  return value.value_or("");
}

std::vector<std::string> strings(const toml::table& t, const char* key) {
  std::vector<std::string> out;
  if (const toml::array* a = t[key].as_array())
    for (const toml::node& n : *a)
      if (auto s = n.value<std::string>()) out.push_back(*s);
  return out;
}

std::vector<int> integers(const toml::table& t, const char* key) {
  std::vector<int> out;
  if (const toml::array* a = t[key].as_array())
    for (const toml::node& n : *a)
      if (auto v = n.value<int64_t>()) out.push_back(static_cast<int>(*v));
  return out;
}

const toml::array& array_of(const toml::table& t, const char* key, const fs::path& file) {
  const toml::array* a = t[key].as_array();
  if (!a) throw std::runtime_error(file.string() + ": no [[" + std::string(key) + "]] entries");
  return *a;
}

}  // namespace

std::vector<Erratum> load_errata(const fs::path& directory) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<Erratum> out;
  for (const fs::path& file : files) {
    const toml::table t = parse(file);
    const toml::array* list = t["erratum"].as_array();
    if (!list) continue;
    for (const toml::node& node : *list) {
      const toml::table& e = *node.as_table();
      out.push_back({file.filename().string(), str(e, "where", file), str(e, "case", file), str(e, "quantity", file),
                     str(e, "printed", file), str(e, "exact", file, false), str(e, "exact_decimal", file, false),
                     str(e, "cause", file, false)});
    }
  }
  return out;
}

const Erratum* find_erratum(const std::vector<Erratum>& errata, const std::string& where, const std::string& case_id,
                            const std::string& quantity) {
  for (const Erratum& e : errata)
    if (e.where == where && e.case_id == case_id && e.quantity == quantity) return &e;
  return nullptr;
}

std::vector<ThesisCase> load_thesis_cases(const fs::path& file) {
  const toml::table t = parse(file);
  std::vector<ThesisCase> out;
  for (const toml::node& node : array_of(t, "case", file)) {
    const toml::table& c = *node.as_table();
    ThesisCase tc;
    tc.id = str(c, "id", file);
    tc.title = str(c, "title", file);
    tc.summary = str(c, "summary", file);
    tc.limit_cycle_printed = str(c, "limit_cycle_printed", file);
    tc.section = static_cast<int>(c["section"].value<int64_t>().value_or(0));
    tc.equations = integers(c, "equations");
    tc.tables = integers(c, "tables");
    tc.figures = integers(c, "figures");
    if (const toml::table* slots = c["slots"].as_table())
      for (const auto& [key, value] : *slots)
        if (auto s = value.value<std::string>()) tc.slots[std::string(key.str())] = *s;
    if (const toml::array* list = c["trajectory"].as_array())
      for (const toml::node& n : *list) {
        const toml::table& tr = *n.as_table();
        tc.trajectories.push_back({str(tr, "kind", file), str(tr, "step", file, false), str(tr, "theta_o", file, false),
                                   str(tr, "dtheta_o", file, false), str(tr, "quote", file, false)});
      }
    out.push_back(std::move(tc));
  }
  return out;
}

std::vector<FigureSpec> load_figures(const fs::path& file) {
  const toml::table t = parse(file);
  std::vector<FigureSpec> out;
  for (const toml::node& node : array_of(t, "figure", file)) {
    const toml::table& f = *node.as_table();
    FigureSpec spec;
    spec.number = static_cast<int>(f["number"].value<int64_t>().value_or(0));
    spec.kind = str(f, "kind", file);
    spec.case_id = str(f, "case", file, false);
    spec.dtheta_m0 = str(f, "dtheta_m0", file, false);
    spec.t_end = str(f, "t_end", file, false);
    spec.sweep = str(f, "sweep", file, false);
    spec.what = str(f, "what", file, false);
    spec.dividers = strings(f, "dividers");
    spec.trajectories = strings(f, "trajectories");
    out.push_back(std::move(spec));
  }
  return out;
}

std::vector<StepPoint> load_step_points(const fs::path& file) {
  const toml::table t = parse(file);
  std::vector<StepPoint> out;
  for (const toml::node& node : array_of(t, "point", file)) {
    const toml::table& p = *node.as_table();
    const std::string table = str(p, "table", file), case_id = str(p, "case", file), step = str(p, "step", file);
    if (const toml::array* rows = p["rows"].as_array())
      for (const toml::node& r : *rows) {
        const toml::array* row = r.as_array();
        if (!row || row->size() != 3) throw std::runtime_error(file.string() + ": a row must be [t, quantity, printed]");
        out.push_back({table, case_id, step, (*row)[0].value_or(std::string()), (*row)[1].value_or(std::string()),
                       (*row)[2].value_or(std::string())});
      }
  }
  return out;
}

std::vector<DividingLineCell> load_dividing_line_cells(const fs::path& file) {
  const toml::table t = parse(file);
  std::vector<DividingLineCell> out;
  for (const toml::node& node : array_of(t, "cell", file)) {
    const toml::table& c = *node.as_table();
    out.push_back({str(c, "table", file), str(c, "case", file), str(c, "v0", file), str(c, "quantity", file),
                   str(c, "printed", file)});
  }
  return out;
}

double printed_number(const std::string& text) {
  std::string t;
  for (char c : text)
    if (c != ' ') t += c;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size()) throw std::runtime_error("not a printed number: '" + text + "'");
  return v;
}

int printed_decimals(const std::string& text) {
  const auto dot = text.find('.');
  if (dot == std::string::npos) return 0;
  int digits = 0;
  for (std::size_t i = dot + 1; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i) ++digits;
  return digits;
}

bool agrees_with_printed(double value, const std::string& printed) {
  const double p = printed_number(printed);
  const double half_unit = 0.5 * std::pow(10.0, -printed_decimals(printed));
  return std::fabs(value - p) <= half_unit * (1 + 1e-9);
}

}  // namespace backlash::reports
