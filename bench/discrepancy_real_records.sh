#!/bin/sh
# The discrepancy workflow's confusion matrix on records as real machines make them (issue 21):
# pairs of effects, errors in J and F with and without an effect, a sensor drift, coloured noise,
# spikes, a 1024-count encoder, 10 s, 20 Hz, jittered time stamps, a late start, clean records
# under each — from the independent odeint generator.  Prints every record's answer, the matrix
# by kind of record, and the median and worst seconds per record, wall and CPU (one thread per
# record: its CPU seconds are one core's; say the machine's load: uptime).
# Usage: bench/discrepancy_real_records.sh [BUILD_DIR] [SHARDS]  (SHARDS processes, each every
# SHARDS-th record; their summaries are printed one after the other)
set -eu
build=${1:-build}
uptime
shards=${2:-1}
k=0
while [ "$k" -lt "$shards" ]; do
  BACKLASH_MATRIX_SHARD="$k/$shards" BACKLASH_FULL_MATRIX=1 "$build/bin/check_discrepancy_real_records" \
    --gtest_filter='RealRecordsMatrix.*' > "${TMPDIR:-/tmp}/discrepancy_real_records.$$.$k" 2>&1 &
  k=$((k + 1))
done
wait
k=0
while [ "$k" -lt "$shards" ]; do
  cat "${TMPDIR:-/tmp}/discrepancy_real_records.$$.$k"
  rm -f "${TMPDIR:-/tmp}/discrepancy_real_records.$$.$k"
  k=$((k + 1))
done
uptime
