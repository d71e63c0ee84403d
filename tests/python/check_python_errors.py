"""Bad input from Python: an exception (a ValueError) with the library's one-line message —
the very line the CLI prints after "backlash: error: " where the CLI takes the same input."""
import pytest

import backlash
from known import cli_error, expect_equal

V = dict(measured_at="load", Jm=0.5, Fm=0.1, JL=0.5, FL=0.3, K=1, backlash=0.3, reference=1)


def message(call):
    with pytest.raises(ValueError) as caught:
        call()
    text = str(caught.value)
    assert "\n" not in text, f"the message is not one line: {text!r}"
    return caught


def test_unknown_case_is_the_cli_message():
    caught = message(lambda: backlash.load("IX"))
    assert isinstance(caught.value, backlash.CaseFileError)
    expect_equal("load('IX') error", str(caught.value), cli_error("limit-cycle", "IX"))


def test_bad_case_file_is_the_cli_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\nmeasured_at = "load"\nK = 1\nbacklash = -0.1\nreference = 1\n'
                   "[motor]\nJ = 1\nF = 0\n[load]\nJ = 1\nF = 0\n")
    caught = message(lambda: backlash.load(bad))
    expect_equal("load(bad.toml) error", str(caught.value), cli_error("limit-cycle", str(bad)))
    expect_equal("load(bad.toml) error", str(caught.value),
                 f"{bad}:4: backlash: negative backlash (got -0.1; the total backlash must be >= 0)")


def test_parameters_name_the_parameter():
    expect_equal("load(Jm=0, ...)", str(message(lambda: backlash.load(**{**V, "Jm": 0})).value),
                 'Jm: non-positive inertia (got "0"; an inertia must be > 0)')
    no_k = {key: value for key, value in V.items() if key != "K"}
    expect_equal("load() without K", str(message(lambda: backlash.load(**no_k)).value), "K: missing key")
    expect_equal("load(Jm=True)", str(message(lambda: backlash.load(**{**V, "Jm": True})).value),
                 "Jm: expected a number, got a bool")
    expect_equal("load(Fm='x')", str(message(lambda: backlash.load(**{**V, "Fm": "x"})).value),
                 'Fm: not a number: "x" (expected a digit; write a decimal such as 0.3 or a fraction such as "1/3")')
    expect_equal("load(K=inf)", str(message(lambda: backlash.load(**{**V, "K": float("inf")})).value),
                 'K: non-finite number (got "inf")')
    caught = message(lambda: backlash.load(**{**V, "Jx": 1}))
    assert isinstance(caught.value, backlash.BadInput)
    assert str(caught.value).startswith("Jx: unknown parameter (allowed: name measured_at K backlash reference Jm")


def test_arguments_out_of_range():
    v = backlash.load("V")
    expect_equal("simulate(t_end=-3)", str(message(lambda: v.simulate(step=0.5, t_end=-3)).value), "t_end: must be > 0, got -3")
    expect_equal("trace([])", str(message(lambda: v.trace([])).value), "v0: empty list")
    expect_equal("sweep('V')", str(message(lambda: backlash.sweep("V")).value),
                 "vary: required for a case (or use fig31 / fig32 as the target)")
    expect_equal("sweep(points=0)", str(message(lambda: backlash.sweep("fig31", points=0)).value),
                 "points: expected an integer >= 1, got 0")
    no_step = backlash.load(**V)
    expect_equal("simulate() without a step", str(message(lambda: no_step.simulate()).value),
                 "step: required (the case has no [experiment] step)")


def test_records():
    caught = message(lambda: backlash.record([0, 1, 1, 2, 3, 4, 5, 6, 7, 8], [0.0] * 10))
    assert isinstance(caught.value, backlash.MeasuredDataError)
    expect_equal("record(t not increasing)", str(caught.value), "<arrays>: t: not strictly increasing: t[2] = 1 after t[1] = 1")
    missing = message(lambda: backlash.read_record("no/such/record.csv"))
    assert str(missing.value).startswith("no/such/record.csv"), str(missing.value)
