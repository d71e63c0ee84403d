#include "printed_tables.hpp"

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <cmath>
#include <map>
#include <tuple>

namespace backlash::testing {

namespace {

struct LedgerEntry {
  std::string printed, exact_decimal, cause;
};
using Key = std::tuple<std::string, std::string, std::string>;

const std::map<Key, LedgerEntry>& ledger(const std::string& name) {
  static std::map<std::string, std::map<Key, LedgerEntry>> cache;
  auto found = cache.find(name);
  if (found != cache.end()) return found->second;
  std::map<Key, LedgerEntry> entries;
  const toml::table file = toml::parse_file(std::string(BACKLASH_ERRATA_DIR) + "/" + name);
  if (const toml::array* list = file["erratum"].as_array())
    for (const toml::node& node : *list) {
      const toml::table& t = *node.as_table();
      entries[{t["where"].value_or(std::string()), t["case"].value_or(std::string()), t["quantity"].value_or(std::string())}] =
          {t["printed"].value_or(std::string()), t["exact_decimal"].value_or(std::string()), t["cause"].value_or(std::string())};
    }
  return cache.emplace(name, std::move(entries)).first->second;
}

int decimals_of(const std::string& printed) {
  const auto dot = printed.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(printed.size() - dot - 1);
}

}  // namespace

const numeric::ValidatedEvaluator& validated_thesis_case(const std::string& case_id) {
  static std::map<std::string, numeric::ValidationResult> cache;
  auto found = cache.find(case_id);
  if (found == cache.end())
    found = cache.emplace(case_id, numeric::validate(numeric::case_evaluator(model::load_case(case_id)))).first;
  return found->second.evaluator();
}

double printed_number(const std::string& text) { return std::stod(text[0] == '.' || (text[0] == '-' && text[1] == '.') ? (text[0] == '-' ? "-0" + text.substr(1) : "0" + text) : text); }

std::vector<PrintedCell> printed_cells(const std::string& table) {
  static const toml::table data = toml::parse_file(BACKLASH_THESIS_TABLES);
  std::vector<PrintedCell> cells;
  if (const toml::array* list = data["cell"].as_array())
    for (const toml::node& node : *list) {
      const toml::table& t = *node.as_table();
      if (t["table"].value_or(std::string()) != table) continue;
      cells.push_back({table, t["case"].value_or(std::string()), t["v0"].value_or(std::string()),
                       t["quantity"].value_or(std::string()), t["printed"].value_or(std::string())});
    }
  return cells;
}

void expect_printed_value(const std::string& ledger_name, const std::string& table, const std::string& case_id,
                          const std::string& quantity, double value, const std::string& printed) {
  const auto& entries = ledger(ledger_name);
  const auto entry = entries.find({table, case_id, quantity});
  if (std::isnan(value)) {  // the printed quantity does not exist (e.g. a recombination that never happens)
    ASSERT_TRUE(entry != entries.end()) << table << " case " << case_id << " [" << quantity << "]: printed " << printed
                                        << " for a state that does not exist, and the errata ledger has no entry for it";
    EXPECT_EQ(entry->second.exact_decimal, "none");
    EXPECT_FALSE(entry->second.cause.empty());
    return;
  }
  ASSERT_TRUE(std::isfinite(value)) << table << " " << quantity << ": computed a non-finite value";
  const double tolerance = 0.5 * std::pow(10.0, -decimals_of(printed)) * (1 + 1e-9);
  const bool agrees = std::fabs(value - printed_number(printed)) <= tolerance;
  char computed[64];
  std::snprintf(computed, sizeof computed, "%.12g", value);
  if (agrees) {
    EXPECT_TRUE(entry == entries.end()) << table << " case " << case_id << " [" << quantity << "]: printed " << printed
                                        << " agrees with the computed " << computed << " but the ledger lists it (stale)";
    return;
  }
  if (entry == entries.end()) {
    ADD_FAILURE() << table << " case " << case_id << " [" << quantity << "]: computed " << computed << " instead of printed "
                  << printed << ", and the errata ledger has no entry for it";
    return;
  }
  EXPECT_EQ(entry->second.printed, printed) << table << " " << quantity << ": ledger records another printed value";
  const double ledger_value = std::stod(entry->second.exact_decimal);
  EXPECT_NEAR(ledger_value, value, 1e-8 * std::max(1.0, std::fabs(value)))
      << table << " case " << case_id << " [" << quantity << "]: computed " << computed << " instead of the ledger's "
      << entry->second.exact_decimal;
  EXPECT_FALSE(entry->second.cause.empty()) << table << " " << quantity << ": no likely cause in the ledger";
}

}  // namespace backlash::testing
