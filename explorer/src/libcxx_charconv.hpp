// libcxx_charconv.hpp — the floating-point std::from_chars / std::to_chars that Debian's
// Emscripten (3.1.6, libc++ 14) lacks, force-included into the explorer's compiles only
// (explorer/CMakeLists.txt: -include).  Same contract as the standard's for what the project
// uses: from_chars(general) reads the longest prefix of the form -?digits[.digits][(e|E)[+-]digits]
// (no hex, inf, nan, leading '+' or spaces), correctly rounded (strtod), leaving the value
// alone and returning result_out_of_range when it overflows or underflows; to_chars(double)
// writes the shortest "%.*g" that reads back to the same double.  Absent when the library has
// them (__cpp_lib_to_chars).
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <system_error>
#include <version>

#if !defined(__cpp_lib_to_chars)
namespace std {

inline from_chars_result from_chars(const char* first, const char* last, double& value,
                                    chars_format = chars_format::general) {
  const char* p = first;
  auto digits = [&] { const char* s = p; while (p < last && *p >= '0' && *p <= '9') ++p; return p - s; };
  if (p < last && *p == '-') ++p;
  long count = digits();
  if (p < last && *p == '.') { ++p; count += digits(); }
  if (count == 0) return {first, errc::invalid_argument};
  if (p < last && (*p == 'e' || *p == 'E')) {
    const char* mark = p++;
    if (p < last && (*p == '+' || *p == '-')) ++p;
    if (digits() == 0) p = mark;
  }
  const std::string text(first, p);
  errno = 0;
  const double read = std::strtod(text.c_str(), nullptr);
  if (errno == ERANGE) return {p, errc::result_out_of_range};
  value = read;
  return {p, errc()};
}

inline to_chars_result to_chars(char* first, char* last, double value) {
  char buffer[40];
  int n = 0;
  for (int precision = 1; precision <= 17; ++precision) {
    n = std::snprintf(buffer, sizeof buffer, "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  if (n > last - first) return {last, errc::value_too_large};
  for (int i = 0; i < n; ++i) first[i] = buffer[i];
  return {first + n, errc()};
}

}  // namespace std
#endif
