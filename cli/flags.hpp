// backlash/cli/flags.hpp — the numbers of the command line's flags, read strictly: a bad
// value is a UsageError naming the flag (exit 2).  Whether a value is in range is the
// facade's to judge (backlash/api/backlash.hpp); its BadInput names the flag (main.cpp).
// Every numeric flag of every command is read here, from the flag's text: CLI11 is given
// strings only (its own conversion takes --step 0x10 as 16 and wraps --seed -1).
#pragma once

#include "commands.hpp"

#include "backlash/output/text.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace backlash::cli {

/// A finite number (backlash/output/text.hpp: the whole text, spaces and tabs around it
/// aside, as one decimal), or UsageError naming the flag and what is wrong: not a number at
/// all, or one double precision cannot hold (beyond ±1.8e308, or nonzero below 2.2e-308 in
/// size, where it keeps fewer digits — use 0 or a larger value).
inline double parse_number(const std::string& text, const std::string& flag) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) throw UsageError(flag + ": empty value");
  const std::string trimmed = text.substr(first, text.find_last_not_of(" \t") - first + 1);
  const std::string too_small = flag + ": '" + text + "' is too small for double precision (nonzero below 2.2e-308 in "
                                "size); use 0 or a larger value";
  double value = 0;
  switch (output::read_number(trimmed, value)) {
    case output::NumberText::ok: break;
    case output::NumberText::empty:
    case output::NumberText::not_a_number: throw UsageError(flag + ": '" + text + "' is not a number");
    case output::NumberText::not_finite: throw UsageError(flag + ": '" + text + "' is not finite");
    case output::NumberText::too_large:
      throw UsageError(flag + ": '" + text + "' is too large for double precision (beyond 1.8e308)");
    case output::NumberText::too_small: throw UsageError(too_small);
  }
  if (value != 0 && !std::isnormal(value)) throw UsageError(too_small);
  return value;
}

/// A comma-separated list of numbers; empty entries are errors.
inline std::vector<double> parse_number_list(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    if (first == std::string::npos) throw UsageError(flag + ": empty entry in '" + text + "'");
    values.push_back(parse_number(item.substr(first, last - first + 1), flag));
  }
  if (values.empty() || text.back() == ',') throw UsageError(flag + ": empty entry in '" + text + "'");
  return values;
}

/// A whole number (e.g. --points 1e3), or UsageError naming the flag.
inline long parse_whole_number(const std::string& text, const std::string& flag) {
  const double v = parse_number(text, flag);
  if (v != std::floor(v)) throw UsageError(flag + ": expected a whole number, got '" + text + "'");
  if (std::fabs(v) > 9e15) throw UsageError(flag + ": '" + text + "' is too large");
  return static_cast<long>(v);
}

/// The same, for an int-sized count (larger values become the largest int, which the facade refuses).
inline int parse_whole_int(const std::string& text, const std::string& flag) {
  const long v = parse_whole_number(text, flag);
  const long largest = std::numeric_limits<int>::max();
  return static_cast<int>(v > largest ? largest : v < -largest ? -largest : v);
}

/// A key such as a seed: the digits of a whole number from 0 to 2^64 − 1, nothing else (no
/// sign, exponent or fraction: --seed -1, 1e23 and 18446744073709551616 are refused, not wrapped
/// or rounded into another key), or UsageError naming the flag.
inline std::uint64_t parse_key(const std::string& text, const std::string& flag) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || !std::isdigit(static_cast<unsigned char>(text.front())) || end != text.data() + text.size())
    throw UsageError(flag + ": expected the digits of a whole number from 0 to 18446744073709551615, got '" + text + "'");
  if (error == std::errc::result_out_of_range)
    throw UsageError(flag + ": '" + text + "' is too large (at most 18446744073709551615)");
  return value;
}

}  // namespace backlash::cli
