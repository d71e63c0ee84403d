// backlash/output/text.hpp — small text helpers shared by the writers and readers, written
// once: a number read from a whole text (flags, CSV cells), a number written as printf's "%.Ng"
// writes it (gnuplot's data), a TOML basic string (case files) and a POSIX shell word (the
// commands run for gnuplot and pdflatex).
#pragma once

#include <string>
#include <string_view>

namespace backlash::output {

/// How a whole text reads as a double.
enum class NumberText {
  ok,            ///< a finite double (subnormals included: the caller may refuse them)
  empty,         ///< no characters
  not_a_number,  ///< anything but one decimal number (no spaces, no hex, at most one leading sign)
  too_large,     ///< beyond ±1.8e308 in size
  too_small,     ///< nonzero but rounds to zero (below about 4.9e-324 in size)
  not_finite,    ///< nan, inf, infinity (any case, any sign)
};

/// Reads all of `text` as a decimal double, correctly rounded (std::from_chars, general
/// format; a leading '+' is allowed).  `value` is set only when the result is ok or not_finite.
NumberText read_number(std::string_view text, double& value);

/// The text std::printf("%.<digits>g", value) gives in the C locale, digits 1 … 17 — the same
/// bytes, at a fraction of printf's cost: std::to_chars in general format with that precision,
/// which the standard defines as printf's conversion (finite values; inf and nan go through
/// snprintf itself).
std::string printf_g(double value, int digits);

/// A TOML basic string holding `text`: in double quotes, '"' and '\' escaped, control
/// characters (below 0x20, and DEL) dropped so the string stays on one line and valid.
std::string toml_string(std::string_view text);

/// `text` as one word for a POSIX shell: in single quotes, each ' written as '\''.
std::string shell_word(std::string_view text);

}  // namespace backlash::output
