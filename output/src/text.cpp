// Small text helpers shared by the writers and readers (backlash/output/text.hpp).
#include "backlash/output/text.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <system_error>
#include <version>

namespace backlash::output {

std::string printf_g(double value, int digits) {
  if (digits < 1 || digits > 17) throw std::invalid_argument("printf_g: digits must be 1 ... 17");
  char text[48];
#if defined(__cpp_lib_to_chars)
  if (std::isfinite(value)) {
    const std::to_chars_result result = std::to_chars(text, text + sizeof text, value, std::chars_format::general, digits);
    return std::string(text, result.ptr);
  }
#endif  // else the explorer's libc++ 14, which lacks it (explorer/src/libcxx_charconv.hpp): printf itself
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

NumberText read_number(std::string_view text, double& value) {
  if (text.empty()) return NumberText::empty;
  std::string_view digits = text;
  if (digits.front() == '+') {
    digits.remove_prefix(1);
    if (digits.empty() || digits.front() == '+' || digits.front() == '-') return NumberText::not_a_number;
  }
  const char* const end = digits.data() + digits.size();
  double read = 0;
  const std::from_chars_result result = std::from_chars(digits.data(), end, read, std::chars_format::general);
  if (result.ptr != end) return NumberText::not_a_number;
  if (result.ec == std::errc::result_out_of_range) {
    // from_chars leaves the value alone: strtod (the same number, checked above) says which end.
    const std::string copy(digits);
    return std::isinf(std::strtod(copy.c_str(), nullptr)) ? NumberText::too_large : NumberText::too_small;
  }
  if (result.ec != std::errc()) return NumberText::not_a_number;
  value = read;
  return std::isfinite(read) ? NumberText::ok : NumberText::not_finite;
}

std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) continue;
    out += c;
  }
  return out + "\"";
}

std::string shell_word(std::string_view text) {
  std::string out = "'";
  for (const char c : text) out += (c == '\'' ? std::string("'\\''") : std::string(1, c));
  return out + "'";
}

}  // namespace backlash::output
