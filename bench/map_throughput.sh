#!/usr/bin/env bash
# Design-map throughput (issue 19): the 100 x 100 map of case V over JL/Jm x FL/F, as
# `backlash map` writes it (settle time, boundary, map.h5, figures), on 1 and on 2 threads, in one
# run.  Prints wall and CPU seconds, points per second per core (target: >= 20,000 on 1 thread) and
# the same without the settle time (--step 0: the limit-cycle searches alone), the number of
# searches that fell back to the grid survey (map.json), and checks that 1 and 2 threads write the
# same points.csv bytes.  Not a test: times depend on the machine and its load.
#
#   bench/map_throughput.sh [BUILD_DIR] [N]        (default: build 100)
set -euo pipefail
build=${1:-build}
n=${2:-100}
cli="$build/bin/backlash"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
map=(map V --vary "JL_over_Jm=0.25:4:$n" --vary "FL_over_F=0:1:$n")
points=$((n * n))

seconds() {  # wall seconds of a command; its CPU seconds in $work/cpu
  /usr/bin/time -f '%e %U %S' -o "$work/time" "$@" >/dev/null 2>&1
  read -r wall user system < "$work/time"
  echo "$user + $system" | bc -l > "$work/cpu"
  echo "$wall"
}
report() {
  local cpu; cpu=$(cat "$work/cpu")
  printf '%-32s wall %6.2f s  %7.0f points/s/core | CPU %6.2f s  %7.0f points/CPU-s\n' "$1" "$2" \
    "$(echo "$points / $2 / $3" | bc -l)" "$cpu" "$(echo "$points / $cpu" | bc -l)"
}

echo "map of case V: ${n}^2 = $points points (JL/Jm x FL/F)"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
t1=$(seconds "$cli" "${map[@]}" --threads 1 --out "$work/t1"); report "1 thread (as written)" "$t1" 1
t2=$(seconds "$cli" "${map[@]}" --threads 2 --out "$work/t2"); report "2 threads (as written)" "$t2" 2
s1=$(seconds "$cli" "${map[@]}" --threads 1 --step 0 --no-boundary --no-figures --no-hdf5 --out "$work/s1")
report "1 thread, searches only" "$s1" 1
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
rate=$(echo "$points / $t1" | bc -l)
printf 'target >= 20000 points/s/core on 1 thread: %s (%.0f)\n' "$(echo "$rate >= 20000" | bc -l | sed 's/1/met/;s/0/missed/')" "$rate"
grep -o '"survey_fallbacks": [0-9]*' "$work/t1/map.json"
cmp -s "$work/t1/points.csv" "$work/t2/points.csv" && echo "points.csv: same bytes on 1 and 2 threads" ||
  { echo "points.csv: DIFFERS between 1 and 2 threads" >&2; exit 1; }
