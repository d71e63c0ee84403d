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
#include <optional>
#include <ostream>
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

const char* to_string(SweepStatus status) {
  switch (status) {
    case SweepStatus::LimitCycle: return "limit_cycle";
    case SweepStatus::None: return "none";
    case SweepStatus::Divergent: return "divergent";
    case SweepStatus::Unvalidated: return "unvalidated";
    case SweepStatus::Refused: return "refused";
    case SweepStatus::Error: return "error";
    case SweepStatus::Unresolved: return "unresolved";
  }
  return "error";
}

std::ostream& operator<<(std::ostream& out, SweepStatus status) { return out << to_string(status); }

SweepStatus sweep_status(CycleStatus status) {
  switch (status) {
    case CycleStatus::LimitCycle: return SweepStatus::LimitCycle;
    case CycleStatus::None: return SweepStatus::None;
    case CycleStatus::Divergent: return SweepStatus::Divergent;
    case CycleStatus::Unresolved: return SweepStatus::Unresolved;
  }
  return SweepStatus::Error;
}

namespace {

// The warm start a block carries from point to point (continuation): the cycle, and the
// separation at which the settle run stopped on it (SettleOptions::expected_separation).
struct Continuation {
  double guess = 0;
  long settle_separation = 0;
  std::optional<HybridState> warm;
  std::string series;
  bool first = true;
};

SweepRow sweep_row(const SweepPoint& point, const ValidatedParametricFamily& family, Continuation& c,
                   const SettleOptions& settle) {
  SweepRow row;
  row.point = point;
  if (c.first || point.series != c.series) c.guess = 0, c.warm.reset(), c.settle_separation = 0;
  c.first = false;
  c.series = point.series;
  Parameters q = point.parameters;  // error coordinates: θR = 0
  const double reference = q.theta_R;
  q.theta_R = 0;
  try {
    std::optional<std::string> problem = parameter_scale_problem(q);
    if (!problem) problem = effect_scale_problem(q, point.effects);
    if (problem) {
      row.status = SweepStatus::Refused;
      row.reason = *problem;
      c.guess = 0, c.warm.reset();
      return row;
    }
    const ValidatedParametricFamily::Verdict verdict = family.judge(q);
    if (!verdict.evaluator) {
      row.status = SweepStatus::Unvalidated;
      row.reason = verdict.reason;
      c.guess = 0, c.warm.reset();
      return row;
    }
    const BranchSelection b = select_branches(q);
    row.branches = std::string(branch_name(b.contact)) + "/" + branch_name(b.free);
    if (point.effects.any()) {
      const EffectValidationResult gate = validate_effects(*verdict.evaluator, point.effects);
      if (!gate.passed()) {
        row.status = SweepStatus::Unvalidated;
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
      if (row.cycle.status == CycleStatus::LimitCycle) c.warm = row.cycle.section_state; else c.warm.reset();
      if (settle.step != 0) row.settle = settle_time(gate.model(), row.cycle, settle);
    } else {
      LimitCycleOptions lc;
      lc.guess = c.guess;
      row.cycle = find_limit_cycle(*verdict.evaluator, lc);
      c.guess = row.cycle.status == CycleStatus::LimitCycle ? row.cycle.separation_velocity : 0;
      if (settle.step != 0) {
        SettleOptions o = settle;
        o.expected_separation = c.settle_separation;
        row.settle = settle_time(*verdict.evaluator, row.cycle, o);
        c.settle_separation = row.settle.stopped_separation;
      }
    }
    shift_angles(row.cycle, reference);
    row.settle.band_low += reference, row.settle.band_high += reference;
    row.status = sweep_status(row.cycle.status);
    row.reason = row.cycle.reason;
  } catch (const std::exception& e) {
    row.status = SweepStatus::Error;
    row.reason = e.what();
    c.guess = 0, c.warm.reset();
  }
  return row;
}

// The family: validated at `validation_samples` evenly spaced points on the sweep's threads
// (deterministic: recorded in order, before any worker starts); points whose parameters double
// precision cannot handle are left out.
void validate_family(ValidatedParametricFamily& family, long count, const std::function<SweepPoint(long)>& point,
                     int validation_samples, int threads) {
  std::vector<Parameters> samples;
  const long k_count = std::min<long>(count, std::max(2, validation_samples));
  for (long k = 0; k < k_count; ++k) {
    const long index = k_count == 1 ? 0 : static_cast<long>(static_cast<long double>(k) * (count - 1) / (k_count - 1));
    Parameters q = point(index).parameters;
    q.theta_R = 0;
    if (!parameter_scale_problem(q)) samples.push_back(q);
  }
  family.validate_samples(samples, threads);
}

// The blocks between the workers and the delivering thread: a worker takes the next block while
// it is fewer than `window` blocks ahead of delivery (memory stays bounded), hands its rows back,
// and the rows are delivered in block order.  A failure (a worker's exception) stops everything.
class BlockQueue {
 public:
  BlockQueue(long first_block, long blocks, long window)
      : blocks_(blocks), window_(window), next_block_(first_block), next_delivery_(first_block) {}
  /// The next block to compute, or nothing when done or stopping.
  std::optional<long> take() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return stopping_ || next_block_ >= blocks_ || next_block_ < next_delivery_ + window_; });
    if (stopping_ || next_block_ >= blocks_) return std::nullopt;
    return next_block_++;
  }
  void put(long block, std::vector<SweepRow> rows) {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_.emplace(block, std::move(rows));
    changed_.notify_all();
  }
  void fail(std::exception_ptr failure) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failure_) failure_ = failure;
    stopping_ = true;
    changed_.notify_all();
  }
  /// The rows of the next block in order, or nothing after a failure or the last block.
  std::optional<std::vector<SweepRow>> next() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (next_delivery_ >= blocks_) return std::nullopt;
    changed_.wait(lock, [&] { return failure_ || finished_.count(next_delivery_) > 0; });
    if (failure_) return std::nullopt;
    std::vector<SweepRow> rows = std::move(finished_.at(next_delivery_));
    finished_.erase(next_delivery_);
    ++next_delivery_;
    changed_.notify_all();
    return rows;
  }
  void stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    changed_.notify_all();
  }
  std::exception_ptr failure() {
    std::lock_guard<std::mutex> lock(mutex_);
    return failure_;
  }

 private:
  const long blocks_, window_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<long, std::vector<SweepRow>> finished_;
  long next_block_, next_delivery_;
  bool stopping_ = false;
  std::exception_ptr failure_;
};

}  // namespace

std::shared_ptr<const ValidatedParametricFamily> sweep_family(long count, const std::function<SweepPoint(long)>& point,
                                                              const SweepOptions& options) {
  auto family = std::make_shared<ValidatedParametricFamily>();
  validate_family(*family, count, point, options.validation_samples, options.threads);
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
  BlockQueue queue(first_block, blocks, 4 * threads);  // blocks computed ahead of the one being delivered
  std::atomic<long> done{0};
  std::mutex progress_mutex;
  auto work = [&] {
    try {
      while (const std::optional<long> b = queue.take()) {
        std::vector<SweepRow> rows;
        Continuation continuation;
        for (long i = *b * block; i < std::min(end, (*b + 1) * block); ++i) {
          rows.push_back(sweep_row(point(i), family, continuation, options.settle));
          const long finished_points = ++done;
          if (options.progress) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            options.progress(finished_points, end - first_block * block);
          }
        }
        queue.put(*b, std::move(rows));
      }
    } catch (...) {
      queue.fail(std::current_exception());
    }
  };
  std::vector<std::thread> pool;
  for (long k = 0; k < threads; ++k) pool.emplace_back(work);
  auto stop_workers = [&] {
    queue.stop();
    for (std::thread& t : pool) t.join();
  };
  long survey_fallbacks = 0;
  try {
    while (const std::optional<std::vector<SweepRow>> rows = queue.next())
      for (const SweepRow& r : *rows) {
        survey_fallbacks += r.cycle.survey_fallback ? 1 : 0;
        row(r);
      }
  } catch (...) {
    stop_workers();
    throw;
  }
  stop_workers();
  if (const std::exception_ptr failure = queue.failure()) std::rethrow_exception(failure);
  if (summary) {
    summary->validated_samples = family.samples_validated();
    summary->failed_samples = family.samples_failed();
    summary->covered_branches = family.covered_branches();
    summary->survey_fallbacks = survey_fallbacks;
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
