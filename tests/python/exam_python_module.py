"""`import backlash` on known answers — the same as the C++ tests (tests/api, tests/numeric):
case V's limit cycle (section 14; exact .500728496422, reports/errata/limit_cycles.toml),
case I's first separation (closed form) — and the module against the CLI, byte for byte."""
import json
import math
import threading
from fractions import Fraction

import numpy as np

import backlash
from known import cli, expect_close, expect_equal

V_PEAK_TO_PEAK = 0.500728496422


def test_case_V_limit_cycle():
    cycle = backlash.load("V").limit_cycle()
    expect_equal("load('V').limit_cycle().status", cycle.status, "limit_cycle")
    expect_close("load('V').limit_cycle().peak_to_peak", cycle.peak_to_peak, V_PEAK_TO_PEAK, 5e-13)
    expect_close("load('V').limit_cycle().amplitude", cycle.amplitude, V_PEAK_TO_PEAK / 2, 1e-12)
    assert cycle.stable, "load('V').limit_cycle().stable returned False instead of True"
    expect_equal("load('V').limit_cycle().json()", cycle.json(), cli("limit-cycle", "V", "--json"))
    expect_equal("load('V').limit_cycle().text()", cycle.text(), cli("limit-cycle", "V"))
    # print(cycle) prints what the CLI prints; repr() is one line.
    expect_equal("str(load('V').limit_cycle())", str(cycle) + "\n", cli("limit-cycle", "V"))
    expect_equal("repr(load('V').limit_cycle())", repr(cycle),
                 "<backlash.Cycle V: limit_cycle, peak_to_peak 0.5007284964 rad, period 6.357429332 s>")


def test_case_I_has_no_limit_cycle():
    cycle = backlash.load("I").limit_cycle()
    expect_equal("load('I').limit_cycle().status", cycle.status, "none")
    assert math.isnan(cycle.peak_to_peak), f"peak_to_peak returned {cycle.peak_to_peak} instead of nan"


def test_case_I_first_separation():
    # J = 1, F = .8, K = 1, θR = 1, step 1: separation at θo = θR, t* = (π − atan(ω/α))/ω, θ̇o = e^{−αt*}.
    alpha = 0.4
    omega = math.sqrt(1 - alpha ** 2)
    t_star = (math.pi - math.atan(omega / alpha)) / omega
    run = backlash.load("I").simulate()
    first = run.events[0]
    expect_equal("the first event of case I", first["kind"], "separation")
    expect_close("the first separation time of case I", first["t"], t_star, 1e-12)
    expect_close("theta_o at the first separation of case I", first["theta_o"], 1.0, 1e-12)
    expect_close("dtheta_o at the first separation of case I", first["dtheta_o"], math.exp(-alpha * t_star), 1e-12)
    expect_equal("simulate().json() of case I", run.json(), cli("simulate", "I", "--json"))


def test_simulation_arrays():
    run = backlash.load("II").simulate(step=0.16, t_end=20, dt=0.01)
    assert isinstance(run.t, np.ndarray) and run.t.dtype == np.float64
    expect_equal("len(simulate(t_end=20, dt=0.01).t)", len(run.t), 2001)
    expect_close("theta_o at t = 0", run.theta_o[0], 1 - 0.16, 1e-15)
    expect_equal("len(theta_m)", len(run.theta_m), len(run.t))
    expect_equal("simulate(...).csv()", run.csv(), cli("simulate", "II", "--step", ".16", "--t-end", "20", "--csv"))
    expect_equal("final['theta_o']", run.final["theta_o"], json.loads(run.json())["final"]["theta_o"])


def test_trace():
    lines = backlash.load("V").trace()
    expect_equal("load('V').trace().json()", lines.json(), cli("trace", "V", "--json"))
    expect_close("cot_phi of case V", lines.cot_phi, 0.2, 1e-15)
    short = backlash.load("I").trace([0.9, 0.5, 0.13])
    expect_equal("trace([.9, .5, .13]).text()", short.text(), cli("trace", "I", "--v0", ".9,.5,.13"))
    expect_equal("len(trace(...).t)", len(short.t), 3)


def test_parameters_in_code_are_exact():
    case = backlash.load(name="V from code", measured_at="load", Jm=Fraction(1, 2), Fm="1/10", JL=0.5, FL="0.3", K=1,
                         backlash=0.3, reference=1, step=0.62)
    expect_equal("parameters", case.parameters,
                 {"Jm": "1/2", "Fm": "1/10", "JL": "1/2", "FL": "3/10", "K": "1", "backlash": "3/10", "reference": "1",
                  "measured_at": "load", "step": "31/50"})
    expect_equal("id", case.id, "V from code")
    expect_close("limit_cycle().peak_to_peak of case V given in code", case.limit_cycle().peak_to_peak, V_PEAK_TO_PEAK, 5e-12)


def test_effects_reach_the_model():
    case = backlash.load(measured_at="load", Jm=0.5, Fm=0.1, JL=0.5, FL=0.3, K=1, backlash=0.3, reference=1, step=0.62,
                         coulomb_load=0.03)
    assert case.has_effects
    cycle = json.loads(case.limit_cycle().json())
    expect_equal("limit_cycle().json()['effects']", cycle["effects"], {"coulomb_load": 0.03})
    expect_equal("simulate().json()['effects']", json.loads(case.simulate().json())["effects"], {"coulomb_load": 0.03})


def test_derive():
    derivation = backlash.load("V").derive()
    expect_equal("load('V').derive().json", derivation.json, cli("derive", "V", "--json"))
    expect_equal("load('V').derive().latex", derivation.latex, cli("derive", "V", "--latex"))
    expect_equal("cot_phi exactly", derivation.document["separation_line"]["cot_phi"]["exact"], "1/5")
    from_code = backlash.load(name="IV", measured_at="load", Jm="0.2", Fm="0.2", JL="0.8", FL=0, K=1, backlash="0.3",
                              reference=1)
    mine, file = from_code.derive().document, json.loads(cli("derive", "IV", "--json"))
    for key in ("contact", "free", "separation_line", "stability_constant", "verification"):
        expect_equal(f"derive() of case IV given in code: {key}", mine[key], file[key])


def test_sweep_matches_cli_and_releases_the_gil(tmp_path):
    out = tmp_path / "sweep.csv"
    cli("sweep", "V", "--vary", "K", "--from", "0.5", "--to", "2", "--points", "7", "--no-progress", "--out", str(out))
    sweep = backlash.sweep("V", vary="K", start=0.5, stop=2, points=7, threads=2)
    expect_equal("sweep('V', vary='K', ...).csv()", sweep.csv(), out.read_text())
    expect_equal("len(sweep)", len(sweep), 7)
    assert np.allclose(sweep.x, np.linspace(0.5, 2, 7), rtol=0, atol=1e-15)
    # While a sweep runs in another thread, this thread keeps running Python: the GIL is free.
    ticks = 0
    worker = threading.Thread(target=lambda: backlash.sweep("fig31", points=400, threads=2))
    worker.start()
    while worker.is_alive():
        ticks += 1
    worker.join()
    assert ticks > 1000, f"the main thread ran {ticks} times during a sweep instead of freely (the GIL is held)"


def test_no_ginac_until_derive():
    import subprocess
    import sys
    program = (
        "import backlash\n"
        "backlash.load('V').limit_cycle()\n"
        "maps = open('/proc/self/maps').read()\n"
        "print('libginac' in maps, 'libcln' in maps)\n"
        "backlash.load('V').derive()\n"
        "print('libginac' in open('/proc/self/maps').read())\n")
    run = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    expect_equal("GiNaC, CLN mapped before derive(); GiNaC after", run.stdout.split(), ["False", "False", "True"])



def test_early_stop_is_a_status_with_its_reason(tmp_path):
    # Undamped, the cycle grows until the event cap ends the run long before t_end: no
    # exception, the result says so; the CLI prints the same JSON and exits 3.
    import subprocess
    from known import CLI
    grows = backlash.load(name="grows", measured_at="load", Jm="1/2", Fm=0, JL="1/2", FL=0, K=1, backlash="3/10",
                          reference=1)
    run = grows.simulate(step=0.62, t_end=2e5, dt=None)
    assert run.stopped_early, f"simulate() returned status {run.status} instead of an early stop"
    expect_equal("simulate().status", run.status, "event_limit")
    assert "event cap" in run.stop_reason, run.stop_reason
    assert str(run).endswith(f"): {run.stop_reason}"), str(run)[-200:]
    case_file = tmp_path / "grows.toml"
    case_file.write_text(grows.case_file())
    printed = subprocess.run([CLI, "simulate", str(case_file), "--step", "0.62", "--t-end", "2e5", "--json"],
                             capture_output=True, text=True)
    expect_equal("the CLI's exit code", printed.returncode, 3)
    expect_equal("simulate().json()", run.json(), printed.stdout)
