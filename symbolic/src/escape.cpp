#include "backlash/symbolic/escape.hpp"

#include <cstdio>
#include <map>

namespace backlash::symbolic::escape {

namespace {

// Decodes one UTF-8 code point at text[i]; returns its length (0: invalid byte).
std::size_t decode(std::string_view text, std::size_t i, char32_t& code) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  std::size_t length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
  if (length == 0 || i + length > text.size()) return 0;
  code = length == 1 ? c : (length == 2 ? c & 0x1F : (length == 3 ? c & 0x0F : c & 0x07));
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) >> 6) != 0x2) return 0;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  if ((length == 2 && code < 0x80) || (length == 3 && code < 0x800) || (length == 4 && code < 0x10000) || code > 0x10FFFF ||
      (code >= 0xD800 && code <= 0xDFFF))
    return 0;
  return length;
}

}  // namespace

std::string valid_utf8(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    char32_t code = 0;
    const std::size_t length = decode(text, i, code);
    if (length == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out;
}

std::string latex_text(std::string_view text) {
  static const std::map<char32_t, std::string> symbols{
      {U'θ', "\\ensuremath{\\theta}"}, {U'Θ', "\\ensuremath{\\Theta}"}, {U'φ', "\\ensuremath{\\varphi}"},
      {U'η', "\\ensuremath{\\eta}"},   {U'ω', "\\ensuremath{\\omega}"}, {U'δ', "\\ensuremath{\\delta}"},
      {U'ψ', "\\ensuremath{\\psi}"},   {U'π', "\\ensuremath{\\pi}"},    {U'σ', "\\ensuremath{\\sigma}"},
      {U'τ', "\\ensuremath{\\tau}"},   {U'ξ', "\\ensuremath{\\xi}"},    {U'α', "\\ensuremath{\\alpha}"},
      {U'β', "\\ensuremath{\\beta}"},  {U'γ', "\\ensuremath{\\gamma}"}, {U'λ', "\\ensuremath{\\lambda}"},
      {U'μ', "\\ensuremath{\\mu}"},    {U'ε', "\\ensuremath{\\varepsilon}"},
      {U'≤', "\\ensuremath{\\le}"},    {U'≥', "\\ensuremath{\\ge}"},    {U'≈', "\\ensuremath{\\approx}"},
      {U'≠', "\\ensuremath{\\ne}"},    {U'≪', "\\ensuremath{\\ll}"},    {U'≫', "\\ensuremath{\\gg}"},
      {U'±', "\\ensuremath{\\pm}"},    {U'×', "\\ensuremath{\\times}"}, {U'·', "\\ensuremath{\\cdot}"},
      {U'∞', "\\ensuremath{\\infty}"}, {U'√', "\\ensuremath{\\surd}"},  {U'→', "\\ensuremath{\\to}"},
      {U'−', "\\ensuremath{-}"},       {U'–', "--"},                    {U'—', "---"},
      {U'°', "\\ensuremath{^\\circ}"}, {U'’', "'"},                     {U'‘', "`"},
      {U'“', "``"},                    {U'”', "''"},                    {U'…', "\\ldots{}"},
      {U'²', "\\ensuremath{^2}"},      {U'³', "\\ensuremath{^3}"},      {U'½', "\\ensuremath{\\frac12}"},
      {U'é', "\\'e"},                  {U'è', "\\`e"},                  {U'ü', "\\\"u"},
      {U'ö', "\\\"o"},                 {U'ä', "\\\"a"},                 {U'∑', "\\ensuremath{\\sum}"},
      {U'′', "'"},                     {U'∓', "\\ensuremath{\\mp}"}};
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    char32_t code = 0;
    const std::size_t length = decode(text, i, code);
    if (length == 0) {
      out += "?";
      ++i;
      continue;
    }
    // θ followed by a combining dot above: θ̇
    if (code == U'θ' && i + length + 1 < text.size() + 1) {
      char32_t next = 0;
      const std::size_t next_length = i + length < text.size() ? decode(text, i + length, next) : 0;
      if (next_length && next == 0x0307) {
        out += "\\ensuremath{\\dot\\theta}";
        i += length + next_length;
        continue;
      }
    }
    i += length;
    if (code < 0x80) {
      const char c = static_cast<char>(code);
      switch (c) {
        case '\\': out += "\\textbackslash{}"; break;
        case '{': out += "\\{"; break;
        case '}': out += "\\}"; break;
        case '$': out += "\\$"; break;
        case '&': out += "\\&"; break;
        case '%': out += "\\%"; break;
        case '#': out += "\\#"; break;
        case '_': out += "\\_"; break;
        case '^': out += "\\textasciicircum{}"; break;
        case '~': out += "\\textasciitilde{}"; break;
        case '<': out += "\\textless{}"; break;
        case '>': out += "\\textgreater{}"; break;
        case '|': out += "\\textbar{}"; break;
        case '\0': break;
        default: out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) ? ' ' : c;
      }
      continue;
    }
    if (code == 0x0307) continue;  // a stray combining dot
    const auto found = symbols.find(code);
    out += found == symbols.end() ? "?" : found->second;
  }
  return out;
}

std::string markdown_text(std::string_view text) {
  std::string out;
  for (char c : valid_utf8(text)) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\0') continue;
    if (u < 0x20 || u == 0x7F) {
      out += ' ';
      continue;
    }
    switch (c) {
      case '\\': case '`': case '*': case '_': case '[': case ']': case '<': case '>': case '|': case '$': case '#':
      case '~':
        out += '\\';
        out += c;
        break;
      default: out += c;
    }
  }
  return out;
}

std::string csv_field(std::string_view text) {
  const std::string valid = valid_utf8(text);
  if (valid.find_first_of(",\"\r\n") == std::string::npos) return valid;
  std::string out = "\"";
  for (char c : valid) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string cpp_string_literal(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '?': out += "\\?"; break;  // no trigraphs
      default:
        if (u < 0x20 || u == 0x7F) {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\%03o", u);
          out += buffer;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string cpp_comment(std::string_view text) {
  std::string out;
  for (char c : valid_utf8(text)) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += (u < 0x20 || u == 0x7F) ? ' ' : c;
  }
  // a trailing backslash would continue the comment onto the next line
  while (!out.empty() && (out.back() == '\\' || out.back() == ' ')) out.pop_back();
  return out;
}

}  // namespace backlash::symbolic::escape
