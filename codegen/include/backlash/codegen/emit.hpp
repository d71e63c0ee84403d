// backlash/codegen/emit.hpp — C++ evaluators (and their LaTeX) from the exact
// symbolic solutions.
//
// Per case (emit_case_header): one self-contained header, namespace
// backlash::generated::case_<ID>, that depends only on <cmath>:
//   free mode   theta_m, dtheta_m, theta_L, dtheta_L, gap = θL − θm   (t, θ̇m0)
//               free_state(t, θ̇m0) — all four sharing their exponentials
//   contact     theta_o, dtheta_o (t, θo0, θ̇o0), contact_state(...)
//   separation  cot_phi, separation_theta(θ̇m0) = θR + cot φ·θ̇m0
//   metadata    case id, branches, parameter order and exact values, input hash
//   latex       the exact expression of every state, as LaTeX strings
// Every exp/cos/sin is hoisted into a named constant (e_m1_5 = exp(-t/5));
// decaying rational rates that are small multiples (≤ 16) of a common rate
// share one exp by binary powering (e_m3_5 = e_m1_5*e_m1_5_p2);
// frequencies (square roots) are named constexpr constants; numbers are exact
// rationals written as "p.0/q.0" (p, q exact in a double: one correctly
// rounded division, never C integer division) or, when irrational, the
// correctly rounded double of a 40-digit evaluation in 17 significant digits
// with the exact value in a comment.  Terms are sorted (non-oscillating first,
// slower decay first, then power of t), so the text is stable across runs.
//
// Per pole-structure branch (emit_branches_header): the general solutions of
// symbolic::derive_general_branches() as functions of runtime parameters
// (namespace backlash::generated::branches::<branch>).  These are the direct
// partial-fraction forms: exact on their branch but, like every partial
// fraction, inaccurate near merging poles — numeric/parametric.hpp holds the
// stable layer that is accurate everywhere.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace backlash::codegen {

/// "backlash_codegen <project version>".
std::string generator_name();

/// 64-bit FNV-1a of bytes; hash_text gives "fnv1a64:<16 hex digits>".
std::uint64_t fnv1a64(std::string_view bytes);
std::string hash_text(std::uint64_t hash);

/// Where a case came from: "cases/V.toml" (folder/file) and the FNV-1a hash
/// of the file's bytes (unreadable file: hash of nothing).
struct CaseSource {
  std::string display_path;
  std::string input_hash;
};
CaseSource describe_source(const model::CaseSpec& spec);

/// "case_V" for id "V"; a file stem is turned into an identifier
/// ("my-case.2" → "case_my_case_2").
std::string case_namespace(const std::string& case_id);

/// The header (case_<ID>.hpp) for one case.
std::string emit_case_header(const model::CaseSpec& spec, const symbolic::CaseDerivation& derivation);

/// LaTeX of every generated expression of a case, state by state
/// (keys: theta_m, dtheta_m, theta_L, dtheta_L, gap, theta_o, dtheta_o,
/// cot_phi, separation_theta).
std::map<std::string, std::string> case_latex(const symbolic::CaseDerivation& derivation);
/// A LaTeX fragment (case_<ID>.tex) with those equations.
std::string emit_case_latex(const model::CaseSpec& spec, const symbolic::CaseDerivation& derivation);

/// The direct per-branch parametric evaluators (branches.hpp) and their LaTeX.
std::string emit_branches_header(const std::vector<symbolic::GeneralBranch>& branches);
std::string emit_branches_latex(const std::vector<symbolic::GeneralBranch>& branches);

/// cases.hpp: includes every case header and defines the X-macro
/// BACKLASH_GENERATED_CASES(X) → X(I) X(II) ...
std::string emit_cases_umbrella(const std::vector<std::string>& case_ids);

struct GeneratedFile {
  std::filesystem::path relative;  ///< e.g. "case_V.hpp"
  std::string content;
};
/// case_<ID>.hpp and case_<ID>.tex (derives the case; throws on failure).
std::vector<GeneratedFile> emit_case_files(const model::CaseSpec& spec);

/// Write `content` to `file` only if it differs from what is there (a no-op
/// rebuild touches nothing).  Returns true if the file was written.  Throws
/// std::runtime_error when the file cannot be written.
bool write_if_changed(const std::filesystem::path& file, const std::string& content);

}  // namespace backlash::codegen
