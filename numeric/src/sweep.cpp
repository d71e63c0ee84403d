#include "backlash/numeric/sweep.hpp"

#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/validated_family.hpp"

#include "backlash/numeric/scales.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <thread>

namespace backlash::numeric {

namespace {

Parameters thesis_base() {
  Parameters p;
  p.K = 1;
  p.theta_R = 1;
  p.backlash = 0.3;
  p.measured_at = model::MeasuredAt::Load;
  return p;
}

}  // namespace

SweepPoint figure31_point(long n, long index) {
  const double F = 0.4;
  const bool four = index >= n;
  const long i = four ? index - n : index;
  const double jl_over_jm = four ? 4.0 : 1.0;
  const double x = n == 1 ? 0.5 : static_cast<double>(i) / static_cast<double>(n - 1);
  Parameters p = thesis_base();
  p.Jm = 1 / (1 + jl_over_jm);
  p.JL = jl_over_jm / (1 + jl_over_jm);
  p.FL = x * F;
  p.Fm = F - p.FL;
  return {four ? "JL=4Jm" : "JL=Jm", x, p, {}};
}

std::vector<SweepPoint> figure31_points(int n) {
  std::vector<SweepPoint> points;
  for (long k = 0; k < 2L * n; ++k) points.push_back(figure31_point(n, k));
  return points;
}

SweepPoint figure32_point(long n, long index) {
  struct Distribution { const char* name; double Fm, FL; };
  static const Distribution distributions[] = {{"FL=0 Fm=.2", 0.2, 0.0}, {"Fm=3FL F=.4", 0.3, 0.1}, {"FL=3Fm F=.4", 0.1, 0.3}};
  const Distribution& d = distributions[index / n];
  const long i = index % n;
  const double x = n == 1 ? 1.0 : 0.1 + (4.0 - 0.1) * static_cast<double>(i) / static_cast<double>(n - 1);
  Parameters p = thesis_base();
  p.Jm = 1 / (1 + x);
  p.JL = x / (1 + x);
  p.Fm = d.Fm;
  p.FL = d.FL;
  return {d.name, x, p, {}};
}

std::vector<SweepPoint> figure32_points(int n) {
  std::vector<SweepPoint> points;
  for (long k = 0; k < 3L * n; ++k) points.push_back(figure32_point(n, k));
  return points;
}

void shift_angles(LimitCycle& cycle, double offset) {
  if (offset == 0) return;
  cycle.theta_o_max += offset;
  cycle.theta_o_min += offset;
  cycle.theta_o_separation += offset;
  cycle.theta_o_recombination += offset;
  for (double* angle : {&cycle.section_state.theta_m, &cycle.section_state.theta_L}) *angle += offset;
}

namespace {

// The warm start a block carries from point to point (continuation).
struct Continuation {
  double guess = 0;
  std::optional<HybridState> warm;
  std::string series;
  bool first = true;
};

SweepRow sweep_row(const SweepPoint& point, const ValidatedParametricFamily& family, Continuation& c,
                   const SettleOptions& settle) {
  SweepRow row;
  row.point = point;
  if (c.first || point.series != c.series) c.guess = 0, c.warm.reset();
  c.first = false;
  c.series = point.series;
  Parameters q = point.parameters;  // error coordinates: θR = 0
  const double reference = q.theta_R;
  q.theta_R = 0;
  try {
    if (const std::optional<std::string> problem = parameter_scale_problem(q)) {
      row.status = "refused";
      row.reason = *problem;
      c.guess = 0, c.warm.reset();
      return row;
    }
    const ValidatedParametricFamily::Verdict verdict = family.judge(q);
    if (!verdict.evaluator) {
      row.status = "unvalidated";
      row.reason = verdict.reason;
      c.guess = 0, c.warm.reset();
      return row;
    }
    const BranchSelection b = select_branches(q);
    row.branches = std::string(branch_name(b.contact)) + "/" + branch_name(b.free);
    if (point.effects.any()) {
      const EffectValidationResult gate = validate_effects(*verdict.evaluator, point.effects);
      if (!gate.passed()) {
        row.status = "unvalidated";
        std::string failing;
        for (const ModeValidation& m : gate.report().modes)
          if (!m.passed) failing += (failing.empty() ? "" : "; ") + m.mode.describe();
        row.reason = "effect modes failed validation against odeint: " + failing;
        c.warm.reset();
        return row;
      }
      EffectLimitCycleOptions lc;
      lc.warm_start = c.warm;
      row.cycle = find_limit_cycle(gate.model(), lc);
      if (row.cycle.status == "limit_cycle") c.warm = row.cycle.section_state; else c.warm.reset();
      if (settle.step != 0) row.settle = settle_time(gate.model(), row.cycle, settle);
    } else {
      LimitCycleOptions lc;
      lc.guess = c.guess;
      row.cycle = find_limit_cycle(*verdict.evaluator, lc);
      c.guess = row.cycle.status == "limit_cycle" ? row.cycle.separation_velocity : 0;
      if (settle.step != 0) row.settle = settle_time(*verdict.evaluator, row.cycle, settle);
    }
    shift_angles(row.cycle, reference);
    row.settle.band_low += reference, row.settle.band_high += reference;
    row.status = row.cycle.status;
    row.reason = row.cycle.reason;
  } catch (const std::exception& e) {
    row.status = "error";
    row.reason = e.what();
    c.guess = 0, c.warm.reset();
  }
  return row;
}

}  // namespace

std::shared_ptr<const ValidatedParametricFamily> sweep_family(long count, const std::function<SweepPoint(long)>& point,
                                                              const SweepOptions& options) {
  // Validated at evenly spaced samples (deterministic: before any worker starts).
  auto family = std::make_shared<ValidatedParametricFamily>();
  std::vector<Parameters> samples;
  const long k_count = std::min<long>(count, std::max(2, options.validation_samples));
  for (long k = 0; k < k_count; ++k) {
    const long index = k_count == 1 ? 0 : static_cast<long>(static_cast<long double>(k) * (count - 1) / (k_count - 1));
    Parameters q = point(index).parameters;
    q.theta_R = 0;
    if (!parameter_scale_problem(q)) samples.push_back(q);
  }
  family->validate_samples(samples);
  return family;
}

void run_sweep_streamed(long count, const std::function<SweepPoint(long)>& point, const SweepOptions& options,
                        const std::function<void(const SweepRow&)>& row, SweepSummary* summary) {
  if (count <= 0) return;
  const std::shared_ptr<const ValidatedParametricFamily> shared =
      options.family ? options.family : sweep_family(count, point, options);
  const ValidatedParametricFamily& family = *shared;
  const long block = std::max(1, options.block);
  const long end = options.last < 0 ? count : std::min(count, options.last);
  const long first_block = std::max(0L, options.first) / block;
  const long blocks = (end + block - 1) / block;
  if (first_block >= blocks) return;
  const long threads = std::max<long>(1, std::min<long>(options.threads, blocks - first_block));
  const long window = 4 * threads;  // blocks computed ahead of the one being delivered

  std::mutex mutex;
  std::condition_variable changed;
  std::map<long, std::vector<SweepRow>> finished;
  long next_block = first_block, next_delivery = first_block;
  bool stopping = false;
  std::exception_ptr failure;
  std::atomic<long> done{0};
  std::mutex progress_mutex;

  auto work = [&] {
    try {
      while (true) {
        long b = 0;
        {
          std::unique_lock<std::mutex> lock(mutex);
          changed.wait(lock, [&] { return stopping || next_block >= blocks || next_block < next_delivery + window; });
          if (stopping || next_block >= blocks) return;
          b = next_block++;
        }
        std::vector<SweepRow> rows;
        Continuation continuation;
        for (long i = b * block; i < std::min(end, (b + 1) * block); ++i) {
          rows.push_back(sweep_row(point(i), family, continuation, options.settle));
          const long finished_points = ++done;
          if (options.progress) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            options.progress(finished_points, end - first_block * block);
          }
        }
        std::lock_guard<std::mutex> lock(mutex);
        finished.emplace(b, std::move(rows));
        changed.notify_all();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      stopping = true;
      changed.notify_all();
    }
  };
  std::vector<std::thread> pool;
  for (long k = 0; k < threads; ++k) pool.emplace_back(work);
  auto stop_workers = [&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stopping = true;
      changed.notify_all();
    }
    for (std::thread& t : pool) t.join();
  };
  try {
    while (next_delivery < blocks) {
      std::vector<SweepRow> rows;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return failure || finished.count(next_delivery) > 0; });
        if (failure) break;
        rows = std::move(finished.at(next_delivery));
        finished.erase(next_delivery);
        ++next_delivery;
        changed.notify_all();
      }
      for (const SweepRow& r : rows) row(r);
    }
  } catch (...) {
    stop_workers();
    throw;
  }
  stop_workers();
  if (failure) std::rethrow_exception(failure);
  if (summary) {
    summary->validated_samples = family.samples_validated();
    summary->failed_samples = family.samples_failed();
    summary->covered_branches = family.covered_branches();
  }
}

std::vector<SweepRow> run_sweep(const std::vector<SweepPoint>& points, const SweepOptions& options, SweepSummary* summary) {
  std::vector<SweepRow> rows;
  rows.reserve(points.size());
  run_sweep_streamed(
      static_cast<long>(points.size()), [&points](long i) { return points[static_cast<std::size_t>(i)]; }, options,
      [&rows](const SweepRow& r) { rows.push_back(r); }, summary);
  return rows;
}

}  // namespace backlash::numeric
