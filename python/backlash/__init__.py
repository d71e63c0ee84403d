"""backlash — exact analysis of servo systems with gear backlash, from Python.

The C++ facade (backlash/api/backlash.hpp) with NumPy arrays.  A motor (inertia Jm,
viscous friction Fm) drives a load (JL, FL) through a gear with total backlash b, in a
loop of gain K toward the reference θR ("reference"); θo is the measured shaft, θm
(measured_at="motor") or θL ("load").  Units: rad, s, rad/s, torques in units of K·rad.
Conventions: docs/physics.md, effects: docs/effects.md, contracts: docs/design.md.

    import backlash
    v = backlash.load("V")                     # a thesis case I..VIII, or a case file path
    cycle = v.limit_cycle()                    # cycle.peak_to_peak, .period, ... ; cycle.json()
    run = v.simulate(step=0.62, t_end=60)      # run.t, run.theta_o (NumPy), run.events;
                                               # run.stopped_early, run.stop_reason (no exception);
                                               # dt=0.01: the samples' spacing (> 0, at most 1e7
                                               # samples; dt=None: events only)
    run = v.simulate_from((0.38, 0))           # from any state, as `simulate --from`: (θm, θ̇m, θL, θ̇L)
                                               # or (θo, θ̇o) [gap=, other_velocity=]; flight=True:
                                               # free flight leaving a face (default: contact)
    lines = v.trace([1, 0.5, 0.13])            # dividing lines
    d = v.derive()                             # exact solutions: d.text, d.latex, d.json
    c = backlash.load(name="mine", measured_at="load", Jm="1/2", Fm=0.1, JL=0.5, FL=0.3,
                      K=1, backlash=0.3, reference=1)
    sweep = backlash.sweep("fig31", points=101, threads=2)

Numbers are exact: a str ("1/3", "0.3"), an int, a fractions.Fraction or a
decimal.Decimal is the exact rational it writes; a float is read as its shortest repr
(0.3 → 3/10), as a case file reads a decimal.

Errors are exceptions with the library's one-line message: BadInput, CaseFileError and
MeasuredDataError (all ValueError) for bad input, ValidationFailed (a RuntimeError) for a
case whose evaluator fails the validation gate.  Every numeric call releases the GIL;
sweep() and discrepancy() use their own threads.  derive() holds the GIL (GiNaC is not
thread-safe) and is the only call that loads GiNaC.
"""

import decimal as _decimal
import fractions as _fractions
import json as _json
import os as _os
from dataclasses import dataclass as _dataclass

from . import _core
from ._core import (BadInput, Case, CaseFileError, Cycle, Discrepancy, MeasuredDataError, Record, Simulation,
                    Sweep, Trace, Validation, ValidationFailed)

__all__ = [
    "load", "sweep", "map", "read_record", "record", "discrepancy", "validate_branches", "derive_general", "data_dir",
    "Case", "Simulation", "Trace", "Cycle", "Sweep", "Record", "Discrepancy", "Validation", "Derivation",
    "BadInput", "CaseFileError", "MeasuredDataError", "ValidationFailed",
]


def _exact_text(name, value):
    """The exact text of a parameter value, as a case file's string would hold it."""
    if isinstance(value, bool):
        raise BadInput(f"{name}: expected a number, got a bool")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, _fractions.Fraction):
        return f"{value.numerator}/{value.denominator}"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (_decimal.Decimal, str)):
        return str(value)
    raise BadInput(f"{name}: expected a number (int, str, Fraction, Decimal or float), got {type(value).__name__}")


_TEXT_PARAMETERS = {"name", "measured_at", "experiment"}


def load(case=None, /, **parameters):
    """A case: load("V") (thesis case I..VIII), load("path/to/case.toml"), or the numbers
    in code — load(measured_at="load", Jm="1/2", Fm=0.1, JL=0.5, FL=0.3, K=1, backlash=0.3,
    reference=1 [, name=..., step=..., t_end=..., experiment="step"|"drive", drive_gain=...,
    and any effect parameter by its name in the table of effects, docs/effects.md, e.g.
    coulomb_load=..., stiffness=..., damping=...]) — checked by the case-file reader's rules."""
    if case is not None:
        if parameters:
            raise TypeError("load() takes a case or parameters, not both")
        return _core.load_case(_os.fspath(case))
    texts = []
    for key, value in parameters.items():
        if value is None:
            continue
        if key in _TEXT_PARAMETERS:
            if not isinstance(value, str):
                raise BadInput(f"{key}: expected a string, got {type(value).__name__}")
            texts.append((key, value))
        else:
            texts.append((key, _exact_text(key, value)))
    return _core.load_parameters(texts)


@_dataclass(frozen=True)
class Derivation:
    """A case's exact derivation, as `backlash derive` prints it."""
    case: str
    text: str   # plain text
    latex: str  # a LaTeX section (no preamble)
    json: str   # the JSON document

    @property
    def document(self):
        """The JSON document as Python objects."""
        return _json.loads(self.json)


def _case_derive(self):
    """The exact derivation of every segment (GiNaC; loaded on first use)."""
    from . import _derive as derive_module
    return Derivation(**derive_module.derive(self.case_file(), self.id))


Case.derive = _case_derive


def derive_general():
    """`backlash derive general`: the 14 parametric pole-structure branches, {"latex", "json"}."""
    from . import _derive as derive_module
    return derive_module.derive_general()


def sweep(target, vary=None, start=None, stop=None, points=101, threads=2):
    """Limit-cycle magnitude over a parameter: sweep("fig31"|"fig32", points=N) (the thesis's
    figures, N per series) or sweep(case, vary="K", start=0.5, stop=2, points=N) with
    x_i = start + (stop − start)·i/(N − 1).  Returns a Sweep (NumPy columns, csv())."""
    target = _os.fspath(target)
    if target not in ("fig31", "fig32"):
        if vary is None:
            raise BadInput("vary: required for a case (or use fig31 / fig32 as the target)")
        if start is None or stop is None:
            raise BadInput(f"{'start' if start is None else 'stop'}: required for a case")
    return _core.sweep(target, vary or "", float(start or 0), float(stop or 0), int(points), int(threads))


def map(target, vary, sample="grid", points=0, threads=2, step=None, out=None, resume=False):
    """A design-space map (docs/design.md, "Design-space maps"): limit cycles over several
    parameters.  vary: ["JL_over_Jm=0.25:4:40", "FL_over_F=0:1:40"] (NAME=FROM:TO:N, the names
    of sweep()); sample "grid", "sobol" or "lhs" (then `points`); step: the settle time's step
    (default the case's).  Without `out`: a dict of NumPy columns x (points × axes), status,
    peak_to_peak, period, multiplier, settle_time, in point order.  With `out`: the folder of
    `backlash map --out` (points.csv, boundary.csv, map.h5, figures), resumable; returns a
    summary dict."""
    target = _os.fspath(target)
    vary = [vary] if isinstance(vary, str) else list(vary)
    step = None if step is None else float(step)
    if out is None:
        return _core.map_rows(target, vary, sample, int(points), int(threads), step)
    return _core.map_write(target, vary, sample, int(points), int(threads), step, _os.fspath(out), bool(resume))


def read_record(file):
    """A measured record from the project's CSV or an EMPS .mat file."""
    return _core.read_record(_os.fspath(file))


def record(t, theta_out, theta_motor=None, theta_load=None, drive=None, name="<arrays>"):
    """A measured record from arrays (checked by the CSV contract): real numbers only, a
    complex array (even with zero imaginary parts) is a ValueError naming the column."""
    def column(values, label):
        if values is None:
            return None
        if any(isinstance(v, complex) or _is_complex_dtype(v) for v in ([values] + list(values))):
            raise ValueError(f"{name}: {label}: complex values, expected real numbers")
        return [float(v) for v in values]
    return _core.make_record(column(t, "t"), column(theta_out, "theta_out"), column(theta_motor, "theta_motor"),
                             column(theta_load, "theta_load"), column(drive, "drive"), name)


def _is_complex_dtype(value):
    """True for a NumPy array or scalar of a complex type (float() would drop its imaginary part)."""
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    return kind == "c"


def discrepancy(model, data, step=None, threads=2, cutoff=None, window=None, validation=None):
    """Where `model` (a Case, a thesis id or a case file) and the record `data` (a Record or
    a file) disagree: the missing effect named and fitted (docs/discrepancy.md).  A model
    whose experiment is a measured drive runs the torque-domain workflow (cutoff [Hz],
    window [s], a validation record); any other the step workflow (step, threads)."""
    if not isinstance(model, Case):
        model = load(model)
    if not isinstance(data, Record):
        data = read_record(data)
    if validation is not None and not isinstance(validation, Record):
        validation = read_record(validation)
    return _core.discrepancy(model, data, step, int(threads), cutoff, window, validation)


def validate_branches(tolerance=1e-9):
    """The parametric and direct evaluators of the 14 pole-structure branches against odeint."""
    return _core.validate_branches(tolerance)


def data_dir():
    """The data folder in use (share/backlash: the thesis's cases, errata, data)."""
    return _core.data_dir()
