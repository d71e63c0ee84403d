// map_store.hpp — a map's rows as fixed-size binary records (what ranks send to rank 0 and
// what points.bin holds until the end), and the HDF5 writer (map_hdf5.cpp).
#pragma once

#include "backlash/map/map.hpp"
#include "backlash/numeric/varied_parameter.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace backlash::map::detail {

/// The statuses a record stores as a code (status_of's texts; anything else is "other");
/// "unresolved" came last, after "other", so that the earlier codes kept their values.
inline const std::vector<std::string>& map_status_names() {
  static const std::vector<std::string> names = {"limit_cycle", "none",  "divergent", "unvalidated",
                                                 "refused",     "error", "other",     "unresolved"};
  return names;
}
inline constexpr std::int8_t map_status_other = 6;
inline std::int8_t map_status_code(const std::string& status) {
  const auto& names = map_status_names();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == status && k != map_status_other) return static_cast<std::int8_t>(k);
  return map_status_other;
}
/// The bit of a record's status word that says the search fell back to the grid survey.
inline constexpr std::int64_t map_survey_fallback_bit = 256;
/// True for the statuses of a point whose limit-cycle search ran (its settle time is computed).
inline bool map_status_searched(std::int64_t code) { return code <= 2 || code == 7; }

/// A record: index (int64), status code (int64; bit 8: the limit-cycle search fell back to the grid
/// survey, numeric::LimitCycle::survey_fallback), then doubles: the d varied values, the
/// parameters of points.csv (numeric::point_column_names: the structure and every effect
/// parameter), peak_to_peak, amplitude, period, separation_velocity, multiplier, settle_time
/// (NaN when the row has none).
struct MapRecord {
  /// The doubles after the varied values: the parameters and the six results.
  static constexpr std::size_t kParameters = 7 + model::kEffectParameterCount;
  static constexpr std::size_t kValues = kParameters + 6;
  std::int64_t index = 0, status = 0;
  bool survey_fallback = false;
  std::vector<double> values;
  static std::size_t size(std::size_t d) { return 16 + 8 * (d + kValues); }
};

inline void append_record(std::string& out, const MapRow& r) {
  const std::int64_t head[2] = {r.index, map_status_code(api::status_of(r.row))};
  const std::int64_t word[2] = {head[0], head[1] | (r.row.cycle.survey_fallback ? map_survey_fallback_bit : 0)};
  out.reserve(out.size() + MapRecord::size(r.x.size()));
  out.append(reinterpret_cast<const char*>(word), sizeof word);
  const numeric::Parameters& p = r.row.point.parameters;
  const numeric::Effects& e = r.row.point.effects;
  const bool cycle = head[1] == 0, computed = map_status_searched(head[1]);
  const numeric::LimitCycle& c = r.row.cycle;
  std::vector<double> v;
  v.reserve(r.x.size() + MapRecord::kValues);  // one allocation, the record's too
  v.insert(v.end(), r.x.begin(), r.x.end());
  for (const double x : numeric::point_column_values(p, e)) v.push_back(x);
  for (const double x : {c.peak_to_peak, c.amplitude, c.period, c.separation_velocity, c.multiplier})
    v.push_back(cycle ? x : NAN);
  v.push_back(computed ? r.row.settle.time : NAN);
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
}

inline MapRecord read_record(const char* bytes, std::size_t d) {
  MapRecord r;
  std::memcpy(&r.index, bytes, 8);
  std::memcpy(&r.status, bytes + 8, 8);
  r.survey_fallback = (r.status & map_survey_fallback_bit) != 0;
  r.status &= ~map_survey_fallback_bit;
  r.values.resize(d + MapRecord::kValues);
  std::memcpy(r.values.data(), bytes + 16, 8 * (d + MapRecord::kValues));
  return r;
}

/// map.h5 (docs/design.md, "Design-space maps"): dataset /points (compound, one element per
/// point, chunks of 4096, extendible) and /boundary; no time stamps (byte-reproducible).
class MapHdf5 {
 public:
  MapHdf5(const std::filesystem::path& file, const MapPlan& plan);
  ~MapHdf5();
  MapHdf5(const MapHdf5&) = delete;
  MapHdf5& operator=(const MapHdf5&) = delete;
  void add(const MapRecord& record);
  void add_boundary(const MapBoundaryRow& row);
  void close();  ///< flushes and closes (throws on an HDF5 failure)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace backlash::map::detail
