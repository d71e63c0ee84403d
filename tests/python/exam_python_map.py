"""backlash.map() (docs/design.md, "Design-space maps") on known answers: a one-axis map is
backlash.sweep() over the same points, bit for bit; the rows are the CLI's points.csv."""
import csv
import io
import math

import numpy as np

import backlash
from known import cli, expect_equal


def test_one_axis_map_is_the_sweep():
    rows = backlash.map("V", ["FL_over_F=0.05:0.95:12"], step=0)
    sweep = backlash.sweep("V", vary="FL_over_F", start=0.05, stop=0.95, points=12)
    expect_equal("map(...)['x'][:, 0]", list(rows["x"][:, 0]), list(sweep.x))
    expect_equal("map(...)['status']", rows["status"], sweep.status)
    same = np.array_equal(rows["peak_to_peak"], sweep.peak_to_peak, equal_nan=True)
    assert same, f"map(...)['peak_to_peak'] returned {rows['peak_to_peak']} instead of {sweep.peak_to_peak}"


def test_map_rows_are_the_cli_csv():
    rows = backlash.map("V", ["K=0.5:2:3", "backlash=0.1:0.3:2"])
    table = list(csv.DictReader(io.StringIO(cli("map", "V", "--vary", "K=0.5:2:3", "--vary", "backlash=0.1:0.3:2"))))
    expect_equal("len(map(...))", len(rows["status"]), len(table))
    for i, row in enumerate(table):
        expect_equal(f"map(...)['status'][{i}]", rows["status"][i], row["status"])
        settle = float(row["settle_time"]) if row["settle_time"] else math.nan
        assert (math.isnan(settle) and math.isnan(rows["settle_time"][i])) or settle == rows["settle_time"][i], (
            f"map(...)['settle_time'][{i}] returned {rows['settle_time'][i]} instead of {settle}")
