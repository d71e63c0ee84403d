// tests/discrepancy/drive_generator.hpp — records of a servo drive like EMPS, made by an
// INDEPENDENT simulator, for the measured-drive discrepancy workflow (measured_drive.hpp).
//
// What is simulated (the "truth"; units: metres, newtons, kilograms, seconds):
//   a rigid carriage   M·x'' = f(t) + T0 − Fv·x' − Fc·s,   s = sgn x' (Coulomb with sticking:
//                      at x' = 0 it stays stuck while |f + T0| ≤ Fc),
//   the force          f(t) = sat_L(c_k) + w_k on [t_k + τ, t_{k+1} + τ): the controller's
//                      output c_k held (zero-order hold) and applied τ after it was computed,
//                      clipped by the amplifier at ±L, w_k an optional unlogged force noise;
//   the controller     digital, every `period` on the QUANTISED encoder position y_k:
//                      a P position loop (kp) with velocity feed-forward of the reference and
//                      a PI velocity loop (kv, integral time ti) on the backward difference of y,
//                          e_k = r_k − y_k,  v_cmd = kp·e_k + r'_k,  ev = v_cmd − (y_k − y_{k−1})/T,
//                          I_k = I_{k−1} + kv·ev·T/ti,  c_k = kv·ev + I_k;
//   the reference      back-and-forth moves between `low` and `high` with trapezoid velocity
//                      profiles whose ramps are quintic (smooth: C² position), some moves in
//                      two speed levels as EMPS's, rests between moves;
//   the log            t_k = k·T, theta_out = y_k, drive = c_k / gain (+ optional log noise):
//                      the controller's output in the drive column's unit (EMPS: volts,
//                      gain = gtau N/V).
//
// Independence from the code the workflow fits with: the plant is integrated with
// Boost.Odeint (runge_kutta_dopri5, dense output, tolerance `tolerance`), piece by piece
// between the controller's ticks and the delayed force switches, with this file's own
// stick/slip handling (zero of the velocity located on the dense output by TOMS 748; stuck
// while |f + T0| ≤ Fc; reversal otherwise).  Nothing from numeric/, discrepancy/ or the
// measurements' signal code is called: the library links only backlash_measurements for the
// MeasuredRecord struct.
#pragma once

#include "backlash/measurements/measured_record.hpp"

#include <cstdint>
#include <limits>
#include <vector>

namespace backlash::generated_data {

struct DrivePlant {
  double mass = 95;        ///< M [kg]
  double viscous = 204;    ///< Fv [N·s/m]
  double coulomb = 0;      ///< Fc [N], with sticking
  double offset = 0;       ///< T0 [N], added to the (clipped) force
  double saturation = std::numeric_limits<double>::infinity();  ///< L [N]: the amplifier's limit
  double delay = 0;        ///< τ [s] ≥ 0: controller output k acts from t_k + τ
};

struct DriveController {
  double period = 1e-3;  ///< T [s]
  double kp = 40;        ///< position loop [1/s]
  double kv = 8000;      ///< velocity loop [N·s/m]
  double ti = 0.05;      ///< integral time of the velocity loop [s]
  bool feed_forward = true;  ///< the reference velocity added to the velocity command
};

struct DriveTrajectory {
  /// [s] With end_in_motion, the record is cut there (in the middle of a move, as a log that
  /// stops at an arbitrary time); without, moves are started until `duration` − final_rest, and
  /// the record ends `final_rest` after the last one stopped (at rest, as EMPS's records): it
  /// may be up to a move (and a rest) longer than `duration`.
  double duration = 15;
  bool end_in_motion = false;
  double final_rest = 0.3;     ///< [s]
  double low = 0.01, high = 0.24;  ///< [m] the moves go from near one end to near the other
  double min_speed = 0.06, max_speed = 0.13;  ///< peak speeds of the moves [m/s]
  double max_acceleration = 0.8;  ///< [m/s²] peak acceleration of the quintic ramps
  double min_ramp = 0.08;         ///< [s] shortest ramp
  double max_rest = 0.4;          ///< [s] rests between moves are uniform in [0, max_rest]
  std::uint64_t seed = 1;         ///< picks the moves
};

struct DriveRecordSpec {
  DrivePlant plant;
  DriveController controller;
  DriveTrajectory trajectory;
  double gain = 1;             ///< force per unit of the drive column [N/unit]
  double quantum = 5e-8;       ///< encoder resolution [m] (0: none)
  double force_noise = 0;      ///< σ of the unlogged force noise w_k [N]
  double log_noise = 0;        ///< σ of noise on the logged drive [drive unit]
  std::uint64_t seed = 1;      ///< the noises
  double tolerance = 1e-12;    ///< odeint's absolute and relative tolerance
};

struct DriveRecord {
  measurements::MeasuredRecord record;  ///< t, theta_out (encoder), drive (controller output)
  std::vector<double> reference;        ///< r_k [m]
  std::vector<double> position, velocity;  ///< the true state at t_k
  double max_force = 0;      ///< max |c_k| [N] (the controller's demand, before the clipping)
  double max_speed = 0;      ///< max |x'| at the ticks [m/s]
  double max_tracking_error = 0;  ///< max |r_k − x(t_k)| [m]
  int sticks = 0, slips = 0, reversals = 0;  ///< friction events of the simulation
  long steps = 0;            ///< odeint steps
};

/// The record, deterministic for a given spec.  std::invalid_argument for a spec it cannot
/// simulate (M ≤ 0, Fv < 0, Fc < 0, L ≤ 0, τ < 0, period ≤ 0, an empty trajectory range);
/// std::runtime_error when the simulation leaves the range the trajectory allows (a loop
/// gone unstable).
DriveRecord generate_drive_record(const DriveRecordSpec& spec);

}  // namespace backlash::generated_data
