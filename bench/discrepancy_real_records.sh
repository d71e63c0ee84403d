#!/bin/sh
# The discrepancy workflow's confusion matrix on records as real machines make them (issue 21):
# pairs of effects, errors in J and F with and without an effect, a sensor drift, coloured noise,
# spikes, a 1024-count encoder, 10 s, 20 Hz, jittered time stamps, a late start, clean records
# under each — from the independent odeint generator.  Prints every record's answer, the matrix
# by kind of record, and the median and worst seconds per record (say the machine's load: uptime).
# Usage: bench/discrepancy_real_records.sh [BUILD_DIR]
set -eu
build=${1:-build}
uptime
BACKLASH_FULL_MATRIX=1 "$build/bin/check_discrepancy_real_records" --gtest_filter='RealRecordsMatrix.*'
