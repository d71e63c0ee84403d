"""Issue 20, `simulate --from`: the run from any admissible state, through the CLI and Python,
and the refusals of states that are not admissible (exit 2, the flag named, nothing on stdout)."""
import json
import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python"))
from known import cli, cli_error, expect_close  # noqa: E402

import backlash  # noqa: E402


def events(document):
    return [(e["t"], e["kind"], e["theta_o"], e["dtheta_o"], e["theta_m"], e["theta_L"]) for e in document["events"]]


def test_item_from_rest_equals_the_step_response():
    # Case V's step 0.62 starts at rest on the driving face at θo = θR − A = 0.38: the same state given by --from
    # gives the step response's events, bit for bit.
    step = json.loads(cli("simulate", "V", "--json"))
    start = json.loads(cli("simulate", "V", "--from", "0.38,0", "--json"))
    assert events(start) == events(step) and len(step["events"]) > 10
    assert start["from"] == {"theta_m": 0.53, "dtheta_m": 0.0, "theta_L": 0.38, "dtheta_L": 0.0, "in_contact": True,
                             "face": -1}


def test_item_four_shaft_values_equal_the_measured_form():
    measured = json.loads(cli("simulate", "V", "--from", "-0.5,0.2", "--flight", "--t-end", "20", "--json"))
    shafts = json.loads(cli("simulate", "V", "--from", "-0.65,0.2,-0.5,0.2", "--flight", "--t-end", "20", "--json"))
    assert events(measured) == events(shafts) and measured["events"][0]["kind"] == "recombination"
    with_gap = json.loads(cli("simulate", "V", "--from", "-0.5,0.2", "--gap", "-0.15", "--t-end", "20", "--json"))
    contact = json.loads(cli("simulate", "V", "--from", "-0.35,0.2,-0.5,0.2", "--t-end", "20", "--json"))
    assert events(with_gap) == events(contact)


def test_item_csv_from_a_state():
    rows = cli("simulate", "III", "--from", "0.2,0.1", "--t-end", "1", "--csv", "--dt", "0.5").splitlines()
    assert rows[0] == "t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode" and len(rows) == 4
    first = [float(x) for x in rows[1].split(",")[:7]]
    assert first[0] == 0 and abs(first[1] - 0.2) < 1e-15 and first[2] == 0.1 and rows[1].endswith(",contact")


@pytest.mark.parametrize("arguments, message", [
    (["--from", "0,0,1,0"], "--from: the gap theta_L - theta_m = 1 is not on a face"),
    (["--from", "0,0,1,0", "--flight"], "--from: the gap theta_L - theta_m = 1 is outside the backlash"),
    (["--from", "0,0,0.15,1"], "--from: in contact both shafts move at one velocity"),
    (["--from", "-0.5,0.2", "--flight", "--gap", "-0.15"], "--from: in free flight on the face x = -b/2 the drive presses"),
    (["--from", "0,0,0.15,1", "--flight"], "--from: in free flight on the face x = +b/2 the gap would close"),
    (["--from", "1,2,3"], "--from: expected theta_m,dtheta_m,theta_L,dtheta_L or theta_o,dtheta_o, got 3 values"),
    (["--from", "0,nan"], "--from: 'nan' is not finite"),
    (["--from", "0,0,0,0", "--gap", "0"], "--gap: only with the measured shaft's two values"),
    (["--from", "0,0", "--step", "1"], "--step excludes --from"),
    (["--flight"], "--flight, --gap and --other-velocity need --from"),
])
def test_item_inadmissible_states_refused(arguments, message):
    run = subprocess.run([os.environ.get("BACKLASH_CLI", "build/bin/backlash"), "simulate", "V", *arguments],
                         capture_output=True, text=True)
    assert run.returncode == 2 and run.stdout == "", (run.returncode, run.stdout)
    assert cli_error("simulate", "V", *arguments).startswith(message)


def test_item_python_simulate_from_equals_the_cli():
    v = backlash.load("V")
    run = v.simulate_from((-0.5, 0.2), flight=True, t_end=20, dt=None)
    cli_run = json.loads(cli("simulate", "V", "--from", "-0.5,0.2", "--flight", "--t-end", "20", "--json"))
    assert json.loads(run.json()) == cli_run
    with pytest.raises(backlash.BadInput, match="from: the gap theta_L - theta_m = 1 is not on a face"):
        v.simulate_from((0, 0, 1, 0))
    sampled = v.simulate_from((0.38, 0), t_end=1, dt=0.5)
    assert list(sampled.t) == [0, 0.5, 1.0]


def test_item_explorer_command_writes_the_page(tmp_path):
    page = os.environ.get("BACKLASH_EXPLORER_PAGE", "")
    if not page:
        pytest.skip("this build makes no explorer page (no emcc, or a sanitizer build)")
    out = tmp_path / "site"
    assert cli("explorer", "--out", str(out)).strip() == f"wrote {out / 'index.html'}"
    written = (out / "index.html").read_bytes()
    assert written == open(page, "rb").read() and b"createBacklashCore" in written and len(written) > 100000
    run = subprocess.run([os.environ.get("BACKLASH_CLI", "build/bin/backlash"), "explorer"], capture_output=True, text=True)
    assert run.returncode == 2 and "--out" in run.stderr


# ------------------------------------------------------------------ a free start inside the backlash

def free_flight_reference(case, start):
    """The free flight of docs/physics.md ("Modes", free) from `start` = (θm, θ̇m, θL, θ̇L), solved
    independently of the library: x' = A x + c in 30 digits (mpmath's matrix exponential of the
    augmented matrix), the gap x = θL − θm scanned on a 10 ms grid for its first arrival at ±b/2 and
    the root polished by mpmath's solver.  Returns (t, face, θm, θ̇m, θL, θ̇L) at the arrival and
    eq. 24's common velocity after an inelastic impact there, (Jm θ̇m + JL θ̇L)/(Jm + JL)."""
    import tomllib
    import mpmath
    mpmath.mp.dps = 30
    with open(os.path.join(os.path.dirname(__file__), "..", "..", "cases", case + ".toml"), "rb") as f:
        spec = tomllib.load(f)
    Jm, Fm = mpmath.mpf(spec["motor"]["J"]), mpmath.mpf(spec["motor"]["F"])
    JL, FL = mpmath.mpf(spec["load"]["J"]), mpmath.mpf(spec["load"]["F"])
    K, R, half = mpmath.mpf(spec["K"]), mpmath.mpf(spec["reference"]), mpmath.mpf(spec["backlash"]) / 2
    M = mpmath.zeros(5, 5)  # rows θm, θ̇m, θL, θ̇L, 1
    M[0, 1] = M[2, 3] = 1
    M[1, 1], M[3, 3] = -Fm / Jm, -FL / JL
    if spec["measured_at"] == "motor":
        M[1, 0], M[1, 4] = -K / Jm, K * R / Jm  # Jm θ̈m + Fm θ̇m + K θm = K θR (eq. 16); the load coasts (eq. 17)
    else:
        M[1, 2], M[1, 4] = -K / Jm, K * R / Jm  # Jm θ̈m + Fm θ̇m = K (θR − θL) (eq. 39)
    x0 = mpmath.matrix([mpmath.mpf(v) for v in start] + [1])

    def state(t):
        return mpmath.expm(M * t) * x0

    def to_face(t, face):
        x = state(t)
        return x[2] - x[0] - face * half

    step, t, x = mpmath.mpf("0.01"), mpmath.mpf(0), state(0)  # 10 ms: far below the flights' durations
    while t < 30:
        after = state(t + step)
        for face in (-1, 1):
            if (x[2] - x[0] - face * half) * (after[2] - after[0] - face * half) <= 0:
                hit = mpmath.findroot(lambda s: to_face(s, face), (t, t + step), solver="anderson")
                x = state(hit)
                return (float(hit), face, float(x[0]), float(x[1]), float(x[2]), float(x[3]),
                        float((Jm * x[1] + JL * x[3]) / (Jm + JL)))
        t, x = t + step, after
    raise AssertionError("no arrival at a face within 30 s")


@pytest.mark.parametrize("case, start", [
    ("V", (-0.52, 0.3, -0.5, -0.1)),   # load measured, x(0) = +0.02 (face +1), the gap closing: to −b/2
    ("V", (-0.52, -1.0, -0.5, 1.0)),   # load measured, the gap opening fast: to +b/2 (a recontact)
    ("V", (-0.52, -0.2, -0.5, 0.4)),   # load measured, the gap opening, turned by the drive: to −b/2
    ("II", (0.4, 0.5, 0.33, 0.1)),     # motor measured, x(0) = −0.07 (face −1), to −b/2 (a recontact)
    ("II", (0.4, -0.3, 0.33, 0.6)),    # motor measured, to +b/2 (contact does not hold: a bounce)
])
def test_item_flight_inside_the_backlash_first_event(case, start):
    # Issue 20: "simulate from any state ... in flight": a free start strictly inside the backlash
    # (refused before) runs to its first arrival at a face, which must be the independent solution's.
    # Tolerances from the event search (first_crossing.hpp, CrossingOptions): the time to the toms748
    # width 1e-14·max(t, 1 s) (the servo time unit is 1 s here), plus the gap's rounding in the
    # closed form, a few ulps of the angles (16 eps) over the gap's speed at the arrival; the angles
    # to their own rounding plus the speed times that time error.
    document = json.loads(cli("simulate", case, "--from", ",".join(map(repr, start)), "--flight",
                              "--t-end", "30", "--json"))
    first = document["events"][0]
    t, face, theta_m, dtheta_m, theta_L, dtheta_L, recombined = free_flight_reference(case, start)
    x0 = start[2] - start[0]
    assert document["from"]["face"] == (1 if x0 > 0 else -1) and document["from"]["in_contact"] is False
    assert first["kind"] == ("recontact" if face == document["from"]["face"] else "recombination")
    eps = sys.float_info.epsilon
    scale = max(1.0, *map(abs, (theta_m, theta_L)))
    time_tolerance = 1e-14 * max(t, 1.0) + 16 * eps * scale / abs(dtheta_L - dtheta_m)
    angle_tolerance = 16 * eps * scale + max(abs(dtheta_m), abs(dtheta_L)) * time_tolerance
    expect_close("the arrival time", first["t"], t, time_tolerance)
    expect_close("theta_m at the arrival", first["theta_m"], theta_m, angle_tolerance)
    expect_close("theta_L at the arrival", first["theta_L"], theta_L, angle_tolerance)
    # eq. 24: the inelastic impact's common velocity (when contact holds after it)
    if not first["bounce"]:
        expect_close("the velocity after the impact", first["dtheta_o"], recombined,
                     16 * eps * max(1.0, abs(dtheta_m), abs(dtheta_L)) + 2 * time_tolerance)


def test_item_flight_from_a_face_unchanged_and_continuous_inside():
    # A start on the face (x = +b/2 exactly, or within the rounding 1e-12 of the angles) is the face
    # start of before, bit for bit; a start δ = 1e-9 inside is a flight from inside whose first event
    # (the recombination on −b/2) comes earlier by δ/|ẋ| — case V's motor is driven by θL alone
    # (eq. 39), so its motor motion is the face start's shifted by δ and x(t) = x_face(t) − δ.
    face = json.loads(cli("simulate", "V", "--from", "-0.65,0.2,-0.5,0.2", "--flight", "--t-end", "20", "--json"))
    near = json.loads(cli("simulate", "V", "--from", "-0.6499999999999,0.2,-0.5,0.2", "--flight", "--t-end", "20",
                          "--json"))
    assert near == face and face["from"]["theta_m"] == -0.65 and face["events"][0]["kind"] == "recombination"
    delta = 1e-9
    inside = json.loads(cli("simulate", "V", "--from", repr(-0.65 + delta) + ",0.2,-0.5,0.2", "--flight",
                            "--t-end", "20", "--json"))
    assert inside["from"]["face"] == 1 and inside["events"][0]["kind"] == "recombination"
    t, _, theta_m, dtheta_m, theta_L, dtheta_L, _ = free_flight_reference("V", (-0.65, 0.2, -0.5, 0.2))
    speed = abs(dtheta_L - dtheta_m)
    # first order in δ; the second-order term δ²|ẍ|/(2|ẋ|³) is below 1e-16 here (|ẍ| ≤ 4 rad/s² in V's flight)
    expected = t - delta / speed
    tolerance = 2e-14 * max(t, 1.0) + 16 * sys.float_info.epsilon / speed + 4 * delta**2 / speed**3
    expect_close("the first event from 1e-9 inside", inside["events"][0]["t"], expected, tolerance)
    expect_close("the face start's first event", face["events"][0]["t"], t, tolerance)


@pytest.mark.parametrize("effect", ["restitution = 0.4", "compliance = { stiffness = 400, damping = 4 }"])
def test_item_flight_inside_the_backlash_with_effects(tmp_path, effect):
    # The effects engine's flights measure the gap from the start's own (its gap witnesses carry x(0)):
    # with an effect that plays no part before the first impact (restitution, a compliant mesh acting
    # only beyond a face) the first event is the nominal one, to the event searches' accuracy.
    with open(os.path.join(os.path.dirname(__file__), "..", "..", "cases", "V.toml")) as f:
        text = f.read()
    case = tmp_path / "V_effect.toml"
    case.write_text(text + "\n[effects]\n" + effect + "\n")
    start = "-0.52,0.3,-0.5,-0.1"
    nominal = json.loads(cli("simulate", "V", "--from", start, "--flight", "--t-end", "1", "--json"))["events"][0]
    with_effect = json.loads(cli("simulate", str(case), "--from", start, "--flight", "--t-end", "1",
                                 "--json"))["events"][0]
    assert with_effect["kind"] == nominal["kind"] == "recombination"
    t, _, theta_m, dtheta_m, theta_L, dtheta_L, _ = free_flight_reference("V", (-0.52, 0.3, -0.5, -0.1))
    tolerance = 1e-14 * max(t, 1.0) + 16 * sys.float_info.epsilon / abs(dtheta_L - dtheta_m)
    expect_close("the first event with " + effect, with_effect["t"], t, tolerance)
    expect_close("the nominal first event", nominal["t"], t, tolerance)
