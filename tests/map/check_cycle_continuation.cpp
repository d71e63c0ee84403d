// Issue 19, "cold limit cycles from a first guess that is already close" and "maps that reuse
// their neighbours" (numeric/limit_cycle.hpp, numeric/sweep.hpp, map/map.hpp; docs/design.md):
//   - a cold search starts Newton's method from the describing function's guess, with g' from the
//     closed forms, and gives the grid survey's answer without running it (survey_fallback false);
//   - g' from the closed forms agrees with Richardson-extrapolated central differences of g;
//   - a map whose points start from their neighbour's cycle (blocks of 32 along a grid line) gives,
//     point by point, the all-cold map's answers (block 1) within 1e-10 relative, and the same
//     bytes on 1 and 2 threads;
//   - the fallbacks are counted: limit-cycle's JSON key survey_fallback, map.json's
//     survey_fallbacks, the sweep summary's count.
// Counts and agreement only, never timings (the speed: bench/time_limit_cycles, bench/map_throughput.sh).
#include "backlash/api/backlash.hpp"
#include "backlash/api/map.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace backlash;

const numeric::ValidatedEvaluator& thesis_case(const std::string& id) {
  static std::map<std::string, numeric::ValidationResult> cache;
  auto it = cache.find(id);
  if (it == cache.end()) it = cache.emplace(id, numeric::validate(numeric::case_evaluator(model::load_case(id)))).first;
  return it->second.evaluator();
}

double relative(double a, double b) { return std::fabs(a - b) / std::max(std::fabs(a), std::fabs(b)); }

// The answers of two searches of one point: the same status and, on a cycle, the same numbers
// within `tolerance` relative (Newton stops when its step is below 1e-13 v*, toms748 when its
// bracket is below 1e-13: both within 1e-12 of v*, and every other figure moves with v*).
void expect_same_cycle(const numeric::LimitCycle& a, const numeric::LimitCycle& b, double tolerance, const std::string& what) {
  ASSERT_EQ(a.status, b.status) << what;
  if (a.status != numeric::CycleStatus::LimitCycle) return;
  EXPECT_LE(relative(a.separation_velocity, b.separation_velocity), tolerance) << what;
  EXPECT_LE(relative(a.multiplier, b.multiplier), tolerance) << what;
  EXPECT_LE(relative(a.amplitude, b.amplitude), tolerance) << what;
  EXPECT_LE(relative(a.peak_to_peak, b.peak_to_peak), tolerance) << what;
  EXPECT_LE(relative(a.period, b.period), tolerance) << what;
  EXPECT_EQ(a.contact_arc_crossings_of_theta_R, b.contact_arc_crossings_of_theta_R) << what;
}

TEST(ColdLimitCycles, item_cold_start_from_the_describing_function_without_the_survey) {
  for (const std::string id : {"III", "IV", "V", "VI", "VII", "VIII"}) {
    const numeric::LimitCycle cold = numeric::find_limit_cycle(thesis_case(id));
    numeric::LimitCycleOptions survey;
    survey.survey_only = true;
    const numeric::LimitCycle surveyed = numeric::find_limit_cycle(thesis_case(id), survey);
    EXPECT_FALSE(cold.survey_fallback) << id << ": Newton from the describing function's guess did not settle";
    EXPECT_TRUE(surveyed.survey_fallback) << id;
    EXPECT_TRUE(cold.other_fixed_points.empty() && surveyed.other_fixed_points.empty()) << id;
    expect_same_cycle(cold, surveyed, 1e-10, "case " + id);
    // Warm from a neighbour 1 % away: the same cycle.
    numeric::LimitCycleOptions warm;
    warm.guess = 1.01 * cold.separation_velocity;
    expect_same_cycle(numeric::find_limit_cycle(thesis_case(id), warm), cold, 1e-10, "case " + id + " warm");
  }
}

TEST(ColdLimitCycles, item_the_fallback_is_counted_and_none_comes_from_the_survey) {
  // Cases I and II (output at the motor): no cycle — only the survey can say so, and says it.
  for (const std::string id : {"I", "II"}) {
    const numeric::LimitCycle c = numeric::find_limit_cycle(thesis_case(id));
    EXPECT_EQ(c.status, numeric::CycleStatus::None) << id;
    EXPECT_TRUE(c.survey_fallback) << id;
  }
  const nlohmann::json v = nlohmann::json::parse(api::Model(api::Case::load("V")).limit_cycle().json());
  ASSERT_TRUE(v.contains("survey_fallback"));
  EXPECT_EQ(v["survey_fallback"], false);
  const nlohmann::json i = nlohmann::json::parse(api::Model(api::Case::load("I")).limit_cycle().json());
  EXPECT_EQ(i["survey_fallback"], true);
}

TEST(ColdLimitCycles, closed_form_derivative_matches_richardson_differences) {
  // g'(v*) from the closed forms against central differences of g with steps h and 2h,
  // Richardson-extrapolated (truncation O(h⁴) ≈ 1e-16); g carries about 1e-15 of rounding, so
  // the difference quotient about 1e-15·g/h ≈ 1e-11 at h = 1e-4 v*: agreement to 1e-9.
  for (const std::string id : {"V", "VII"}) {
    const numeric::ValidatedEvaluator& e = thesis_case(id);
    const numeric::LimitCycle c = numeric::find_limit_cycle(e);
    ASSERT_EQ(c.status, numeric::CycleStatus::LimitCycle);
    const double v = c.separation_velocity, h = 1e-4 * v;
    auto g = [&](double x) { return numeric::half_cycle(e, x).v_out; };
    const double d1 = (g(v + h) - g(v - h)) / (2 * h), d2 = (g(v + 2 * h) - g(v - 2 * h)) / (4 * h);
    EXPECT_NEAR(c.half_map_derivative, (4 * d1 - d2) / 3, 1e-9) << id;
    EXPECT_DOUBLE_EQ(c.multiplier, c.half_map_derivative * c.half_map_derivative) << id;
  }
}

api::MapRequest small_map(int block, int threads) {
  api::MapRequest r;
  r.target = "V";
  r.vary = {api::parse_vary("JL_over_Jm=0.5:2:4"), api::parse_vary("FL_over_F=0:1:12")};
  r.block = block;
  r.threads = threads;
  r.step = 0;  // the settle time does not depend on the search
  return r;
}

std::vector<api::MapRow> map_rows(const api::MapRequest& r) {
  std::vector<api::MapRow> rows;
  api::run_map(r, [&rows](const api::MapRow& row) { rows.push_back(row); });
  return rows;
}

TEST(MapContinuation, item_warm_started_map_equals_the_all_cold_map) {
  const std::vector<api::MapRow> warm = map_rows(small_map(32, 1)), cold = map_rows(small_map(1, 1));
  ASSERT_EQ(warm.size(), 48u);
  ASSERT_EQ(cold.size(), warm.size());
  long cycles = 0;
  for (std::size_t k = 0; k < warm.size(); ++k) {
    expect_same_cycle(warm[k].row.cycle, cold[k].row.cycle, 1e-10, "point " + std::to_string(k));
    cycles += warm[k].row.status == numeric::SweepStatus::LimitCycle ? 1 : 0;
  }
  EXPECT_EQ(cycles, 48);  // case V keeps its cycle over this grid: every point compared
}

TEST(MapContinuation, item_same_bytes_on_one_and_two_threads) {
  auto text = [](const api::MapRequest& r) {
    std::string out = api::map_csv_header(api::MapPlan(r));
    api::run_map(r, [&out](const api::MapRow& row) { out += api::map_csv_row(row); });
    return out;
  };
  EXPECT_EQ(text(small_map(32, 1)), text(small_map(32, 2)));
}

TEST(MapContinuation, item_map_json_counts_the_survey_fallbacks) {
  // Fm from 0.1 to 1 (case V loses its cycle as the motor's friction grows): the "none" points
  // come from the survey, so map.json counts at least those.
  api::MapRequest r;
  r.target = "V";
  r.vary = {api::parse_vary("Fm=0.1:1:6")};
  r.step = 0;
  long fallbacks = 0, none = 0;
  api::run_map(r, [&](const api::MapRow& row) {
    fallbacks += row.row.cycle.survey_fallback ? 1 : 0;
    none += row.row.status == numeric::SweepStatus::None ? 1 : 0;
  });
  EXPECT_GT(none, 0);
  EXPECT_GE(fallbacks, none);
  const fs::path out = fs::temp_directory_path() / ("backlash-cycle-continuation-" + std::to_string(::getpid()));
  api::MapOutput o;
  o.out = out;
  o.figures = false;
  o.hdf5 = false;
  const api::MapSummary summary = api::write_map(r, o);
  std::ifstream in(out / "map.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::error_code ignored;
  fs::remove_all(out, ignored);
  EXPECT_EQ(j.at("survey_fallbacks"), fallbacks);
  EXPECT_EQ(summary.survey_fallbacks, fallbacks);
}

}  // namespace
