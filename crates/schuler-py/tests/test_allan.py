"""`allan` against `schuler allan`'s allan.csv on a simulated static log (shortest
round-trip numbers: equal), and the white-noise slope of the curve against theory: an
angle random walk N gives sigma(tau) = N / sqrt(tau), so the deviation at the shortest
cluster times falls with slope -1/2 on log-log axes (tactical preset, 0.1 deg/sqrt(h);
the fitted slope over the first decade within 0.05 of -0.5, the noise of a 20-min log)."""

import numpy as np
import pandas as pd

import schuler
from conftest import REPO

STATIC = """
seed = 3
earth = "wgs84"
[start]
time = 0.0
position = ["45 deg", "7 deg", "200 m"]
attitude = ["0 deg", "0 deg", "0 deg"]
[[motion]]
type = "hold"
duration = "1200 s"
[imu]
rate_hz = 100
preset = "tactical"
"""


def test_allan_equals_the_cli(cli, tmp_path):
    scenario = tmp_path / "static.toml"
    scenario.write_text(STATIC)
    cli("simulate", "--config", scenario, "--out", tmp_path / "sim")
    cli("allan", tmp_path / "sim" / "imu.txt", "--out", tmp_path / "allan")
    ref = pd.read_csv(tmp_path / "allan" / "allan.csv")
    a = schuler.allan(tmp_path / "sim" / "imu.txt")
    np.testing.assert_array_equal(a["tau_s"], ref["tau_s"])
    np.testing.assert_array_equal(a["m"], ref["m"])
    for ch, unit in [("gyro_x", "radps"), ("gyro_z", "radps"), ("accel_y", "mps2")]:
        cli_unit = "rad_s" if unit == "radps" else "m_s2"
        np.testing.assert_array_equal(a[f"{ch}_{unit}"], ref[f"{ch}_{cli_unit}"])
    # From a table: the same curve.
    sim = schuler.simulate(STATIC)
    b = schuler.allan(sim.imu)
    pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-12)
    first = a[a["tau_s"] <= 10 * a["tau_s"].iloc[0]]
    slope = np.polyfit(np.log(first["tau_s"]), np.log(first["gyro_x_radps"]), 1)[0]
    assert abs(slope + 0.5) < 0.05, slope
