#!/usr/bin/env bash
# Runs the symbolic engine's benchmark and the SymPy baseline in one go and
# prints the ratio (issue targets: 8 cases ≤ 0.3 s; ≥ 300× faster than SymPy).
# Usage: bench/compare_symbolic_with_sympy.sh [BUILD_DIR]   (default: build)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
cpp_json="$(mktemp)"; sympy_json="$(mktemp)"
trap 'rm -f "$cpp_json" "$sympy_json"' EXIT
BACKLASH_CASES_DIR="$here/../cases" "$build/bin/time_symbolic" --benchmark_format=json --benchmark_min_time=0.5 > "$cpp_json"
/usr/bin/python3 "$here/sympy_inverse_laplace.py" --cases "$here/../cases" --json > "$sympy_json"
/usr/bin/python3 - "$cpp_json" "$sympy_json" <<'PY'
import json, sys
cpp = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"]}
sympy = json.load(open(sys.argv[2]))
def seconds(name):
    b = cpp[name]
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
    return b["real_time"] * scale
cases = seconds("time_DeriveAndVerifyEightCases")
forty = seconds("time_FortyInverseTransforms")
general = seconds("time_DeriveAndVerifyGeneralBranches")
sym = sympy["total_seconds"]
print(f"backlash: 8 cases derived + verified      {cases*1e3:9.2f} ms   (target <= 300 ms: {'met' if cases <= 0.3 else 'MISSED'})")
print(f"backlash: 14 general branches + verified  {general*1e3:9.2f} ms")
print(f"backlash: the {sympy['n_transforms']} inverse transforms        {forty*1e3:9.2f} ms")
print(f"SymPy {sympy.get('sympy_version','?')}: the same {sympy['n_transforms']} transforms  {sym*1e3:9.2f} ms   ({sympy['n_failed']} failed)")
print(f"ratio SymPy / backlash (same transforms):  {sym/forty:9.0f}x  (target >= 300x: {'met' if sym/forty >= 300 else 'MISSED'})")
print(f"ratio SymPy / backlash (transforms vs full derivation with verification): {sym/cases:9.0f}x")
PY
