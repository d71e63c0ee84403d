// tests/discrepancy/two_body_generator.hpp — records of a geared servo WITH BACKLASH, made by
// an INDEPENDENT simulator, for the two-body measured-drive workflow (issue 22;
// docs/discrepancy.md, "Measured-drive records").
//
// What is simulated (the "truth"; units as the project's: rad, s, N·m; gear ratio 1;
// conventions of docs/physics.md):
//   the motor      Jm·θ̈m = u(t) + Rm − Fm·θ̇m − Cm·sm,
//   the load       JL·θ̈L =        RL − FL·θ̇L − CL·sL,
//                  s = sgn θ̇ while a body moves; a body with Coulomb friction C > 0 that stops
//                  stays stuck while the rest of its torque N satisfies |N| ≤ C, and breaks away
//                  in the direction of N when N leaves that band (its own stick logic);
//   the gear       the gap x = θL − θm, the faces x = ±b/2 (centred, b the total backlash).
//                  Inside the gap nothing is transmitted (the dead zone).  Beyond face σ the
//                  teeth overlap by δσ = σ·x − b/2 > 0 and
//                    - a COMPLIANT mesh (stiffness k finite, damping c ≥ 0) transmits
//                      P = k·δσ + c·δ̇σ while P > 0 (never a pull: docs/effects.md,
//                      "Compliance"), RL = −σ·P, Rm = +σ·P;
//                    - RIGID teeth (k = ∞) meet in an inelastic impact that conserves momentum,
//                      (Jm + JL)·ω⁺ = Jm·θ̇m + JL·θ̇L, and then move as one body while the
//                      torque the motor transmits keeps its holding sign (docs/physics.md,
//                      "Gap, faces, events"); they part when it changes sign;
//   the controller digital, every `period` T, the position on the QUANTISED encoder y of the
//                  motor or the load, the velocity on the quantised motor encoder ym (a
//                  dual-loop drive when y is the load's):
//                    e_k = r_k − y_k,  I_k = I_{k−1} + ki·T·e_k,
//                    u_k = kp·e_k + kv·(ṙ_k − (ym_k − ym_{k−1})/T) + I_k
//                  (kv = ki = 0: a pure P position loop; ki > 0: PI), held on [t_k, t_{k+1});
//   the reference  a trapezoid between −A and +A: rests, moves at speed V with smooth (quintic
//                  velocity) ramps, `moves` moves, so moves − 1 reversals of the motion;
//   the log        t_k = k·T, theta_motor = the quantised motor encoder, theta_load = the
//                  quantised load encoder (both written or the motor's alone),
//                  drive = u_k / gain + noise (the logged current: the torque command).
//
// Independence from the code the workflow fits with: the plant is integrated with
// Boost.Odeint (runge_kutta_dopri5 with dense output) piece by piece between the controller's
// ticks, with this file's own hybrid logic: every event (a face reached, a mesh engaged or
// released, an impact, a separation, a body stopping, sticking or breaking away) is a zero of
// an event function located on the dense output by TOMS 748.  Nothing of numeric/,
// discrepancy/, measurements/ or model/ is called (the library links only Boost's headers);
// the CSV and the case file are written here as plain text.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace backlash::generated_data {

inline constexpr double kRigid = std::numeric_limits<double>::infinity();

struct TwoBodyPlant {
  double Jm = 0.01, Fm = 0.02;  ///< motor inertia [kg·m²], viscous friction [N·m·s/rad]
  double JL = 0.03, FL = 0.05;  ///< load inertia, viscous friction
  double backlash = 0.0349;     ///< b [rad]: the total gap (faces at ±b/2); 0: no gap
  double stiffness = kRigid;    ///< k [N·m/rad] of the mesh; kRigid: rigid teeth, inelastic impacts
  double damping = 0;           ///< c [N·m·s/rad] of a compliant mesh
  double coulomb_motor = 0;     ///< Cm [N·m], with sticking
  double coulomb_load = 0;      ///< CL [N·m], with sticking
};

/// The true state: motor angle and speed, load angle and speed [rad, rad/s].
struct TwoBodyState {
  double theta_m = 0, omega_m = 0, theta_l = 0, omega_l = 0;
};

/// Energy bookkeeping of a simulation [J]: what the motor torque put in equals the kinetic
/// energy gained plus what is stored in an engaged mesh plus every loss.
struct TwoBodyEnergy {
  double work = 0;           ///< ∫ u·θ̇m dt
  double dissipated = 0;     ///< ∫ (Fm·θ̇m² + FL·θ̇L² + Cm·|θ̇m| + CL·|θ̇L| + c·δ̇²) dt
  double impact_losses = 0;  ///< Σ Jm·JL/(2(Jm + JL))·(θ̇m − θ̇L)² over the rigid impacts
  double release_losses = 0; ///< Σ k·δ²/2 at the releases of an overlapping mesh (minus at re-engagements)
  double kinetic = 0, spring = 0;  ///< at the end of the simulation (kinetic: its change from the start)
};

struct TwoBodyEvents {
  int impacts = 0, separations = 0;     ///< rigid teeth
  int engagements = 0, releases = 0;    ///< compliant mesh
  int sticks = 0, breakaways = 0;       ///< Coulomb friction, either body
  std::vector<double> contact_times;    ///< every impact or engagement [s]
  std::vector<double> separation_times; ///< every separation or release [s]
  long steps = 0;                       ///< odeint steps
};

/// The plant driven open loop by a held torque: `torque[k]` acts on [t[k], t[k+1]); the
/// state at every t[k].  (The closed loop below uses the same integrator; exposed for the
/// generator's own tests against hand-solved cases.)
struct TwoBodyRun {
  std::vector<TwoBodyState> state;
  TwoBodyEvents events;
  TwoBodyEnergy energy;
};
TwoBodyRun simulate_two_body(const TwoBodyPlant& plant, const std::vector<double>& t, const std::vector<double>& torque,
                             const TwoBodyState& start, double tolerance = 1e-11);

struct TwoBodyLoop {
  double period = 1e-3;   ///< T [s]
  bool on_load = false;   ///< the position loop closed on the load encoder (backlash inside it)
  double kp = 20;         ///< position gain [N·m/rad]
  double kv = 1.2;        ///< velocity gain on the motor encoder's backward difference [N·m·s/rad]
  double ki = 0;          ///< integral gain [N·m/(rad·s)]
};

struct TwoBodyReference {
  double amplitude = 0.5;  ///< A [rad]: the moves go between −A and +A
  double speed = 2;        ///< V [rad/s] cruise speed
  double ramp = 0.1;       ///< [s] each acceleration and deceleration (> 0)
  double rest = 0.3;       ///< [s] at each end (and at the start and the end of the record)
  int moves = 6;           ///< moves − 1 reversals
};

struct TwoBodyRecordSpec {
  TwoBodyPlant plant;
  TwoBodyLoop loop;
  TwoBodyReference reference;
  long counts_per_rev = 1 << 16;  ///< encoder resolution of both encoders (0: not quantised)
  double gain = 1;                ///< torque per unit of the drive column [N·m/unit]
  double current_noise = 0;       ///< σ of the additive noise on the logged drive [drive unit]
  std::uint64_t seed = 1;         ///< the noise
  double tolerance = 1e-11;       ///< odeint's absolute and relative tolerance
};

struct TwoBodyRecord {
  std::vector<double> t, theta_motor, theta_load, drive;  ///< the log (quantised encoders, logged drive)
  std::vector<double> reference, torque;                  ///< r_k and the true command u_k [N·m]
  std::vector<TwoBodyState> state;                        ///< the true state at t_k
  TwoBodyEvents events;
  TwoBodyEnergy energy;
  int reversals = 0;  ///< of the motor's true motion (sign changes of θ̇m beyond 30 % of V)
};

/// The workflow tests' standard record with backlash b [rad]: moves between ±0.8 rad and a
/// logged drive with noise σ = 0.002; the rest as TwoBodyRecordSpec's defaults.
TwoBodyRecordSpec standard_record_spec(double backlash);

/// The closed-loop record, deterministic for a given spec.  std::invalid_argument for a spec
/// it cannot simulate (J ≤ 0, F < 0, C < 0, b < 0, k ≤ 0, c < 0, T ≤ 0, A ≤ 0, V ≤ 0,
/// ramp ≤ 0, moves < 1, gain = 0, a move too short for its ramps); std::runtime_error when the loop
/// runs away (a body further than 10·A + π from the reference) or the events do not resolve.
TwoBodyRecord generate_two_body_record(const TwoBodyRecordSpec& spec);

/// The CSV of the record: `t,theta_motor,theta_load,drive` (both encoders) or
/// `t,theta_motor,drive` (the motor encoder alone); numbers in the shortest form that reads
/// back to the same double.
std::string two_body_csv(const TwoBodyRecord& record, bool both_encoders);

/// The model (case) file a user would write for this drive: `[experiment] kind = "drive"`,
/// `drive_gain`, the nominal plant (`backlash`, `[motor]`, `[load]`, `[effects]` for the
/// Coulomb frictions and a finite mesh stiffness as `compliance`), `[fit] free` if given.
struct TwoBodyCase {
  std::string name = "generated two-body drive";
  std::string comment;  ///< written first, each line as a TOML comment
  TwoBodyPlant nominal;
  double drive_gain = 1;
  std::vector<std::string> free;  ///< e.g. "backlash", "load.J", "load.F"
};
std::string two_body_case_toml(const TwoBodyCase& model);

/// Writes text to a file (std::runtime_error naming it when it cannot).
void write_text_file(const std::filesystem::path& file, const std::string& text);

}  // namespace backlash::generated_data
