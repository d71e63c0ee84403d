#!/usr/bin/python3
"""SymPy baseline for backlash's symbolic engine.

Times sympy.inverse_laplace_transform on the same inverse Laplace transforms
that symbolic/ derives (docs/physics.md), so that the C++ benchmark
can print a speed ratio.  Per case, five transforms:

  contact_theta_o   Θo(s) = (J(s a + b) + F a + K θR/s) / (J s² + F s + K)
                    J = Jm+JL, F = Fm+FL, a = θo(0), b = θo'(0) symbolic
  free_theta_m      motor position in the backlash
                    at motor: (Jm(s θ0 + v) + Fm θ0 + K θR/s) / (Jm s² + Fm s + K)
                    at load:  (Jm(s θ0 + v) + Fm θ0 + K(θR/s − ΘL(s))) / (Jm s² + Fm s)
  free_dtheta_m     s Θm(s) − θ0
  free_theta_L      ΘL(s) = θ0/s + v / (s (s + FL/JL))
  free_dtheta_L     v / (s + FL/JL)

with θ0 = θR + cotφ·v on the separation line, cotφ = (Jm FL − Fm JL)/(K JL),
v = θ'm(0) symbolic.  All case parameters are exact rationals.

Must run with /usr/bin/python3 (Debian's, which has sympy).

    bench/sympy_inverse_laplace.py [--cases DIR] [--only I,V] [--repeat N]
                                   [--json] [--check] [--timeout SEC]

Each timed call starts from an empty SymPy cache (clear_cache() before every
call), so every transform is timed cold and independently of run order.
With --repeat N the reported "seconds" is the minimum over the N runs
(all runs are listed in --json).  --check verifies each result (untimed):
ODE residual simplifies to 0 and initial conditions hold.
"""

import argparse
import json
import os
import platform
import signal
import sys
import time

try:
    import tomllib
except ImportError:  # pragma: no cover - python < 3.11
    tomllib = None

import sympy
from sympy import (Rational, S, Symbol, symbols, simplify, diff,
                   Heaviside, inverse_laplace_transform)
from sympy.core.cache import clear_cache
from sympy.integrals.transforms import InverseLaplaceTransform

CASE_NAMES = ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"]

# Thesis values (section 14 / each case's section): Jm, Fm, JL, FL, measured_at.
BUILTIN = {
    "I":    ("0.6", "0.48", "0.4", "0.32", "motor"),
    "II":   ("0.5", "0.2",  "0.5", "0",    "motor"),
    "III":  ("0.5", "0.2",  "0.5", "0",    "load"),
    "IV":   ("0.2", "0.2",  "0.8", "0",    "load"),
    "V":    ("0.5", "0.1",  "0.5", "0.3",  "load"),
    "VI":   ("0.5", "0.3",  "0.5", "0.1",  "load"),
    "VII":  ("0.2", "0.1",  "0.8", "0.3",  "load"),
    "VIII": ("0.2", "0.3",  "0.8", "0.1",  "load"),
}

TRANSFORMS = ["contact_theta_o", "free_theta_m", "free_dtheta_m",
              "free_theta_L", "free_dtheta_L"]

# Symbols: t positive (so Heaviside(t) -> 1), s plain; initial conditions are
# real but *not* declared positive (they take either sign).
t = symbols("t", positive=True)
s = symbols("s")
a, b, v = symbols("a b v", real=True)


def exact(x):
    """A TOML number or "p/q" string as an exact Rational (0.3 -> 3/10)."""
    if isinstance(x, bool):
        raise ValueError("boolean is not a number: %r" % (x,))
    if isinstance(x, int):
        return Rational(x)
    if isinstance(x, float):
        return Rational(repr(x))
    if isinstance(x, str):
        return Rational(x.strip())
    raise ValueError("not a number: %r" % (x,))


def load_case_file(path, name):
    with open(path, "rb") as f:
        d = tomllib.load(f)
    return {
        "name": name,
        "source": path,
        "Jm": exact(d["motor"]["J"]), "Fm": exact(d["motor"]["F"]),
        "JL": exact(d["load"]["J"]), "FL": exact(d["load"]["F"]),
        "K": exact(d["K"]), "thetaR": exact(d["reference"]),
        "backlash": exact(d["backlash"]),
        "measured_at": d["measured_at"],
    }


def builtin_case(name):
    jm, fm, jl, fl, at = BUILTIN[name]
    return {
        "name": name, "source": "builtin",
        "Jm": Rational(jm), "Fm": Rational(fm),
        "JL": Rational(jl), "FL": Rational(fl),
        "K": S.One, "thetaR": S.One, "backlash": None,
        "measured_at": at,
    }


def load_cases(cases_dir, only):
    names = only or CASE_NAMES
    out = []
    for n in names:
        path = os.path.join(cases_dir, n + ".toml") if cases_dir else None
        if path and os.path.isfile(path):
            if tomllib is None:
                sys.exit("error: tomllib unavailable (need python >= 3.11)")
            try:
                out.append(load_case_file(path, n))
            except Exception as e:  # noqa: BLE001
                sys.exit("error: %s: %s" % (path, e))
        elif n in BUILTIN:
            out.append(builtin_case(n))
        else:
            sys.exit("error: unknown case %r (no %s and no built-in values)"
                     % (n, path or (n + ".toml")))
    return out


def laplace_forms(c):
    """The five s-domain expressions for one case, plus data for --check."""
    Jm, Fm, JL, FL, K, thR = (c[k] for k in ("Jm", "Fm", "JL", "FL", "K", "thetaR"))
    J, F = Jm + JL, Fm + FL
    cotphi = (Jm * FL - Fm * JL) / (K * JL)
    th0 = thR + cotphi * v

    contact = (J * (s * a + b) + F * a + K * thR / s) / (J * s**2 + F * s + K)
    theta_L = th0 / s + v / (s * (s + FL / JL))
    dtheta_L = v / (s + FL / JL)
    if c["measured_at"] == "motor":
        theta_m = (Jm * (s * th0 + v) + Fm * th0 + K * thR / s) / (Jm * s**2 + Fm * s + K)
    elif c["measured_at"] == "load":
        theta_m = (Jm * (s * th0 + v) + Fm * th0 + K * (thR / s - theta_L)) / (Jm * s**2 + Fm * s)
    else:
        raise ValueError("measured_at must be 'motor' or 'load', got %r" % c["measured_at"])
    dtheta_m = s * theta_m - th0
    forms = {
        "contact_theta_o": contact,
        "free_theta_m": theta_m,
        "free_dtheta_m": dtheta_m,
        "free_theta_L": theta_L,
        "free_dtheta_L": dtheta_L,
    }
    return forms, {"J": J, "F": F, "cotphi": cotphi, "theta0": th0}


def clean(expr):
    """Replace Heaviside(t) factors (t > 0) by 1."""
    return expr.replace(lambda e: isinstance(e, Heaviside) and e.args[0] == t,
                        lambda e: S.One)


class Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise Timeout()


def run_one(F, timeout):
    """Time one inverse transform.  Returns (seconds, result or None, error)."""
    clear_cache()
    if timeout > 0:
        signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, timeout)
    t0 = time.perf_counter()
    try:
        r = inverse_laplace_transform(F, s, t)
        dt = time.perf_counter() - t0
    except Timeout:
        return time.perf_counter() - t0, None, "timeout after %gs" % timeout
    except Exception as e:  # noqa: BLE001 - record, never crash
        return time.perf_counter() - t0, None, "%s: %s" % (type(e).__name__, e)
    finally:
        if timeout > 0:
            signal.setitimer(signal.ITIMER_REAL, 0)
    if r is None or r.has(InverseLaplaceTransform):
        return dt, r, "unevaluated (InverseLaplaceTransform left in result)"
    return dt, r, None


def is_zero(e):
    e = clean(sympy.sympify(e))
    if e == 0:
        return True
    z = simplify(sympy.expand(e))
    if z == 0:
        return True
    # last resort: numeric spot check at a few points
    free = sorted(z.free_symbols, key=str)
    for pts in ((Rational(3, 7), Rational(-5, 3), Rational(2, 9), Rational(7, 5)),
                (Rational(11, 4), Rational(1, 3), Rational(-3, 2), Rational(1, 8))):
        val = z.subs({sym: pts[i % len(pts)] for i, sym in enumerate(free)})
        if abs(sympy.N(val, 30)) > 1e-20:
            return False
    return True


def at0(e):
    e = clean(e)
    try:
        r = e.subs(t, 0)
        if r.has(sympy.nan, sympy.zoo, sympy.oo):
            raise ValueError
        return r
    except Exception:  # noqa: BLE001
        return sympy.limit(e, t, 0, "+")


def check_case(c, results, extra):
    """Verify results (not timed).  Returns {transform: (ok, note)}."""
    Jm, Fm, JL, FL, K, thR = (c[k] for k in ("Jm", "Fm", "JL", "FL", "K", "thetaR"))
    J, F, th0 = extra["J"], extra["F"], extra["theta0"]
    r = {k: (clean(x) if x is not None else None) for k, x in results.items()}
    out = {}

    def verdict(name, conds):
        if r[name] is None:
            out[name] = (False, "no result")
            return
        bad = [label for label, e in conds() if not is_zero(e)]
        out[name] = (not bad, "ok" if not bad else "fails: " + ", ".join(bad))

    def safe(name, conds):
        try:
            verdict(name, conds)
        except Exception as e:  # noqa: BLE001
            out[name] = (False, "check error: %s: %s" % (type(e).__name__, e))

    x = r["contact_theta_o"]
    safe("contact_theta_o", lambda: [
        ("ODE", J * diff(x, t, 2) + F * diff(x, t) + K * x - K * thR),
        ("x(0)=a", at0(x) - a),
        ("x'(0)=b", at0(diff(x, t)) - b)])

    L = r["free_theta_L"]
    safe("free_theta_L", lambda: [
        ("ODE", JL * diff(L, t, 2) + FL * diff(L, t)),
        ("L(0)=th0", at0(L) - th0),
        ("L'(0)=v", at0(diff(L, t)) - v)])

    w = r["free_dtheta_L"]
    safe("free_dtheta_L", lambda: [
        ("ODE", JL * diff(w, t) + FL * w),
        ("w(0)=v", at0(w) - v)]
        + ([("w=L'", w - diff(L, t))] if L is not None else []))

    m = r["free_theta_m"]
    if c["measured_at"] == "motor":
        rhs = K * thR
        ode = lambda: Jm * diff(m, t, 2) + Fm * diff(m, t) + K * m - rhs
    else:
        # driven open loop by the free load; use the independently known
        # closed form of θL(t) rather than SymPy's own result
        if FL == 0:
            Lt = th0 + v * t
        else:
            Lt = th0 + v * JL / FL * (1 - sympy.exp(-FL / JL * t))
        ode = lambda: Jm * diff(m, t, 2) + Fm * diff(m, t) - K * (thR - Lt)
    safe("free_theta_m", lambda: [
        ("ODE", ode()),
        ("m(0)=th0", at0(m) - th0),
        ("m'(0)=v", at0(diff(m, t)) - v)])

    dm = r["free_dtheta_m"]
    safe("free_dtheta_m", lambda: [
        ("dm(0)=v", at0(dm) - v)]
        + ([("dm=m'", dm - diff(m, t))] if m is not None else
           [("no m to compare", S.One)]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--cases", default=os.path.join(here, "..", "cases"),
                    help="directory holding I.toml ... VIII.toml (default: ../cases;"
                         " missing files fall back to built-in thesis values)")
    ap.add_argument("--only", default="", help="comma-separated case names, e.g. I,V")
    ap.add_argument("--repeat", type=int, default=1, help="timed runs per transform")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--check", action="store_true", help="verify each result (untimed)")
    ap.add_argument("--timeout", type=float, default=600.0,
                    help="seconds per transform before giving up (0 = none)")
    ap.add_argument("--show", action="store_true", help="print the inverse transforms")
    args = ap.parse_args()
    if args.repeat < 1:
        sys.exit("error: --repeat must be >= 1")
    only = [x.strip() for x in args.only.split(",") if x.strip()]
    cases = load_cases(args.cases, only)

    report = {
        "tool": "sympy.inverse_laplace_transform",
        "sympy_version": sympy.__version__,
        "python_version": platform.python_version(),
        "repeat": args.repeat,
        "statistic": "min over repeats; sympy cache cleared before every call",
        "cases": [],
    }
    grand = 0.0
    n_fail = n_checkfail = 0
    if not args.json:
        print("sympy %s, python %s, repeat %d (min; cache cleared per call)"
              % (sympy.__version__, platform.python_version(), args.repeat))
        hdr = "%-5s %-6s " % ("case", "at") + " ".join("%15s" % n for n in TRANSFORMS) + " %9s" % "case_s"
        print(hdr)
    for c in cases:
        forms, extra = laplace_forms(c)
        entry = {"case": c["name"], "source": c["source"],
                 "measured_at": c["measured_at"],
                 "cot_phi": str(extra["cotphi"]), "transforms": {}}
        results = {}
        case_total = 0.0
        cells = []
        for name in TRANSFORMS:
            runs, res, err = [], None, None
            for _ in range(args.repeat):
                dt, res, err = run_one(forms[name], args.timeout)
                runs.append(dt)
                if err and err.startswith("timeout"):
                    break
            best = min(runs)
            case_total += best
            results[name] = None if err else res
            d = {"seconds": best, "runs": runs, "ok": err is None,
                 "laplace": str(forms[name])}
            if err:
                d["error"] = err
                n_fail += 1
            elif res is not None:
                d["result"] = str(clean(res))
            entry["transforms"][name] = d
            cells.append(("%.4f" % best) + ("" if err is None else " FAIL"))
        if args.check:
            chk = check_case(c, results, extra)
            for name in TRANSFORMS:
                ok, note = chk[name]
                entry["transforms"][name]["check"] = "pass" if ok else "fail"
                entry["transforms"][name]["check_note"] = note
                if not ok:
                    n_checkfail += 1
        entry["total_seconds"] = case_total
        grand += case_total
        report["cases"].append(entry)
        if not args.json:
            print("%-5s %-6s " % (c["name"], c["measured_at"])
                  + " ".join("%15s" % x for x in cells) + " %9.4f" % case_total)
            for name in TRANSFORMS:
                tr = entry["transforms"][name]
                if "error" in tr:
                    print("      %s: %s" % (name, tr["error"]))
                if args.check and tr["check"] == "fail":
                    print("      check %s: %s" % (name, tr["check_note"]))
                if args.show and "result" in tr:
                    print("      %s(t) = %s" % (name, tr["result"]))
            sys.stdout.flush()
    n_tr = len(cases) * len(TRANSFORMS)
    report["n_transforms"] = n_tr
    report["n_failed"] = n_fail
    report["total_seconds"] = grand
    report["mean_seconds_per_transform"] = grand / n_tr if n_tr else 0.0
    if args.check:
        report["n_check_failed"] = n_checkfail
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        line = "transforms=%d failed=%d" % (n_tr, n_fail)
        if args.check:
            line += " check_failed=%d" % n_checkfail
        print(line)
        print("total_seconds=%.4f" % grand)


if __name__ == "__main__":
    main()
