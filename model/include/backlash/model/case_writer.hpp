// backlash/model/case_writer.hpp — the one case-file writer, beside the reader (case_spec.hpp).
//
// Every case file the project writes — the facade's Case::case_file(), the corrected models
// of the discrepancy workflows — is written here, in the schema of docs/design.md ("Case
// files") and in one layout: the top-level keys, [motor], [load], [experiment], [fit], [effects]
// (in the order of the table of effects, effect_table.hpp).  Each number arrives as the
// text it is written as: exact ("p/q" quoted, which the reader parses exactly) or, for a
// fitted value, the shortest decimal that reads back as the same double.
#pragma once

#include "backlash/model/case_spec.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace backlash::model {

/// An exact number as the quoted string "p/q" (parsed exactly by the reader; strings are
/// written by backlash/output/text.hpp's toml_string).
std::string exact_text(const Rational& value);

/// The shortest decimal that reads back as `value` (with ".0" when it would read as an integer).
std::string decimal_text(double value);

/// `original` exactly when `value` is its nearest double (a fit that kept it), else `value`'s decimal.
std::string exact_or_decimal(const Rational& original, double value);

/// The [experiment] table as written.
struct ExperimentText {
  ExperimentKind kind = ExperimentKind::Step;
  std::string step;        ///< a step experiment's step
  std::string drive_gain;  ///< a measured drive's gain
  std::optional<std::string> t_end;
  std::optional<std::string> step_time;  ///< a step experiment's step time, when the file gives one
};

/// A case file's contents, every number as the text it is written as.
struct CaseFileText {
  std::vector<std::string> comments;  ///< lines written first, each after "# "
  bool blank_line_before_tables = false;
  std::string name;
  MeasuredAt measured_at = MeasuredAt::Load;
  std::string K, backlash, reference, Jm, Fm, JL, FL;
  std::optional<ExperimentText> experiment;
  /// The effect parameters present (table order); an effect is written when its first parameter is.
  std::array<std::optional<std::string>, kEffectParameterCount> effects;
  std::vector<std::string> fit_free, fit_fixed;
};

/// The effects of a fitted model (numeric::Effects: doubles, `has(effect)`) as the texts of
/// CaseFileText::effects: each parameter of an effect present exactly as in the case file
/// `given` when the fit kept it, else its fitted decimal.
template <class FittedEffects>
std::array<std::optional<std::string>, kEffectParameterCount> fitted_effect_texts(const Effects& given,
                                                                                  const FittedEffects& fitted) {
  std::array<std::optional<std::string>, kEffectParameterCount> texts;
  for (const EffectInfo& effect : effects_table) {
    if (!fitted.has(effect)) continue;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
      const double value = field(fitted, effect_parameters[i].id);
      const std::optional<Rational>& original = field(given, effect_parameters[i].id);
      texts[i] = original ? exact_or_decimal(*original, value) : decimal_text(value);
    }
  }
  return texts;
}

/// The text of a case file.
std::string write_case_file(const CaseFileText& contents);

/// `spec` written exactly: read back by load_case_file / parse_case it gives the same spec
/// (every number, the experiment, the effects present, [fit] free).
std::string write_case_file(const CaseSpec& spec);

}  // namespace backlash::model
