// discrepancy/src/quiet_ceres.hpp (internal) — Ceres reports through glog; the workflow's fits
// (fitting.cpp, drive_workflow.cpp) make a failed evaluation a status, not a line on stderr.
#pragma once

namespace backlash::discrepancy::detail {

/// Raises glog's threshold to FATAL, once per process (defined in fitting.cpp).
void quiet_ceres();

}  // namespace backlash::discrepancy::detail
