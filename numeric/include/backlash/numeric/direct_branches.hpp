// backlash/numeric/direct_branches.hpp — the generated direct per-branch
// evaluators (backlash/generated/branches.hpp, emitted by backlash_codegen from
// symbolic::derive_general_branches()) behind one switch.
//
// These are the exact partial-fraction forms: exact on their own branch, and
// losing digits near a branch boundary (e.g. load_generic's error grows like
// 1/FL² as FL → 0).  Use parametric.hpp's stable evaluator for arbitrary
// parameters; these are validated on their branch's representative point.
#pragma once

#include "backlash/numeric/parametric.hpp"

namespace backlash::numeric {

/// Free-mode states from the generated formulas of `free_branch` (a free branch).
FreeState direct_free_state(Branch free_branch, const Parameters& p, double t, double dtheta_m0);
/// Contact-mode states from the generated formulas of `contact_branch`.
ContactState direct_contact_state(Branch contact_branch, const Parameters& p, double t, double theta_o0,
                                  double dtheta_o0);
/// cot φ as the generated code of `free_branch` writes it.
double direct_cot_phi(Branch free_branch, const Parameters& p);

}  // namespace backlash::numeric
