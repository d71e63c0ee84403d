// The load observer of the measured-drive workflow on a drive with a gap (two_body_drive.hpp):
// the load's motion reconstructed from the measured motor motion for a trial gap.
#include "backlash/discrepancy/two_body_drive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace backlash::discrepancy {

namespace {

// The load coasting over h seconds under its own friction: JL·v' = −FL·v − TL·sgn v, exact
// (sticking at v = 0: with no other torque on it a load at rest stays at rest).
void coast(double& x, double& v, double h, double JL, double FL, double TL) {
  if (v == 0) return;
  const double s = v > 0 ? 1 : -1, k = FL / JL, c = TL / JL;  // v' = −k·v − c·s
  // Time to stop under the deceleration (k·|v| + c): k = 0 gives |v|/c.
  double stop = INFINITY;
  if (c > 0) stop = k > 0 ? std::log1p(k * std::fabs(v) / c) / k : std::fabs(v) / c;
  const double tau = std::min(h, stop);
  if (k > 0) {
    const double vinf = -c * s / k;  // the velocity it would tend to
    const double e = std::expm1(-k * tau);
    x += vinf * tau - (v - vinf) * e / k;
    v = vinf + (v - vinf) * (1 + e);
  } else {
    x += v * tau - 0.5 * c * s * tau * tau;
    v -= c * s * tau;
  }
  if (tau >= stop) v = 0;
}

}  // namespace

std::vector<double> load_observer(std::span<const double> qm, std::span<const double> vm, std::span<const double> am,
                                  double fs, double b, double x0, double JL, double FL, double TL, double compliance) {
  const std::size_t n = qm.size();
  if (vm.size() != n || am.size() != n) throw std::invalid_argument("load_observer: qm, vm and am differ in length");
  if (!(fs > 0) || !(b >= 0) || !(JL > 0) || !(FL >= 0) || !(TL >= 0) || !std::isfinite(x0) || !(compliance >= 0))
    throw std::invalid_argument("load_observer: needs fs > 0, b >= 0, JL > 0, FL >= 0, TL >= 0, finite x0 (got fs " + std::to_string(fs) + ", b " + std::to_string(b) + ", JL " + std::to_string(JL) + ", FL " + std::to_string(FL) + ", TL " + std::to_string(TL) + ")");
  std::vector<double> gap(n, x0 - b / 2);
  if (n == 0) return gap;
  const double h = 1 / fs;
  // Start: in contact on the face the first motion presses (the motor moving forward pushes the
  // load from behind: face −1).
  int face = -1;
  for (std::size_t k = 0; k < n; ++k)
    if (vm[k] != 0) {
      face = vm[k] > 0 ? -1 : 1;
      break;
    }
  bool contact = true;
  double xL = qm[0] + x0 + face * b / 2, vL = vm[0];
  for (std::size_t k = 0; k < n; ++k) {
    if (contact) {
      const double s = vm[k] > 0 ? 1 : vm[k] < 0 ? -1 : 0;
      const double push = JL * am[k] + FL * vm[k] + TL * s;  // the torque the load needs to follow: R
      xL = qm[k] + x0 + face * b / 2 - compliance * push, vL = vm[k];  // the mesh deflected by R/kc
      if (-face * push < 0 && b > 0) contact = false;  // holding the face would need a pull
    } else {
      coast(xL, vL, h, JL, FL, TL);
      const double x = xL - qm[k] - x0;
      if (x <= -b / 2 || x >= b / 2) {  // a face reached: the inelastic impact, contact again
        face = x <= -b / 2 ? -1 : 1;
        contact = true;
        xL = qm[k] + x0 + face * b / 2, vL = vm[k];
      }
    }
    gap[k] = xL - qm[k];
  }
  return gap;
}

}  // namespace backlash::discrepancy
