"""The readers against numpy's own text parser on the same files (an independent
reader): every value equal, the degrees of GNSS fixes within the round trip through
radians the library keeps them in (1 ulp of an angle near 1 rad, 2e-16 rad, is
1.3e-14 deg: 1e-12 deg leaves room for the longitude's larger value)."""

import numpy as np
import pandas as pd

import schuler


def test_read_imu_equals_the_text(drive):
    imu = schuler.read_imu(drive / "imu.txt")
    text = np.loadtxt(drive / "imu.txt")
    assert list(imu.columns) == ["t_s", "dt_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dvel_x_mps", "dvel_y_mps", "dvel_z_mps"]
    assert len(imu) == len(text)
    np.testing.assert_array_equal(imu["t_s"], text[:, 0])
    np.testing.assert_array_equal(imu.iloc[:, 2:].to_numpy(), text[:, 1:])
    # Each interval is the time since the previous sample; the first, the nominal one
    # (the median of the first intervals: all equal here, 5 ms as the decimal times
    # differ, within an ulp of 0.005).
    np.testing.assert_array_equal(imu["dt_s"].to_numpy()[1:], np.diff(text[:, 0]))
    assert abs(imu["dt_s"][0] - 0.005) <= np.spacing(0.005) * 8


def test_read_imu_csv_and_options(drive):
    txt = schuler.read_imu(drive / "imu.txt", start=100.0, end=200.0)
    csv = schuler.read_imu(drive / "imu.csv", start=100.0, end=200.0)
    pd.testing.assert_frame_equal(txt, csv)
    assert txt["t_s"].min() >= 100.0 and txt["t_s"].max() <= 200.0
    # A 90-deg yaw mounting turns the IMU's x increments into the vehicle's y.
    turned = schuler.read_imu(drive / "imu.txt", imu_rotation=(0, 0, 90), end=10.0)
    plain = schuler.read_imu(drive / "imu.txt", end=10.0)
    np.testing.assert_allclose(turned["dvel_y_mps"], plain["dvel_x_mps"], rtol=0, atol=1e-15)


def test_read_gnss_equals_the_text(drive):
    g = schuler.read_gnss(drive / "gnss.txt")
    text = np.loadtxt(drive / "gnss.txt")
    np.testing.assert_array_equal(g["t_s"], text[:, 0])
    np.testing.assert_allclose(g[["lat_deg", "lon_deg"]].to_numpy(), text[:, 1:3], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(g[["h_m", "std_n_m", "std_e_m", "std_d_m"]].to_numpy(), text[:, 3:7])
    assert g["vn_mps"].isna().all()  # gnss.txt carries no velocity
    # --gnss-time-offset acts on the fixes as in nav.
    shifted = schuler.read_gnss(drive / "gnss.txt", gnss_time_offset="-18 s")
    np.testing.assert_array_equal(shifted["t_s"], text[:, 0] - 18.0)


def test_read_nav_and_baro(drive):
    nav = schuler.read_nav(drive / "truth.nav")
    text = np.loadtxt(drive / "truth.nav")
    np.testing.assert_array_equal(nav["t_s"], text[:, 1])
    np.testing.assert_allclose(nav[["lat_deg", "lon_deg"]].to_numpy(), text[:, 2:4], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(nav[["h_m", "vn_mps", "ve_mps", "vd_mps"]].to_numpy(), text[:, 4:8])
    np.testing.assert_allclose(nav[["roll_deg", "pitch_deg", "yaw_deg"]].to_numpy(), text[:, 8:11], rtol=0, atol=1e-12)
    baro = schuler.read_baro(drive / "baro.csv")
    ref = pd.read_csv(drive / "baro.csv")
    np.testing.assert_array_equal(baro["t_s"], ref["t"])
    np.testing.assert_array_equal(baro["h_m"], ref["h_m"])
