// `backlash sweep` — limit-cycle magnitude over parameters (thesis figs. 31, 32), through
// the facade (api::sweep, streamed).
//
//   backlash sweep fig31 [--points N] [--threads T] [--out FILE.csv]
//       magnitude vs FL/F for JL = Jm and JL = 4 Jm (F = .4, J = 1, K = 1, b = .3)
//   backlash sweep fig32 [--points N] [--threads T] [--out FILE.csv]
//       magnitude vs JL/Jm for three friction distributions
//   backlash sweep CASE --vary NAME --from A --to B [--points N] [--threads T] [--out FILE.csv]
//       any case file, one parameter or effect varied (api::SweepRequest::vary)
// CSV streamed on stdout as rows are done, in order (or to --out, through a temporary file
// renamed into place at the end); why a row has no cycle on stderr; a progress bar on
// stderr when it is a terminal (--no-progress turns it off).
#include "commands.hpp"
#include "flags.hpp"
#include "progress.hpp"

#include "backlash/api/backlash.hpp"
#include "backlash/output/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace backlash::cli {

namespace {

struct SweepOptions {
  std::string target;
  std::string points = "101";
  std::string threads = "2";
  std::string vary, from, to;
  std::string out;
  bool no_progress = false;
};

/// Why a row has no cycle: the first few reasons on stderr (one line each), then a count.
class NoCycleNotes {
 public:
  void note(const numeric::SweepRow& row) {
    const std::string status = api::status_of(row);
    if (status == "limit_cycle" || row.reason.empty() || ++count_ > shown) return;
    std::string reason = row.reason;
    for (char& ch : reason)
      if (ch == '\n' || ch == '\r') ch = ' ';
    std::fprintf(stderr, "sweep: %s x = %.12g: %s: %s\n", row.point.series.c_str(), row.point.x, status.c_str(),
                 reason.c_str());
  }
  void finish() const {
    if (count_ > shown) std::fprintf(stderr, "sweep: ... and %ld more rows without a cycle\n", count_ - shown);
  }

 private:
  static constexpr long shown = 20;
  long count_ = 0;
};

api::SweepRequest request_of(const SweepOptions& o) {
  api::SweepRequest request;
  request.target = o.target;
  request.vary = o.vary;
  if (!o.from.empty()) request.from = parse_number(o.from, "--from");
  if (!o.to.empty()) request.to = parse_number(o.to, "--to");
  request.points = parse_whole_number(o.points, "--points");
  request.threads = parse_whole_int(o.threads, "--threads");
  request.progress = progress_bar(o.no_progress);
  return request;
}

void run_sweep_command(const SweepOptions& o) {
  const api::SweepRequest request = request_of(o);
  // The target is checked before any work; rows are streamed to it (or to stdout) as they come.
  std::unique_ptr<output::AtomicFile> file;
  if (!o.out.empty()) file = std::make_unique<output::AtomicFile>(std::filesystem::path(o.out));
  NoCycleNotes notes;
  const api::Sweep sweep = api::sweep(
      request, [&](std::string_view text) { file ? file->write(text) : print(text); },
      [&](const numeric::SweepRow& row) { notes.note(row); });
  notes.finish();
  if (file) file->commit();
  else flush_stdout();
  std::fputs(sweep.summary_line().c_str(), stderr);
}

}  // namespace

void register_sweep_command(CLI::App& app) {
  auto options = std::make_shared<SweepOptions>();
  CLI::App* command = app.add_subcommand("sweep", "Limit-cycle magnitude over parameters (thesis figs. 31, 32), CSV");
  command->add_option("TARGET", options->target, "fig31, fig32, or a case (I..VIII or file) with --vary")->required();
  command->add_option("--points", options->points, "points per series (default 101)");
  command->add_option("--threads", options->threads, "worker threads (default 2)");
  command->add_option("--vary", options->vary, "parameter to vary (custom sweeps)");
  command->add_option("--from", options->from, "first value");
  command->add_option("--to", options->to, "last value");
  command->add_option("--out", options->out, "write the CSV to this file (a regular file; replaced at the end, atomically)");
  command->add_flag("--no-progress", options->no_progress, "no progress bar");
  command->callback([options] { run_sweep_command(*options); });
}

}  // namespace backlash::cli
