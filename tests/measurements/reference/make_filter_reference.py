#!/usr/bin/python3
"""Writes the SciPy reference for tests/measurements/exam_inverse_dynamics_signals.cpp.

    /usr/bin/python3 tests/measurements/reference/make_filter_reference.py

(from the repository root; Debian's python3-scipy and python3-numpy, listed in
scripts/install-deps.sh).  Writes, next to this script:

  filter_reference.csv  a fixed test signal x (2000 samples at 1 kHz: slow
                        motion, two sinusoids in the pass band, one above it,
                        white noise, quantised to 5e-8 like the EMPS encoder)
                        and what SciPy/NumPy make of it:
                          y4  sosfiltfilt(butter(4, 88, fs=1000, output='sos'), x)
                          y3  sosfiltfilt(butter(3, 20, fs=1000, output='sos'), x)   odd order: padlen 12
                          y1  sosfiltfilt(butter(1, 150, fs=1000, output='sos'), x)  padlen 6
                          v4  numpy.gradient(y4, 1/fs, edge_order=2)
                          a4  second derivative of y4: numpy.diff(y4, 2)/h² inside; at the
                              ends the four-point one-sided stencil, its weights solved here
                              from the Taylor conditions (numpy.linalg.solve), not typed in
  welch_reference.csv   welch(x, fs=1000, nperseg=256) (SciPy's defaults otherwise)
  emps_welch_reference.csv
                        welch(qm, fs=1000, nperseg=2048) of tests/data/emps/DATA_EMPS.mat,
                        and in its header the cut-off rule of
                        backlash/measurements/inverse_dynamics_signals.hpp applied to it
                        (floor, band edge, highest raw line), then the inverse-dynamics
                        fit at that cut-off: qm and drive = gtau*vir filtered by
                        sosfiltfilt(butter(4, fc, fs=1000, output='sos')), v = gradient
                        (edge_order=2), a = second-order second differences as above,
                        least squares drive ≈ M·a + Fv·v + Fc·sign(v) + c (numpy.linalg.lstsq),
                        and τ_int of its residual (Geyer's initial positive sequence on the
                        FFT autocorrelation, as the header states it)

Each CSV starts with comment lines ('#') naming this script, the versions and
the command, then a header row.  Numbers are written with repr(): the shortest
text that reads back to the same double.
"""
import pathlib
import sys

import numpy as np
import scipy
import scipy.io
import scipy.signal

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[2]
FS = 1000.0
COMMAND = "/usr/bin/python3 tests/measurements/reference/make_filter_reference.py"


def header(extra):
    lines = [
        f"# written by tests/measurements/reference/make_filter_reference.py with scipy {scipy.__version__}, "
        f"numpy {np.__version__}, python {sys.version.split()[0]}",
        f"# command (from the repository root): {COMMAND}",
    ]
    return "\n".join(lines + [f"# {line}" for line in extra]) + "\n"


def write_csv(name, extra, columns):
    names = list(columns)
    length = len(columns[names[0]])
    assert all(len(columns[n]) == length for n in names)
    with open(HERE / name, "w", newline="\n") as out:
        out.write(header(extra))
        out.write(",".join(names) + "\n")
        for row in range(length):
            out.write(",".join(repr(float(columns[n][row])) for n in names) + "\n")


def test_signal():
    n = 2000
    t = np.arange(n) / FS
    rng = np.random.default_rng(20240611)
    x = (0.02 * np.sin(2 * np.pi * 1.3 * t) + 0.005 * t**2
         + 1e-3 * np.sin(2 * np.pi * 37 * t + 0.3)
         + 2e-5 * np.sin(2 * np.pi * 60 * t + 1.1)
         + 2e-4 * np.sin(2 * np.pi * 180 * t)
         + 1e-6 * rng.standard_normal(n))
    return t, np.round(x / 5e-8) * 5e-8


def one_sided_second_derivative_weights():
    """Weights w of f''(0) ≈ Σ w_j f(j·h)/h², j = 0…3, exact for cubics."""
    j = np.arange(4.0)
    taylor = np.array([j**p for p in range(4)])  # row p: Σ w_j j^p = p!·[p == 2]
    return np.linalg.solve(taylor, np.array([0.0, 0.0, 2.0, 0.0]))


def second_derivative(y, h):
    a = np.empty_like(y)
    a[1:-1] = np.diff(y, 2) / h**2
    w = one_sided_second_derivative_weights()
    a[0] = w @ y[:4] / h**2
    a[-1] = w @ y[::-1][:4] / h**2
    return a


def integrated_autocorrelation_time(r):
    """Geyer's initial positive sequence on the biased FFT autocorrelation."""
    d = r - r.mean()
    n = len(d)
    size = 1 << (2 * n - 1).bit_length()
    c = np.fft.irfft(np.abs(np.fft.rfft(d, size)) ** 2, size)[:n]
    rho = c / c[0]
    pairs, m = 0.0, 0
    while 2 * m + 1 < n:
        pair = rho[2 * m] + rho[2 * m + 1]
        if m >= 1 and not pair > 0:
            break
        pairs += pair
        m += 1
    return -1 + 2 * pairs, 2 * m - 1


def filter_reference():
    t, x = test_signal()
    h = 1 / FS
    y = {order: scipy.signal.sosfiltfilt(scipy.signal.butter(order, fc, fs=FS, output="sos"), x)
         for order, fc in [(4, 88.0), (3, 20.0), (1, 150.0)]}
    v4 = np.gradient(y[4], h, edge_order=2)
    a4 = second_derivative(y[4], h)
    write_csv("filter_reference.csv",
              ["fs = 1000 Hz; x: the fixed test signal; y4, y3, y1: sosfiltfilt with butter(order, fc, fs, output='sos'),",
               "fc = 88, 20, 150 Hz; v4 = gradient(y4, 1/fs, edge_order=2); a4: second-order second differences of y4"],
              {"t": t, "x": x, "y4": y[4], "y3": y[3], "y1": y[1], "v4": v4, "a4": a4})
    f, p = scipy.signal.welch(x, fs=FS, nperseg=256)
    write_csv("welch_reference.csv", ["welch(x, fs=1000, nperseg=256) of filter_reference.csv's x"],
              {"f": f, "psd": p})


def emps_reference():
    record = scipy.io.loadmat(ROOT / "tests" / "data" / "emps" / "DATA_EMPS.mat")
    qm = record["qm"].ravel()
    f, p = scipy.signal.welch(qm, fs=FS, nperseg=2048)
    floor = np.median(p[(f >= FS / 4) & (f <= FS / 2)])
    threshold = 100 * floor
    smoothed = np.array([np.median(p[max(0, k - 4):k + 5]) for k in range(len(p))])
    edge = f[smoothed > threshold].max()
    line = f[p > threshold].max()
    cutoff = min(max(edge, FS / 100), 0.4 * FS)
    sos = scipy.signal.butter(4, cutoff, fs=FS, output="sos")
    drive = record["gtau"].item() * record["vir"].ravel()
    qf, uf = scipy.signal.sosfiltfilt(sos, qm), scipy.signal.sosfiltfilt(sos, drive)
    v = np.gradient(qf, 1 / FS, edge_order=2)
    a = second_derivative(qf, 1 / FS)
    regressors = np.column_stack([a, v, np.sign(v), np.ones_like(v)])
    theta = np.linalg.lstsq(regressors, uf, rcond=None)[0]
    residual = uf - regressors @ theta
    tau, lags = integrated_autocorrelation_time(residual)
    write_csv("emps_welch_reference.csv",
              ["welch(qm, fs=1000, nperseg=2048) of tests/data/emps/DATA_EMPS.mat",
               f"noise_floor = {floor!r}  (median over {FS / 4} <= f <= {FS / 2} Hz)",
               f"band_edge_hz = {edge!r}  (highest f with the 9-bin running median > 100 * floor)",
               f"highest_line_hz = {line!r}  (highest f with the raw psd > 100 * floor)",
               f"cutoff_hz = {cutoff!r}",
               "fit at cutoff_hz: drive ≈ M·a + Fv·v + Fc·sign(v) + c",
               f"M = {theta[0]!r}", f"Fv = {theta[1]!r}", f"Fc = {theta[2]!r}", f"c = {theta[3]!r}",
               f"rms = {np.sqrt(np.mean(residual**2))!r}",
               f"tau_int = {tau!r}", f"tau_lags = {lags!r}"],
              {"f": f, "psd": p})


if __name__ == "__main__":
    filter_reference()
    emps_reference()
