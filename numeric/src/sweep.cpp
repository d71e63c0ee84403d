#include "backlash/numeric/sweep.hpp"

#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/validated_family.hpp"

#include <atomic>
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

std::vector<SweepPoint> figure31_points(int n) {
  std::vector<SweepPoint> points;
  const double F = 0.4;
  for (const auto& [series, jl_over_jm] : {std::pair<std::string, double>{"JL=Jm", 1.0}, {"JL=4Jm", 4.0}}) {
    for (int i = 0; i < n; ++i) {
      const double x = n == 1 ? 0.5 : i / double(n - 1);
      Parameters p = thesis_base();
      p.Jm = 1 / (1 + jl_over_jm);
      p.JL = jl_over_jm / (1 + jl_over_jm);
      p.FL = x * F;
      p.Fm = F - p.FL;
      points.push_back({series, x, p, {}});
    }
  }
  return points;
}

std::vector<SweepPoint> figure32_points(int n) {
  struct Distribution { const char* name; double Fm, FL; };
  const Distribution distributions[] = {{"FL=0 Fm=.2", 0.2, 0.0}, {"Fm=3FL F=.4", 0.3, 0.1}, {"FL=3Fm F=.4", 0.1, 0.3}};
  std::vector<SweepPoint> points;
  for (const Distribution& d : distributions) {
    for (int i = 0; i < n; ++i) {
      const double x = n == 1 ? 1.0 : 0.1 + (4.0 - 0.1) * i / double(n - 1);
      Parameters p = thesis_base();
      p.Jm = 1 / (1 + x);
      p.JL = x / (1 + x);
      p.Fm = d.Fm;
      p.FL = d.FL;
      points.push_back({d.name, x, p, {}});
    }
  }
  return points;
}

std::vector<SweepRow> run_sweep(const std::vector<SweepPoint>& points, const SweepOptions& options, SweepSummary* summary) {
  std::vector<SweepRow> rows(points.size());
  ValidatedParametricFamily family;
  {
    std::vector<Parameters> samples;
    const size_t count = std::min<size_t>(points.size(), std::max(2, options.validation_samples));
    for (size_t k = 0; k < count; ++k)
      samples.push_back(points[count == 1 ? 0 : k * (points.size() - 1) / (count - 1)].parameters);
    family.validate_samples(samples);
  }
  std::atomic<long> done{0};
  std::mutex progress_mutex;
  const int threads = std::max(1, std::min<int>(options.threads, static_cast<int>(points.size())));
  auto work = [&](size_t begin, size_t end) {
    double guess = 0;
    std::optional<HybridState> warm;
    std::string previous_series;
    for (size_t i = begin; i < end; ++i) {
      SweepRow& row = rows[i];
      row.point = points[i];
      if (row.point.series != previous_series) guess = 0, warm.reset();
      previous_series = row.point.series;
      try {
        const std::optional<ValidatedEvaluator> evaluator = family.at(row.point.parameters);
        if (!evaluator) {
          row.status = "unvalidated";
        } else {
          const BranchSelection b = select_branches(row.point.parameters);
          row.branches = std::string(branch_name(b.contact)) + "/" + branch_name(b.free);
          if (row.point.effects.any()) {
            const EffectValidationResult gate = validate_effects(*evaluator, row.point.effects);
            if (!gate.passed()) {
              row.status = "unvalidated";
            } else {
              EffectLimitCycleOptions lc;
              lc.warm_start = warm;
              row.cycle = find_limit_cycle(gate.model(), lc);
              row.status = row.cycle.status;
              if (row.cycle.status == "limit_cycle") warm = row.cycle.section_state; else warm.reset();
            }
          } else {
            LimitCycleOptions lc;
            lc.guess = guess;
            row.cycle = find_limit_cycle(*evaluator, lc);
            row.status = row.cycle.status;
            guess = row.cycle.status == "limit_cycle" ? row.cycle.separation_velocity : 0;
          }
        }
      } catch (const std::exception& e) {
        row.status = std::string("error: ") + e.what();
        guess = 0;
      }
      const long finished = ++done;
      if (options.progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        options.progress(finished, static_cast<long>(points.size()));
      }
    }
  };
  std::vector<std::thread> pool;
  const size_t chunk = (points.size() + threads - 1) / threads;
  for (int k = 0; k < threads; ++k) {
    const size_t begin = k * chunk, end = std::min(points.size(), begin + chunk);
    if (begin < end) pool.emplace_back(work, begin, end);
  }
  for (std::thread& t : pool) t.join();
  if (summary) {
    summary->validated_samples = family.samples_validated();
    summary->failed_samples = family.samples_failed();
    summary->covered_branches = family.covered_branches();
  }
  return rows;
}

}  // namespace backlash::numeric
