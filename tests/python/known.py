"""Helpers of the Python tests: the CLI beside the module, and failures that say what
was returned instead of what."""
import math
import os
import subprocess

SOURCE = os.environ.get("BACKLASH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("BACKLASH_CLI", os.path.join(SOURCE, "build", "bin", "backlash"))


def cli(*arguments):
    """stdout of `backlash ARGUMENTS` (it must succeed)."""
    run = subprocess.run([CLI, *arguments], capture_output=True, text=True)
    assert run.returncode == 0, f"backlash {' '.join(arguments)} exited with {run.returncode}: {run.stderr}"
    return run.stdout


def cli_error(*arguments):
    """The one-line error of a failing `backlash ARGUMENTS`, without the "backlash: error: " prefix."""
    run = subprocess.run([CLI, *arguments], capture_output=True, text=True)
    assert run.returncode != 0, f"backlash {' '.join(arguments)} succeeded instead of failing"
    prefix = "backlash: error: "
    assert run.stderr.startswith(prefix) and run.stderr.count("\n") == 1, run.stderr
    return run.stderr[len(prefix):].rstrip("\n")


def expect_close(what, actual, expected, tolerance):
    assert math.isfinite(actual) and abs(actual - expected) <= tolerance, \
        f"{what} returned {actual!r} instead of {expected!r} (±{tolerance})"


def expect_equal(what, actual, expected):
    assert actual == expected, f"{what} returned {actual!r} instead of {expected!r}"
