"""`simulate` against `schuler simulate`'s files of the same scenario (the IMU file
holds shortest round-trip numbers: equal bit for bit; the truth and GNSS files round
to their printed decimals), the same seed giving the same bits from TOML text, a file
and a dict; `compare` against `schuler compare`'s compare.json and errors.csv
(shortest round-trip numbers: equal)."""

import json
import pathlib
import tomllib

import numpy as np
import pandas as pd
import pytest

import schuler
from conftest import REPO, START

DRIVE = REPO / "examples" / "drive.toml"


@pytest.fixture(scope="module")
def sim():
    return schuler.simulate(DRIVE)


def test_simulate_equals_the_cli_files(sim, drive):
    imu = schuler.read_imu(drive / "imu.txt")
    assert len(sim.imu) == len(imu)
    # Every increment and time exactly. The intervals: the simulator's exact 5 ms
    # against the file's differences of time tags (round-off of t up to 1100 s,
    # 2.3e-13 per ulp: within 1e-12).
    pd.testing.assert_frame_equal(sim.imu.drop(columns="dt_s"), imu.drop(columns="dt_s"), check_exact=True)
    np.testing.assert_allclose(sim.imu["dt_s"], imu["dt_s"], rtol=0, atol=1e-12)
    truth = np.loadtxt(drive / "truth.nav")[:, 1:]
    decimals = np.array([6, 11, 11, 6, 6, 6, 6, 9, 9, 9], dtype=float)
    diff = np.abs(sim.truth.iloc[:, :10].to_numpy() - truth)
    assert (diff <= 0.5 * 10 ** -decimals * 1.001).all()
    gnss = pd.read_csv(drive / "gnss.csv")
    np.testing.assert_array_equal(sim.gnss["t_s"], gnss["t"])
    np.testing.assert_array_equal(sim.gnss[["lat_deg", "lon_deg", "h_m"]].to_numpy(), gnss[["lat_deg", "lon_deg", "h_m"]].to_numpy())
    np.testing.assert_array_equal(sim.baro["h_m"], pd.read_csv(drive / "baro.csv")["h_m"])
    err = np.loadtxt(drive / "imu_err_truth.txt")
    assert (np.abs(sim.sensor_errors.to_numpy() - err) <= 0.5e-6 * 1.001).all()


def test_same_scenario_same_bits(sim):
    text = DRIVE.read_text()
    from_text = schuler.simulate(text)
    pd.testing.assert_frame_equal(from_text.imu, sim.imu, check_exact=True)
    as_dict = tomllib.loads(text)
    from_dict = schuler.simulate(as_dict)
    pd.testing.assert_frame_equal(from_dict.gnss, sim.gnss, check_exact=True)
    assert "seed = 7" in sim.scenario
    as_dict["seed"] = 8
    other = schuler.simulate(as_dict)
    assert not np.array_equal(other.imu["dvel_x_mps"], sim.imu["dvel_x_mps"])


def test_simulate_then_navigate_in_memory(sim):
    """Navigate the simulated data without a file, against the simulation's truth: in
    the 60-s outage below half the tactical accelerometer bias's drift, ½ (1 mg)
    (60 s)² = 17.7 m (what the filter would leave knowing nothing of the bias); with
    GNSS (0.5 m, 1 m std) within 2 m."""
    r = schuler.navigate(sim.imu, gnss=sim.gnss, baro=sim.baro, output_rate=1, lever_arm=(0.5, 0, -1), **START)
    c = schuler.compare(r.trajectory, sim.truth.iloc[:, :10], outages=[(400, 460)])
    assert c.summary["epochs"]["matched"] == len(r.trajectory)
    inside = c.errors.query("400 < t_s <= 460")["horizontal_m"]
    outside = c.errors.query("t_s <= 400 or t_s > 470")["horizontal_m"]
    assert inside.max() < 17.7 / 2, inside.max()
    assert outside.max() < 2.0, outside.max()
    assert c.summary["outages"][0]["max_horizontal_m"] == c.errors.query("400 < t_s <= 460")["horizontal_m"].max()


def test_compare_equals_the_cli(cli, drive, tmp_path):
    nav_out = tmp_path / "nav"
    cli("nav", "--imu", drive / "imu.txt", "--gnss", drive / "gnss.txt", "--init-pos", "45.07,7.68,245", "--init-att", "0,0,10", "--output-rate", "1", "--no-report", "--out", nav_out)
    cmp_out = tmp_path / "cmp"
    cli("compare", nav_out / "nav.txt", drive / "truth.nav", "--outages", "400-460", "--out", cmp_out)
    c = schuler.compare(nav_out / "nav.txt", drive / "truth.nav", outages=[(400, 460)])
    ref = json.loads((cmp_out / "compare.json").read_text())
    assert c.summary == ref
    errors = pd.read_csv(cmp_out / "errors.csv")
    np.testing.assert_array_equal(c.errors.iloc[:, :11].to_numpy(), errors.iloc[:, :11].to_numpy())
    with pytest.raises(schuler.SchulerError):
        schuler.compare(nav_out / "nav.txt", drive / "truth.nav", start=1e6)


def test_fixes_without_simulated_velocity_have_none(sim):
    """A scenario without `velocity_std` measures no velocity: its fixes' velocity
    columns are NaN (as a file without them reads), so they aid by position alone;
    with it, the velocity is measured and kept."""
    assert sim.gnss["vn_mps"].notna().all() and (sim.gnss["std_vn_mps"] > 0).all()
    text = "\n".join(l for l in DRIVE.read_text().splitlines() if not l.startswith("velocity_std"))
    no_vel = schuler.simulate(text)
    assert no_vel.gnss[["vn_mps", "std_vd_mps"]].isna().all().all()
    r = schuler.navigate(no_vel.imu, gnss=no_vel.gnss, output_rate=1, end=300.0, **START)
    c = r.summary["counts"]
    assert c["gnss_position"] > 200 and c["gnss_velocity"] == 0


def test_gnss_without_velocity_std_has_no_velocity(cli, tmp_path):
    """A receiver simulated without `velocity_std` measures no velocity: `gnss.csv`
    has no velocity columns and the Python table NaN velocities (so both aid by
    position only); the positions are the same numbers."""
    text = (
        'seed = 3\n[start]\nposition = ["30.5 deg", "114.3 deg", "50 m"]\n'
        'attitude = ["0 deg", "0 deg", "30 deg"]\n[[motion]]\ntype = "hold"\nduration = "10 s"\n'
        '[imu]\nrate_hz = 100\npreset = "tactical"\n'
        '[gnss]\nrate_hz = 1\nposition_std = ["0.5 m", "0.5 m", "1 m"]\n'
    )
    (tmp_path / "s.toml").write_text(text)
    cli("simulate", "--config", tmp_path / "s.toml", "--out", tmp_path / "out")
    csv = pd.read_csv(tmp_path / "out" / "gnss.csv")
    assert list(csv.columns) == ["t", "lat_deg", "lon_deg", "h_m", "std_n_m", "std_e_m", "std_d_m", "outlier"]
    sim = schuler.simulate(text)
    assert sim.gnss[list(schuler.GNSS_VELOCITY)].isna().all().all()
    np.testing.assert_array_equal(sim.gnss[["t_s", "lat_deg", "lon_deg", "h_m"]].to_numpy(), csv[["t", "lat_deg", "lon_deg", "h_m"]].to_numpy())
