"""`channel` against `schuler channel`'s errors.csv (shortest round-trip numbers:
equal) and summary.json; `closed_form` against the channel's closed-form columns and
against the closed forms' own properties (SEEDS.md (18)-(23), (32)): zero at t = 0,
the Schuler period 2 pi sqrt(a/g) = 84.4 min, the gyro drift's mean position slope
-a nu (0.31 m/s for 0.01 deg/h), the bias cancelled by the tilt it levels to
(g alpha0 = df), and the vertical channel's e-fold time 1/(sqrt(2) omega0) = 570 s."""

import json

import numpy as np
import pandas as pd
import pytest

import schuler

A, G = 6.371e6, 9.81
W0 = np.sqrt(G / A)
T0 = 2 * np.pi / W0


def test_channel_equals_the_cli(cli, tmp_path):
    cli("channel", "--system", "sins", "--accel-bias-p2", "1e-3m/s^2", "--gyro-drift", "0.01deg/h", "--turn", "1h:180deg", "--duration", "3h", "--out", tmp_path)
    r = schuler.channel(system="sins", accel_bias_p2="1e-3m/s^2", gyro_drift="0.01deg/h", turn=["1h:180deg"], duration="3h")
    ref = pd.read_csv(tmp_path / "errors.csv")
    assert r.errors.shape == ref.shape and len(ref) > 10000
    np.testing.assert_array_equal(r.errors.to_numpy(), ref.to_numpy())
    assert r.summary == json.loads((tmp_path / "summary.json").read_text())


def test_closed_form_equals_the_channel_and_its_period():
    r = schuler.channel(accel_bias="1e-3m/s^2", duration="4h")
    g = r.summary["linear_model_g_m_s2"]
    c = schuler.closed_form(r.errors["t_s"], accel_bias=1e-3, g=g)
    for q, closed in [("dr_m", "dr_closed_m"), ("dv_mps", "dv_closed_mps"), ("alpha_rad", "alpha_closed_rad")]:
        np.testing.assert_array_equal(c[q].to_numpy(), r.errors[closed].to_numpy())
    # The nonlinear system's measured period is the closed form's: 84.4 min.
    assert abs(r.summary["schuler_period_s"]["measured"] / 60.0 - 84.4) < 0.05
    assert abs(T0 / 60.0 - 84.39) < 0.01


def test_closed_form_properties():
    t = np.linspace(0.0, 4 * T0, 4001)
    drift = np.radians(0.01) / 3600.0
    c = schuler.closed_form(t, accel_bias=1e-3, drift=drift, alpha0=2e-5, dv0=1.0, dr0=100.0)
    # At t = 0: the initial errors alone.
    first = c.iloc[0]
    assert first["dr_m"] == pytest.approx(100.0, abs=1e-9)
    assert first["dv_mps"] == pytest.approx(1.0, abs=1e-12)
    assert first["alpha_rad"] == pytest.approx(2e-5, abs=1e-15)
    zero = schuler.closed_form(t)
    assert (zero[["dr_m", "dv_mps", "alpha_rad", "dh_m", "dvh_mps"]].to_numpy() == 0).all()
    # Periodic with T0 but for the drift's linear position term (22): over one period
    # the position moves by -a nu T0 (0.31 m/s), velocity and vertical return.
    at = schuler.closed_form([0.0, T0, 2 * T0], drift=drift)
    slope = (at["dr_m"].iloc[2] - at["dr_m"].iloc[1]) / T0
    assert slope == pytest.approx(-A * drift, rel=1e-9) and abs(A * drift - 0.309) < 0.001
    np.testing.assert_allclose(at["dv_mps"], 0.0, atol=1e-15)
    np.testing.assert_allclose(at["alpha_rad"], 0.0, atol=1e-18)
    # The initial velocity error (23): dV = dV0 cos(w0 t); its zero crossings half a
    # period apart (rate of the grid: 4 T0 / 4000, so within 2 steps).
    v = schuler.closed_form(t, dv0=1.0)["dv_mps"].to_numpy()
    crossings = t[1:][np.sign(v[1:]) != np.sign(v[:-1])]
    assert np.allclose(np.diff(crossings), T0 / 2, atol=2 * t[1])
    # A platform leveled with a biased accelerometer: alpha0 = df/g cancels the bias
    # for all later time (20) + (21).
    # (the platform stays tilted by alpha0 = df/g, and no error grows).
    cancel = schuler.closed_form(t, accel_bias=1e-3, alpha0=1e-3 / G)
    assert np.abs(cancel[["dr_m", "dv_mps"]].to_numpy()).max() < 1e-9
    np.testing.assert_allclose(cancel["alpha_rad"], 1e-3 / G, rtol=1e-12)
    # The free vertical channel (32): grows by e every 1/(sqrt(2) w0) = 570 s.
    tau = 1.0 / (np.sqrt(2) * W0)
    assert abs(tau - 570.0) < 1.0
    h = schuler.closed_form([10 * tau, 11 * tau], dh0=1.0)["dh_m"].to_numpy()
    assert h[1] / h[0] == pytest.approx(np.e, rel=1e-8)


def test_bad_values_are_refused():
    with pytest.raises(schuler.SchulerError, match="radius"):
        schuler.closed_form([0.0], radius=-1.0)
    with pytest.raises(schuler.SchulerError, match=r"t\[1\]"):
        schuler.closed_form([0.0, np.nan])
    with pytest.raises(schuler.SchulerError, match="accel_bias_p1 applies to system sins"):
        schuler.channel(accel_bias_p1="1e-3m/s^2")
