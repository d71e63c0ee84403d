// backlash/model/case_spec.hpp — a servo-with-backlash case, as exact rationals.
//
// A case file (TOML, schema in docs/design.md, "Case files") describes the thesis's
// two-body system (gear ratio N = 1):
//   contact mode  (Jm+JL)·θo'' + (Fm+FL)·θo' + K·θo = K·θR        (eqs. 6, 15, 25)
//   free load     JL·θL'' + FL·θL' = 0                              (eq. 17)
//   free motor    Jm·θm'' + Fm·θm' + K·θm = K·θR   (output at motor, eq. 16)
//                 Jm·θm'' + Fm·θm' = K·(θR − θL)    (output at load,  eq. 39)
// with total backlash b.  Every number is exact: the decimal 0.3 as written in
// the file is the rational 3/10, never the double nearest to it.
//
// This library has no GiNaC dependency: numeric/ uses it as well as symbolic/.
#pragma once

#include "backlash/model/effect_table.hpp"

#include <boost/multiprecision/cpp_int.hpp>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace backlash::model {

using Rational = boost::multiprecision::cpp_rational;

enum class MeasuredAt { Motor, Load };

enum class ExperimentKind {
  Step,   ///< start at rest in contact with θo = θR − step; the loop K(θR − θo) drives
  Drive,  ///< a measured drive: the drive torque is a record's `drive` column × drive_gain, the loop is open
};

/// An optional experiment ([experiment]).
struct Experiment {
  ExperimentKind kind = ExperimentKind::Step;
  Rational step;                 ///< step experiments (0 for a measured drive)
  Rational drive_gain{1};        ///< measured drive: torque per unit of the `drive` column
  std::optional<Rational> t_end;
  /// Step experiments: the time of the step on a measured record's clock [s] (absent: 0, the
  /// record starts with the step).  Only the discrepancy workflow reads it (docs/discrepancy.md).
  std::optional<Rational> step_time;
};

/// The effects the thesis left out (docs/effects.md), as read from the optional [effects]
/// table: one exact member per parameter of the table of effects (effect_table.hpp), named
/// by its FIELD.  An absent member is the parameter at its neutral value: no Coulomb torque,
/// the inelastic impact (e = 0), an unlimited drive, a rigid mesh, no delay, no offset.
struct Effects {
#define BACKLASH_EFFECT_PARAMETER_MEMBER(FIELD, ...) std::optional<Rational> FIELD;
  BACKLASH_EFFECT_PARAMETERS(BACKLASH_EFFECT_PARAMETER_MEMBER)
#undef BACKLASH_EFFECT_PARAMETER_MEMBER

  /// True when the effect is present: its first parameter given and not neutral.
  bool has(const EffectInfo& effect) const;
  /// True when some effect differs from its neutral value.
  bool any() const;
};

struct CaseSpec {
  std::string id;            ///< "I".."VIII" for thesis cases, else the file stem
  std::string name;          ///< the file's `name`
  std::filesystem::path source;  ///< file it was read from
  MeasuredAt measured_at = MeasuredAt::Load;
  Rational K;                ///< loop gain
  Rational backlash;         ///< total backlash b (contact faces at ±b/2)
  Rational reference;        ///< θR
  Rational Jm, Fm;           ///< motor-side inertia and viscous friction
  Rational JL, FL;           ///< load inertia and viscous friction
  std::optional<Experiment> experiment;
  Effects effects;           ///< the [effects] table (all neutral when absent)
  /// [fit] free = [...]: the nominal parameters a record may correct ("motor.J", "motor.F",
  /// "load.J", "load.F", "K", "backlash", "reference"), fitted before any effect is sought.
  std::vector<std::string> fit_free;
  /// [fit] fixed = [...]: the nominal parameters the user trusts — a step record's discrepancy
  /// search never corrects them (same names as fit_free, none in both).
  std::vector<std::string> fit_fixed;
};

/// The names [fit] free accepts, in this order.
const std::vector<std::string>& fittable_parameters();

/// The most significant digits a number of a case file may have (a decimal's, from its first
/// to its last nonzero digit; each of a fraction's numerator and denominator): 17 print a
/// double in full, and the exact derivation's cost grows with the digits (docs/design.md,
/// "Case files").  More is refused at the number's line.
inline constexpr std::size_t largest_significant_digits = 100;

/// A bad case file. what() is one line: "FILE:LINE: KEY: problem".
class CaseFileError : public std::runtime_error {
 public:
  CaseFileError(std::filesystem::path file, long line, std::string key, const std::string& problem);
  const std::filesystem::path& file() const { return file_; }
  long line() const { return line_; }
  const std::string& key() const { return key_; }

 private:
  std::filesystem::path file_;
  long line_;
  std::string key_;
};

/// Strict loader: unknown or missing keys, non-positive inertia, negative
/// friction/backlash/gain, non-finite or non-numeric values → CaseFileError.
/// The file must be a regular file of at most 1 MiB (a case file is a few hundred bytes:
/// /dev/zero or a log is refused before it is read).  K may be omitted only with a
/// measured-drive experiment (the loop is open: it is then 1 and unused).
/// [effects]: negative Coulomb torque, e outside [0, 1), a limit <= 0, a
/// stiffness <= 0, a negative damping or delay, an unknown effect, and the pair
/// restitution + compliance (both would model the impact) → CaseFileError.
/// Decimals as written become exact rationals (0.3 → 3/10); strings "p/q" and
/// integers are accepted, each with at most largest_significant_digits significant digits.
CaseSpec load_case_file(const std::filesystem::path& file);

/// The same strict reader on a case file's text already in memory; `file` names it in
/// messages ("FILE:LINE: KEY: problem") and becomes the spec's source and id (its stem).
CaseSpec parse_case(const std::string& contents, const std::filesystem::path& file);

/// The eight thesis cases, in thesis order: I, II, ..., VIII.
const std::vector<std::string>& thesis_case_ids();

/// Folder holding I.toml … VIII.toml: $BACKLASH_CASES_DIR if set, else data_dir()/cases
/// (data_dir.hpp: share/backlash of the installation or of the build tree, found at run
/// time; no path is compiled in).
std::filesystem::path thesis_cases_dir();

/// CASE = a thesis id ("V", case-insensitive) or the path of a case file.
/// Unknown id that is not an existing file → CaseFileError naming it.
CaseSpec load_case(const std::string& case_or_path);

/// Exact text "p/q" (or "p" when q = 1), parseable by GiNaC's numeric(const char*).
std::string to_string(const Rational& value);

/// Nearest double.
double to_double(const Rational& value);

const char* to_string(MeasuredAt where);

}  // namespace backlash::model
