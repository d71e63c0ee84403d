// `backlash map` — design-space maps: limit cycles over several parameters at once
// (backlash/api/map.hpp, the map library map/; docs/design.md, "Design-space maps").
//
//   backlash map CASE --vary P=A:B:N [--vary Q=A:B:N]... [--sample grid|sobol|lhs --points N]
//                [--threads T] [--step A] [--out DIR [--resume]] [--no-boundary] [--no-hdf5] [--json]
//   mpirun -n N backlash map ... --out DIR      the points split over N ranks, the same files
//
// Without --out the points' CSV streams to stdout; with --out DIR the folder gets points.csv,
// boundary.csv, map.h5, map.json, figures/ and summary.md, atomically.  SIGINT/SIGTERM/SIGHUP
// stop a run at the next block or boundary point (exit 1), keeping what is done for --resume;
// a second run onto the same --out is refused while the first lives (exit 2).
#include "commands.hpp"
#include "flags.hpp"

#include "backlash/api/map.hpp"
#include "backlash/output/signals.hpp"
#ifdef BACKLASH_MPI
#include "backlash/api/map_mpi.hpp"
#endif

#include <nlohmann/json.hpp>

#include <iostream>

namespace backlash::cli {

namespace {

struct MapFlags {
  std::string target, sample = "grid", out;
  std::vector<std::string> vary;
  std::string points = "0", stop_after = "-1", threads = "2", block = "32", seed = "13";  // flags.hpp reads them
  std::optional<std::string> step;
  bool resume = false, json = false, no_boundary = false, no_hdf5 = false, no_figures = false;
};

api::MapRequest request_of(const MapFlags& f) {
  api::MapRequest r;
  r.target = f.target;
  for (const std::string& v : f.vary) r.vary.push_back(api::parse_vary(v));
  r.sample = f.sample;
  r.points = parse_whole_number(f.points, "--points");
  r.threads = parse_whole_int(f.threads, "--threads");
  if (f.step) r.step = parse_number(*f.step, "--step");
  r.block = parse_whole_int(f.block, "--block");
  r.boundary = !f.no_boundary;
  r.seed = parse_key(f.seed, "--seed");
  return r;
}

void run(const MapFlags& f) {
  const api::MapRequest request = request_of(f);
  std::unique_ptr<api::MapTransport> transport;
#ifdef BACKLASH_MPI
  if (api::launched_by_mpi()) transport = api::mpi_transport();
#endif
  if (f.out.empty()) {
    if (transport && transport->size() > 1) throw UsageError("--out: required under MPI (the ranks write one folder)");
    if (f.resume) throw UsageError("--resume: needs --out DIR");
    const api::MapPlan plan(request);  // bad input before any output
    std::cout << api::map_csv_header(plan);
    api::run_map(request, [](const api::MapRow& row) { std::cout << api::map_csv_row(row); });
    std::cout.flush();
    return;
  }
  api::MapOutput output;
  output.out = f.out;
  output.resume = f.resume;
  output.hdf5 = !f.no_hdf5;
  output.figures = !f.no_figures;
  output.stop_after = parse_whole_number(f.stop_after, "--stop-after");
  output.transport = transport.get();
  output.interrupted = [] { return output::StopOnSignal::requested(); };
  const api::MapSummary s = [&] {
    const output::StopOnSignal stop;  // a signal stops the run cleanly (cli/main.cpp installs the handlers)
    return api::write_map(request, output);
  }();
  if (transport && transport->rank() != 0) return;
  const int ranks = transport ? transport->size() : 1;
  if (!s.complete)
    throw std::runtime_error("map: interrupted; " + std::to_string(s.kept) + " of " + std::to_string(s.points) +
                             " points kept in " + api::map_partial_folder(f.out).string() +
                             "; run the same command with --resume to finish");
  std::cerr << "map: " << s.points << " points (" << s.points - s.resumed_from << " computed by this run) on "
            << f.threads << " threads x " << ranks << " ranks; " << s.boundary_points << " boundary points; "
            << f.out << (s.figures_note.empty() ? "" : "; " + s.figures_note) << "\n";
  if (f.json) {
    nlohmann::ordered_json j;
    j["points"] = s.points;
    j["resumed_from"] = s.resumed_from;
    j["boundary_points"] = s.boundary_points;
    j["out"] = f.out;
    if (!s.figures_note.empty()) j["figures_note"] = s.figures_note;
    std::cout << j.dump(2) << "\n";
  }
}

}  // namespace

void register_map_command(CLI::App& app) {
  auto flags = std::make_shared<MapFlags>();
  CLI::App* map = app.add_subcommand("map", "Design-space map: limit cycles, boundary and settle times over several parameters");
  map->add_option("case", flags->target, "A thesis case I..VIII or a case file")->required();
  map->add_option("--vary", flags->vary, "NAME=FROM:TO:N (repeat for more axes)")->required();
  map->add_option("--sample", flags->sample, "grid (default), sobol or lhs");
  map->add_option("--points", flags->points, "sobol/lhs: the number of points");
  map->add_option("--threads", flags->threads, "worker threads (per MPI rank), default 2");
  map->add_option("--step", flags->step, "the step A [rad] for the settle time (default: the case's)");
  map->add_option("--out", flags->out, "the output folder (default: the CSV on stdout)");
  map->add_flag("--resume", flags->resume, "continue an interrupted map into the same --out");
  map->add_flag("--json", flags->json, "with --out: print a JSON summary on stdout");
  map->add_flag("--no-boundary", flags->no_boundary, "do not solve the cycle/no-cycle boundary");
  map->add_flag("--no-hdf5", flags->no_hdf5, "do not write map.h5");
  map->add_flag("--no-figures", flags->no_figures, "do not draw figures/ and summary.md");
  map->add_option("--seed", flags->seed, "lhs: the permutations' key, a whole number in 0 … 2^64 - 1 (default 13)");
  map->add_option("--block", flags->block, "points per warm-start block (default 32)")->group("");
  map->add_option("--stop-after", flags->stop_after, "stop after this many points (tests of --resume)")->group("");
  map->callback([flags] {
    try {
      run(*flags);
    } catch (const api::BadInput& bad) {
      throw UsageError("--" + bad.argument() + ": " + bad.problem());
    }
  });
}

}  // namespace backlash::cli
