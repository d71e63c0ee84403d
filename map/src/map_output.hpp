// map_output.hpp — the pieces of `write_map` (map_output.cpp, map_finish.cpp): the partial
// folder's row writer and checkpoint, and the final files.  The partial folder itself, the
// --out checks and the rename into place are the output layer's (backlash/output/
// staged_directory.hpp).
#pragma once

#include "backlash/map/map.hpp"

#include "map_text.hpp"

#include "backlash/output/output_error.hpp"
#include "backlash/output/staged_directory.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace backlash::map::detail {

/// A stop asked for (a signal, or MapOutput::stop_after): the partial folder stays, resumable.
struct Interrupted {};

/// The request as the checkpoint records it: a resume must match it exactly (threads and ranks
/// are not part of it: they do not change the output).
std::string fingerprint(const MapPlan& plan, const MapOutput& output);
/// The sweep's options for the map's points: threads, block, and the settle time's step.
numeric::SweepOptions sweep_options(const MapPlan& plan);
/// The partial folder of --out DIR: ".DIR.map-partial" beside it (output::StagedDirectory::partial).
inline constexpr std::string_view partial_tag = "map-partial";
/// Whose folders --out may replace (backlash/output/target.hpp): "… is not a backlash output".
inline const output::FolderOwner map_owner{"backlash output"};
/// An output::OutputError in the map's words: a refused target as BadInput "out" (its message
/// without the leading "--out "), a failed write rethrown as it is.
[[noreturn]] void rethrow_as_bad_out(const output::OutputError& e);

/// Rank 0: appends each row to points.csv and points.bin in index order; at every block end
/// flushes both and rewrites the checkpoint (the fingerprint, the points done, the two files'
/// lengths), then polls for a stop.  Throws Interrupted to stop.
class RowWriter {
 public:
  RowWriter(const std::filesystem::path& staging, const MapPlan& plan, const MapOutput& output, std::string print,
            long done, std::uintmax_t csv_bytes, std::uintmax_t bin_bytes);
  ~RowWriter();
  RowWriter(const RowWriter&) = delete;
  RowWriter& operator=(const RowWriter&) = delete;
  void take(const std::string& record, const std::string& csv);
  long done() const { return done_; }
  long written() const { return written_; }
  const std::filesystem::path& staging() const { return staging_; }
  void close();

 private:
  void checkpoint();
  std::filesystem::path staging_;
  std::string print_;
  long done_ = 0;
  std::uintmax_t csv_bytes_ = 0, bin_bytes_ = 0, pending_csv_ = 0, pending_bin_ = 0;
  long pending_rows_ = 0, written_ = 0;
  long block_, count_, stop_after_;
  std::function<bool()> interrupted_;
  std::function<void(long, long)> progress_;
  std::FILE* csv_ = nullptr;
  std::FILE* bin_ = nullptr;
};

/// Every rank: the final files from points.bin (rank 0), the boundary solved over all ranks,
/// map.json, then the partial folder `stage` committed onto --out (rank 0; null on the others):
/// its marker written and renamed into place.
void finish_map(const MapPlan& plan, const MapOutput& output,
                const std::shared_ptr<const numeric::ValidatedParametricFamily>& family, MapSummary& summary,
                output::StagedDirectory* stage);

}  // namespace backlash::map::detail
