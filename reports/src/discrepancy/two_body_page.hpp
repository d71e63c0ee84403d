// reports/src/discrepancy/two_body_page.hpp (internal) — the measured-drive page's parts for a
// drive with a gap (discrepancy/two_body_drive.hpp): JSON keys, figures, page sections.
#pragma once

#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/reports/plot.hpp"

#include <nlohmann/json.hpp>

#include <sstream>
#include <vector>

namespace backlash::discrepancy::detail {

/// "two_body": the method, the encoders, rigid, the gap's offset, the lost motion at each reversal.
nlohmann::json two_body_json(const TwoBodyFindings& two);

/// The lost motion at each reversal (measured beside the model's) and, with both encoders, the
/// hysteresis loop (load against motor, measured and the model's).
void two_body_figures(const TwoBodyFindings& two, std::vector<reports::Plot>& figures);

/// The page's section "The gap": the parameter corrections, rigid or not, the lost motion table.
void two_body_page(std::ostringstream& md, const TwoBodyFindings& two, bool drawn);

}  // namespace backlash::discrepancy::detail
