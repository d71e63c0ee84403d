// Tables 4, 9, 12–13, 15–16, 20–21, 24–25, 27–28, 30–31: the states at
// recombination on each case's dividing lines, computed exactly (certified
// first crossing on the validated closed forms), against every printed state
// of the thesis's tables; every deviation beyond the printed precision is in
// reports/errata/dividing_line_tables.toml with a likely cause.
#include "printed_tables.hpp"

#include "backlash/numeric/dividing_lines.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

namespace {

using namespace backlash;
using backlash::testing::PrintedCell;

const numeric::ValidatedEvaluator& validated(const std::string& case_id) { return backlash::testing::validated_thesis_case(case_id); }

double quantity_of(const numeric::DividingLinePoint& p, const std::string& quantity) {
  if (quantity == "t" || quantity == "t (load part)") return p.t;
  if (quantity == "theta_m") return p.theta_m;
  if (quantity == "dtheta_m") return p.dtheta_m;
  if (quantity == "theta_L") return p.theta_L;
  if (quantity == "dtheta_L") return p.dtheta_L;
  if (quantity == "dtheta_o") return p.dtheta_o;
  if (quantity == "theta_m - 1") return p.theta_m - 1;
  if (quantity == "theta_L - 1") return p.theta_L - 1;
  if (quantity == "theta_o - 1") return p.theta_o - 1;
  ADD_FAILURE() << "unknown quantity " << quantity;
  return 0;
}

void check_table(const std::string& table) {
  const std::vector<PrintedCell> cells = backlash::testing::printed_cells(table);
  ASSERT_FALSE(cells.empty()) << "no transcribed cells for " << table;
  for (const PrintedCell& cell : cells) {
    const double v0 = backlash::testing::printed_number(cell.v0);
    const numeric::DividingLinePoint point = numeric::dividing_line_point(validated(cell.case_id), v0);
    const std::string quantity = cell.quantity + " at dtheta_m0=" + cell.v0;
    const double value = point.status == numeric::RecombinationStatus::Recombination
                             ? quantity_of(point, cell.quantity)
                             : std::numeric_limits<double>::quiet_NaN();  // no such recombination
    backlash::testing::expect_printed_value("dividing_line_tables.toml", table, cell.case_id, quantity,
                                            value, cell.printed);
  }
}

TEST(Table4_CaseI_DividingLines, StatesAtRecombination) { check_table("Table4"); }
TEST(Table4_CaseI_DividingLines, NoRecombinationBelowTheThreshold) {
  const numeric::DividingLines lines = numeric::trace_dividing_lines(validated("I"), {0.13, 0.146, 0.147});
  ASSERT_TRUE(lines.threshold.has_value());
  EXPECT_NEAR(*lines.threshold, 0.146149, 5e-7) << "threshold returned " << *lines.threshold;
  EXPECT_EQ(lines.points[0].status, numeric::RecombinationStatus::NoRecombination);
  EXPECT_EQ(lines.points[1].status, numeric::RecombinationStatus::NoRecombination);
  EXPECT_EQ(lines.points[2].status, numeric::RecombinationStatus::Recombination);
}
TEST(Table9_CaseII_DividingLines, StatesAtRecombination) { check_table("Table9"); }
TEST(Table12_CaseIII_DividingLines, MotorAtRecombination) { check_table("Table12"); }
TEST(Table13_CaseIII_DividingLines, RecombinedState) { check_table("Table13"); }
TEST(Table15_CaseIV_DividingLines, MotorAtRecombination) { check_table("Table15"); }
TEST(Table16_CaseIV_DividingLines, RecombinedState) { check_table("Table16"); }
TEST(Table20_CaseV_DividingLines, MotorAndLoadAtRecombination) { check_table("Table20"); }
TEST(Table21_CaseV_DividingLines, RecombinedVelocity) { check_table("Table21"); }
TEST(Table24_CaseVI_DividingLines, MotorAndLoadAtRecombination) { check_table("Table24"); }
TEST(Table25_CaseVI_DividingLines, RecombinedVelocity) { check_table("Table25"); }
TEST(Table27_CaseVII_DividingLines, MotorAndLoadAtRecombination) { check_table("Table27"); }
TEST(Table28_CaseVII_DividingLines, RecombinedVelocity) { check_table("Table28"); }
TEST(Table30_CaseVIII_DividingLines, MotorAndLoadAtRecombination) { check_table("Table30"); }
TEST(Table31_CaseVIII_DividingLines, RecombinedVelocity) { check_table("Table31"); }

}  // namespace

namespace {

// The dividing line is traced from one certified profile of the unit flight (gap linear in
// θ̇m0); each point is also found by its own certified search: both must agree.
TEST(DividingLinesAllCases, ProfileAndPointwiseSearchesAgree) {
  std::vector<double> grid;
  for (int k = 0; k <= 60; ++k) grid.push_back(0.005 * std::pow(400.0, k / 60.0));
  for (const std::string& id : model::thesis_case_ids()) {
    const numeric::DividingLines lines = numeric::trace_dividing_lines(validated(id), grid);
    for (const numeric::DividingLinePoint& p : lines.points) {
      const numeric::DividingLinePoint q = numeric::dividing_line_point(validated(id), p.dtheta_m0);
      ASSERT_EQ(p.status, q.status) << "case " << id << " v0 = " << p.dtheta_m0;
      EXPECT_NEAR(p.t, q.t, 1e-11 * std::max(1.0, q.t)) << "case " << id << " v0 = " << p.dtheta_m0;
    }
  }
}

}  // namespace
