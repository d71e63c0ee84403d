#!/usr/bin/env bash
# Design-space map throughput (issue 13): a 3-parameter map of case V, JL/Jm × FL/F × K, N³
# points (N = 100: 10⁶), with the settle time and map.h5, without the boundary (timed apart on a
# small grid), run as 1 rank × 1 thread, 1 rank × 2 threads and 2 MPI ranks × 1 thread.  Prints
# the wall time, points per second per core and the ratios, and checks that the three
# points.csv and map.h5 are the same bytes.  Not a test: times depend on the machine and its load.
#
#   bench/map_scaling.sh [BUILD_DIR] [N]        (default: build 100)
set -euo pipefail
build=${1:-build}
n=${2:-100}
cli="$build/bin/backlash"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# As root OpenMPI needs --allow-run-as-root; 2 ranks on a small shared machine need --oversubscribe,
# shared memory (btl self,vader) and ranks that yield while they wait instead of polling.
mpirun=(mpirun --allow-run-as-root --oversubscribe --mca btl self,vader --mca mpi_yield_when_idle 1)
map=(map V --vary "JL_over_Jm=0.25:4:$n" --vary "FL_over_F=0:1:$n" --vary "K=0.5:2:$n" --no-boundary --no-figures)
points=$((n * n * n))

# Wall seconds of a command; its CPU seconds (user + system, children included) in $work/cpu.
seconds() {
  /usr/bin/time -f '%e %U %S' -o "$work/time" "$@" >/dev/null 2>&1
  read -r wall user system < "$work/time"
  echo "$user + $system" | bc -l > "$work/cpu"
  echo "$wall"
}
# The machine may be shared: points per CPU-second is the intrinsic rate, wall time the observed one.
report() {
  local cpu; cpu=$(cat "$work/cpu")
  printf '%-20s wall %8.1f s  %8.0f points/s  %6.0f points/s/core | CPU %8.1f s  %6.0f points/CPU-s\n' "$1" "$2" \
    "$(echo "$points / $2" | bc -l)" "$(echo "$points / $2 / $3" | bc -l)" "$cpu" "$(echo "$points / $cpu" | bc -l)"
}

echo "map of case V: ${n}^3 = $points points (JL/Jm x FL/F x K), settle time and map.h5 on, boundary off"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
t11=$(seconds "$cli" "${map[@]}" --threads 1 --out "$work/r1t1"); report "1 rank x 1 thread" "$t11" 1
t12=$(seconds "$cli" "${map[@]}" --threads 2 --out "$work/r1t2"); report "1 rank x 2 threads" "$t12" 2
t21=$(seconds "${mpirun[@]}" -n 2 "$cli" "${map[@]}" --threads 1 --out "$work/r2t1"); report "2 ranks x 1 thread" "$t21" 2
printf 'speed-up 1 -> 2 threads: %.2f   1 -> 2 ranks: %.2f\n' "$(echo "$t11 / $t12" | bc -l)" "$(echo "$t11 / $t21" | bc -l)"
for f in points.csv map.h5; do
  cmp -s "$work/r1t1/$f" "$work/r1t2/$f" && cmp -s "$work/r1t1/$f" "$work/r2t1/$f" && echo "$f: same bytes in all three runs" ||
    { echo "$f: DIFFERS" >&2; exit 1; }
done
ls -l "$work/r1t1" | awk '/points.csv|map.h5/ {printf "%s: %.1f MB\n", $9, $5 / 1e6}'

# The boundary's cost, apart: a 20 x 20 grid of Fm x K (case V loses its cycle across it).
b=(map V --vary Fm=0.1:1:20 --vary K=0.2:2:20 --no-figures --no-hdf5 --step 0 --threads 2)
tn=$(seconds "$cli" "${b[@]}" --no-boundary --out "$work/b0")
tb=$(seconds "$cli" "${b[@]}" --out "$work/b1" 2>/dev/null)
crossings=$(($(wc -l < "$work/b1/boundary.csv") - 1))
printf 'boundary: 400 points %.1f s, with %d roots %.1f s (%.0f core-ms per root)\n' "$tn" "$crossings" "$tb" \
  "$(echo "($tb - $tn) * 1000 * 2 / $crossings" | bc -l)"
