// backlash/symbolic/escape.hpp — text from outside (a case file's `name`, the
// ledger's causes) made safe for each output language.
//
//   LaTeX      text mode: \ { } $ & % # _ ^ ~ < > escaped, line breaks and
//              control characters become spaces, NUL is dropped, the Greek
//              letters and symbols the project writes (θ, θ̇, φ, η, ω, ≤, −, …)
//              become math; any other non-ASCII character becomes "?" (pdflatex
//              cannot typeset arbitrary Unicode).
//   Markdown   one line: Markdown's punctuation (\ ` * _ [ ] < > | $ # ~)
//              backslash-escaped, line breaks and control characters → spaces.
//   CSV        RFC 4180: a field with , " CR or LF is quoted, quotes doubled.
//   C++        a string literal: \" \\ \n \r \t and every other control byte
//              as a three-digit octal escape (a NUL stays visible and cannot
//              end the literal early); a one-line comment: no line breaks.
//   JSON       nlohmann escapes; only invalid UTF-8 must be repaired first
//              (replaced by U+FFFD), else dump() throws.
#pragma once

#include <string>
#include <string_view>

namespace backlash::symbolic::escape {

std::string latex_text(std::string_view text);
std::string markdown_text(std::string_view text);
std::string csv_field(std::string_view text);
std::string cpp_string_literal(std::string_view text);
std::string cpp_comment(std::string_view text);
/// Invalid UTF-8 sequences replaced by U+FFFD.
std::string valid_utf8(std::string_view text);

}  // namespace backlash::symbolic::escape
