// backlash/numeric/mode.hpp — which linear mode the hybrid model with effects is in
// (docs/effects.md): rigid contact on a face, free flight, or the mesh engaged (compliance);
// each body slipping in a direction s = ±1 or stuck; the drive linear or clipped at ±L.
// The modes' closed forms are internal to the effects engine (numeric/effects/effect_modes.hpp);
// this is the name of a mode, as the effects gate reports it (effects_simulation.hpp).
#pragma once

#include <string>

namespace backlash::numeric {

enum class ModeKind { Contact, Free, Mesh };

struct Mode {
  ModeKind kind = ModeKind::Contact;
  int face = -1;        ///< σ: contact / mesh face, or (free) the face last left
  int regime = 0;       ///< drive: 0 linear, ±1 clipped at ±L
  int slip_motor = 1;   ///< ±1 slipping in that direction, 0 stuck (in contact: the pair's)
  int slip_load = 1;    ///< free / mesh: the load's; in contact equal to slip_motor
  bool operator==(const Mode& other) const = default;
  std::string describe() const;
};

}  // namespace backlash::numeric
