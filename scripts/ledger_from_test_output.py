#!/usr/bin/python3
"""Draft errata-ledger entries from failing thesis tests.

Reads the output of a thesis test binary (lines "WHERE case C [QUANTITY]:
derivation returned EXACT = DECIMAL instead of printed P, and the errata
ledger has no entry for it") and prints TOML [[erratum]] entries.  The cause
is a first classification by size of the deviation in units of the printed
last digit; an engineer reviews every entry before it enters
reports/errata/ledger.toml (this script never writes the ledger).
"""
import re
import sys

PATTERN = re.compile(r"^(\S+) case (\S+) \[(.*)\]: derivation returned (.*) = (\S+) instead of printed (\S+), and the errata")

def last_digit_units(printed: str, exact: float) -> float:
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    p = float(printed)
    diff = p - exact
    while diff > 90: diff -= 180
    while diff <= -90: diff += 180
    return abs(diff) * 10 ** decimals

def main() -> None:
    for line in sys.stdin:
        m = PATTERN.match(line.strip())
        if not m:
            continue
        where, case, quantity, exact, decimal, printed = m.groups()
        units = last_digit_units(printed, float(decimal))
        if units <= 1.5:
            cause = f"last printed digit off by {units:.2f} units (slide-rule rounding)"
        else:
            cause = f"off by {units:.1f} units of the last printed digit: REVIEW"
        print("[[erratum]]")
        print(f'where = "{where}"')
        print(f'case = "{case}"')
        print(f'quantity = "{quantity}"')
        print(f'printed = "{printed}"')
        print(f'exact = "{exact}"')
        print(f'exact_decimal = "{decimal}"')
        print(f'cause = "{cause}"')
        print()

if __name__ == "__main__":
    main()
