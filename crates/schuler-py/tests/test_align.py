"""`align` against `schuler align` on a simulated log at rest (align.json and
align_convergence.csv hold shortest round-trip numbers: equal exactly; the report is
what the CLI prints before its run times), arrays giving the file's bits, and the
result against the simulation's true attitude; `navigate(align=True)` and
`navigate(init="gnss" | "gnss-any-heading")` against `schuler nav --align` /
`--init` on the same files (nav.txt to its printed digits, align.json exactly)."""

import json

import numpy as np
import pandas as pd
import pytest

import schuler
from conftest import START
from test_navigate import NAV_DECIMALS, assert_printed

#: The base: 45 deg N, 7 deg E, 200 m; the IMU rolled 1 deg, pitched -0.5 deg,
#: heading 60 deg; navigation grade at 100 Hz, 15 minutes at rest.
BASE = (45.0, 7.0, 200.0)
TRUE_ATT = (1.0, -0.5, 60.0)
AT_REST = f"""
seed = 11
earth = "wgs84"
[start]
time = 0.0
position = ["{BASE[0]} deg", "{BASE[1]} deg", "{BASE[2]} m"]
attitude = ["{TRUE_ATT[0]} deg", "{TRUE_ATT[1]} deg", "{TRUE_ATT[2]} deg"]
[[motion]]
type = "hold"
duration = "900 s"
[imu]
rate_hz = 100
preset = "navigation"
"""

#: The stages: coarse 190 s, fine 600 s (the log's first 790 s).
STAGES = dict(coarse="190 s", fine="600 s")


@pytest.fixture(scope="module")
def at_rest(cli, tmp_path_factory):
    """The log at rest simulated by the CLI: its folder."""
    d = tmp_path_factory.mktemp("rest")
    (d / "rest.toml").write_text(AT_REST)
    cli("simulate", "--config", d / "rest.toml", "--out", d / "sim")
    return d / "sim"


def test_align_equals_the_cli(cli, at_rest, tmp_path):
    out = cli("align", "--imu", at_rest / "imu.txt", "--pos", "45,7,200", "--coarse", "190 s", "--fine", "600 s", "--out", tmp_path)
    a = schuler.align(at_rest / "imu.txt", pos=BASE, **STAGES)
    assert a.summary == json.loads((tmp_path / "align.json").read_text())
    ref = pd.read_csv(tmp_path / "align_convergence.csv")
    assert len(ref) > 100
    assert list(a.convergence.columns) == ["t_s"] + [c.replace("_dph", "_degph") for c in ref.columns[1:]]
    np.testing.assert_array_equal(a.convergence.to_numpy(), ref.to_numpy())
    assert a.report and out.startswith(a.report), (a.report, out)
    assert "run time" in out and "run time" not in a.report
    # The same samples as a table: the same bits.
    b = schuler.align(schuler.read_imu(at_rest / "imu.txt"), pos=BASE, **STAGES)
    assert b.summary == a.summary
    pd.testing.assert_frame_equal(b.convergence, a.convergence, check_exact=True)


def test_align_reaches_the_true_attitude(at_rest):
    """The simulation's attitude is the truth: each angle within 4 of its standard
    deviations (a 6e-5 chance for a consistent filter to miss, per angle)."""
    a = schuler.align(at_rest / "imu.txt", pos=BASE, **STAGES)
    err = np.subtract(a.attitude_deg, TRUE_ATT)
    err[2] = (err[2] + 180.0) % 360.0 - 180.0
    assert (np.abs(err) < 4 * np.asarray(a.attitude_std_deg)).all(), (err, a.attitude_std_deg)
    # Navigation grade at 45 deg: heading to better than 0.1 deg, level to 0.01 deg.
    assert a.attitude_std_deg[2] < 0.1 and max(a.attitude_std_deg[:2]) < 0.01


def test_align_options_are_the_cli_checks(at_rest):
    with pytest.raises(schuler.SchulerError, match="block"):
        schuler.align(at_rest / "imu.txt", pos=BASE, coarse="10 s", block="20 s")
    with pytest.raises(TypeError, match="^unknown option `no_such_option`$"):
        schuler.align(at_rest / "imu.txt", pos=BASE, no_such_option=1)


def test_navigate_after_alignment_equals_the_cli(cli, at_rest, tmp_path):
    cli("nav", "--imu", at_rest / "imu.txt", "--align", "--init-pos", "45,7,200", "--coarse", "190 s", "--fine", "600 s", "--output-rate", "1", "--out", tmp_path)
    r = schuler.navigate(at_rest / "imu.txt", align=True, init_pos=BASE, output_rate=1, **STAGES)
    assert_printed(r.trajectory, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    assert r.alignment.summary == json.loads((tmp_path / "align.json").read_text())
    assert r.start_in_motion is None
    # At rest after the alignment: 110 s of free inertial from the aligned state
    # stay within a few metres (the closed forms: a 50 ug residual bias gives
    # 0.5 * 5e-4 * 110^2 = 3 m; 10 m bounds it).
    north = np.radians(r.trajectory["lat_deg"] - BASE[0]) * 6.37e6
    assert np.abs(north).max() < 10.0


@pytest.mark.parametrize("init", ["gnss", "gnss-any-heading"])
def test_start_from_the_fixes_equals_the_cli(cli, drive, tmp_path, init):
    cli("nav", "--init", init, "--imu", drive / "imu.txt", "--gnss", drive / "gnss.txt", "--lever-arm", "0.5,0,-1", "--imu-grade", "tactical", "--output-rate", "1", "--no-report", "--out", tmp_path)
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", init=init, lever_arm=(0.5, 0, -1), imu_grade="tactical", output_rate=1)
    assert_printed(r.trajectory, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    assert_printed(r.std, tmp_path / "std.txt", [6] + [9] * 21)
    m = r.start_in_motion
    assert r.alignment is None and m["t_s"] >= r.trajectory["t_s"].iloc[0]
    # The same fixes as a table.
    t = schuler.navigate(drive / "imu.txt", gnss=schuler.read_gnss(drive / "gnss.txt"), init=init, lever_arm=(0.5, 0, -1), imu_grade="tactical", output_rate=1)
    pd.testing.assert_frame_equal(t.trajectory, r.trajectory, check_exact=True)


def test_a_session_refuses_starts_it_cannot_make():
    with pytest.raises(schuler.SchulerError, match="navigate"):
        schuler.Session(align=True, init_pos=START["init_pos"])
