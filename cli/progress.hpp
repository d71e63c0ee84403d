// backlash/cli/progress.hpp — the one progress bar of the command line (sweep, discrepancy):
// "[#####     ]  50% (done/total)" on stderr, redrawn in place, ended by a newline when
// done reaches total; only when stderr is a terminal, and never with --no-progress.
#pragma once

#include <cstdio>
#include <functional>
#include <string>

#include <unistd.h>

namespace backlash::cli {

/// Draws the bar for `done` of `total` (total > 0).
inline void draw_progress(long done, long total) {
  const int width = 40, filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\r[%s%s] %3ld%% (%ld/%ld)", std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), 100 * done / total, done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

/// draw_progress when stderr is a terminal and the user did not turn it off, else nothing.
inline std::function<void(long, long)> progress_bar(bool no_progress) {
  if (no_progress || !isatty(STDERR_FILENO)) return {};
  return draw_progress;
}

}  // namespace backlash::cli
