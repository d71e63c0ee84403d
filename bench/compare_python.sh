#!/usr/bin/env bash
# The Python module against C++ and the CLI, measured in one run (CPU-bound work on a
# machine that may be shared: best of the repetitions):
#   limit cycle of case V on a validated model: Python `case.limit_cycle()` vs the C++
#   facade's Model::limit_cycle() (build/bin/time_api)                      target ≤ 2×
#   the whole route (load, gates, limit cycle) likewise
#   a 10⁴-point sweep (fig31, 5000 points per series, 2 threads): Python
#   backlash.sweep() (NumPy columns; and with its CSV written, the CLI's output) vs
#   `backlash sweep fig31 --points 5000 --out F` (wall time, the CLI's whole process
#   included), best of 3 each
# All times are wall-clock times (C++: Google Benchmark's real time), best of the repetitions.
# Usage: bench/compare_python.sh [BUILD_DIR]   (default: build)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "${1:-$here/../build}" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python=/usr/bin/python3

"$build/bin/time_api" --benchmark_format=json --benchmark_min_time=0.5 --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=false > "$work/cpp.json" 2>/dev/null

# The CLI's sweep, wall time of the whole process, best of 3.
best_cli=1e9
for _ in 1 2 3; do
  start=$(date +%s.%N)
  "$build/bin/backlash" sweep fig31 --points 5000 --threads 2 --no-progress --out "$work/cli.csv" 2>/dev/null
  end=$(date +%s.%N)
  best_cli=$(echo "$start $end $best_cli" | awk '{d = $2 - $1; print (d < $3 ? d : $3)}')
done

PYTHONPATH="$build/python" PYTHONDONTWRITEBYTECODE=1 "$python" - "$work" "$best_cli" <<'PY'
import json, sys, time, timeit
import backlash

work, cli_seconds = sys.argv[1], float(sys.argv[2])
cpp = {}
for b in json.load(open(f"{work}/cpp.json"))["benchmarks"]:
    if b.get("run_type") == "iteration":
        name = b["name"].split("/")[0]
        cpp[name] = min(cpp.get(name, float("inf")), b["real_time"] * {"us": 1e-6, "ms": 1e-3, "ns": 1e-9}[b["time_unit"]])

def best(call, number):
    return min(timeit.repeat(call, number=number, repeat=5)) / number

v = backlash.load("V")
v.limit_cycle()  # runs the gates once
py_cycle = best(v.limit_cycle, 200)
py_route = best(lambda: backlash.load("V").limit_cycle(), 50)

py_sweep = py_sweep_csv = float("inf")
for _ in range(3):
    start = time.perf_counter()
    sweep = backlash.sweep("fig31", points=5000, threads=2)
    peak_to_peak = sweep.peak_to_peak  # the NumPy column
    middle = time.perf_counter()
    with open(f"{work}/python.csv", "w") as out:
        out.write(sweep.csv())
    end = time.perf_counter()
    py_sweep, py_sweep_csv = min(py_sweep, middle - start), min(py_sweep_csv, end - start)
assert len(sweep) == 10000 and len(peak_to_peak) == 10000
same = open(f"{work}/python.csv").read() == open(f"{work}/cli.csv").read()

print(f"limit cycle of case V (validated model): Python {py_cycle * 1e6:9.1f} us, C++ {cpp['LimitCycleV'] * 1e6:9.1f} us,"
      f" ratio {py_cycle / cpp['LimitCycleV']:.3f} (target <= 2)")
print(f"load + gates + limit cycle of case V:    Python {py_route * 1e6:9.1f} us, C++ {cpp['LoadValidateLimitCycleV'] * 1e6:9.1f} us,"
      f" ratio {py_route / cpp['LoadValidateLimitCycleV']:.3f}")
print(f"10^4-point sweep (fig31, 2 threads):     Python {py_sweep:9.3f} s,  CLI {cli_seconds:9.3f} s,"
      f"  ratio {py_sweep / cli_seconds:.3f} (target <= 1)")
print(f"  the same with the CSV written:          Python {py_sweep_csv:9.3f} s,  CLI {cli_seconds:9.3f} s,"
      f"  ratio {py_sweep_csv / cli_seconds:.3f}; CSV identical: {same}")
PY
