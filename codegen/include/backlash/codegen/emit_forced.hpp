// backlash/codegen/emit_forced.hpp — C++ evaluators (and LaTeX) of a case's
// exact forced modes (symbolic/forced_modes.hpp: the linear modes with a
// constant forcing that Coulomb friction, saturation and a torque offset add).
//
// Emitted into each case header, nested in its namespace, as
//   namespace backlash::generated::case_<ID>::forced {
//     contact_constant(t, w0, g)  → {displacement, velocity}   J Δ'' + F Δ' = g
//     load_constant(t, v0, g)     → {displacement, velocity}   JL Δ'' + FL Δ' = g
//     motor_constant(t, v0, g)    → {displacement, velocity}   Jm Δ'' + Fm Δ' = g
//     motor_closed(t, y0, v0)     → {y, velocity, displacement} (output at the motor)
//     coupled(t, vm0, yL0, vL0, um, uL)
//         → {motor_displacement, motor_velocity, load_displacement, load_velocity} (output at the load)
//     struct latex { … }           the exact expression of every output
//   }
// with the conventions of the case header (emit.hpp): every exp/cos/sin hoisted
// into a named constant (decaying rational rates that are small multiples of a
// common rate share one exp by binary powering), exact rationals as "p.0/q.0",
// irrational constants correctly rounded from 40 digits, terms sorted, <cmath>
// only.  Displacements are Δ = θ − θ(0), never absolute angles.
#pragma once

#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/forced_modes.hpp"

#include <map>
#include <string>

namespace backlash::codegen {

/// The `namespace forced { … }` block of a case header (derives the forced
/// modes with the case's radicals; throws symbolic::VerificationError on a
/// failed exact check).
std::string emit_forced_namespace(const symbolic::CaseDerivation& derivation);
std::string emit_forced_namespace(const symbolic::ForcedModes& modes);

/// LaTeX of every forced output, keyed "<mode>.<output>" ("coupled.load_velocity"),
/// and of every mode's ODE, keyed "<mode>".
std::map<std::string, std::string> forced_latex(const symbolic::ForcedModes& modes);

/// The LaTeX section appended to case_<ID>.tex.
std::string emit_forced_latex(const symbolic::CaseDerivation& derivation);

}  // namespace backlash::codegen
