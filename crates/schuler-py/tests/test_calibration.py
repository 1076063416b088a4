"""Self-calibration through Python (issue 33): `navigate(..., estimate_lever_arm=...,
estimate_gnss_time_offset=...)` gives the CLI's estimates (to the digits `schuler nav`
prints them) and their history at the once-a-second snapshots. The example drive's
antenna is at (0.5, 0, -1) m and its GNSS has no offset: each estimate must hold the
truth inside 3 of its standard deviations. A constant's variance never grows in a
Kalman filter (its row of the transition is the identity and it has no process
noise, and an update only takes information away from the variance), so each
history's standard deviation is non-increasing: the check that the history is the
filter's own, epoch by epoch."""

import re

import numpy as np

import schuler
from conftest import START

PRIORS = dict(estimate_lever_arm="1 m", estimate_gnss_time_offset="0.5 s")


def printed(stdout, start):
    """The `a ± b` pairs of the line of `stdout` that starts with `start`."""
    line = next(l for l in stdout.splitlines() if l.startswith(start))
    return [(float(a), float(b)) for a, b in re.findall(r"([-+]?\d+\.\d+) ± (\d+\.\d+)", line)]


def test_calibration_equals_the_cli_and_keeps_its_history(cli, drive, tmp_path):
    gnss = drive / "gnss.csv"
    out = cli(
        "nav", "--imu", drive / "imu.txt", "--gnss", gnss, "--gnss-vel", gnss,
        "--init-pos", "45.07,7.68,245", "--init-att", "0,0,10", "--imu-grade", "tactical",
        "--output-rate", "1", "--no-report", "--estimate-lever-arm", "1 m",
        "--estimate-gnss-time-offset", "0.5 s", "--out", tmp_path,
    )
    r = schuler.navigate(drive / "imu.txt", gnss=gnss, gnss_vel=str(gnss), imu_grade="tactical", output_rate=1, **PRIORS, **START)
    c = r.summary["calibration"]
    lever = printed(out, "lever arm estimated: ")
    (tau,) = printed(out, "GNSS time offset estimated: ")
    # Half a unit of the printed decimal (3 for the lever arm, 4 for the offset),
    # plus its double rounding.
    for k, (value, std) in enumerate(lever):
        assert abs(c["lever_arm_m"][k] - value) <= 0.5e-3 * 1.001
        assert abs(c["lever_arm_std_m"][k] - std) <= 0.5e-3 * 1.001
    assert abs(c["gnss_time_offset_s"] - tau[0]) <= 0.5e-4 * 1.001
    assert abs(c["gnss_time_offset_std_s"] - tau[1]) <= 0.5e-4 * 1.001
    for k, truth in enumerate([0.5, 0.0, -1.0]):
        assert abs(c["lever_arm_m"][k] - truth) < 3 * c["lever_arm_std_m"][k]
    assert abs(c["gnss_time_offset_s"]) < 3 * c["gnss_time_offset_std_s"]
    assert len(c["lever_arm_observed"]) == 3 and isinstance(c["gnss_time_offset_observed"], bool)

    h = c["history"]
    t = np.asarray(h["t_s"])
    assert len(t) > 1000 and (np.diff(t) > 0).all()
    for name in ["lever_arm_x", "lever_arm_y", "lever_arm_z", "gnss_time_offset"]:
        unit = "_s" if name.startswith("gnss") else "_m"
        value, std = np.asarray(h[name + unit]), np.asarray(h[name + "_std" + unit])
        assert value.shape == t.shape and std.shape == t.shape
        # Non-increasing, to the rounding of the covariance update (1e-12 relative).
        assert (np.diff(std) <= 1e-12 * std[:-1]).all(), name
    # Down to the end's (the updates after the last snapshot).
    assert c["lever_arm_std_m"][0] <= h["lever_arm_x_std_m"][-1]
    assert c["gnss_time_offset_std_s"] <= h["gnss_time_offset_std_s"][-1]


def test_no_calibration_no_dict(drive):
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.csv", output_rate=1, **START)
    assert r.summary["calibration"] == {}
