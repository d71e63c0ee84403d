#!/usr/bin/env python3
"""compare_outputs_numerically.py A B [--threshold 1e-14] — two output folders (e.g. two
/work/golden/make_outputs.sh sets) compared number by number.

Every file of A is read as text and cut into numbers and the text between them; a file of B
whose text between the numbers is the same is reported with the largest relative difference of
its numbers, |a − b| / max(|a|, |b|) (0 for two zeros), and where it is, and the largest
|a − b| / max(1, |a|, |b|) (the scale of the project's own tolerances: a number near zero, such
as θo − θR or a velocity at a turn, moves by its neighbours' rounding, not its own); a file whose text or
count of numbers differs (a different event sequence, a changed word) is reported as
"structure differs", a binary file that differs as "binary differs".  Logs are compared
without their timings ("(1.23 s)").  Byte-identical files are counted, not listed.  Exit 1 when
any file differs in structure or by more than --threshold.

Issue 19 allows every output of the event loop to move by 1e-14 relative at most: this prints
the figure that shows it.
"""
import argparse
import os
import re
import sys

NUMBER = re.compile(rb"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|[-+]?(?:inf|nan)\b")
TIMING = re.compile(rb"[0-9.]+ s\)")


def split(data):
    """The numbers of `data` and the text between them."""
    numbers, text, last = [], [], 0
    for m in NUMBER.finditer(data):
        text.append(data[last:m.start()])
        numbers.append(m.group())
        last = m.end()
    text.append(data[last:])
    return numbers, text


def relative(a, b, floor=0.0):
    x, y = float(a), float(b)
    if x == y or (x != x and y != y):
        return 0.0
    scale = max(abs(x), abs(y), floor)
    return abs(x - y) / scale if scale > 0 else 0.0


def compare(path_a, path_b, name):
    a, b = open(path_a, "rb").read(), open(path_b, "rb").read()
    if name.endswith(".log"):
        a, b = TIMING.sub(b"T s)", a), TIMING.sub(b"T s)", b)
    if a == b:
        return None
    if b"\0" in a or b"\0" in b:
        return ("binary differs", None, "", None)
    na, ta = split(a)
    nb, tb = split(b)
    if ta != tb or len(na) != len(nb):
        return ("structure differs", None, "", None)
    worst, where, floored = 0.0, "", 0.0
    for i, (x, y) in enumerate(zip(na, nb)):
        r = relative(x, y)
        floored = max(floored, relative(x, y, 1.0))
        if r > worst:
            worst, where = r, f"number {i}: {x.decode()} vs {y.decode()}"
    return ("numbers differ", worst, f"{where}; relative to max(1, |x|): {floored:.3g}", floored)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--threshold", type=float, default=1e-14)
    args = parser.parse_args()
    same, failed, overall, overall_floored = 0, False, 0.0, 0.0
    for root, _, files in sorted(os.walk(args.a)):
        for f in sorted(files):
            path_a = os.path.join(root, f)
            name = os.path.relpath(path_a, args.a)
            path_b = os.path.join(args.b, name)
            if not os.path.exists(path_b):
                print(f"{name}: only in {args.a}")
                failed = True
                continue
            result = compare(path_a, path_b, name)
            if result is None:
                same += 1
                continue
            kind, worst, where, floored = result
            if worst is None:
                print(f"{name}: {kind}")
                failed = True
            else:
                overall = max(overall, worst)
                overall_floored = max(overall_floored, floored)
                failed |= worst > args.threshold
                print(f"{name}: largest relative difference {worst:.3g} ({where})")
    print(f"{same} files byte-identical; largest relative difference of the others {overall:.3g}, "
          f"relative to max(1, |x|) {overall_floored:.3g} "
          f"(threshold {args.threshold:g} on the first: {'exceeded or structure changed' if failed else 'within'})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
