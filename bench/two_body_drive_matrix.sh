#!/bin/sh
# Backlash from a logged drive (issue 22): the recovery table on records of the independent
# two-body generator (tests/discrepancy/two_body_generator.cpp) — the backlash 0.1°, 1°, 5°,
# 20° and 0.3 rad, both encoders and the motor encoder alone, the position loop on the motor
# and (second run of each size) on the load encoder; then a drive without a gap. One line per
# record: the truth, the fitted backlash ± σ, the error, the status.  Say the machine's load
# (uptime) when quoting the seconds.
# Usage: bench/two_body_drive_matrix.sh [BUILD_DIR]
set -eu
build=${1:-build}
uptime
BACKLASH_TWO_BODY_MATRIX=1 "$build/bin/check_two_body_drive_workflow" \
  --gtest_filter='TwoBodyDriveWorkflow.item1_*' | grep -E 'fitted|FAILED|PASSED|OK \]'
