// The measured-drive workflow's results on a drive with a gap (discrepancy/two_body_drive.hpp):
// its JSON keys, figures (lost motion at each reversal, the hysteresis loop) and page sections.
#include "two_body_page.hpp"

#include "page_json.hpp"
#include "plots.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::discrepancy::detail {

nlohmann::json two_body_json(const TwoBodyFindings& two) {
  nlohmann::json reversals = nlohmann::json::array();
  for (const LostMotion& l : two.reversals)
    reversals.push_back({{"t", l.t}, {"direction", l.direction}, {"measured", json_number(l.measured)}, {"model", json_number(l.model)}});
  return {{"method", two.method},
          {"load_encoder", two.load_encoder},
          {"rigid", two.rigid},
          {"gap_offset", two.gap_offset},
          {"contact_fraction", json_number(two.contact_fraction)},
          {"torque_rms_rigid", json_number(two.torque_rms_rigid)},
          {"noise", {{"level", json_number(two.noise.level)}, {"drive", json_number(two.noise.drive)},
                     {"motor_encoder", json_number(two.noise.motor)}, {"load_encoder", json_number(two.noise.load)},
                     {"sigma_drive", json_number(two.noise.sigma_drive)}, {"sigma_motor", json_number(two.noise.sigma_motor)},
                     {"sigma_load", json_number(two.noise.sigma_load)}, {"step_motor", two.noise.step_motor},
                     {"step_load", two.noise.step_load}}},
          {"backlash_sigma_moves", json_number(two.backlash_sigma_moves)},
          {"backlash_sigma_timing", json_number(two.backlash_sigma_timing)},
          {"reversals", reversals}};
}

void two_body_figures(const TwoBodyFindings& two, std::vector<reports::Plot>& figures) {
  std::vector<double> index, measured, model;  // line_plot copies the points
  for (std::size_t i = 0; i < two.reversals.size(); ++i) {
    index.push_back(static_cast<double>(i + 1));
    // In mrad: the two agree to a few µrad, and gnuplot's 6 significant digits on rad ticks
    // would print the same label on neighbouring ticks.
    measured.push_back(1e3 * two.reversals[i].measured);
    model.push_back(1e3 * two.reversals[i].model);
  }
  std::vector<Curve> lost{{"model", "#2a7", &index, &model}};
  if (two.load_encoder) lost.insert(lost.begin(), Curve{"measured", "#222", &index, &measured});
  reports::Plot plot = line_plot("lost_motion", "Lost motion at each reversal of the motor (the gap's swing face to face)",
                                 "reversal", "lost motion [mrad]", lost);
  // The y range padded (a tenth of the span, or 1 % of the value when all are equal): a
  // curve on the range's end would lie on the axis, unseen.
  double lo = INFINITY, hi = -INFINITY;
  for (const Curve& c : lost)
    for (double y : *c.y)
      if (std::isfinite(y)) lo = std::min(lo, y), hi = std::max(hi, y);
  if (lo <= hi) {
    const double pad = hi > lo ? 0.1 * (hi - lo) : 0.01 * std::max(std::fabs(hi), 1e-12);
    plot.y_range = {lo - pad, hi + pad};
  }
  plot.key = "below";
  figures.push_back(plot);
  if (!two.load_encoder) return;
  reports::Plot loop = line_plot("hysteresis_loop", "Hysteresis loop: the load against the motor", "motor position [rad]",
                                 "load position [rad]",
                                 {{"measured", "#222", &two.loop_motor, &two.loop_load},
                                  {"model (load observer on the measured motor)", "#2a7", &two.loop_motor, &two.loop_model, true}});
  loop.key = "inside left top";  // the loop runs from the bottom left to the top right
  figures.push_back(loop);
}

void two_body_page(std::ostringstream& md, const TwoBodyFindings& two, bool drawn) {
  md << "## The gap\n\nA drive with a gap: the motor and the load as two bodies, the logged drive on the motor; method: "
     << two.method << " (docs/discrepancy.md, \"Measured drive with a gap\"). " << two.reversals_count
     << " reversals of the motor.\n\n| parameter | nominal | fitted | ± (1σ) | ratio |\n|---|---|---|---|---|\n";
  for (const ParameterCorrection& c : two.parameter_corrections)
    md << "| " << c.key << " | " << number(c.nominal) << " | " << number(c.fitted) << " | " << number(c.uncertainty) << " | "
       << number(c.ratio) << " |\n";
  if (std::isfinite(two.backlash_sigma_timing))
    md << "\nσ of the backlash: " << number(two.backlash_sigma_moves) << " from the scatter over the moves (jackknife) and "
       << number(two.backlash_sigma_timing) << " from the separations and impacts placed on whole samples (shared by every "
       << "move), added in quadrature.\n";
  if (two.rigid) md << "\n**A rigid drive**: the backlash is not distinguishable from 0 (within 3σ).\n";
  if (two.load_encoder)
    md << "\nThe encoders' relative zero: " << number(two.gap_offset) << "; " << number(100 * two.contact_fraction)
       << " % of the compared samples in certain contact (the backlash is read there).\n";
  else
    md << "\nTorque RMS of the same fit with no gap: " << number(two.torque_rms_rigid) << ".\n";
  md << "\n### Lost motion at each reversal\n\n| reversal | t [s] | direction | measured | model |\n|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < two.reversals.size() && i < 20; ++i) {
    const LostMotion& l = two.reversals[i];
    md << "| " << i + 1 << " | " << number(l.t) << " | " << (l.direction > 0 ? "forward" : "backward") << " | "
       << (std::isfinite(l.measured) ? number(l.measured) : std::string("(motor encoder alone)")) << " | " << number(l.model) << " |\n";
  }
  if (two.reversals.size() > 20) md << "\n(the first 20 of " << two.reversals.size() << "; all in discrepancy.json)\n";
  if (!drawn) return;
  md << "\n![lost motion](lost_motion.svg)\n\n";
  if (two.load_encoder) md << "![hysteresis loop](hysteresis_loop.svg)\n\n";
}

}  // namespace backlash::discrepancy::detail
