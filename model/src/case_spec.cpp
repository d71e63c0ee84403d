// case_spec.cpp — strict, exact loader for backlash case files (docs/design.md, "Case files").
//
// Numbers never pass through a double: a TOML float such as `0.3` is read back
// from the file text (the node's source position) and parsed as the exact
// decimal 3/10; integers are exact; strings "1/3", "-2/5", "0.25" are parsed
// exactly.  Every problem becomes a CaseFileError whose what() is one line
// "FILE:LINE: KEY: problem".  Two cases have no line or key to name and print
// shorter forms: a file that cannot be read ("FILE: problem") and an unknown
// case id that is not a file either ("unknown case 'IX': ...", no FILE).
#include "backlash/model/case_spec.hpp"
#include "backlash/model/data_dir.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <span>
#include <sstream>
#include <string_view>

namespace backlash::model {

namespace {

using boost::multiprecision::cpp_int;

// ------------------------------------------------------------------ errors

std::string format_case_file_error(const std::filesystem::path& file, long line, const std::string& key,
                                   const std::string& problem) {
  std::string message;
  if (!file.empty()) {
    message += file.string();
    if (line > 0) message += ":" + std::to_string(line);
    message += ": ";
  }
  if (!key.empty()) message += key + ": ";
  message += problem;
  // what() is documented as one line: fold any line breaks a parser message may carry.
  std::replace(message.begin(), message.end(), '\n', ' ');
  std::replace(message.begin(), message.end(), '\r', ' ');
  return message;
}

// ------------------------------------------------------------------ exact decimals

/// Largest decimal exponent accepted (|e| in "1e-3"); keeps 10^e a reasonable size.
constexpr long largest_decimal_exponent = 4000;

/// Outcome of parsing a number's text: the exact value, or why it is not one.
struct ExactParse {
  std::optional<Rational> value;
  std::string problem;
  std::size_t significant_digits = 0;  ///< of the mantissa (the larger of a fraction's two)
};

/// The digits of `digits` from its first to its last nonzero digit (0 for zero).
std::size_t significant_digit_count(const std::string& digits) {
  const std::size_t first = digits.find_first_not_of('0');
  return first == std::string::npos ? 0 : digits.find_last_not_of('0') - first + 1;
}

ExactParse parse_failure(std::string problem) { return {std::nullopt, std::move(problem)}; }

/// Reads a run of decimal digits starting at `position`, appending them to
/// `digits`.  With `allow_underscores`, single '_' between two digits are
/// skipped (TOML's separators).  Returns false if no digit was found or an
/// underscore is misplaced.
bool read_digit_run(std::string_view text, std::size_t& position, std::string& digits, bool allow_underscores) {
  const std::size_t start = position;
  while (position < text.size()) {
    const char character = text[position];
    if (std::isdigit(static_cast<unsigned char>(character))) {
      digits += character;
      ++position;
    } else if (allow_underscores && character == '_' && position > start && position + 1 < text.size() &&
               std::isdigit(static_cast<unsigned char>(text[position - 1])) &&
               std::isdigit(static_cast<unsigned char>(text[position + 1]))) {
      ++position;
    } else {
      break;
    }
  }
  return position > start;
}

cpp_int power_of_ten(long exponent) {
  return boost::multiprecision::pow(cpp_int(10), static_cast<unsigned>(exponent));
}

/// Exact value of a decimal literal [+-]DIGITS[.DIGITS][(e|E)[+-]DIGITS].
/// `allow_sign` = false rejects a leading sign (denominators).
ExactParse parse_exact_decimal(std::string_view text, bool allow_underscores, bool allow_sign) {
  std::size_t position = 0;
  bool negative = false;
  if (position < text.size() && (text[position] == '+' || text[position] == '-')) {
    if (!allow_sign) return parse_failure("unexpected sign");
    negative = text[position] == '-';
    ++position;
  }
  std::string mantissa_digits;
  if (!read_digit_run(text, position, mantissa_digits, allow_underscores)) return parse_failure("expected a digit");
  long fraction_digit_count = 0;
  if (position < text.size() && text[position] == '.') {
    ++position;
    const std::size_t before = mantissa_digits.size();
    if (!read_digit_run(text, position, mantissa_digits, allow_underscores))
      return parse_failure("expected a digit after '.'");
    fraction_digit_count = static_cast<long>(mantissa_digits.size() - before);
  }
  long exponent = 0;
  if (position < text.size() && (text[position] == 'e' || text[position] == 'E')) {
    ++position;
    bool exponent_negative = false;
    if (position < text.size() && (text[position] == '+' || text[position] == '-')) {
      exponent_negative = text[position] == '-';
      ++position;
    }
    std::string exponent_digits;
    if (!read_digit_run(text, position, exponent_digits, allow_underscores))
      return parse_failure("expected a digit in the exponent");
    exponent_digits.erase(0, std::min(exponent_digits.find_first_not_of('0'), exponent_digits.size() - 1));
    if (exponent_digits.size() > 6) return parse_failure("exponent out of range");
    exponent = std::stol(exponent_digits);
    if (exponent_negative) exponent = -exponent;
  }
  if (position != text.size()) return parse_failure("unexpected character '" + std::string(1, text[position]) + "'");
  const std::size_t significant = significant_digit_count(mantissa_digits);
  if (significant > largest_significant_digits) return {std::nullopt, "too many digits", significant};

  const long scale = exponent - fraction_digit_count;
  if (scale > largest_decimal_exponent || scale < -largest_decimal_exponent)
    return parse_failure("exponent out of range");
  // cpp_int reads a leading 0 as an octal prefix: strip leading zeros first.
  mantissa_digits.erase(0, std::min(mantissa_digits.find_first_not_of('0'), mantissa_digits.size() - 1));
  cpp_int mantissa(mantissa_digits);
  if (negative) mantissa = -mantissa;
  if (scale >= 0) return {Rational(mantissa * power_of_ten(scale)), {}, significant};
  return {Rational(mantissa, power_of_ten(-scale)), {}, significant};
}

bool names_a_non_finite_number(std::string_view text) {
  std::string lowered;
  for (char character : text) lowered += static_cast<char>(std::tolower(static_cast<unsigned char>(character)));
  if (!lowered.empty() && (lowered[0] == '+' || lowered[0] == '-')) lowered.erase(0, 1);
  return lowered == "inf" || lowered == "nan" || lowered == "infinity";
}

/// Exact value of a number written in a string: "p/q", "-2/5", "0.25", "3", "1e-3".
ExactParse parse_exact_number_string(std::string_view text) {
  if (names_a_non_finite_number(text)) return parse_failure("non-finite");
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos) return parse_exact_decimal(text, false, true);
  ExactParse numerator = parse_exact_decimal(text.substr(0, slash), false, true);
  if (numerator.problem == "too many digits") return numerator;
  if (!numerator.value) return parse_failure("numerator: " + numerator.problem);
  ExactParse denominator = parse_exact_decimal(text.substr(slash + 1), false, false);
  if (denominator.problem == "too many digits") return denominator;
  if (!denominator.value) return parse_failure("denominator: " + denominator.problem);
  if (*denominator.value == 0) return parse_failure("division by zero");
  return {*numerator.value / *denominator.value, {}, std::max(numerator.significant_digits, denominator.significant_digits)};
}

// ------------------------------------------------------------------ source text

/// The file's lines, to read a float's literal text back at its source position.
class SourceLines {
 public:
  explicit SourceLines(const std::string& contents) {
    std::size_t start = 0;
    while (start <= contents.size()) {
      std::size_t end = contents.find('\n', start);
      if (end == std::string::npos) end = contents.size();
      std::string line = contents.substr(start, end - start);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines_.push_back(std::move(line));
      start = end + 1;
    }
    // toml++ does not count a UTF-8 byte order mark as a column.
    if (!lines_.empty() && lines_.front().rfind("\xEF\xBB\xBF", 0) == 0) lines_.front().erase(0, 3);
  }

  /// Text from (line, column) on — both 1-based, column in code points as
  /// toml++ counts them — to the end of that line.  Empty if out of range.
  std::string_view rest_of_line_from(long line, long column) const {
    if (line < 1 || static_cast<std::size_t>(line) > lines_.size() || column < 1) return {};
    const std::string& text = lines_[static_cast<std::size_t>(line - 1)];
    long code_points_to_skip = column - 1;
    std::size_t byte = 0;
    while (byte < text.size() && code_points_to_skip > 0) {
      ++byte;
      while (byte < text.size() && (static_cast<unsigned char>(text[byte]) & 0xC0) == 0x80) ++byte;
      --code_points_to_skip;
    }
    if (code_points_to_skip > 0) return {};
    return std::string_view(text).substr(byte);
  }

 private:
  std::vector<std::string> lines_;
};

/// The characters a finite TOML float literal is made of.
bool is_float_literal_character(char character) {
  return std::isdigit(static_cast<unsigned char>(character)) || character == '+' || character == '-' ||
         character == '.' || character == '_' || character == 'e' || character == 'E';
}

// ------------------------------------------------------------------ reading values

const char* describe_node_type(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

long line_of(const toml::node& node, long fallback) {
  const long line = static_cast<long>(node.source().begin.line);
  return line > 0 ? line : fallback;
}

std::string join(std::span<const std::string_view> names) {
  std::string joined;
  for (std::string_view name : names) {
    if (!joined.empty()) joined += ", ";
    joined += name;
  }
  return joined;
}

bool equal_ignoring_case(std::string_view left, std::string_view right) {
  return left.size() == right.size() && std::equal(left.begin(), left.end(), right.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

/// An exact number together with the text it was written as (for messages).
struct ExactNumber {
  Rational value;
  std::string as_written;
};

/// Reads one case file's parsed table into a CaseSpec, checking every rule.
class CaseFileReader {
 public:
  CaseFileReader(std::filesystem::path file, const std::string& contents) : file_(std::move(file)), lines_(contents) {}

  CaseSpec read(const toml::table& root) const {
    CaseSpec spec;
    spec.source = file_;
    spec.id = file_.stem().string();

    reject_unknown_keys(root, "",
                        {"name", "measured_at", "K", "backlash", "reference", "motor", "load", "experiment", "effects", "fit"});
    const long top_line = 1;
    spec.name = read_name(require(root, "", top_line, "name"));
    spec.measured_at = read_measured_at(require(root, "", top_line, "measured_at"));
    if (const toml::node* experiment_node = root.get("experiment")) spec.experiment = read_experiment(*experiment_node, top_line);
    const bool open_loop = spec.experiment && spec.experiment->kind == ExperimentKind::Drive;

    if (open_loop && !root.get("K")) {
      spec.K = 1;  // a measured drive opens the loop: K is not used
    } else {
      const toml::node& gain_node = require(root, "", top_line, "K");
      const ExactNumber gain = read_number(gain_node, "K");
      if (gain.value <= 0)
        fail(line_of(gain_node, top_line), "K",
             "non-positive loop gain (got " + gain.as_written +
                 "; K must be > 0, otherwise the loop does not pull the output toward the reference)");
      spec.K = gain.value;
    }

    const toml::node& backlash_node = require(root, "", top_line, "backlash");
    const ExactNumber backlash = read_number(backlash_node, "backlash");
    if (backlash.value < 0)
      fail(line_of(backlash_node, top_line), "backlash",
           "negative backlash (got " + backlash.as_written + "; the total backlash must be >= 0)");
    spec.backlash = backlash.value;

    spec.reference = read_number(require(root, "", top_line, "reference"), "reference").value;

    read_body(root, "motor", spec.Jm, spec.Fm);
    read_body(root, "load", spec.JL, spec.FL);

    if (const toml::node* effects_node = root.get("effects")) spec.effects = read_effects(*effects_node, top_line);
    if (const toml::node* fit_node = root.get("fit")) read_fit(*fit_node, top_line, spec.fit_free, spec.fit_fixed);
    return spec;
  }

  /// [experiment]: kind = "step" (default: step required) or "drive" (drive_gain optional).
  Experiment read_experiment(const toml::node& node, long fallback_line) const {
    const toml::table& experiment = require_table(node, "experiment");
    const long header_line = line_of(experiment, fallback_line);
    reject_unknown_keys(experiment, "experiment", {"kind", "step", "t_end", "drive_gain", "step_time"});
    Experiment parsed;
    if (const toml::node* kind_node = experiment.get("kind")) {
      const auto* text = kind_node->as_string();
      if (text == nullptr || (text->get() != "step" && text->get() != "drive"))
        fail(line_of(*kind_node, header_line), "experiment.kind",
             std::string("expected \"step\" or \"drive\", got ") +
                 (text ? "\"" + text->get() + "\"" : std::string(describe_node_type(*kind_node))));
      parsed.kind = text->get() == "drive" ? ExperimentKind::Drive : ExperimentKind::Step;
    }
    if (parsed.kind == ExperimentKind::Step) {
      if (const toml::node* gain_node = experiment.get("drive_gain"))
        fail(line_of(*gain_node, header_line), "experiment.drive_gain",
             "only a measured-drive experiment (kind = \"drive\") has a drive gain");
      parsed.step = read_number(require(experiment, "experiment", header_line, "step"), "experiment.step").value;
      if (const toml::node* time_node = experiment.get("step_time"))
        parsed.step_time = read_number(*time_node, "experiment.step_time").value;
    } else {
      if (const toml::node* time_node = experiment.get("step_time"))
        fail(line_of(*time_node, header_line), "experiment.step_time",
             "a measured-drive experiment has no step: the drive comes from the record's drive column");
      if (const toml::node* step_node = experiment.get("step"))
        fail(line_of(*step_node, header_line), "experiment.step",
             "a measured-drive experiment has no step: the drive comes from the record's drive column");
      if (const toml::node* gain_node = experiment.get("drive_gain")) {
        const ExactNumber gain = read_number(*gain_node, "experiment.drive_gain");
        if (gain.value == 0)
          fail(line_of(*gain_node, header_line), "experiment.drive_gain", "zero drive gain (got " + gain.as_written + ")");
        parsed.drive_gain = gain.value;
      }
    }
    if (const toml::node* end_node = experiment.get("t_end")) {
      const ExactNumber end_time = read_number(*end_node, "experiment.t_end");
      if (end_time.value <= 0)
        fail(line_of(*end_node, header_line), "experiment.t_end",
             "non-positive end time (got " + end_time.as_written + "; t_end must be > 0)");
      parsed.t_end = end_time.value;
    }
    return parsed;
  }

  /// [fit]: free = ["motor.J", ...] and/or fixed = [...] — known names, no repeats, none in both.
  void read_fit(const toml::node& node, long fallback_line, std::vector<std::string>& free,
                std::vector<std::string>& fixed) const {
    const toml::table& fit = require_table(node, "fit");
    const long header_line = line_of(fit, fallback_line);
    reject_unknown_keys(fit, "fit", {"free", "fixed"});
    if (fit.get("fixed") == nullptr) require(fit, "fit", header_line, "free");
    if (const toml::node* free_node = fit.get("free")) free = read_fit_names(*free_node, header_line, "fit.free", {});
    if (const toml::node* fixed_node = fit.get("fixed"))
      fixed = read_fit_names(*fixed_node, header_line, "fit.fixed", free);
  }

  /// One list of [fit]: known names, no repeats, none of `other` (the free list).
  std::vector<std::string> read_fit_names(const toml::node& list, long header_line, const std::string& key,
                                          const std::vector<std::string>& other) const {
    const toml::array* names = list.as_array();
    if (names == nullptr)
      fail(line_of(list, header_line), key, std::string("expected an array of parameter names, got ") + describe_node_type(list));
    std::vector<std::string> out;
    for (const toml::node& entry : *names) {
      const auto* text = entry.as_string();
      const auto& known = fittable_parameters();
      const long line = line_of(entry, line_of(list, header_line));
      if (text == nullptr || std::find(known.begin(), known.end(), text->get()) == known.end()) {
        std::string allowed;
        for (const std::string& k : known) allowed += (allowed.empty() ? "" : ", ") + k;
        fail(line, key,
             "unknown parameter " + (text ? "\"" + text->get() + "\"" : std::string(describe_node_type(entry))) +
                 " (allowed: " + allowed + ")");
      }
      if (std::find(out.begin(), out.end(), text->get()) != out.end()) fail(line, key, "\"" + text->get() + "\" given twice");
      if (std::find(other.begin(), other.end(), text->get()) != other.end())
        fail(line, key, "\"" + text->get() + "\" is also in fit.free: a parameter is free or fixed, not both");
      out.push_back(text->get());
    }
    return out;
  }

 private:
  [[noreturn]] void fail(long line, const std::string& key, const std::string& problem) const {
    throw CaseFileError(file_, line > 0 ? line : 1, key, problem);
  }

  static std::string dotted(const std::string& table_prefix, std::string_view key) {
    return table_prefix.empty() ? std::string(key) : table_prefix + "." + std::string(key);
  }

  /// Rejects the key on the earliest line that is not in `allowed`.
  void reject_unknown_keys(const toml::table& table, const std::string& table_prefix,
                           std::initializer_list<std::string_view> allowed) const {
    reject_unknown_keys(table, table_prefix, std::span<const std::string_view>(allowed.begin(), allowed.size()));
  }
  void reject_unknown_keys(const toml::table& table, const std::string& table_prefix,
                           std::span<const std::string_view> allowed) const {
    const toml::key* earliest_unknown = nullptr;
    long earliest_line = 0;
    for (auto&& [key, node] : table) {
      if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
      long line = static_cast<long>(key.source().begin.line);
      if (line <= 0) line = line_of(node, 1);
      if (earliest_unknown == nullptr || line < earliest_line) {
        earliest_unknown = &key;
        earliest_line = line;
      }
    }
    if (earliest_unknown == nullptr) return;
    std::string problem = "unknown key (";
    for (std::string_view name : allowed)
      if (equal_ignoring_case(name, earliest_unknown->str())) problem += "did you mean '" + std::string(name) + "'? ";
    problem += "allowed: " + join(allowed) + ")";
    fail(earliest_line, dotted(table_prefix, earliest_unknown->str()), problem);
  }

  const toml::node& require(const toml::table& table, const std::string& table_prefix, long table_line,
                            std::string_view key) const {
    const toml::node* node = table.get(key);
    if (node == nullptr) fail(table_line, dotted(table_prefix, key), "missing key");
    return *node;
  }

  const toml::table& require_table(const toml::node& node, const std::string& key) const {
    const toml::table* table = node.as_table();
    if (table == nullptr)
      fail(line_of(node, 1), key, std::string("expected a table [") + key + "], got " + describe_node_type(node));
    return *table;
  }

  /// [motor] or [load]: inertia J > 0, viscous friction F >= 0.
  void read_body(const toml::table& root, const std::string& table_name, Rational& inertia,
                 Rational& friction) const {
    const toml::node* table_node = root.get(table_name);
    if (table_node == nullptr) fail(1, table_name, "missing table [" + table_name + "]");
    const toml::table& table = require_table(*table_node, table_name);
    const long header_line = line_of(table, 1);
    reject_unknown_keys(table, table_name, {"J", "F"});

    const toml::node& inertia_node = require(table, table_name, header_line, "J");
    const ExactNumber inertia_number = read_number(inertia_node, table_name + ".J");
    if (inertia_number.value <= 0)
      fail(line_of(inertia_node, header_line), table_name + ".J",
           "non-positive inertia (got " + inertia_number.as_written + "; an inertia must be > 0)");

    const toml::node& friction_node = require(table, table_name, header_line, "F");
    const ExactNumber friction_number = read_number(friction_node, table_name + ".F");
    if (friction_number.value < 0)
      fail(line_of(friction_node, header_line), table_name + ".F",
           "negative friction (got " + friction_number.as_written + "; viscous friction must be >= 0)");

    inertia = inertia_number.value;
    friction = friction_number.value;
  }

  /// A number of the [effects] table that must satisfy `valid`, else `problem` (the value is appended).
  template <class Valid>
  Rational read_effect_number(const toml::node& node, const std::string& key, Valid valid,
                              const std::string& problem) const {
    const ExactNumber number = read_number(node, key);
    if (!valid(number.value)) fail(line_of(node, 1), key, problem + " (got " + number.as_written + ")");
    return number.value;
  }

  /// One parameter of the table of effects (effect_table.hpp) at `node`, checked against its
  /// admissible values; `key` is its dotted case-file key.
  Rational read_effect_parameter(const toml::node& node, const EffectParameterInfo& parameter,
                                 const std::string& key) const {
    if (parameter.admissible == Admissible::Any) return read_number(node, key).value;
    const ExactNumber number = read_number(node, key);
    const Rational& x = number.value;
    const bool admitted = parameter.admissible == Admissible::NonNegative ? x >= 0
                          : parameter.admissible == Admissible::Positive  ? x > 0
                                                                           : x >= 0 && x < 1;
    if (!admitted) fail(line_of(node, 1), key, std::string(parameter.problem) + " (got " + number.as_written + ")");
    return x;
  }

  /// An effect of several parameters, KEY = { ... } (every parameter required).
  void read_effect_table(const toml::node& entry, const EffectInfo& effect, long header_line, Effects& effects) const {
    const std::string prefix = "effects." + std::string(effect.key);
    const toml::table& table = require_table(entry, prefix);
    const long table_line = line_of(table, header_line);
    std::vector<std::string_view> keys;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) keys.push_back(effect_parameters[i].key);
    reject_unknown_keys(table, prefix, keys);
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
      const EffectParameterInfo& parameter = effect_parameters[i];
      const toml::node& node = require(table, prefix, table_line, parameter.key);
      field(effects, parameter.id) = read_effect_parameter(node, parameter, dotted(prefix, parameter.key));
    }
    check_levels(table, effect, prefix, table_line, effects);
  }

  /// A friction with a `static` and a `kinetic` level (Stribeck) needs kinetic <= static.
  void check_levels(const toml::table& table, const EffectInfo& effect, const std::string& prefix, long table_line,
                    const Effects& effects) const {
    const std::optional<Rational>*kinetic = nullptr, *level = nullptr;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
      if (effect_parameters[i].key == "kinetic") kinetic = &field(effects, effect_parameters[i].id);
      if (effect_parameters[i].key == "static") level = &field(effects, effect_parameters[i].id);
    }
    if (kinetic && level && **kinetic > **level)
      fail(line_of(*table.get("kinetic"), table_line), dotted(prefix, "kinetic"),
           "the kinetic friction level must be <= the static one (" + dotted(prefix, "static") + ")");
  }

  /// [effects] (docs/effects.md): every entry optional, exact, checked by the table of effects
  /// (effect_table.hpp); the effects of one parameter first, then those written as tables.
  Effects read_effects(const toml::node& node, long fallback_line) const {
    const toml::table& table = require_table(node, "effects");
    const long header_line = line_of(table, fallback_line);
    std::vector<std::string_view> keys;
    for (const EffectInfo& effect : effects_table) keys.push_back(effect.key);
    reject_unknown_keys(table, "effects", keys);
    Effects effects;
    for (const bool single : {true, false})
      for (const EffectInfo& effect : effects_table) {
        const toml::node* entry = table.get(effect.key);
        if (entry == nullptr || effect.single() != single) continue;
        if (single)
          field(effects, effect.primary().id) =
              read_effect_parameter(*entry, effect.primary(), "effects." + std::string(effect.key));
        else
          read_effect_table(*entry, effect, header_line, effects);
        check_one_contact_law(table, effect, header_line, effects);
      }
    return effects;
  }

  /// Two contact laws (restitution, compliance) cannot be combined: the later one read is refused.
  void check_one_contact_law(const toml::table& table, const EffectInfo& effect, long header_line,
                             const Effects& effects) const {
    if (!effect.contact_law || !effects.has(effect)) return;
    for (const EffectInfo& other : effects_table)
      if (&other != &effect && other.contact_law && effects.has(other) && other.single())
        fail(line_of(*table.get(other.key), header_line), "effects." + std::string(other.key),
             std::string(other.key) + " and " + std::string(effect.key) +
                 " both model the impact (a compliant mesh has its own rebound, set by its damping); give one of them");
  }

  std::string read_name(const toml::node& node) const {
    const auto* text = node.as_string();
    if (text == nullptr) fail(line_of(node, 1), "name", std::string("expected a string, got ") + describe_node_type(node));
    if (text->get().empty()) fail(line_of(node, 1), "name", "empty name");
    return text->get();
  }

  MeasuredAt read_measured_at(const toml::node& node) const {
    const auto* text = node.as_string();
    if (text == nullptr)
      fail(line_of(node, 1), "measured_at",
           std::string("expected \"motor\" or \"load\", got ") + describe_node_type(node));
    if (text->get() == "motor") return MeasuredAt::Motor;
    if (text->get() == "load") return MeasuredAt::Load;
    fail(line_of(node, 1), "measured_at", "expected \"motor\" or \"load\", got \"" + text->get() + "\"");
  }

  /// Every number is held to magnitudes double precision computes with room to spare: its
  /// square, its products with the others and their ratios stay finite and normal.  Beyond
  /// 1e±100 the numeric part would overflow or flush to zero ("floating point overflow"
  /// without a line, 1e-400 silently read as 0), so such a number is refused here, at its line.
  ExactNumber read_number(const toml::node& node, const std::string& key) const {
    ExactNumber number = read_number_unchecked(node, key);
    static const Rational largest = boost::multiprecision::pow(boost::multiprecision::cpp_int(10), 100);
    static const Rational smallest = 1 / largest;
    const Rational magnitude = abs(number.value);
    if (magnitude != 0 && (magnitude > largest || magnitude < smallest))
      fail(line_of(node, 1), key,
           "magnitude out of range (got " + number.as_written +
               "; a number other than 0 must lie between 1e-100 and 1e100 in size, where double precision "
               "computes its products and ratios)");
    return number;
  }

  ExactNumber read_number_unchecked(const toml::node& node, const std::string& key) const {
    const long line = line_of(node, 1);
    if (const auto* integer = node.as_integer()) {
      return {Rational(integer->get()), std::to_string(integer->get())};
    }
    if (const auto* floating = node.as_floating_point()) {
      const double approximate = floating->get();
      if (!std::isfinite(approximate))
        fail(line, key, std::string("non-finite number (got ") + (std::isnan(approximate) ? "nan" : approximate < 0 ? "-inf" : "inf") + ")");
      return read_float_literal(node, approximate, key);
    }
    if (const auto* text = node.as_string()) {
      const ExactParse parsed = parse_exact_number_string(text->get());
      if (parsed.problem == "non-finite") fail(line, key, "non-finite number (got \"" + text->get() + "\")");
      refuse_too_many_digits(parsed, line, key);
      if (!parsed.value)
        fail(line, key,
             "not a number: \"" + text->get() + "\" (" + parsed.problem +
                 "; write a decimal such as 0.3 or a fraction such as \"1/3\")");
      return {*parsed.value, "\"" + text->get() + "\""};
    }
    fail(line, key, std::string("expected a number, got ") + describe_node_type(node));
  }

  /// docs/design.md, "Case files": the exact derivation's cost grows with the digits.
  void refuse_too_many_digits(const ExactParse& parsed, long line, const std::string& key) const {
    if (parsed.problem != "too many digits") return;
    fail(line, key,
         "too many significant digits (" + std::to_string(parsed.significant_digits) + "; at most " +
             std::to_string(largest_significant_digits) + " are read, a double printed in full has 17)");
  }

  /// Reads the float's literal text back from the file and parses it exactly;
  /// cross-checks it against the double toml++ produced.  (to_double is
  /// declared in the public header, defined below.)
  ExactNumber read_float_literal(const toml::node& node, double approximate, const std::string& key) const {
    const auto& begin = node.source().begin;
    const std::string_view rest = lines_.rest_of_line_from(static_cast<long>(begin.line), static_cast<long>(begin.column));
    std::size_t length = 0;
    while (length < rest.size() && is_float_literal_character(rest[length])) ++length;
    const std::string literal(rest.substr(0, length));
    const ExactParse parsed = parse_exact_decimal(literal, true, true);
    refuse_too_many_digits(parsed, line_of(node, 1), key);
    // toml++ rounds the literal correctly; so must the exact value of the text we found.
    if (!parsed.value || to_double(*parsed.value) != approximate)
      fail(line_of(node, 1), key,
           "could not read the exact text of this number back from the file (found \"" + literal +
               "\"); write it as a string such as \"3/10\"");
    return {*parsed.value, literal};
  }

  std::filesystem::path file_;
  SourceLines lines_;
};

/// Largest case file read: a case file is a few hundred bytes.
constexpr std::uintmax_t largest_case_file = 1 << 20;

std::string read_whole_file(const std::filesystem::path& file) {
  std::error_code status;
  const std::filesystem::file_status kind = std::filesystem::status(file, status);
  if (status && status != std::errc::no_such_file_or_directory)
    throw CaseFileError(file, 0, "", "cannot open case file: " + status.message());
  if (!std::filesystem::exists(kind)) throw CaseFileError(file, 0, "", "cannot open case file: no such file");
  if (std::filesystem::is_directory(kind)) throw CaseFileError(file, 0, "", "cannot open case file: it is a directory");
  if (!std::filesystem::is_regular_file(kind))
    throw CaseFileError(file, 0, "", "cannot open case file: not a regular file (a device, a pipe or a socket)");
  const std::uintmax_t size = std::filesystem::file_size(file, status);
  if (!status && size > largest_case_file)
    throw CaseFileError(file, 0, "", "case file too large (" + std::to_string(size) + " bytes; a case file is at most 1 MiB)");
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw CaseFileError(file, 0, "", std::string("cannot open case file: ") + std::strerror(errno));
  std::ostringstream contents;
  contents << stream.rdbuf();
  if (stream.bad()) throw CaseFileError(file, 0, "", "cannot read case file");
  return contents.str();
}

std::string to_upper_ascii(std::string text) {
  for (char& character : text) character = static_cast<char>(std::toupper(static_cast<unsigned char>(character)));
  return text;
}

}  // namespace

// ------------------------------------------------------------------ public API

CaseFileError::CaseFileError(std::filesystem::path file, long line, std::string key, const std::string& problem)
    : std::runtime_error(format_case_file_error(file, line, key, problem)),
      file_(std::move(file)),
      line_(line),
      key_(std::move(key)) {}

CaseSpec load_case_file(const std::filesystem::path& file) { return parse_case(read_whole_file(file), file); }

CaseSpec parse_case(const std::string& contents, const std::filesystem::path& file) {
  toml::table root;
  try {
    root = toml::parse(std::string_view(contents), std::string_view(file.string()));
  } catch (const toml::parse_error& error) {
    const long line = static_cast<long>(error.source().begin.line);
    throw CaseFileError(file, line > 0 ? line : 1, "syntax", std::string(error.description()));
  }
  return CaseFileReader(file, contents).read(root);
}

bool Effects::has(const EffectInfo& effect) const {
  const std::optional<Rational>& value = field(*this, effect.primary().id);
  return value && (effect.primary().neutral == kAbsent || *value != Rational(effect.primary().neutral));
}

bool Effects::any() const {
  for (const EffectInfo& effect : effects_table)
    if (has(effect)) return true;
  return false;
}

const std::vector<std::string>& fittable_parameters() {
  static const std::vector<std::string> names{"motor.J", "motor.F", "load.J", "load.F", "K", "backlash", "reference"};
  return names;
}

const std::vector<std::string>& thesis_case_ids() {
  static const std::vector<std::string> ids{"I", "II", "III", "IV", "V", "VI", "VII", "VIII"};
  return ids;
}

std::filesystem::path thesis_cases_dir() {
  if (const char* from_environment = std::getenv("BACKLASH_CASES_DIR");
      from_environment != nullptr && *from_environment != '\0')
    return std::filesystem::path(from_environment);
  return data_dir() / "cases";
}

CaseSpec load_case(const std::string& case_or_path) {
  const std::string upper = to_upper_ascii(case_or_path);
  for (const std::string& id : thesis_case_ids()) {
    if (id != upper) continue;
    CaseSpec spec = load_case_file(thesis_cases_dir() / (id + ".toml"));
    spec.id = id;
    return spec;
  }
  const std::filesystem::path path(case_or_path);
  std::error_code status;
  const bool looks_like_a_path = case_or_path.find('/') != std::string::npos || path.extension() == ".toml";
  if (!case_or_path.empty() && (looks_like_a_path || std::filesystem::exists(path, status)))
    return load_case_file(path);
  throw CaseFileError({}, 0, "", "unknown case '" + case_or_path + "': expected I..VIII or a case file path");
}

std::string to_string(const Rational& value) {
  const cpp_int numerator = boost::multiprecision::numerator(value);
  const cpp_int denominator = boost::multiprecision::denominator(value);
  if (denominator == 1) return numerator.str();
  return numerator.str() + "/" + denominator.str();
}

double to_double(const Rational& value) { return value.convert_to<double>(); }

const char* to_string(MeasuredAt where) { return where == MeasuredAt::Motor ? "motor" : "load"; }

}  // namespace backlash::model
