// Issue 22, the workflow's inputs and a smoke recovery (the recovery targets over 0.1° to 20° are
// checked on the independent generator's records in check_two_body_drive_workflow.cpp):
//  * a logged drive's record may leave theta_out out (t, theta_motor[, theta_load], drive);
//  * a case file with a gap and a record without the motor encoder or the drive is refused,
//    the file, line 1 and the column named; a rigid drive's record without theta_out likewise;
//  * the load observer: in contact it follows the motor on its face, it leaves it when the
//    motor decelerates faster than the coasting load, and recontacts on the opposite face after
//    crossing the gap (a constructed motion with a known answer);
//  * on a small two-inertia record (a PD loop, both encoders, RK4 with a penalty mesh in this
//    file — not the fitted code path) the backlash and the load's inertia are recovered.
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/discrepancy/two_body_drive.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

using namespace backlash;

namespace {

model::CaseSpec gap_model(double backlash) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("backlash_two_body_" + std::to_string(getpid()) + ".toml");
  {
    std::ofstream out(file);
    out << "name = \"two-body drive\"\nmeasured_at = \"motor\"\nbacklash = " << backlash
        << "\nreference = 0\n[motor]\nJ = 1e-3\nF = 1e-3\n[load]\nJ = 3e-3\nF = 3e-3\n[effects]\ncoulomb_motor = 0.02\n"
           "[experiment]\nkind = \"drive\"\ndrive_gain = 1\n";
  }
  model::CaseSpec spec = model::load_case_file(file);
  std::filesystem::remove(file);
  return spec;
}

std::string rows(const std::string& header, int columns, int n = 300) {
  std::string text = header + "\n";
  for (int k = 0; k < n; ++k) {
    text += std::to_string(k * 1e-3);
    for (int c = 1; c < columns; ++c) text += "," + std::to_string(std::sin(0.01 * k + c));
    text += "\n";
  }
  return text;
}

std::string refusal(const model::CaseSpec& spec, const measurements::MeasuredRecord& record) {
  try {
    discrepancy::find_drive_discrepancy(spec, record);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "(accepted)";
}

// A small two-inertia drive: PD loop on the motor encoder, penalty mesh (stiffness k, damping c)
// with a gap b, Coulomb friction smoothed over 1 mrad/s, RK4 at 10 µs, encoders quantised to
// 2^16 counts per turn, logged drive with noise.  Not the fitted code path.
measurements::MeasuredRecord two_inertia_record(double b) {
  const double Jm = 1e-3, JL = 4e-3, Fm = 1e-3, FL = 5e-3, Tm = 0.02, TL = 0.05, k = 2000, c = 0.1;
  const double q = 2 * M_PI / 65536, h = 1e-5;
  double x[4] = {0, 0, -b / 2, 0};  // θm, vm, θL, vL
  auto rate = [&](const double* s, double u, double* d) {
    const double gap = s[2] - s[0], rel = s[3] - s[1];
    double R = 0;  // the mesh torque on the load
    for (int face : {-1, 1}) {
      const double delta = face * gap - b / 2;
      if (delta > 0) R -= face * std::max(0.0, k * delta + c * face * rel);
    }
    d[0] = s[1], d[1] = (u - Fm * s[1] - Tm * std::tanh(s[1] / 1e-3) - R) / Jm;
    d[2] = s[3], d[3] = (R - FL * s[3] - TL * std::tanh(s[3] / 1e-3)) / JL;
  };
  measurements::MeasuredRecord r;
  r.theta_motor.emplace(), r.theta_load.emplace(), r.drive.emplace();
  r.source = "two_inertia.csv";
  unsigned seed = 12345;
  for (int n = 0; n < 6000; ++n) {
    const double t = n * 1e-3, ref = std::sin(2 * M_PI * 0.5 * t) + 0.3 * std::sin(2 * M_PI * 1.7 * t);
    const double qm = std::round(x[0] / q) * q, qL = std::round(x[2] / q) * q;
    const double u = 2.0 * (ref - qm) - 0.08 * x[1];
    seed = seed * 1103515245u + 12345u;
    r.t.push_back(t), r.theta_motor->push_back(qm), r.theta_load->push_back(qL);
    r.drive->push_back(u + 0.002 * ((seed >> 8) / 16777216.0 - 0.5));
    for (int i = 0; i < 100; ++i) {
      double k1[4], k2[4], k3[4], k4[4], y[4];
      rate(x, u, k1);
      for (int j = 0; j < 4; ++j) y[j] = x[j] + h / 2 * k1[j];
      rate(y, u, k2);
      for (int j = 0; j < 4; ++j) y[j] = x[j] + h / 2 * k2[j];
      rate(y, u, k3);
      for (int j = 0; j < 4; ++j) y[j] = x[j] + h * k3[j];
      rate(y, u, k4);
      for (int j = 0; j < 4; ++j) x[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    }
  }
  return r;
}

}  // namespace

TEST(TwoBodyDriveInputs, item22_logged_drive_record_without_theta_out_is_read) {
  const measurements::MeasuredRecord motor = measurements::parse_measured_csv(rows("t,theta_motor,drive", 3), "m.csv");
  EXPECT_TRUE(motor.theta_out.empty());
  ASSERT_TRUE(motor.theta_motor && motor.drive);
  EXPECT_EQ(motor.theta_motor->size(), 300u);
  const measurements::MeasuredRecord both = measurements::parse_measured_csv(rows("t,theta_motor,theta_load,drive", 4), "b.csv");
  EXPECT_TRUE(both.theta_out.empty() && both.theta_load);
  // Written back without a theta_out column, bit for bit.
  const std::string text = measurements::format_measured_csv(both);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,theta_motor,theta_load,drive");
  EXPECT_EQ(*measurements::parse_measured_csv(text, "again.csv").theta_load, *both.theta_load);
  // Without the drive theta_out stays required.
  EXPECT_THROW(measurements::parse_measured_csv(rows("t,theta_motor", 2), "s.csv"), measurements::MeasuredDataError);
}

TEST(TwoBodyDriveInputs, item22_gap_model_refuses_a_record_without_the_motor_encoder) {
  const model::CaseSpec spec = gap_model(0.1);
  const auto no_motor = measurements::parse_measured_csv(rows("t,theta_out,drive", 3), "rigid.csv");
  EXPECT_NE(refusal(spec, no_motor).find("rigid.csv:1: theta_motor: missing column"), std::string::npos) << refusal(spec, no_motor);
  const auto no_drive = measurements::parse_measured_csv(rows("t,theta_out,theta_motor", 3), "nodrive.csv");
  EXPECT_NE(refusal(spec, no_drive).find("nodrive.csv:1: drive: missing column"), std::string::npos) << refusal(spec, no_drive);
  // A rigid drive's record must give theta_out.
  const auto motor_only = measurements::parse_measured_csv(rows("t,theta_motor,drive", 3), "motor.csv");
  EXPECT_NE(refusal(gap_model(0), motor_only).find("motor.csv:1: theta_out: missing column"), std::string::npos)
      << refusal(gap_model(0), motor_only);
}

TEST(TwoBodyDriveInputs, item22_load_observer_crosses_the_gap_at_a_reversal) {
  // The motor moves forward at 1 rad/s to θm = 0.5 at t = 0.5 s, then backward at 1 rad/s; its
  // central differences: v = 0 and a = −2000 rad/s² at the peak.  There the load (frictionless,
  // JL = 1) would need a pull: it leaves face −b/2 at rest at θL = 0.5 − b/2 = 0.4 and stays, so
  // the gap is x = 0.4 − (1 − t) = t − 0.6 until it reaches +b/2 at t = 0.7 s, and from then on
  // the load rides on face +b/2.
  const double fs = 1000, b = 0.2;
  const std::size_t n = 1000;
  std::vector<double> qm(n), vm(n), am(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    qm[k] = k <= 500 ? t : 1.0 - t;
    vm[k] = k < 500 ? 1 : k == 500 ? 0 : -1;
  }
  am[500] = -2 * fs;
  const std::vector<double> x = discrepancy::load_observer(qm, vm, am, fs, b, 0, 1, 0, 0);
  EXPECT_DOUBLE_EQ(x[100], -b / 2);        // in contact, pushed forward
  EXPECT_NEAR(x[550], 0.55 - 0.6, 1e-12);  // in flight, the load at rest
  EXPECT_NEAR(x[650], 0.65 - 0.6, 1e-12);
  EXPECT_NEAR(x[710], b / 2, 1e-12);       // recontact on the other face, pushed backward
  EXPECT_NEAR(x[900], b / 2, 1e-12);
}

TEST(TwoBodyDriveInputs, item22_both_encoders_name_the_backlash) {
  const double b = 0.05;  // about 2.9°
  const measurements::MeasuredRecord record = two_inertia_record(b);
  const discrepancy::DriveDiscrepancyResult r = discrepancy::find_drive_discrepancy(gap_model(0.1), record);
  ASSERT_TRUE(r.two_body);
  const discrepancy::TwoBodyFindings& two = *r.two_body;
  EXPECT_TRUE(two.load_encoder);
  ASSERT_GE(two.parameter_corrections.size(), 3u);
  const discrepancy::ParameterCorrection& backlash = two.parameter_corrections[0];
  EXPECT_EQ(backlash.key, "backlash");
  EXPECT_LE(std::fabs(backlash.fitted - b), std::max(0.05 * b, 3 * backlash.uncertainty)) << backlash.fitted;
  EXPECT_EQ(two.parameter_corrections[1].key, "load.J");
  EXPECT_NEAR(two.parameter_corrections[1].fitted, 4e-3, 0.1 * 4e-3);
  EXPECT_FALSE(two.rigid);
  EXPECT_FALSE(two.reversals.empty());
  EXPECT_EQ(two.loop_load.size(), record.size());
}

