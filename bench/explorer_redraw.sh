#!/bin/sh
# The explorer page's redraw rate while a slider is dragged, per thesis case, in headless
# Chromium (issue 20; bench/README.md).  Not a test: it prints frames/s and where a redraw's
# time goes, the time of a 60 s trajectory, and the machine's load (other work on the machine
# slows the page).  BASELINE_PAGE: another build's page (e.g. main's), measured in the same run.
#   bench/explorer_redraw.sh [BUILD_DIR] [FRAMES] [PARAMETER] [BASELINE_PAGE]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
page=$build/explorer/index.html
[ -f "$page" ] || { echo "no explorer page at $page (build the target backlash_explorer; needs emcc)" >&2; exit 1; }
echo "load before: $(uptime)"
node "$here/explorer_redraw.mjs" "$page" "${2:-60}" "${3:-K}" ${4:+"$4"}
echo "load after:  $(uptime)"
