#include "thesis_printed.hpp"

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace backlash::testing {

using namespace GiNaC;

namespace {

struct LedgerEntry {
  std::string where, case_id, quantity, printed, exact, cause;
};

using Key = std::tuple<std::string, std::string, std::string>;

std::map<Key, LedgerEntry>& ledger() {
  static std::map<Key, LedgerEntry> entries = [] {
    std::map<Key, LedgerEntry> out;
    const toml::table file = toml::parse_file(BACKLASH_ERRATA_LEDGER);
    if (const toml::array* list = file["erratum"].as_array()) {
      for (const toml::node& node : *list) {
        const toml::table& t = *node.as_table();
        LedgerEntry e{t["where"].value_or(std::string()), t["case"].value_or(std::string()),
                      t["quantity"].value_or(std::string()), t["printed"].value_or(std::string()),
                      t["exact"].value_or(std::string()), t["cause"].value_or(std::string())};
        out[{e.where, e.case_id, e.quantity}] = e;
      }
    }
    return out;
  }();
  return entries;
}

struct DigitsGuard {
  long saved;
  explicit DigitsGuard(long digits) : saved(Digits) { Digits = digits; }
  ~DigitsGuard() { Digits = saved; }
};

// Value at 50 digits.
numeric high_precision(const ex& e) {
  DigitsGuard guard(50);
  const ex v = evalf(e);
  if (!is_a<numeric>(v)) throw std::runtime_error("not a number: " + symbolic::text(e));
  return ex_to<numeric>(v);
}

}  // namespace

numeric exact_decimal(const std::string& text) {
  std::string digits;
  int decimals = 0;
  bool after_point = false;
  bool negative = false;
  for (char c : text) {
    if (c == '-') negative = true;
    else if (c == '+') continue;
    else if (c == '.') after_point = true;
    else { digits += c; if (after_point) ++decimals; }
  }
  if (digits.empty()) throw std::invalid_argument("not a decimal: " + text);
  numeric value(digits.c_str());
  value = value / numeric(10).power(decimals);
  return negative ? -value : value;
}

namespace {

int printed_decimals(const std::string& printed) {
  const auto dot = printed.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(printed.size() - dot - 1);
}

// Decimal text ("-.125", "1.66", "0") exactly; anything else through GiNaC's parser (with Pi).
ex parse_exact(const std::string& text) {
  const bool decimal = !text.empty() && text.find_first_not_of("+-.0123456789") == std::string::npos;
  if (decimal) return exact_decimal(text);
  symtab table;
  table["Pi"] = Pi;
  parser reader(table);
  return reader(text);
}

void check(const std::string& where, const std::string& case_id, const std::string& quantity, const ex& exact_value,
           const std::string& printed, bool angle) {
  const Key key{where, case_id, quantity};
  const numeric exact_number = high_precision(exact_value);
  const numeric printed_number = high_precision(parse_exact(printed));
  numeric difference = printed_number - exact_number;
  if (angle) {  // modulo 180°
    while (difference > 90) difference -= 180;
    while (difference <= -90) difference += 180;
  }
  const double tolerance = 0.5 * std::pow(10.0, -printed_decimals(printed)) * (1 + 1e-12);
  const bool agrees = std::fabs(difference.to_double()) <= tolerance;
  std::ostringstream exact_text;
  exact_text << symbolic::text(exact_value) << " = " << exact_number.to_double();
  const auto entry = ledger().find(key);
  if (agrees) {
    EXPECT_TRUE(entry == ledger().end())
        << where << " case " << case_id << " " << quantity << ": printed " << printed << " agrees with the exact "
        << exact_text.str() << " but the errata ledger lists it (stale entry)";
    return;
  }
  if (entry == ledger().end()) {
    ADD_FAILURE() << where << " case " << case_id << " [" << quantity << "]: derivation returned " << exact_text.str()
                  << " instead of printed " << printed << ", and the errata ledger has no entry for it";
    return;
  }
  EXPECT_EQ(entry->second.printed, printed) << where << " " << quantity << ": ledger records a different printed value";
  const numeric ledger_exact = high_precision(parse_exact(entry->second.exact));
  numeric ledger_difference = ledger_exact - exact_number;
  if (angle) {
    while (ledger_difference > 90) ledger_difference -= 180;
    while (ledger_difference <= -90) ledger_difference += 180;
  }
  EXPECT_TRUE(abs(ledger_difference) < numeric("1e-40") * (1 + abs(exact_number)))
      << where << " case " << case_id << " [" << quantity << "]: derivation returned " << exact_text.str()
      << " instead of the ledger's exact value " << entry->second.exact;
  EXPECT_FALSE(entry->second.cause.empty()) << where << " " << quantity << ": ledger entry gives no likely cause";
}

}  // namespace

void expect_printed(const std::string& where, const std::string& case_id, const std::string& quantity, const ex& exact,
                    const std::string& printed, const symbolic::RadicalList& radicals) {
  check(where, case_id, quantity, symbolic::with_explicit_radicals(exact, radicals), printed, false);
}

void expect_printed_angle(const std::string& where, const std::string& case_id, const std::string& quantity,
                          const ex& exact_degrees, const std::string& printed) {
  check(where, case_id, quantity, exact_degrees, printed, true);
}

std::vector<std::string> ledger_places() {
  std::vector<std::string> places;
  for (const auto& [key, entry] : ledger()) places.push_back(entry.where);
  return places;
}

}  // namespace backlash::testing
