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


def test_allan_fits_equal_the_cli(cli, tmp_path):
    """`allan_fit` against `schuler allan`'s files and stdout: allan.csv (shortest
    round-trip numbers: equal), imu_noise.toml and the printed tables (equal text);
    the log's true white noise (the tactical preset's 0.1 deg/sqrt(h) and 0.05
    m/s/sqrt(h)) against each axis' fitted N."""
    scenario = tmp_path / "static.toml"
    scenario.write_text(STATIC)
    cli("simulate", "--config", scenario, "--out", tmp_path / "sim")
    imu = tmp_path / "sim" / "imu.txt"
    out = cli("allan", imu, "--out", tmp_path / "allan")
    f = schuler.allan_fit(imu)
    ref = pd.read_csv(tmp_path / "allan" / "allan.csv")
    assert f.curves.shape == ref.shape
    names = [c.replace("rad_s", "radps").replace("m_s2", "mps2") for c in ref.columns]
    assert list(f.curves.columns) == names
    np.testing.assert_array_equal(f.curves.to_numpy(), ref.to_numpy())
    assert f.noise_toml == (tmp_path / "allan" / "imu_noise.toml").read_text()
    assert out.startswith(f.report), (f.report, out)
    assert f.warnings == []
    n = f.fits[(f.fits["model"] == "ieee952") & (f.fits["term"] == "N")]
    assert len(n) == 6
    truth = np.where(n["channel"].str.startswith("gyro"), np.radians(0.1) / 60.0, 0.05 / 60.0)
    # Within 2 %: four times the 95 % interval's half width (about 0.5 % on this
    # 20-min log), so that none of the six axes misses by chance.
    assert (np.abs(n["value"] / truth - 1) < 0.02).all(), (n, truth)
    gm = f.fits[f.fits["model"] == "gauss_markov"]
    assert set(gm["term"]) >= {"N", "sigma", "K"}
    # From the simulated table: the same curves and fits (the path's name apart).
    g = schuler.allan_fit(schuler.simulate(STATIC).imu)
    pd.testing.assert_frame_equal(g.curves, f.curves, check_exact=False, rtol=1e-12)
    assert "<imu array>" in g.noise_toml
