"""Issue 18, item 10 from Python: simulate()'s sample spacing and count are the CLI's --dt checks,
made once by the facade (api::check_sample_interval, the sample count in Model::simulate) and
named dt here: a ValueError with the reason, before any work or memory is spent."""
import subprocess
import sys

import pytest

import backlash
from known import CLI, expect_equal


def refusal(call):
    with pytest.raises(backlash.BadInput) as caught:
        call()
    assert isinstance(caught.value, ValueError)
    return str(caught.value)


def test_item10_dt_zero_negative_or_nan_is_refused_as_the_cli_refuses_it():
    # Before: dt=0 returned a run with empty arrays where `simulate --dt 0` exits 2.
    v = backlash.load("V")
    expect_equal("simulate(dt=0)", refusal(lambda: v.simulate(dt=0)), "dt: must be > 0, got 0")
    expect_equal("simulate(dt=-1)", refusal(lambda: v.simulate(dt=-1)), "dt: must be > 0, got -1")
    expect_equal("simulate(dt=nan)", refusal(lambda: v.simulate(dt=float("nan"))), "dt: must be > 0, got nan")
    cli = subprocess.run([CLI, "simulate", "V", "--dt", "0"], capture_output=True, text=True)
    expect_equal("the CLI's exit code for --dt 0", cli.returncode, 2)
    expect_equal("the CLI's message", cli.stderr, "backlash: error: --dt: must be > 0, got 0\n")


def test_item10_too_many_samples_are_refused_before_any_memory_is_spent():
    # Before: simulate(dt=1e-7) allocated 9.4 GB without refusal.  Run in a child whose
    # address space is limited to 1 GiB, so that the old behaviour fails instead of swapping.
    program = (
        "import resource, backlash\n"
        "resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))\n"
        "try:\n"
        "    backlash.load('V').simulate(dt=1e-7)\n"
        "    print('no refusal')\n"
        "except backlash.BadInput as e:\n"
        "    print('BadInput:', e)\n")
    run = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=120)
    expect_equal("simulate(dt=1e-7)", run.stdout,
                 "BadInput: dt: 1e-07 s over t_end = 60 s gives 6e+08 samples; at most 1e+07 are recorded "
                 "(use a larger interval or a shorter t_end)\n")


def test_item10_dt_none_is_events_only_and_a_positive_dt_samples():
    v = backlash.load("V")
    events_only = v.simulate(dt=None)
    expect_equal("simulate(dt=None) samples", len(events_only.t), 0)
    assert len(events_only.events) > 0
    expect_equal("simulate() samples (dt=0.01 over 60 s)", len(v.simulate().t), 6001)
