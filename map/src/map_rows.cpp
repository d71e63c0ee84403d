// map_rows.cpp — a map's rows: computed in order (run_map), written as CSV, and the
// cycle/no-cycle boundary solved along grid lines (map/map.hpp).
#include "backlash/map/map.hpp"
#include "backlash/numeric/varied_parameter.hpp"

#include "map_output.hpp"

#include "backlash/numeric/validated_family.hpp"

#include <boost/math/tools/roots.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace backlash::map {

namespace {

// The shortest text that reads back to the same double; empty for NaN (a cell the row lacks).
void append_number(std::string& out, double value) {
  if (std::isnan(value)) return;
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  out.append(text, result.ptr);
}

// The texts of a row's numbers, column by column, kept on this thread by their bits (a small
// direct-mapped table per column): a map's rows repeat most of their columns (the fixed
// parameters and effects, the slower axes), and the fast axis's columns cycle through the same
// few values row after row; a number's text depends on its bits alone — a kept text is the one
// append_number writes.
class ColumnTexts {
 public:
  void append(std::string& out, std::size_t column, double value) {
    if (column >= kept_.size()) kept_.resize(column + 1);
    std::vector<Kept>& table = kept_[column];
    if (table.empty()) table.resize(kSlots);
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    Kept& k = table[(bits * 0x9E3779B97F4A7C15ULL) >> (64 - kSlotBits)];
    if (!k.valid || k.bits != bits) k.text.clear(), append_number(k.text, value), k.bits = bits, k.valid = true;
    out += k.text;
  }

 private:
  static constexpr int kSlotBits = 8;
  static constexpr std::size_t kSlots = std::size_t{1} << kSlotBits;
  struct Kept {
    std::uint64_t bits = 0;
    bool valid = false;
    std::string text;  ///< append_number's (short: within the small-string buffer)
  };
  std::vector<std::vector<Kept>> kept_;
};

void append_quoted(std::string& out, const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) {
    out += text;
    return;
  }
  out += '"';
  for (const char c : text) {
    if (c == '"') out += '"';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  out += '"';
}

std::string parameter_columns() {
  std::string columns;
  for (const std::string& name : numeric::point_column_names()) columns += (columns.empty() ? "" : ",") + name;
  return columns;
}

}  // namespace

std::string map_csv_header(const MapPlan& plan) {
  std::string out = "index";
  for (const MapAxis& a : plan.request().vary) out += ",x_" + a.name;
  out += ",";
  out += parameter_columns();
  out += ",status,reason,branches,peak_to_peak,amplitude,period,separation_velocity,multiplier,settle_time,settle_status\n";
  return out;
}

std::string map_csv_row(const MapRow& r) {
  thread_local ColumnTexts texts;
  std::size_t column = 0;
  std::string out;
  out.reserve(400);  // one allocation a row: the pieces below are appended, never concatenated
  out += std::to_string(r.index);
  for (const double x : r.x) out += ',', texts.append(out, column++, x);
  const numeric::Parameters& p = r.row.point.parameters;
  const numeric::Effects& e = r.row.point.effects;
  for (const double v : numeric::point_column_values(p, e)) out += ',', texts.append(out, column++, v);
  const std::string status = api::status_of(r.row);
  const bool cycle = status == "limit_cycle";
  out += ',', out += status, out += ',';
  append_quoted(out, r.row.reason);
  out += ',', out += r.row.branches;
  const numeric::LimitCycle& c = r.row.cycle;
  for (const double v : {c.peak_to_peak, c.amplitude, c.period, c.separation_velocity, c.multiplier})
    out += ',', append_number(out, cycle ? v : NAN);
  const bool computed = status == "limit_cycle" || status == "none" || status == "divergent" || status == "unresolved";
  out += ',', append_number(out, computed ? r.row.settle.time : NAN);
  out += ',';
  if (computed) out += r.row.settle.status;
  out += '\n';
  return out;
}

std::string map_boundary_csv_header(const MapPlan& plan) {
  std::string out = "along,lower,upper,kind";
  for (const MapAxis& a : plan.request().vary) out += ",x_" + a.name;
  return out + ",bracket_low,bracket_high,evaluations\n";
}

std::string map_boundary_csv_row(const MapBoundaryRow& b) {
  std::string out = std::to_string(b.along) + "," + std::to_string(b.lower) + "," + std::to_string(b.upper) + "," + b.kind;
  for (const double x : b.x) out += ',', append_number(out, x);
  out += ',', append_number(out, b.low);
  out += ',', append_number(out, b.high);
  return out + "," + std::to_string(b.evaluations) + "\n";
}

numeric::SweepOptions detail::sweep_options(const MapPlan& plan) {
  numeric::SweepOptions o;
  o.threads = plan.request().threads;
  o.block = plan.request().block;
  o.settle.step = plan.step();
  o.settle.t_end = plan.t_end();
  return o;
}

void run_map(const MapRequest& request, const std::function<void(const MapRow&)>& sink) {
  const MapPlan plan(request);
  const auto point = [&plan](long i) { return plan.point(i); };
  const numeric::SweepOptions options = detail::sweep_options(plan);
  long index = 0;
  numeric::run_sweep_streamed(plan.count(), point, options, [&](const numeric::SweepRow& row) {
    sink(MapRow{index, plan.values(index), row});
    ++index;
  });
}

MapBoundaryRow solve_boundary(const MapPlan& plan, int along, long lower, long upper, bool cycle_at_lower,
                              std::shared_ptr<const numeric::ValidatedParametricFamily> family) {
  MapBoundaryRow b;
  b.along = along, b.lower = lower, b.upper = upper;
  b.kind = cycle_at_lower ? "dies" : "appears";
  b.x = plan.values(lower);
  const auto k = static_cast<std::size_t>(along);
  // s(t): one cold point at t on the line, the sweep's own row (numeric/sweep.hpp).
  numeric::SweepOptions options = detail::sweep_options(plan);
  options.threads = 1;
  options.settle.step = 0;
  options.family = std::move(family);
  auto s = [&](double t) {
    const numeric::SweepPoint point = plan.point_at(lower, along, t);
    ++b.evaluations;
    std::string status;
    numeric::run_sweep_streamed(1, [&](long) { return point; }, options,
                                [&](const numeric::SweepRow& row) { status = api::status_of(row); });
    return status == "limit_cycle" ? -1.0 : 1.0;
  };
  double a = b.x[k], c = plan.values(upper)[k];
  if (a > c) std::swap(a, c);
  const double fa = s(a), fc = s(c);
  b.low = a, b.high = c;
  if (fa == fc) {  // cold searches agree at both ends: the grid's verdict was a warm start's
    b.kind += " (unresolved)";
  } else {
    std::uintmax_t iterations = 200;
    const auto root = boost::math::tools::bisect(s, a, c, boost::math::tools::eps_tolerance<double>(40), iterations);
    b.low = root.first, b.high = root.second;
  }
  b.x[k] = 0.5 * (b.low + b.high);
  return b;
}

}  // namespace backlash::map
