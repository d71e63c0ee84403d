// map_output.cpp — `backlash map --out DIR`: the rows streamed into a partial folder with a
// checkpoint at every block, on one process or over MPI ranks (MapTransport), then the final
// files (HDF5, boundary, figures) and the atomic rename (map/map.hpp; docs/design.md,
// "Design-space maps").  The partial folder is the output layer's (backlash/output/
// staged_directory.hpp: StagedDirectory::partial); what it holds and when it may be resumed
// (the checkpoint) is the map's.
#include "backlash/map/map.hpp"

#include "map_output.hpp"
#include "map_store.hpp"

#include "backlash/numeric/validated_family.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

namespace backlash::map {

using api::BadInput;

namespace fs = std::filesystem;
using detail::Interrupted;

namespace detail {

std::string fingerprint(const MapPlan& plan, const MapOutput& output) {
  const MapRequest& r = plan.request();
  std::string out = "backlash map checkpoint 1\ncase " + plan.source().id() + "\n" + plan.source().case_file();
  for (const MapAxis& a : r.vary) appendf(out, "vary %s %.17g %.17g %ld\n", a.name.c_str(), a.from, a.to, a.count);
  appendf(out, "sample %s %ld seed %llu block %d step %.17g t_end %.17g boundary %d hdf5 %d figures %d\n",
          r.sample.c_str(), plan.count(), static_cast<unsigned long long>(r.seed), r.block, plan.step(), plan.t_end(),
          r.boundary ? 1 : 0, output.hdf5 ? 1 : 0, output.figures ? 1 : 0);
  return out;
}

// The output layer's refusal of a target (OutputError bad_target) in the map's words, as it has
// always printed it: BadInput "out" ("--out: DIR: not a folder name", exit 2).  A failed write
// (exit 1) goes on as it is.
[[noreturn]] void rethrow_as_bad_out(const output::OutputError& e) {
  if (e.kind() != output::OutputError::Kind::bad_target) throw e;
  std::string message = e.what();
  for (const char* head : {"--out: ", "--out "})
    if (message.rfind(head, 0) == 0) {
      message.erase(0, std::char_traits<char>::length(head));
      break;
    }
  throw BadInput("out", message);
}

RowWriter::RowWriter(const fs::path& staging, const MapPlan& plan, const MapOutput& output, std::string print,
                     long done, std::uintmax_t csv_bytes, std::uintmax_t bin_bytes)
    : staging_(staging), print_(std::move(print)), done_(done), csv_bytes_(csv_bytes), bin_bytes_(bin_bytes),
      block_(plan.request().block), count_(plan.count()), stop_after_(output.stop_after),
      interrupted_(output.interrupted), progress_(output.progress) {
  if (done == 0) {
    std::ofstream(staging / "points.csv", std::ios::binary) << map_csv_header(plan);
    std::ofstream(staging / "points.bin", std::ios::binary);
    csv_bytes_ = fs::file_size(staging / "points.csv");
    bin_bytes_ = 0;
  }
  // The completed prefix only: a partial block's rows are cut off and recomputed.
  fs::resize_file(staging / "points.csv", csv_bytes_);
  fs::resize_file(staging / "points.bin", bin_bytes_);
  csv_ = std::fopen((staging / "points.csv").c_str(), "ab");
  bin_ = std::fopen((staging / "points.bin").c_str(), "ab");
  if (!csv_ || !bin_) throw std::runtime_error("cannot open the partial map in " + staging.string());
  checkpoint();
}

RowWriter::~RowWriter() { close(); }

void RowWriter::close() {
  if (csv_) std::fclose(csv_), csv_ = nullptr;
  if (bin_) std::fclose(bin_), bin_ = nullptr;
}

void RowWriter::take(const std::string& record, const std::string& csv) {
  if (std::fwrite(csv.data(), 1, csv.size(), csv_) != csv.size() ||
      std::fwrite(record.data(), 1, record.size(), bin_) != record.size())
    throw std::runtime_error("cannot write the partial map in " + staging_.string());
  ++written_;
  pending_csv_ += csv.size(), pending_bin_ += record.size();
  const long index = done_ + pending_rows_++;
  if ((index + 1) % block_ == 0 || index + 1 == count_) {
    if (std::fflush(csv_) != 0 || std::fflush(bin_) != 0) throw std::runtime_error("cannot write " + staging_.string());
    done_ = index + 1, csv_bytes_ += pending_csv_, bin_bytes_ += pending_bin_;
    pending_rows_ = 0, pending_csv_ = 0, pending_bin_ = 0;
    checkpoint();
    if (progress_) progress_(done_, count_);
    if (interrupted_ && interrupted_()) throw Interrupted{};
  }
  if (stop_after_ >= 0 && written_ >= stop_after_) throw Interrupted{};
}

void RowWriter::checkpoint() {
  const fs::path file = staging_ / "checkpoint", temporary = staging_ / "checkpoint.new";
  {
    std::ofstream out(temporary, std::ios::binary);
    out << print_ << "done " << done_ << "\ncsv " << csv_bytes_ << "\nbin " << bin_bytes_ << "\n";
    if (!out.flush()) throw std::runtime_error("cannot write the checkpoint in " + staging_.string());
  }
  fs::rename(temporary, file);
}

// The checkpoint of an interrupted run of the same request: done, csv bytes, bin bytes.
bool read_checkpoint(const fs::path& staging, const std::string& print, long& done, std::uintmax_t& csv,
                     std::uintmax_t& bin) {
  std::ifstream in(staging / "checkpoint", std::ios::binary);
  if (!in) return false;
  std::stringstream text;
  text << in.rdbuf();
  const std::string all = text.str();
  if (all.compare(0, print.size(), print) != 0) return false;
  std::istringstream tail(all.substr(print.size()));
  std::string a, b, c, rest;
  return static_cast<bool>(tail >> a >> done >> b >> csv >> c >> bin) && a == "done" && b == "csv" && c == "bin" &&
         !(tail >> rest);
}

// points.bin against the checkpoint: `done` records numbered 0 … done − 1 in order, in its first `bin` bytes.
std::string check_records(const fs::path& file, const MapPlan& plan, long done, std::uintmax_t bin) {
  const std::size_t size = MapRecord::size(plan.request().vary.size());
  std::error_code error;
  const std::uintmax_t length = fs::file_size(file, error);
  if (error) return "points.bin: " + error.message();
  if (bin != size * static_cast<std::uintmax_t>(done) || length < bin)
    return "points.bin holds " + std::to_string(length) + " bytes, the checkpoint's " + std::to_string(done) +
           " points need " + std::to_string(size * static_cast<std::uintmax_t>(done));
  std::ifstream in(file, std::ios::binary);
  std::vector<char> record(size);
  for (long k = 0; k < done; ++k) {
    std::int64_t index = -1;
    if (in.read(record.data(), static_cast<std::streamsize>(size))) std::memcpy(&index, record.data(), 8);
    if (index != k) return "points.bin: record " + std::to_string(k) + " is not point " + std::to_string(k);
  }
  return "";
}

// points.csv against the checkpoint: this request's header, then rows "0,…" to "done − 1,…", in exactly its first `csv` bytes.
std::string check_rows(const fs::path& file, const MapPlan& plan, long done, std::uintmax_t csv) {
  std::error_code error;
  const std::uintmax_t length = fs::file_size(file, error);
  if (error) return "points.csv: " + error.message();
  if (length < csv)
    return "points.csv holds " + std::to_string(length) + " bytes, the checkpoint covers " + std::to_string(csv);
  std::ifstream in(file, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || in.eof() || line + "\n" != map_csv_header(plan)) return "points.csv has another header";
  std::uintmax_t read = line.size() + 1;
  for (long k = 0; k < done; ++k) {
    if (!std::getline(in, line) || in.eof()) return "points.csv ends before row " + std::to_string(k);
    if (line.rfind(std::to_string(k) + ",", 0) != 0) return "points.csv: row " + std::to_string(k) + " is not point " + std::to_string(k);
    read += line.size() + 1;
  }
  if (read != csv) return "points.csv: the checkpoint's " + std::to_string(done) + " rows end at byte " +
                          std::to_string(read) + ", not " + std::to_string(csv);
  return "";
}

// The checkpoint against every file it covers ("" when they match, else the reason).
std::string check_partial(const fs::path& staging, const MapPlan& plan, long done, std::uintmax_t csv,
                          std::uintmax_t bin) {
  if (done < 0 || done > plan.count())
    return "the checkpoint counts " + std::to_string(done) + " points of " + std::to_string(plan.count());
  const std::string records = check_records(staging / "points.bin", plan, done, bin);
  return records.empty() ? check_rows(staging / "points.csv", plan, done, csv) : records;
}

}  // namespace detail

namespace {

// Opens the partial folder (fresh or resumed) at rank 0; returns the first point to compute.
std::unique_ptr<detail::RowWriter> open_partial(const MapPlan& plan, const MapOutput& output,
                                                std::optional<output::StagedDirectory>& stage) {
  try {
    stage.emplace(output::StagedDirectory::partial(output.out, detail::partial_tag, "map", detail::map_owner));
  } catch (const output::OutputError& e) {
    detail::rethrow_as_bad_out(e);
  }
  const fs::path staging = stage->path();
  const std::string print = detail::fingerprint(plan, output);
  long done = 0;
  std::uintmax_t csv = 0, bin = 0;
  std::error_code error;
  if (output.resume) {
    if (!detail::read_checkpoint(staging, print, done, csv, bin))
      throw BadInput("resume", "no interrupted map of this request at " + staging.string() +
                                   " (run without --resume to start it; the case, --vary, --sample, --points, "
                                   "--step and the outputs must be the same)");
    if (const std::string mismatch = detail::check_partial(staging, plan, done, csv, bin); !mismatch.empty())
      throw BadInput("resume", "the interrupted map at " + staging.string() + " does not match its checkpoint: " +
                                   mismatch + "; run without --resume to start over");
  } else {
    if (!fs::is_empty(staging, error) && !fs::exists(staging / "checkpoint"))
      throw BadInput("out", staging.string() + " exists and is not a partial map; remove it");
    for (const fs::directory_entry& entry : fs::directory_iterator(staging)) fs::remove_all(entry.path());
  }
  return std::make_unique<detail::RowWriter>(staging, plan, output, print, done, csv, bin);
}

// Rows of points [first, last) handed to `take(record, csv)` in order.
void compute(const MapPlan& plan, numeric::SweepOptions options, long first, long last,
             const std::function<void(const std::string&, const std::string&)>& take) {
  options.first = first, options.last = last;
  long index = first;
  numeric::run_sweep_streamed(plan.count(), [&plan](long i) { return plan.point(i); }, options,
                              [&](const numeric::SweepRow& row) {
                                const MapRow r{index, plan.values(index), row};
                                std::string record;
                                detail::append_record(record, r);
                                take(record, map_csv_row(r));
                                ++index;
                              });
}

// MPI: rounds of `per_rank` blocks per rank, contiguous, gathered at rank 0 in order.
bool compute_distributed(const MapPlan& plan, const numeric::SweepOptions& options, MapTransport& t, long first,
                         detail::RowWriter* writer) {
  const long block = options.block, count = plan.count();
  const long per_rank = 8L * options.threads * block;
  bool stopped = false;
  for (long next = first;;) {
    std::string go = t.rank() == 0 ? (stopped ? std::string("stop") : "go " + std::to_string(next)) : std::string();
    t.broadcast(go);
    if (go == "stop") return false;
    next = std::stol(go.substr(3));
    if (next >= count) return true;
    const long begin = std::min(count, next + t.rank() * per_rank), end = std::min(count, begin + per_rank);
    std::string piece;
    if (begin < end)
      compute(plan, options, begin, end, [&](const std::string& record, const std::string& csv) {
        const auto length = static_cast<std::uint32_t>(csv.size());
        piece += record;
        piece.append(reinterpret_cast<const char*>(&length), 4);
        piece += csv;
      });
    const std::vector<std::string> pieces = t.gather(piece);
    const std::size_t size = detail::MapRecord::size(plan.request().vary.size());
    try {
      for (const std::string& p : pieces)
        for (std::size_t at = 0; at < p.size();) {
          std::uint32_t length = 0;
          std::memcpy(&length, p.data() + at + size, 4);
          writer->take(p.substr(at, size), p.substr(at + size + 4, length));
          at += size + 4 + length;
        }
    } catch (const Interrupted&) {
      stopped = true;
    }
    next += t.size() * per_rank;
  }
}

}  // namespace

std::filesystem::path map_partial_folder(const std::filesystem::path& out) {
  return output::StagedDirectory::partial_path(out, detail::partial_tag);
}

MapSummary write_map(const MapRequest& request, const MapOutput& output) {
  const MapPlan plan(request);
  MapTransport* t = output.transport;
  const bool root = !t || t->rank() == 0;
  std::optional<output::StagedDirectory> stage;  // rank 0: kept unless committed (--resume)
  std::unique_ptr<detail::RowWriter> writer;
  std::string start;
  try {
    if (root) writer = open_partial(plan, output, stage), start = "ok " + std::to_string(writer->done());
  } catch (const std::exception& e) {
    if (!t || t->size() == 1) throw;
    start = std::string("error ") + e.what();
  }
  if (t && t->size() > 1) t->broadcast(start);
  if (start.rfind("error ", 0) == 0) throw BadInput("out", start.substr(6));
  MapSummary summary;
  summary.points = plan.count();
  summary.resumed_from = std::stol(start.substr(3));
  const numeric::SweepOptions options = [&] {
    numeric::SweepOptions o = detail::sweep_options(plan);
    o.family = numeric::sweep_family(plan.count(), [&plan](long i) { return plan.point(i); }, o);
    return o;
  }();
  bool complete = true;
  if (t && t->size() > 1) {
    complete = compute_distributed(plan, options, *t, summary.resumed_from, writer.get());
  } else {
    try {
      if (summary.resumed_from < plan.count())  // a run stopped in the boundary phase has every point
        compute(plan, options, summary.resumed_from, plan.count(),
                [&](const std::string& record, const std::string& csv) { writer->take(record, csv); });
    } catch (const Interrupted&) {
      complete = false;
    }
  }
  if (root) summary.written = writer->written(), summary.kept = writer->done(), writer->close();
  summary.complete = complete;
  if (!complete) return summary;
  try {
    detail::finish_map(plan, output, options.family, summary, stage ? &*stage : nullptr);
  } catch (const Interrupted&) {  // stopped in the boundary phase: every point kept, the boundary redone on --resume
    summary.complete = false;
  }
  return summary;
}

}  // namespace backlash::map
