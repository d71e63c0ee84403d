// sample_band.cpp — the turns of a damped oscillator (sample_band.hpp).
#include "hybrid/sample_band.hpp"

#include <cmath>
#include <numbers>

namespace backlash::numeric::detail {

int damped_turns(double alpha, double w2, double e0, double de0, double duration, double* turns, int capacity) {
  const double wd2 = w2 - alpha * alpha;
  if (!(w2 > 0) || !(wd2 > 1e-6 * w2) || !std::isfinite(duration)) return -1;
  const double wd = std::sqrt(wd2);
  const double P = de0, Q = (alpha * de0 + w2 * e0) / wd;
  if (P == 0 && Q == 0) return 0;  // at rest on θR: e ≡ 0
  double base = std::numbers::pi / 2 - std::atan2(Q, P);  // in [−π/2, 3π/2): the first turn is base mod π
  if (base <= 0) base += std::numbers::pi;
  if (base > std::numbers::pi) base -= std::numbers::pi;
  int count = 0;
  for (double tau = base / wd; tau < duration; tau = (base + count * std::numbers::pi) / wd) {
    if (count == capacity) return -1;
    turns[count++] = tau;
  }
  return count;
}

}  // namespace backlash::numeric::detail
