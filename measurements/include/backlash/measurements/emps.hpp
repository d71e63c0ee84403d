// backlash/measurements/emps.hpp — EMPS benchmark records (.mat, read with matio).
//
// The Electro-Mechanical Positioning System benchmark (Janot, Gautier, Brunot
// 2019; data and README in tests/data/emps/): a prismatic joint driven by a DC
// motor through a ball screw under closed-loop position control.  A record holds
//   t         time [s]                               N×1 double
//   qm        motor position from the encoder [m]    N×1 double
//   qg        reference position [m]                 N×1 double
//   vir       controller output, motor voltage [V]   N×1 double
//   gtau      motor force gain [N/V]                 scalar (force = gtau·vir)
//   kp, kv    position (P) / velocity (PI) gains     scalars
//   pulses_N  validation record only: the pulses     N×1 double
// Other variables in the file are ignored.
//
// What the two published files contain (measured here, pinned by
// tests/measurements/exam_emps_records.cpp):
//   DATA_EMPS.mat         MATLAB 5.0 (written on PCWIN64, 2018), all variables
//                         double, series 24841×1: t = 0 … 24.84 s at 1 kHz
//                         (every step 1 ms within 5e-8 s), gtau = 35.150651882485469,
//                         kp = 160.18, kv = 243.45, no NaN, t strictly increasing.
//   DATA_EMPS_PULSES.mat  the same layout, sampling and gains, plus
//                         pulses_N: 0 or 5 only; 25 pulses rising at
//                         t = 0.344 + k s (k = 0…24), each 0.5 s long, the last
//                         running to the end of the record: 49 edges.
// The pulses are ALREADY IN vir: at each of the 49 edges vir steps by
// Δpulses_N·(1.013 ± 0.007) (largest mismatch 0.16), while between edges vir
// moves by 0.043 on average and never more than 0.74 per sample (in the
// estimation record: 0.023 on average, at most 0.37).  So
// pulses_N is in vir's unit (volts, despite its name: 5 V ≈ 176 N) and the
// force on the mechanism is gtau·vir alone — adding pulses_N again would count
// the pulses twice.  emps_pulses_in_vir() makes this decision from the data of
// each file rather than assuming it.
#pragma once

#include "backlash/measurements/measured_record.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

namespace backlash::measurements {

struct EmpsRecord {
  std::vector<double> t;    ///< [s], strictly increasing
  std::vector<double> qm;   ///< motor position [m]
  std::vector<double> qg;   ///< reference position [m]
  std::vector<double> vir;  ///< controller output [V]
  double gtau = 0;          ///< force gain [N/V]
  double kp = 0, kv = 0;    ///< loop gains
  std::optional<std::vector<double>> pulses_N;  ///< validation record only
  std::filesystem::path source;

  std::size_t size() const { return t.size(); }
};

/// Reads an EMPS record through matio.  Errors are MeasuredDataError, one line
/// "FILE: VARIABLE: problem" (VARIABLE empty for file-level problems): no such
/// file, not a regular file, larger than max_file_bytes, not a MATLAB v5/v7.3
/// .mat file, a truncated or corrupt file, a missing variable, a variable that
/// is not numeric (char, cell, struct, logical, sparse) or complex, a time
/// series that is not a vector, one of another length than t, fewer than 2
/// samples, a scalar that is not 1×1, NaN or an infinity anywhere, t not
/// strictly increasing, gtau = 0.
/// matio's own diagnostics are captured into the message, never printed (the
/// first call installs a quiet log function into matio, process-wide).
EmpsRecord read_emps(const std::filesystem::path& file, std::uintmax_t max_file_bytes = default_max_file_bytes);

/// How pulses_N relates to vir, decided from the data.
enum class EmpsPulses {
  none,       ///< no pulses_N, or it is all zero
  contained,  ///< vir steps with every edge of pulses_N, 1:1 in volts: already in vir
  added,      ///< vir does not step at any edge: a force [N] on top of gtau·vir
};

/// Decides from the record: at every sample k where pulses_N changes by Δp,
/// "contained" if |Δvir − Δp| <= Δp/4 at all edges, "added" if
/// |gtau·Δvir| <= |Δp|/4 at all edges.  Anything else (mixed or in between)
/// → MeasuredDataError naming pulses_N: the import refuses to guess.
EmpsPulses emps_pulses_in_vir(const EmpsRecord& record);

/// The drive force on the mechanism [N]: gtau·vir, plus pulses_N if and only
/// if emps_pulses_in_vir() says "added".
std::vector<double> emps_drive_force(const EmpsRecord& record);

/// The record in the project's CSV form: t, theta_out = qm, drive =
/// emps_drive_force(); source kept.
MeasuredRecord to_measured_record(const EmpsRecord& record);

const char* to_string(EmpsPulses pulses);

}  // namespace backlash::measurements
