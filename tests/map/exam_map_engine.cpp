// Design-space maps through the facade (api/map.hpp; docs/design.md, "Design-space maps"):
// known answers (a one-axis map is the sweep, the thesis case V is a point of a grid, the Sobol
// sequence's first points), thread independence, resume equality, the boundary root against a
// fine bracket, bad input.
#include "backlash/api/map.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using namespace backlash;

fs::path scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("backlash-map-engine-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    fs::remove_all(fs::temp_directory_path() / ("backlash-map-engine-" + std::to_string(::getpid())), ignored);
  }
} cleanup;

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string map_text(const api::MapRequest& r) {
  std::string out = api::map_csv_header(api::MapPlan(r));
  api::run_map(r, [&out](const api::MapRow& row) { out += api::map_csv_row(row); });
  return out;
}

api::MapRequest request(std::vector<std::string> vary, int threads = 2) {
  api::MapRequest r;
  r.target = "V";
  for (const std::string& v : vary) r.vary.push_back(api::parse_vary(v));
  r.threads = threads;
  return r;
}

TEST(MapKnownAnswers, exam_one_axis_map_is_the_sweep_bit_for_bit) {
  api::SweepRequest s;
  s.target = "V";
  s.vary = "FL_over_F";
  s.from = 0.05, s.to = 0.95, s.points = 40;
  const api::Sweep sweep = api::sweep(s);
  std::vector<api::MapRow> rows;
  api::run_map(request({"FL_over_F=0.05:0.95:40"}), [&rows](const api::MapRow& r) { rows.push_back(r); });
  ASSERT_EQ(rows.size(), sweep.rows.size());
  int cycles = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const numeric::SweepRow& a = rows[i].row;
    const numeric::SweepRow& b = sweep.rows[i];
    EXPECT_EQ(rows[i].x[0], b.point.x) << "point " << i << ": returned x " << rows[i].x[0] << " instead of " << b.point.x;
    EXPECT_EQ(api::status_of(a), api::status_of(b)) << "point " << i;
    EXPECT_EQ(a.cycle.peak_to_peak, b.cycle.peak_to_peak)
        << "point " << i << ": returned " << a.cycle.peak_to_peak << " instead of " << b.cycle.peak_to_peak;
    EXPECT_EQ(a.cycle.period, b.cycle.period) << "point " << i;
    EXPECT_EQ(a.cycle.multiplier, b.cycle.multiplier) << "point " << i;
    EXPECT_EQ(a.branches, b.branches) << "point " << i;
    cycles += api::status_of(a) == "limit_cycle";
  }
  EXPECT_GT(cycles, 0) << "returned no limit cycle instead of some along FL/F (thesis fig. 31)";
}

TEST(MapKnownAnswers, exam_thesis_case_V_is_a_grid_point) {
  // K ∈ {0.5, 1}, b ∈ {0.3, 0.6}: the point (K = 1, b = 0.3) is case V itself, in doubles.
  std::vector<api::MapRow> rows;
  api::run_map(request({"K=0.5:1:2", "backlash=0.3:0.6:2"}), [&rows](const api::MapRow& r) { rows.push_back(r); });
  ASSERT_EQ(rows.size(), 4u);
  const api::MapRow& v = rows[2];
  ASSERT_EQ(v.x, (std::vector<double>{1.0, 0.3}));
  const api::Cycle expected = api::Model(api::load("V")).limit_cycle();
  ASSERT_EQ(expected.status(), "limit_cycle");
  ASSERT_EQ(api::status_of(v.row), "limit_cycle") << v.row.reason;
  // The model uses case V's generated evaluator, the map the parametric one: the same closed
  // forms evaluated by two codes (agreeing to ~1e-12 in the validation gate).
  EXPECT_NEAR(v.row.cycle.peak_to_peak, expected.cycle.peak_to_peak, 1e-9 * expected.cycle.peak_to_peak)
      << "returned " << v.row.cycle.peak_to_peak << " instead of " << expected.cycle.peak_to_peak;
  EXPECT_NEAR(v.row.cycle.period, expected.cycle.period, 1e-9 * expected.cycle.period)
      << "returned " << v.row.cycle.period << " instead of " << expected.cycle.period;
  EXPECT_EQ(v.row.settle.status, "settled") << "returned " << v.row.settle.status << " instead of settled";
  EXPECT_GT(v.row.settle.time, 0);
  EXPECT_LT(v.row.settle.time, 60);
}

TEST(MapKnownAnswers, exam_settle_time_of_the_rigid_drive_is_the_linear_two_percent_time) {
  // b = 0: case V is the linear loop θo'' + 0.4 θo' + θo = θR (J = 1, F = 0.4, K = 1), from rest at
  // θo = θR − 0.62.  Its error e(t) = −A e^(−ζt)(cos ωd t + ζ/ωd sin ωd t), ζ = 0.2, ωd = √(1 − ζ²);
  // the settle time is the first t_k = k·60/2000 after which |e| <= 0.02·A at every t_k
  // (numeric/settle.hpp; no rest within 60 s: the band is θR ± tol).
  std::vector<api::MapRow> rows;
  api::run_map(request({"backlash=0:0:1"}), [&rows](const api::MapRow& r) { rows.push_back(r); });
  ASSERT_EQ(rows.size(), 1u);
  const double A = 0.62, zeta = 0.2, wd = std::sqrt(1 - zeta * zeta);
  auto e = [&](double t) { return -A * std::exp(-zeta * t) * (std::cos(wd * t) + zeta / wd * std::sin(wd * t)); };
  long k = 2000;
  while (k > 0 && std::fabs(e(static_cast<double>(k - 1) * 60 / 2000)) <= 0.02 * A) --k;
  const double expected = static_cast<double>(k) * 60 / 2000;
  EXPECT_EQ(api::status_of(rows[0].row), "none") << rows[0].row.reason;
  EXPECT_EQ(rows[0].row.settle.status, "settled");
  EXPECT_EQ(rows[0].row.settle.time, expected) << "returned " << rows[0].row.settle.time << " instead of " << expected;
}

TEST(MapKnownAnswers, exam_sobol_points_are_boost_s_sequence) {
  api::MapRequest r = request({"K=1:2:1", "backlash=0:1:1"});
  r.sample = "sobol";
  r.points = 4;
  const api::MapPlan plan(r);
  // Boost's Sobol sequence skips the zero point: (1/2, 1/2), (3/4, 1/4), (1/4, 3/4), (3/8, 3/8) (the Joe–Kuo
  // sequence, as SciPy's unscrambled qmc.Sobol prints it after its zero point).
  // K = 1 + u: exact in binary.
  const std::vector<std::vector<double>> expected = {{1.5, 0.5}, {1.75, 0.25}, {1.25, 0.75}, {1.375, 0.375}};
  for (long i = 0; i < 4; ++i)
    EXPECT_EQ(plan.values(i), expected[static_cast<std::size_t>(i)])
        << "point " << i << ": returned (" << plan.values(i)[0] << ", " << plan.values(i)[1] << ")";
}

TEST(MapProperties, check_latin_hypercube_fills_every_stratum_once) {
  for (const long n : {1L, 7L, 64L, 1000L}) {
    api::MapRequest r = request({"K=0.5:2", "backlash=0.1:0.5", "FL_over_F=0:1"});
    r.sample = "lhs";
    r.points = n;
    const api::MapPlan plan(r);
    for (int k = 0; k < 3; ++k) {
      std::set<long> strata;
      const api::MapAxis& a = r.vary[static_cast<std::size_t>(k)];
      for (long i = 0; i < n; ++i) {
        const double u = (plan.values(i)[static_cast<std::size_t>(k)] - a.from) / (a.to - a.from);
        strata.insert(std::min(n - 1, static_cast<long>(std::floor(u * static_cast<double>(n)))));
      }
      EXPECT_EQ(static_cast<long>(strata.size()), n)
          << "n = " << n << ", axis " << k << ": returned " << strata.size() << " strata instead of " << n;
    }
  }
}

TEST(MapProperties, check_rows_do_not_depend_on_the_thread_count) {
  const std::string one = map_text(request({"JL_over_Jm=0.5:3:5", "FL_over_F=0.1:0.9:9"}, 1));
  const std::string three = map_text(request({"JL_over_Jm=0.5:3:5", "FL_over_F=0.1:0.9:9"}, 3));
  EXPECT_EQ(one, three) << "returned different rows for 1 and 3 threads";
  EXPECT_EQ(std::count(one.begin(), one.end(), '\n'), 46);
}

TEST(MapBoundary, exam_root_lies_inside_a_fine_bracket) {
  api::MapRequest r = request({"Fm=0.1:1:10"});
  const api::MapPlan plan(r);
  std::vector<std::string> status;
  api::run_map(r, [&status](const api::MapRow& row) { status.push_back(api::status_of(row.row)); });
  int found = 0;
  for (long i = 0; i + 1 < plan.count(); ++i) {
    const std::string& s = status[static_cast<std::size_t>(i)];
    const std::string& u = status[static_cast<std::size_t>(i + 1)];
    if (s == u || (s != "limit_cycle" && s != "none") || (u != "limit_cycle" && u != "none")) continue;
    ++found;
    const api::MapBoundaryRow b = api::solve_boundary(plan, 0, i, i + 1, s == "limit_cycle");
    ASSERT_EQ(b.kind.find("unresolved"), std::string::npos) << b.kind;
    EXPECT_LT(b.high - b.low, 1e-9 * std::fabs(b.high)) << "returned a bracket [" << b.low << ", " << b.high << "]";
    // A fine bracket around the root: cold single points just below and above it.
    const double h = 1e-6, root = b.x[0];
    auto cycle_at = [&](double x) {
      api::MapRequest one = request({"Fm=0:1:1"});
      one.vary[0].from = one.vary[0].to = x;
      bool cycle = false;
      api::run_map(one, [&cycle](const api::MapRow& row) { cycle = api::status_of(row.row) == "limit_cycle"; });
      return cycle;
    };
    char lo[64], hi[64];
    std::snprintf(lo, sizeof lo, "%.17g", root - h);
    std::snprintf(hi, sizeof hi, "%.17g", root + h);
    const bool below = cycle_at(std::stod(lo)), above = cycle_at(std::stod(hi));
    EXPECT_EQ(below, s == "limit_cycle") << "at the root - 1e-6 (" << lo << "): returned cycle=" << below;
    EXPECT_EQ(above, u == "limit_cycle") << "at the root + 1e-6 (" << hi << "): returned cycle=" << above;
  }
  EXPECT_GT(found, 0) << "returned no cycle/no-cycle change along Fm in [0.1, 1] instead of one (case V loses its cycle near Fm = 0.5)";
}

TEST(MapOutput, exam_resumed_map_is_byte_identical) {
  api::MapRequest r = request({"JL_over_Jm=0.5:2:3", "FL_over_F=0.1:0.9:30"});
  r.block = 8;
  api::MapOutput whole;
  whole.out = scratch() / "whole";
  const api::MapSummary a = api::write_map(r, whole);
  ASSERT_TRUE(a.complete);
  api::MapOutput part = whole;
  part.out = scratch() / "resumed";
  part.stop_after = 21;  // inside the third block: the block is cut off and recomputed
  const api::MapSummary first = api::write_map(r, part);
  EXPECT_FALSE(first.complete);
  EXPECT_FALSE(fs::exists(part.out)) << "an interrupted map must not appear under --out";
  part.stop_after = -1;
  part.resume = true;
  r.threads = 1;  // a resume may use other threads
  const api::MapSummary second = api::write_map(r, part);
  ASSERT_TRUE(second.complete);
  EXPECT_EQ(second.resumed_from, 16) << "returned " << second.resumed_from << " instead of 16 (two blocks of 8 kept)";
  for (const char* file : {"points.csv", "boundary.csv", "map.h5", "map.json"})
    EXPECT_EQ(slurp(whole.out / file), slurp(part.out / file)) << file << ": the resumed map differs";
  EXPECT_FALSE(fs::exists(scratch() / ".resumed.map-partial")) << "the partial folder was left behind";
  const std::string csv = slurp(whole.out / "points.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 91) << "returned " << std::count(csv.begin(), csv.end(), '\n')
                                                           << " lines instead of 91 (a header and 90 points)";
}

// --out through the output layer (backlash/output/staged_directory.hpp): refusals are BadInput
// "out" in the words the map has always used; an earlier map is replaced whole, with the marker
// "written by backlash map", and nothing is left beside it.
TEST(MapOutput, check_out_refusals_and_the_replacement_of_an_earlier_map) {
  auto problem = [](const fs::path& out) -> std::string {
    api::MapOutput o;
    o.out = out;
    try {
      api::write_map(request({"K=1:2:3"}), o);
    } catch (const api::BadInput& e) {
      return e.argument() + ": " + e.problem();
    }
    return "(nothing thrown)";
  };
  EXPECT_EQ(problem(""), "out: empty path");
  EXPECT_EQ(problem("/"), "out: /: not a folder name");
  const fs::path foreign = scratch() / "foreign";
  fs::create_directories(foreign);
  std::ofstream(foreign / "keep.txt") << "mine\n";
  EXPECT_EQ(problem(foreign),
            "out: " + foreign.string() + ": the folder exists and is not a backlash output; choose a new folder");
  EXPECT_EQ(slurp(foreign / "keep.txt"), "mine\n") << "a folder that is not a backlash output was touched";
  api::MapOutput o;
  o.out = scratch() / "again";
  ASSERT_TRUE(api::write_map(request({"K=1:2:3"}), o).complete);
  ASSERT_TRUE(api::write_map(request({"K=1:2:4"}), o).complete);
  EXPECT_EQ(slurp(o.out / ".backlash-report"), "written by backlash map\n");
  const std::string csv = slurp(o.out / "points.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << "the earlier map was not replaced: " << csv;
  for (const fs::directory_entry& e : fs::directory_iterator(scratch()))
    EXPECT_EQ(e.path().filename().string().rfind(".again.", 0), std::string::npos) << e.path() << " was left behind";
}

TEST(MapBadInput, exam_bad_requests_name_their_argument) {
  auto argument = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const api::BadInput& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.argument();
    }
    return "(nothing thrown)";
  };
  EXPECT_EQ(argument([] { api::parse_vary("K"); }), "vary");
  EXPECT_EQ(argument([] { api::parse_vary("Kx=1:2:3"); }), "vary");
  EXPECT_EQ(argument([] { api::parse_vary("K=1:x:3"); }), "vary");
  EXPECT_EQ(argument([] { api::parse_vary("K=1:2:0"); }), "vary");
  EXPECT_EQ(argument([] { api::MapPlan(request({"K=-1:2:3"})); }), "vary");
  EXPECT_EQ(argument([] { api::MapPlan(request({"K=1:2:3", "K=1:2:3"})); }), "vary");
  EXPECT_EQ(argument([] { api::MapPlan(request({"JL_over_Jm=1:2:3", "JL=1:2:3"})); }), "vary");
  EXPECT_EQ(argument([] { api::MapPlan(request({"K=1:2:3"}, 0)); }), "threads");
  EXPECT_EQ(argument([] {
              api::MapRequest r = request({"K=1:2:3"});
              r.sample = "sobol";
              api::MapPlan plan(r);
            }),
            "points");
  EXPECT_EQ(argument([] {
              api::MapRequest r = request({"K=1:2:3"});
              r.sample = "random";
              api::MapPlan plan(r);
            }),
            "sample");
  EXPECT_EQ(argument([] {
              api::MapOutput o;
              o.out = scratch() / "missing-folder" / "map";
              api::write_map(request({"K=1:2:3"}), o);
            }),
            "out");
  EXPECT_FALSE(fs::exists(scratch() / "missing-folder"));
  // --resume of another request: refused, the partial folder of the first left as it was.
  api::MapOutput o;
  o.out = scratch() / "other";
  o.stop_after = 3;
  EXPECT_FALSE(api::write_map(request({"K=1:2:9"}), o).complete);
  const std::string checkpoint = slurp(api::map_partial_folder(o.out) / "checkpoint");
  o.stop_after = -1;
  o.resume = true;
  EXPECT_EQ(argument([&] { api::write_map(request({"K=1:2:10"}), o); }), "resume");
  EXPECT_EQ(slurp(api::map_partial_folder(o.out) / "checkpoint"), checkpoint);
  EXPECT_FALSE(fs::exists(o.out));
}

}  // namespace
