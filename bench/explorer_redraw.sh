#!/bin/sh
# The explorer page's redraw rate while a slider is dragged, per thesis case, in headless
# Chromium (issue 20; bench/README.md).  Not a test: it prints frames/s and where a redraw's
# time goes, the time of a 60 s trajectory, and the machine's load (other work on the machine
# slows the page).  BASELINE_PAGE: another build's page (e.g. main's), measured in the same run.
#   bench/explorer_redraw.sh [BUILD_DIR] [FRAMES] [PARAMETER|P1,P2,…|all] [BASELINE_PAGE]
# PARAMETER: a slider by its field's name (Jm, Fm, JL, FL, K, backlash or b, reference or θR, step,
# t_end, an effect's parameter), or all (parameters, effects): every slider of the page (its parameter
# fields', its effects'), one table each and a slider × case summary (explorer_redraw.mjs).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
page=$build/explorer/index.html
[ -f "$page" ] || { echo "no explorer page at $page (build the target backlash_explorer; needs emcc)" >&2; exit 1; }
echo "load before: $(uptime)"
node "$here/explorer_redraw.mjs" "$page" "${2:-60}" "${3:-K}" ${4:+"$4"}
echo "load after:  $(uptime)"
