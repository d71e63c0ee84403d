// `backlash sweep` — limit-cycle magnitude over parameters (thesis figs. 31, 32).
//
//   backlash sweep fig31 [--points N] [--threads T] [--out FILE.csv]
//       magnitude vs FL/F for JL = Jm and JL = 4 Jm (F = .4, J = 1, K = 1, b = .3)
//   backlash sweep fig32 [--points N] [--threads T] [--out FILE.csv]
//       magnitude vs JL/Jm for three friction distributions
//   backlash sweep CASE --vary NAME --from A --to B [--points N] [--threads T] [--out FILE.csv]
//       any case file, one parameter varied: Jm, Fm, JL, FL, K, backlash, reference,
//       JL_over_Jm (keeping Jm + JL), FL_over_F (keeping Fm + FL)
// CSV streamed on stdout as rows are done, in order (or to --out, through a temporary file
// renamed into place at the end); why a row has no cycle on stderr; a progress bar on
// stderr when it is a terminal (--no-progress turns it off).
#include "commands.hpp"
#include "numeric_case.hpp"
#include "output_files.hpp"

#include "backlash/numeric/sweep.hpp"
#include "backlash/symbolic/escape.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>

#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

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

/// The largest point count: indices and x values stay exact in a double.
constexpr long long largest_count = 1LL << 40;

long long parse_count(const std::string& text, const std::string& flag, long long minimum, long long maximum) {
  const double v = parse_number(text, flag);
  if (v != std::floor(v) || v < static_cast<double>(minimum))
    throw UsageError(flag + ": expected a whole number >= " + std::to_string(minimum) + ", got '" + text + "'");
  if (v > static_cast<double>(maximum))
    throw UsageError(flag + ": at most " + std::to_string(maximum) + ", got '" + text + "'");
  return static_cast<long long>(v);
}

// A custom sweep: the case's parameters with one of them set to x.
struct CustomSweep {
  std::string series;
  numeric::Parameters base;
  numeric::Effects base_effects;
  std::string vary;
  double from = 0, to = 0;
  long long n = 1;

  double x(long long i) const {
    return n == 1 ? from : from + (to - from) * static_cast<double>(i) / static_cast<double>(n - 1);
  }

  numeric::SweepPoint point(long long i) const {
    const double value = x(i);
    numeric::Parameters p = base;
    numeric::Effects e = base_effects;
    const std::string& v = vary;
    if (v == "Jm") p.Jm = value;
    else if (v == "Fm") p.Fm = value;
    else if (v == "JL") p.JL = value;
    else if (v == "FL") p.FL = value;
    else if (v == "K") p.K = value;
    else if (v == "backlash") p.backlash = value;
    else if (v == "reference") p.theta_R = value;
    else if (v == "JL_over_Jm") { const double J = base.Jm + base.JL; p.Jm = J / (1 + value); p.JL = J * value / (1 + value); }
    else if (v == "FL_over_F") { const double F = base.Fm + base.FL; p.FL = value * F; p.Fm = F - p.FL; }
    else if (v == "coulomb_motor") e.coulomb_motor = value;
    else if (v == "coulomb_load") e.coulomb_load = value;
    else if (v == "restitution") e.restitution = value;
    else if (v == "saturation") e.saturation = value;
    else if (v == "stiffness") e.mesh_stiffness = value;
    else if (v == "damping") e.mesh_damping = value;
    else if (v == "delay") e.delay = value;
    else if (v == "torque_offset") e.torque_offset = value;
    return {series, value, p, e};
  }

  // Every constraint is an interval in x, so checking both ends checks every point.
  void check_ends() const {
    static const char* known[] = {"Jm", "Fm", "JL", "FL", "K", "backlash", "reference", "JL_over_Jm", "FL_over_F",
                                  "coulomb_motor", "coulomb_load", "restitution", "saturation", "stiffness", "damping",
                                  "delay", "torque_offset"};
    if (std::find(std::begin(known), std::end(known), vary) == std::end(known))
      throw UsageError("--vary: unknown parameter '" + vary + "' (Jm, Fm, JL, FL, K, backlash, reference, JL_over_Jm, FL_over_F, "
                       "coulomb_motor, coulomb_load, restitution, saturation, stiffness, damping, delay, torque_offset)");
    for (long long i : {0LL, n - 1}) {
      const numeric::SweepPoint pt = point(i);
      const numeric::Parameters& p = pt.parameters;
      const numeric::Effects& e = pt.effects;
      const std::string value = (i == 0 ? "--from " : "--to ") + std::string(i == 0 ? from_text : to_text);
      if (!(p.Jm > 0) || !(p.JL > 0) || p.Fm < 0 || p.FL < 0 || !(p.K > 0) || p.backlash < 0)
        throw UsageError(value + ": " + vary + " there gives non-physical parameters");
      if (e.coulomb_motor < 0 || e.coulomb_load < 0 || e.restitution < 0 || e.restitution >= 1 || !(e.saturation > 0) ||
          !(e.mesh_stiffness > 0) || e.mesh_damping < 0 || e.delay < 0)
        throw UsageError(value + ": " + vary + " there is outside the effect's range (docs/effects.md)");
    }
    const numeric::Effects& e = base_effects;
    if (vary == "restitution" && e.compliant())
      throw UsageError("--vary " + vary + ": restitution and compliance both model the impact; give one of them");
    if (vary == "stiffness" || vary == "damping") {
      if (!e.compliant())
        throw UsageError("--vary " + vary + ": the case has no [effects] compliance to vary (give one in the case file)");
      if (e.restitution > 0)
        throw UsageError("--vary " + vary + ": restitution and compliance both model the impact; give one of them");
    }
  }
  std::string from_text, to_text;
};

CustomSweep custom_sweep(const SweepOptions& o, long long n) {
  const model::CaseSpec spec = model::load_case(o.target);
  if (o.vary.empty() || o.from.empty() || o.to.empty())
    throw UsageError("sweep " + o.target + ": --vary, --from and --to are required for a case (or use fig31 / fig32)");
  CustomSweep sweep;
  sweep.from = parse_number(o.from, "--from");
  sweep.to = parse_number(o.to, "--to");
  sweep.from_text = o.from;
  sweep.to_text = o.to;
  sweep.base = numeric::parameters_of(spec);
  sweep.base_effects = numeric::effects_of(spec);
  sweep.vary = o.vary;
  sweep.series = spec.id + ":" + o.vary;
  sweep.n = n;
  sweep.check_ends();
  return sweep;
}

std::string csv_row(const numeric::SweepRow& r) {
  std::ostringstream csv;
  csv.precision(12);
  const numeric::Parameters& p = r.point.parameters;
  std::string effects = r.point.effects.describe();
  std::replace(effects.begin(), effects.end(), ',', ';');  // one CSV cell
  effects.erase(std::remove(effects.begin(), effects.end(), ' '), effects.end());
  csv << symbolic::escape::csv_field(r.point.series) << "," << r.point.x << "," << p.Jm << "," << p.Fm << "," << p.JL << "," << p.FL << "," << p.K << ","
      << p.backlash << "," << effects << "," << numeric::to_string(r.status) << "," << r.branches;
  if (r.status == numeric::SweepStatus::LimitCycle) {
    csv << "," << r.cycle.peak_to_peak << "," << r.cycle.amplitude << "," << r.cycle.period << ",";
    if (std::isfinite(r.cycle.separation_velocity)) csv << r.cycle.separation_velocity;  // none: a pure bounce cycle
    csv << "," << r.cycle.multiplier << "\n";
  } else {
    csv << ",,,,,\n";
  }
  return csv.str();
}

void run_sweep_command(const SweepOptions& o) {
  const long long n = parse_count(o.points, "--points", 1, largest_count / 3);
  const int threads = static_cast<int>(parse_count(o.threads, "--threads", 1, 1024));
  std::function<numeric::SweepPoint(long)> point;
  long long count = 0;
  if (o.target == "fig31") {
    point = [n](long i) { return numeric::figure31_point(static_cast<long>(n), i); };
    count = 2 * n;
  } else if (o.target == "fig32") {
    point = [n](long i) { return numeric::figure32_point(static_cast<long>(n), i); };
    count = 3 * n;
  } else {
    std::string lowered = o.target;
    for (char& ch : lowered) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (lowered.rfind("fig", 0) == 0 && !std::filesystem::exists(o.target))
      throw UsageError("sweep: unknown figure '" + o.target + "': the thesis's sweeps are fig31 and fig32 (or give a case with --vary)");
    auto sweep = std::make_shared<CustomSweep>(custom_sweep(o, n));
    point = [sweep](long i) { return sweep->point(i); };
    count = n;
  }
  // The target is checked before any work; rows are streamed to it (or to stdout) as they come.
  std::unique_ptr<AtomicFile> file;
  if (!o.out.empty()) file = std::make_unique<AtomicFile>(std::filesystem::path(o.out));
  FILE* out = file ? file->stream() : stdout;
  numeric::SweepOptions options;
  options.threads = threads;
  const bool bar = !o.no_progress && isatty(STDERR_FILENO);
  if (bar)
    options.progress = [](long done, long total) {
      const int width = 40, filled = static_cast<int>(width * done / total);
      std::fprintf(stderr, "\r[%s%s] %3ld%% (%ld/%ld)", std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                   100 * done / total, done, total);
      if (done == total) std::fprintf(stderr, "\n");
    };
  numeric::SweepSummary summary;
  const std::string header =
      "series,x,Jm,Fm,JL,FL,K,backlash,effects,status,branches,peak_to_peak,amplitude,period,separation_velocity,multiplier\n";
  if (std::fputs(header.c_str(), out) < 0) throw std::runtime_error("cannot write the sweep's output");
  // Why a row has no cycle: the first few reasons on stderr (one line each), then a count.
  constexpr long reasons_shown = 20;
  long without_cycle = 0, rows = 0;
  numeric::run_sweep_streamed(
      static_cast<long>(count), point, options,
      [&](const numeric::SweepRow& r) {
        const std::string line = csv_row(r);
        if (std::fputs(line.c_str(), out) < 0) throw std::runtime_error("cannot write the sweep's output");
        ++rows;
        if (r.status != numeric::SweepStatus::LimitCycle && !r.reason.empty() && ++without_cycle <= reasons_shown) {
          std::string reason = r.reason;
          for (char& ch : reason)
            if (ch == '\n' || ch == '\r') ch = ' ';
          std::fprintf(stderr, "sweep: %s x = %.12g: %s: %s\n", r.point.series.c_str(), r.point.x, numeric::to_string(r.status),
                       reason.c_str());
        }
      },
      &summary);
  if (without_cycle > reasons_shown)
    std::fprintf(stderr, "sweep: ... and %ld more rows without a cycle\n", without_cycle - reasons_shown);
  if (file) file->commit();
  else std::fflush(stdout);
  std::fprintf(stderr, "sweep: %ld points on %d threads; parametric family validated at %ld samples (%ld failed), branches:",
               rows, threads, summary.validated_samples, summary.failed_samples);
  for (const std::string& b : summary.covered_branches) std::fprintf(stderr, " %s", b.c_str());
  std::fprintf(stderr, "\n");
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
