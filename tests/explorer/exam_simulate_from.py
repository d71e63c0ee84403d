"""Issue 20, `simulate --from`: the run from any admissible state, through the CLI and Python,
and the refusals of states that are not admissible (exit 2, the flag named, nothing on stdout)."""
import json
import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python"))
from known import cli, cli_error  # noqa: E402

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
    (["--from", "0,0,0,0", "--flight"], "--from: the gap theta_L - theta_m = 0 is inside the backlash"),
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
