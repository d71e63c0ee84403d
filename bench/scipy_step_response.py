#!/usr/bin/python3
"""SciPy baseline for bench/compare_simulation.sh: the hybrid step response of a
case file, with SciPy's solve_ivp and its `events`.

The same automaton and event semantics as backlash's simulators (docs/physics.md,
numeric/include/backlash/numeric/hybrid_simulation.hpp):
  start        at rest, in contact on the face that drives toward θR (σ = −1 for a
               step A ≥ 0, else +1), θo = θR − A;
  contact σ    (Jm+JL) θo'' + (Fm+FL) θo' + K θo = K θR, integrated in (θo − θR, θ̇o);
               holds while −σ·Tc ≥ 0, Tc = JL θ̈o + FL θ̇o;
  separation   terminal event −σ·Tc = 0, direction −1 (not one where the motion has
               decayed to rounding level: |θo − θR| ≤ ν, |θ̇o| ≤ ν√(K/J), ν = 1024 ε max(1, |θR|));
  free         eqs. 16/39 and 17, in start-relative coordinates (θm − θm0, θ̇m, Δ, Δ̇),
               Δ = gap change since the start (integrated directly, no cancellation);
  recombination  terminal event σΔ + b = 0 (the gap reaches the opposite face);
  recontact    terminal event σΔ = 0, direction +1, armed by a first terminal event
               σΔ + ν_gap = 0 (ν_gap = 1e-12·max(1, b): the gap has left the face; SciPy
               would otherwise report the zero it starts on);
  impact       inelastic (eq. 24); a bounce when −σ'·Tc < 0 on the face σ' hit;
  rest         no event before t_end and every velocity below 1e-9 at t_end: the rest
               event is the last time a velocity was ≥ 1e-9.

solve_ivp checks event signs only at step ends (a double crossing inside one step is
missed — scipy/scipy#9135-style behaviour, docs/design.md, "Facts about the tools"), so max_step is bounded by
0.1 / (the fastest rate of the modes), the same bound as the odeint simulator's.

Tolerance.  rtol = atol = 1e-10 with DOP853 (the default here), max_step as above.
Chosen with `bench/compare_simulation.sh --calibrate-scipy`, which runs the eight thesis
cases' 60 s step responses at rtol = atol = 1e-6 … 1e-12 and compares every event time
with the closed-form simulator's: with the step bounded by max_step, DOP853's error is far
below its tolerance, and every tolerance gave the same event sequences and event times
within 1.1e-13 of the closed form (1e-6: 1.1e-13, 1e-10: 3.6e-14, 1e-12: 7.1e-14).  So
the max_step bound (needed anyway against double crossings), not rtol, sets SciPy's cost
here; 1e-10 is the accuracy the comparison asks for.  compare_simulation.sh re-checks the
event accuracy of every run it times.

Usage: scipy_step_response.py --case cases/V.toml [--step A] [--t-end 60] [--json]
                              [--repeat N] [--rtol R] [--atol A] [--method DOP853]
"""
import argparse
import json
import math
import sys
import time
import tomllib
from fractions import Fraction

import numpy as np
import scipy
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

REST_VELOCITY = 1e-9
EPS = np.finfo(float).eps


def exact(value):
    if isinstance(value, str):
        return float(Fraction(value))
    return float(value)


def load_case(path):
    with open(path, "rb") as f:
        d = tomllib.load(f)
    p = {
        "name": d.get("name", path),
        "at_motor": d["measured_at"] == "motor",
        "K": exact(d["K"]),
        "b": exact(d["backlash"]),
        "R": exact(d["reference"]),
        "Jm": exact(d["motor"]["J"]),
        "Fm": exact(d["motor"]["F"]),
        "JL": exact(d["load"]["J"]),
        "FL": exact(d["load"]["F"]),
    }
    experiment = d.get("experiment", {})
    return p, (exact(experiment["step"]) if "step" in experiment else None), \
        (exact(experiment["t_end"]) if "t_end" in experiment else None)


def fastest_rate(p):
    J, F = p["Jm"] + p["JL"], p["Fm"] + p["FL"]
    rate = max(F / J + math.sqrt(p["K"] / J), p["Fm"] / p["Jm"] + math.sqrt(p["K"] / p["Jm"]), p["FL"] / p["JL"])
    return rate if rate > 0 else 1.0


def torque(p, e, w):
    """Tc from the deviation e = θo − θR and the velocity w."""
    J, F = p["Jm"] + p["JL"], p["Fm"] + p["FL"]
    return p["JL"] * (-p["K"] * e - F * w) / J + p["FL"] * w


def torque_from_theta(p, theta_o, w):
    J, F = p["Jm"] + p["JL"], p["Fm"] + p["FL"]
    return p["JL"] * (p["K"] * (p["R"] - theta_o) - F * w) / J + p["FL"] * w


def contact_state(p, face, theta_o, w):
    x = face * p["b"] / 2  # θL − θm
    if p["at_motor"]:
        return dict(theta_m=theta_o, theta_L=theta_o + x, dtheta_m=w, dtheta_L=w, contact=True, face=face)
    return dict(theta_m=theta_o - x, theta_L=theta_o, dtheta_m=w, dtheta_L=w, contact=True, face=face)


def measured(p, s):
    return s["theta_m"] if p["at_motor"] else s["theta_L"]


def simulate(p, step, t_end, rtol, atol, method):
    K, Jm, Fm, JL, FL, R, b = p["K"], p["Jm"], p["Fm"], p["JL"], p["FL"], p["R"], p["b"]
    J, F = Jm + JL, Fm + FL
    max_step = 0.1 / fastest_rate(p)
    noise = 1024 * EPS * max(1.0, abs(R))
    rate = math.sqrt(K / J)
    gap_noise = 1e-12 * max(1.0, b)
    state = contact_state(p, -1 if step >= 0 else 1, R - step, 0.0)
    t = 0.0
    events = []
    status = "completed"

    def push(kind, bounce=False):
        events.append({"t": t, "kind": kind, "bounce": bounce, "theta_o": measured(p, state),
                       "dtheta_o": state["dtheta_m"] if p["at_motor"] else state["dtheta_L"]})

    def contact_rhs(_, y):
        return [y[1], (-K * y[0] - F * y[1]) / J]

    while t < t_end:
        remaining = t_end - t
        if state["contact"]:
            face = state["face"]
            y0 = [measured(p, state) - R, state["dtheta_m"]]

            def hold(_, y, face=face):
                return -face * torque(p, y[0], y[1])
            hold.terminal, hold.direction = True, -1
            converged = False
            sol = solve_ivp(contact_rhs, (0.0, remaining), y0, method=method, rtol=rtol, atol=atol,
                            max_step=max_step, events=hold)
            if sol.t_events[0].size:
                tau = sol.t_events[0][0]
                e, w = sol.y_events[0][0]
                converged = abs(e) <= noise and abs(w) <= noise * rate
            if not sol.t_events[0].size or converged:
                # (a converged contact is re-integrated to t_end without the event)
                if converged:
                    sol = solve_ivp(contact_rhs, (0.0, remaining), y0, method=method, rtol=rtol, atol=atol,
                                    max_step=max_step)
                e, w = sol.y[:, -1]
                state = contact_state(p, face, R + e, w)
                t = t_end
                break
            t += tau
            state = contact_state(p, face, R + e, w)
            state["contact"] = False  # face σ is the face just left
            push("separation")
            continue

        # Free flight from the face σ left, start-relative coordinates.
        face = state["face"]
        theta_m0, theta_L0 = state["theta_m"], state["theta_L"]
        e0 = measured(p, state) - R
        at_motor = p["at_motor"]

        def free_rhs(_, y):
            e = e0 + y[0] if at_motor else e0 + y[0] + y[2]
            am = (-K * e - Fm * y[1]) / Jm
            aL = -FL * (y[1] + y[3]) / JL
            return [y[1], am, y[3], aL - am]

        def recombination(_, y, face=face):
            return face * y[2] + b
        recombination.terminal, recombination.direction = True, -1

        def arm(_, y, face=face):
            return face * y[2] + gap_noise
        arm.terminal, arm.direction = True, -1

        def recontact(_, y, face=face):
            return face * y[2]
        recontact.terminal, recontact.direction = True, 1

        y = [0.0, state["dtheta_m"], 0.0, state["dtheta_L"] - state["dtheta_m"]]
        tau0 = 0.0
        sol = solve_ivp(free_rhs, (0.0, remaining), y, method=method, rtol=rtol, atol=atol, max_step=max_step,
                        events=[recombination, arm])
        event = None
        if sol.t_events[0].size:
            event = ("recombination", sol.t_events[0][0], sol.y_events[0][0])
        elif sol.t_events[1].size:  # armed: continue with the recontact event
            tau0, y = sol.t_events[1][0], sol.y_events[1][0]
            sol = solve_ivp(free_rhs, (tau0, remaining), y, method=method, rtol=rtol, atol=atol,
                            max_step=max_step, events=[recombination, recontact])
            if sol.t_events[0].size and (not sol.t_events[1].size or sol.t_events[0][0] <= sol.t_events[1][0]):
                event = ("recombination", sol.t_events[0][0], sol.y_events[0][0])
            elif sol.t_events[1].size:
                event = ("recontact", sol.t_events[1][0], sol.y_events[1][0])

        def free_state(y):
            return dict(theta_m=theta_m0 + y[0], dtheta_m=y[1], theta_L=theta_L0 + y[0] + y[2],
                        dtheta_L=y[1] + y[3], contact=False, face=face)

        if event is None:
            end = free_state(sol.y[:, -1])
            if max(abs(end["dtheta_m"]), abs(end["dtheta_L"])) < REST_VELOCITY:
                # Rest: the last time a velocity was ≥ REST_VELOCITY (re-integrated with dense output).
                dense = solve_ivp(free_rhs, (0.0, remaining), [0.0, state["dtheta_m"], 0.0,
                                  state["dtheta_L"] - state["dtheta_m"]], method=method, rtol=rtol, atol=atol,
                                  max_step=max_step, dense_output=True)

                def speed(tau):
                    z = dense.sol(tau)
                    return max(abs(z[1]), abs(z[1] + z[3])) - REST_VELOCITY
                ts = dense.t
                above = [i for i in range(len(ts)) if speed(ts[i]) >= 0]
                tau_rest = 0.0
                if above and above[-1] + 1 < len(ts):
                    i = above[-1]
                    tau_rest = brentq(speed, ts[i], ts[i + 1], xtol=4 * EPS, rtol=4 * EPS)
                t_final = t + remaining
                t += tau_rest
                state = free_state(dense.sol(tau_rest))
                push("rest")
                t, state, status = t_final, end, "rest"
                break
            state, t = end, t_end
            break
        kind, tau, y_event = event
        t += tau
        before = free_state(y_event)
        face_hit = -face if kind == "recombination" else face
        omega = (Jm * before["dtheta_m"] + JL * before["dtheta_L"]) / J
        theta_o = measured(p, before)
        state = contact_state(p, face_hit, theta_o, omega)
        tc = torque_from_theta(p, theta_o, omega)
        holds = -face_hit * tc >= -1e-14 * max(1.0, abs(tc))
        if not holds:
            state["contact"] = False
        push(kind, bounce=not holds)
    return {"status": status, "events": events,
            "final": {"theta_o": measured(p, state), "theta_m": state["theta_m"], "theta_L": state["theta_L"]},
            "max_step": max_step}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", required=True, help="case file (TOML)")
    ap.add_argument("--step", type=float, help="step size A (default: the case's [experiment] step)")
    ap.add_argument("--t-end", type=float, default=60.0)
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--atol", type=float, help="default: = rtol")
    ap.add_argument("--method", default="DOP853")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs; the best is reported")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    p, case_step, _ = load_case(args.case)
    step = args.step if args.step is not None else (case_step if case_step is not None else 1.0)
    atol = args.atol if args.atol is not None else args.rtol
    best = math.inf
    best_cpu = math.inf
    result = None
    for _ in range(max(1, args.repeat)):
        wall, cpu = time.perf_counter(), time.process_time()
        result = simulate(p, step, args.t_end, args.rtol, atol, args.method)
        best = min(best, time.perf_counter() - wall)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    out = {"case": p["name"], "file": args.case, "step": step, "t_end": args.t_end, "method": args.method,
           "rtol": args.rtol, "atol": atol, "max_step": result["max_step"], "status": result["status"],
           "events": result["events"], "final": result["final"], "repeats": args.repeat,
           "elapsed_seconds": best, "cpu_seconds": best_cpu, "scipy_version": scipy.__version__}
    if args.json:
        json.dump(out, sys.stdout)
        print()
    else:
        print(f"{out['case']}: step {step}, t_end {args.t_end}, {args.method} rtol {args.rtol} atol {atol}, "
              f"max_step {out['max_step']:.4g}: {out['status']}, {len(out['events'])} events, "
              f"best of {args.repeat}: {best * 1e3:.2f} ms wall, {best_cpu * 1e3:.2f} ms cpu")
        for e in out["events"]:
            print(f"  {e['t']:.15f}  {e['kind']:<13} {'bounce' if e['bounce'] else '':6} "
                  f"theta_o {e['theta_o']:.12f}  dtheta_o {e['dtheta_o']:.6e}")


if __name__ == "__main__":
    main()
