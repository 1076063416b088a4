"""`navigate` against `schuler nav` on the same files: every table equal to the CLI's
files to the last printed digit (a difference of at most half a unit of the last
decimal, plus the double rounding of that half: 1e-3 of it); shortest round-trip
numbers (innovations.csv, rejected.csv) exactly. Arrays in place of files give the
same bits (GNSS tables of `read_gnss` too); the result against the simulation's truth stays within the README's
bounds for this drive."""

import numpy as np
import pandas as pd
import pytest

import schuler
from conftest import START

#: nav.txt's decimals after week and time: lat, lon 1e-11 deg; h, v 1e-6; angles 1e-9 deg.
NAV_DECIMALS = [6, 11, 11, 6, 6, 6, 6, 9, 9, 9]


def assert_printed(frame: pd.DataFrame, path, decimals, skip_columns=0):
    """`frame` equals the text file `path` to its printed decimals."""
    text = np.loadtxt(path)[:, skip_columns:]
    assert text.shape == frame.shape, (text.shape, frame.shape)
    half = 0.5 * 10.0 ** -np.asarray(decimals, dtype=float) * 1.001
    diff = np.abs(frame.to_numpy() - text)
    # Yaw printed as 360.0 rounds to 0 in [0, 360).
    assert (diff <= half).all(), diff.max(axis=0) / half


def run_cli(cli, drive, out, *extra):
    cli("nav", "--imu", drive / "imu.txt", "--init-pos", "45.07,7.68,245", "--init-att", "0,0,10", "--out", out, *extra)


def test_free_inertial_equals_the_cli(cli, drive, tmp_path):
    run_cli(cli, drive, tmp_path, "--output-rate", "10")
    r = schuler.navigate(drive / "imu.txt", output_rate=10, **START)
    assert_printed(r.trajectory, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    assert r.std.empty and r.innovations.empty and r.smoothed is None


def test_aided_tables_equal_the_cli(cli, drive, tmp_path):
    flags = ["--gnss", drive / "gnss.txt", "--baro", drive / "baro.csv", "--output-rate", "10", "--smooth", "--gate", "0.3", "--scale-factors", "--lever-arm", "0.1,0,-0.2"]
    run_cli(cli, drive, tmp_path, *flags, "--no-report")
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", baro=drive / "baro.csv", output_rate=10, smooth=True, gate=0.3, scale_factors=True, lever_arm=(0.1, 0, -0.2), **START)
    assert_printed(r.trajectory, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    assert_printed(r.std, tmp_path / "std.txt", [6] + [9] * 21)
    assert_printed(r.sensor_errors, tmp_path / "imu_err.txt", [6] + [9] * 12)
    assert_printed(r.smoothed.iloc[:, :10], tmp_path / "smoothed" / "nav.txt", NAV_DECIMALS, skip_columns=1)
    inn = pd.read_csv(tmp_path / "innovations.csv")
    assert list(r.innovations["kind"]) == list(inn["kind"])
    np.testing.assert_array_equal(r.innovations["accepted"].to_numpy(), inn["accepted"].to_numpy() == 1)
    for a, b in [("t_s", "t"), ("nis", "nis"), ("z_1", "z_1"), ("z_3", "z_3"), ("sigma_2", "sigma_2")]:
        np.testing.assert_array_equal(r.innovations[a].to_numpy(), inn[b].to_numpy())
    rej = pd.read_csv(tmp_path / "rejected.csv")
    assert len(rej) > 100, "the tight gate refuses measurements"
    np.testing.assert_array_equal(r.refused["t_s"], rej["t"])
    assert list(r.refused["measurement"]) == list(rej["measurement"])
    assert list(r.refused["reason"]) == list(rej["reason"])
    np.testing.assert_array_equal(r.refused["nis"], rej["nis"])
    c = r.summary["counts"]
    assert c["rejected"] == (rej["reason"] == "chi-square gate").sum()
    assert c["gnss_position"] + c["baro_height"] + c["rejected"] == len(inn)


def test_smoothed_std_equals_the_cli(cli, drive, tmp_path):
    run_cli(cli, drive, tmp_path, "--gnss", drive / "gnss.txt", "--output-rate", "1", "--smooth", "--no-report")
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", output_rate=1, smooth=True, **START)
    std = np.loadtxt(tmp_path / "smoothed" / "std.txt")[:, :10]
    frame = r.smoothed[["t_s"] + [c for c in r.smoothed.columns if c.startswith("std_")]]
    diff = np.abs(frame.to_numpy() - std)
    assert (diff <= 0.5e-6 * 1.001).all() and (diff[:, 1:] <= 0.5e-9 * 1.001).all()


def test_arrays_give_the_files_bits(drive):
    kw = dict(output_rate=10, **START)
    ref = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", **kw)
    imu = schuler.read_imu(drive / "imu.txt")
    from_frame = schuler.navigate(imu, gnss=drive / "gnss.txt", **kw)
    pd.testing.assert_frame_equal(from_frame.trajectory, ref.trajectory, check_exact=True)
    # The KF-GINS layout as a plain array, in C and in Fortran order (a strided view).
    a = np.loadtxt(drive / "imu.txt")
    for arr in (a, np.asfortranarray(a)):
        r = schuler.navigate(arr, gnss=drive / "gnss.txt", **kw)
        pd.testing.assert_frame_equal(r.trajectory, ref.trajectory, check_exact=True)
    # GNSS as read_gnss's table: its degrees convert back to the reader's radians.
    g = schuler.navigate(imu, gnss=schuler.read_gnss(drive / "gnss.txt"), **kw)
    pd.testing.assert_frame_equal(g.trajectory, ref.trajectory, check_exact=True)


def test_against_the_truth(drive):
    """The simulation's truth (an independent trajectory generator) bounds the errors:
    GNSS 0.5 m noise, a 60-s outage with a tactical IMU: the README's example drive has
    at most 5.01 m in its outage; 6 m allows for this run's defaults."""
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", output_rate=1, **START)
    truth = schuler.read_nav(drive / "truth.nav")
    t = r.trajectory.merge(truth, on="t_s", suffixes=("", "_true"))
    assert len(t) == len(r.trajectory)
    north = np.radians(t["lat_deg"] - t["lat_deg_true"]) * 6.371e6
    east = np.radians(t["lon_deg"] - t["lon_deg_true"]) * 6.371e6 * np.cos(np.radians(t["lat_deg_true"]))
    horizontal = np.hypot(north, east)
    assert horizontal.max() < 6.0, horizontal.max()
    assert 0.5 < r.summary["mean_nis_per_dof"] < 2.0


def push_gnss(s, gnss):
    """Pushes the fixes of a `read_gnss` table (positions) into session `s`."""
    for row in gnss.itertuples():
        s.push_gnss(row.t_s, row.lat_deg, row.lon_deg, row.h_m, (row.std_n_m, row.std_e_m, row.std_d_m))


def push_imu_and_finish(s, imu, singly=1000):
    """Pushes the `read_imu` table `imu` into session `s`, its first `singly` samples
    one by one (the first with its interval), the rest as one block, taking the tables
    in between, and finishes it: the trajectory and the standard deviations of both
    takes joined, and the finished result."""
    head, tail = imu.iloc[:singly], imu.iloc[singly:]
    for row in head.itertuples():
        s.push_imu(row.t_s, (row.dtheta_x_rad, row.dtheta_y_rad, row.dtheta_z_rad), (row.dvel_x_mps, row.dvel_y_mps, row.dvel_z_mps), dt=row.dt_s if row.Index == 0 else None)
    first = s.take()
    s.push_imu_block(tail.drop(columns="dt_s"))
    rest = s.finish()
    joined = [pd.concat([getattr(first, k), getattr(rest, k)], ignore_index=True) for k in ("trajectory", "std")]
    return joined[0], joined[1], rest


def test_session_pushes_equal_navigate(drive):
    kw = dict(output_rate=10, end=300.0, **START)
    imu = schuler.read_imu(drive / "imu.txt", end=300.0)
    gnss = schuler.read_gnss(drive / "gnss.txt")
    gnss = gnss[gnss["t_s"] <= 300.0]
    ref = schuler.navigate(imu, gnss=gnss, **kw)
    s = schuler.Session(gnss=True, **kw)
    push_gnss(s, gnss)
    traj, _, rest = push_imu_and_finish(s, imu)
    pd.testing.assert_frame_equal(traj, ref.trajectory, check_exact=True)
    assert rest.summary == ref.summary
    with pytest.raises(schuler.SchulerError, match="finished"):
        s.finish()
