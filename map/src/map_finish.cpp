// map_finish.cpp — the end of `backlash map --out DIR`: map.h5, the figures and the statuses
// from points.bin in one pass, the cycle/no-cycle boundary solved over every rank and thread,
// boundary.csv, map.json, and the partial folder committed into place (output::StagedDirectory,
// map/map.hpp).
#include "map_output.hpp"
#include "map_store.hpp"

#include "backlash/numeric/validated_family.hpp"

#include "backlash/map/figures.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <cstring>
#include <fstream>
#include <optional>
#include <thread>

namespace backlash::map::detail {

namespace fs = std::filesystem;

namespace {

// The one place the map meets its figures (map/figures.hpp).
class Figures {
 public:
  Figures(const MapPlan& plan, bool wanted) {
    if (!wanted) return;
    std::vector<figures::MapAxis> axes;
    for (const MapAxis& a : plan.request().vary)
      axes.push_back({a.name, a.from, a.to, plan.request().sample == "grid" ? static_cast<int>(a.count) : 40, false});
    try {
      figures_.emplace(plan.source().id(), axes, plan.request().sample);
    } catch (const std::exception& e) {  // axes it cannot bin (e.g. from = to when sampled): no figures, the rest written
      note_ = std::string("figures not drawn: ") + e.what();
    }
  }
  void add(const MapRecord& r, std::size_t d) {
    if (!figures_) return;
    figures::MapPoint p;
    p.index = r.index;
    p.x.assign(r.values.begin(), r.values.begin() + static_cast<long>(d));
    p.status = map_status_names()[static_cast<std::size_t>(r.status)];
    const std::size_t results = d + MapRecord::kParameters;  // peak_to_peak, amplitude, period, ...
    p.peak_to_peak = r.values[results], p.period = r.values[results + 2], p.multiplier = r.values[results + 4];
    p.settle_time = r.values[d + 20];
    figures_->add(p);
  }
  void add_boundary(const MapBoundaryRow& b) {
    if (figures_) figures_->add_boundary({b.x, b.along});
  }
  std::string write(const fs::path& folder) const { return figures_ ? figures_->write(folder) : note_; }

 private:
  std::optional<figures::MapFigures> figures_;
  std::string note_;
};

struct Crossing {
  std::int64_t along = 0, lower = 0, upper = 0, cycle_at_lower = 0;
};

// Rank 0: one pass over points.bin; returns the grid's crossings (consecutive points along an
// axis, one with a limit cycle, the other "none").
std::vector<Crossing> read_points(const MapPlan& plan, const fs::path& staging, MapHdf5* h5, Figures& figures,
                                  bool boundary, long& survey_fallbacks) {
  const std::size_t d = plan.request().vary.size(), size = MapRecord::size(d);
  std::vector<std::int8_t> status;
  if (boundary) status.resize(static_cast<std::size_t>(plan.count()));
  std::ifstream in(staging / "points.bin", std::ios::binary);
  std::vector<char> buffer(size * 4096);
  for (long at = 0; at < plan.count();) {
    const long n = std::min<long>(4096, plan.count() - at);
    if (!in.read(buffer.data(), static_cast<std::streamsize>(size) * n))
      throw std::runtime_error("the partial map " + staging.string() + " is shorter than its checkpoint");
    for (long k = 0; k < n; ++k, ++at) {
      const MapRecord r = read_record(buffer.data() + size * static_cast<std::size_t>(k), d);
      if (h5) h5->add(r);
      figures.add(r, d);
      survey_fallbacks += r.survey_fallback ? 1 : 0;
      if (boundary) status[static_cast<std::size_t>(at)] = static_cast<std::int8_t>(r.status);
    }
  }
  std::vector<Crossing> crossings;
  if (!boundary) return crossings;
  for (int a = 0; a < static_cast<int>(d); ++a) {
    const long stride = plan.stride(a), n = plan.request().vary[static_cast<std::size_t>(a)].count;
    for (long i = 0; i < plan.count(); ++i) {
      if (plan.grid_index(i, a) + 1 >= n) continue;
      const int s = status[static_cast<std::size_t>(i)], u = status[static_cast<std::size_t>(i + stride)];
      if (s != u && s <= 1 && u <= 1) crossings.push_back({a, i, i + stride, s == 0 ? 1 : 0});
    }
  }
  return crossings;
}

std::string encode_boundary(const MapBoundaryRow& b) {
  std::string out;
  const std::int64_t head[5] = {b.along, b.lower, b.upper, b.evaluations, static_cast<std::int64_t>(b.kind.size())};
  out.append(reinterpret_cast<const char*>(head), sizeof head);
  out += b.kind;
  const std::int64_t n = static_cast<std::int64_t>(b.x.size());
  out.append(reinterpret_cast<const char*>(&n), 8);
  out.append(reinterpret_cast<const char*>(b.x.data()), 8 * b.x.size());
  const double bracket[2] = {b.low, b.high};
  out.append(reinterpret_cast<const char*>(bracket), sizeof bracket);
  return out;
}

MapBoundaryRow decode_boundary(const std::string& s, std::size_t& at) {
  MapBoundaryRow b;
  std::int64_t head[5], n = 0;
  std::memcpy(head, s.data() + at, sizeof head), at += sizeof head;
  b.along = static_cast<int>(head[0]), b.lower = head[1], b.upper = head[2], b.evaluations = static_cast<int>(head[3]);
  b.kind = s.substr(at, static_cast<std::size_t>(head[4])), at += static_cast<std::size_t>(head[4]);
  std::memcpy(&n, s.data() + at, 8), at += 8;
  b.x.resize(static_cast<std::size_t>(n));
  std::memcpy(b.x.data(), s.data() + at, 8 * b.x.size()), at += 8 * b.x.size();
  std::memcpy(&b.low, s.data() + at, 8), std::memcpy(&b.high, s.data() + at + 8, 8), at += 16;
  return b;
}

// Every rank solves a contiguous share of the crossings on its threads; rank 0 gets them all, in
// order.  `interrupted` is polled before each crossing: a stop on any rank throws Interrupted at
// rank 0 (the other ranks return what they have; rank 0 writes nothing more).
std::vector<MapBoundaryRow> solve_all(const MapPlan& plan, std::vector<Crossing> crossings, MapTransport* t,
                                      const std::shared_ptr<const numeric::ValidatedParametricFamily>& family,
                                      const std::function<bool()>& interrupted) {
  if (t && t->size() > 1) {
    std::string list(reinterpret_cast<const char*>(crossings.data()), crossings.size() * sizeof(Crossing));
    t->broadcast(list);
    crossings.resize(list.size() / sizeof(Crossing));
    if (!list.empty()) std::memcpy(crossings.data(), list.data(), list.size());  // no crossing: data() may be null
  }
  const long ranks = t ? t->size() : 1, rank = t ? t->rank() : 0, n = static_cast<long>(crossings.size());
  const long begin = n * rank / ranks, end = n * (rank + 1) / ranks;
  std::vector<MapBoundaryRow> mine(static_cast<std::size_t>(end - begin));
  std::atomic<long> next{begin};
  std::atomic<bool> stopped{false};
  std::vector<std::thread> pool;
  for (int k = 0; k < plan.request().threads; ++k)
    pool.emplace_back([&] {
      for (long i; !stopped && (i = next++) < end;) {
        if (interrupted && interrupted()) stopped = true;
        if (stopped) break;
        const Crossing& c = crossings[static_cast<std::size_t>(i)];
        mine[static_cast<std::size_t>(i - begin)] =
            solve_boundary(plan, static_cast<int>(c.along), c.lower, c.upper, c.cycle_at_lower != 0, family);
      }
    });
  for (std::thread& thread : pool) thread.join();
  if (!t || t->size() == 1) {
    if (stopped) throw Interrupted{};
    return mine;
  }
  std::string piece(1, stopped ? 'S' : 'G');
  for (const MapBoundaryRow& b : mine) piece += encode_boundary(b);
  std::vector<MapBoundaryRow> all;
  for (const std::string& p : t->gather(piece)) {
    if (p.front() == 'S') throw Interrupted{};
    for (std::size_t at = 1; at < p.size();) all.push_back(decode_boundary(p, at));
  }
  return all;
}

std::string map_json(const MapPlan& plan, const MapSummary& summary) {
  const MapRequest& r = plan.request();
  nlohmann::ordered_json j;
  j["case"] = plan.source().id();
  j["sample"] = r.sample;
  j["points"] = plan.count();
  for (const MapAxis& a : r.vary) j["vary"].push_back({{"name", a.name}, {"from", a.from}, {"to", a.to}, {"count", a.count}});
  if (r.sample == "lhs") j["seed"] = r.seed;
  j["block"] = r.block;
  j["settle"] = {{"step", plan.step()}, {"t_end", plan.t_end()}, {"samples", numeric::SettleOptions{}.samples},
                 {"fraction", numeric::SettleOptions{}.fraction}};
  j["boundary_points"] = summary.boundary_points;
  j["survey_fallbacks"] = summary.survey_fallbacks;
  return j.dump(2) + "\n";
}

}  // namespace

void finish_map(const MapPlan& plan, const MapOutput& output,
                const std::shared_ptr<const numeric::ValidatedParametricFamily>& family, MapSummary& summary,
                output::StagedDirectory* stage) {
  const bool root = !output.transport || output.transport->rank() == 0;
  const bool boundary = plan.request().boundary && plan.request().sample == "grid";
  const fs::path staging = root ? stage->path() : fs::path();
  std::optional<MapHdf5> h5;
  Figures figures(plan, root && output.figures);
  std::vector<Crossing> crossings;
  if (root) {
    if (output.hdf5) h5.emplace(staging / "map.h5", plan);
    crossings = read_points(plan, staging, h5 ? &*h5 : nullptr, figures, boundary, summary.survey_fallbacks);
  }
  std::vector<MapBoundaryRow> rows;
  if (boundary) rows = solve_all(plan, std::move(crossings), output.transport, family, output.interrupted);
  if (!root) return;
  summary.boundary_points = static_cast<long>(rows.size());
  if (boundary) {
    std::ofstream csv(staging / "boundary.csv", std::ios::binary);
    csv << map_boundary_csv_header(plan);
    for (const MapBoundaryRow& b : rows) {
      csv << map_boundary_csv_row(b);
      if (h5) h5->add_boundary(b);
      figures.add_boundary(b);
    }
    if (!csv.flush()) throw std::runtime_error("cannot write " + (staging / "boundary.csv").string());
  }
  if (h5) h5->close();
  if (output.figures) summary.figures_note = figures.write(staging);
  std::ofstream(staging / "map.json", std::ios::binary) << map_json(plan, summary);
  fs::remove(staging / "points.bin");
  fs::remove(staging / "checkpoint");
  try {
    stage->commit();  // the marker ("written by backlash map"), then the rename onto --out
  } catch (const output::OutputError& e) {
    rethrow_as_bad_out(e);
  }
}

}  // namespace backlash::map::detail
