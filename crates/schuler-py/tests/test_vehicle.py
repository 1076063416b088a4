"""The vehicle aids from Python (odometer, dual-antenna heading, rest intervals):
`navigate(..., odometer=, heading=, rest=)` from tables and `Session` pushes, each
against `schuler nav` on the same files (`--odometer`, `--dual-antenna`, `--zupt`) to
the last printed digit, and bad values raising exceptions that name the field.

The readings come from the simulator's truth of the README's example drive (as
crates/schuler-cli/tests/vehicle_cli.rs makes them): the forward speed at 10 Hz with
a 0.3 % scale error and 0.05 m/s noise, the heading of an antenna baseline pointing
right at 1 Hz with 0.1 deg noise, and the 60-s wait as a rest interval; seeded, and
written to the files in shortest round-trip form, so the files and the tables hold
the same numbers."""

import numpy as np
import pandas as pd
import pytest

import schuler
from conftest import START
from test_navigate import NAV_DECIMALS, assert_printed, push_gnss, push_imu_and_finish

#: Flags of every run here: the drive's lever arm and IMU grade, every vehicle aid's
#: options (the odometer's scale factor estimated, the NHC, zero-rate updates at rest,
#: the antenna baseline to the right).
OPTIONS = dict(
    lever_arm=(0.5, 0, -1),
    imu_grade="tactical",
    output_rate=10,
    odometer_std="0.05 m/s",
    odometer_scale_std="1 %",
    nhc=True,
    zaru=True,
    dual_antenna_baseline_yaw=90.0,
    **START,
)


def cli_flags(options):
    """`options` as the CLI's flags (the package's own conversion is under test, so
    this one is written out)."""
    out = []
    for k, v in options.items():
        flag = "--" + k.replace("_", "-")
        if v is True:
            out.append(flag)
        else:
            out += [flag, ",".join(map(repr, v)) if isinstance(v, tuple) else str(v)]
    return out


def write(path, frame):
    """`frame` as a text log: one row per line, shortest round-trip numbers."""
    path.write_text("".join(" ".join(repr(float(x)) for x in row) + "\n" for row in frame.to_numpy()))
    return path


@pytest.fixture(scope="module")
def logs(drive, tmp_path_factory):
    """The vehicle logs of the drive as tables and as files."""
    truth = schuler.read_nav(drive / "truth.nav")
    roll, pitch, yaw = (np.radians(truth[c].to_numpy()) for c in ("roll_deg", "pitch_deg", "yaw_deg"))
    vn, ve, vd = (truth[c].to_numpy() for c in ("vn_mps", "ve_mps", "vd_mps"))
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    # Body x (forward) and y (right) in NED: the first two columns of C_bn (Z-Y-X).
    forward = cp * cy * vn + cp * sy * ve - sp * vd
    right_n, right_e = -cr * sy + sr * sp * cy, cr * cy + sr * sp * sy
    rng = np.random.default_rng(1)
    t = truth["t_s"].to_numpy()
    odo = np.arange(0, len(t), 20)
    odometer = pd.DataFrame({"t_s": t[odo], "speed_mps": 1.003 * forward[odo] + 0.05 * rng.standard_normal(len(odo))})
    ant = np.arange(0, len(t), 200)
    heading = pd.DataFrame({
        "t_s": t[ant],
        "heading_deg": np.degrees(np.arctan2(right_e[ant], right_n[ant])) + 0.1 * rng.standard_normal(len(ant)),
        "heading_std_deg": np.full(len(ant), 0.1),
    })
    still = np.hypot(np.hypot(vn, ve), vd) == 0.0
    moving = np.flatnonzero(~still)[0]
    assert moving > 200 * 50, "the drive waits 60 s"
    rest = pd.DataFrame({"t0_s": [t[0]], "t1_s": [t[moving - 1]]})
    folder = tmp_path_factory.mktemp("vehicle")
    files = {name: write(folder / f"{name}.txt", frame) for name, frame in (("odometer", odometer), ("heading", heading), ("rest", rest))}
    return dict(odometer=odometer, heading=heading, rest=rest, files=files)


def run_cli(cli, drive, logs, out, *extra):
    f = logs["files"]
    cli("nav", "--imu", drive / "imu.txt", "--gnss", drive / "gnss.txt", "--odometer", f["odometer"], "--dual-antenna", f["heading"], "--zupt", f["rest"], "--no-report", "--out", out, *cli_flags(OPTIONS), *extra)


def test_navigate_with_vehicle_tables_equals_the_cli(cli, drive, logs, tmp_path):
    run_cli(cli, drive, logs, tmp_path)
    r = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", odometer=logs["odometer"], heading=logs["heading"], rest=logs["rest"], **OPTIONS)
    assert_printed(r.trajectory, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    # 15 states, the odometer's scale factor: std.txt and imu_err.txt as printed.
    assert_printed(r.std, tmp_path / "std.txt", [6] + [9] * (r.std.shape[1] - 1))
    assert_printed(r.sensor_errors, tmp_path / "imu_err.txt", [6] + [9] * (r.sensor_errors.shape[1] - 1))
    inn = pd.read_csv(tmp_path / "innovations.csv")
    assert list(r.innovations["kind"]) == list(inn["kind"])
    for a, b in [("t_s", "t"), ("nis", "nis"), ("z_1", "z_1")]:
        np.testing.assert_array_equal(r.innovations[a].to_numpy(), inn[b].to_numpy())
    c = r.summary["counts"]
    # Every aid was used: the tables reached the filter as the files did.
    assert min(c["odometer"], c["heading"], c["zero_velocity"], c["zero_rate"], c["non_holonomic"]) > 0, c
    # 2-D arrays in the files' column order give the same bits.
    a = schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", odometer=logs["odometer"].to_numpy(), heading=logs["heading"].to_numpy(), rest=logs["rest"].to_numpy(), **OPTIONS)
    pd.testing.assert_frame_equal(a.trajectory, r.trajectory, check_exact=True)


def test_session_vehicle_pushes_equal_the_cli(cli, drive, logs, tmp_path):
    end = 300.0
    run_cli(cli, drive, logs, tmp_path, "--end", str(end))
    kw = dict(OPTIONS, end=end)
    imu = schuler.read_imu(drive / "imu.txt", end=end)
    gnss = schuler.read_gnss(drive / "gnss.txt")
    gnss = gnss[gnss["t_s"] <= end]
    odometer = logs["odometer"][logs["odometer"]["t_s"] <= end]
    heading = logs["heading"][logs["heading"]["t_s"] <= end]
    ref = schuler.navigate(imu, gnss=gnss, odometer=odometer, heading=heading, rest=logs["rest"], **kw)
    s = schuler.Session(gnss=True, odometer=True, heading=True, rest=True, **kw)
    for row in logs["rest"].itertuples():
        s.push_rest(row.t0_s, row.t1_s)
    push_gnss(s, gnss)
    for row in odometer.itertuples():
        s.push_odometer(row.t_s, row.speed_mps)
    for row in heading.itertuples():
        s.push_heading(row.t_s, row.heading_deg, row.heading_std_deg)
    traj, std, rest = push_imu_and_finish(s, imu)
    pd.testing.assert_frame_equal(traj, ref.trajectory, check_exact=True)
    pd.testing.assert_frame_equal(std, ref.std, check_exact=True)
    assert rest.summary == ref.summary
    assert_printed(traj, tmp_path / "nav.txt", NAV_DECIMALS, skip_columns=1)
    assert_printed(std, tmp_path / "std.txt", [6] + [9] * (std.shape[1] - 1))
    c = rest.summary["counts"]
    assert min(c["odometer"], c["heading"], c["zero_velocity"]) > 0, c


def test_bad_vehicle_values_name_the_field(drive, logs):
    a = np.loadtxt(drive / "imu.txt", max_rows=600)
    kw = dict(OPTIONS)

    def refused(**aid):
        with pytest.raises(schuler.InputError) as e:
            schuler.navigate(a, **aid, **kw)
        return e.value

    odo = logs["odometer"].iloc[:10].copy()
    odo.loc[3, "speed_mps"] = 1e5
    e = refused(odometer=odo)
    assert (e.path, e.line, e.field) == ("<odometer array>", 4, "speed_mps")
    assert "escape velocity" in str(e)
    odo = logs["odometer"].iloc[:10].copy()
    odo.loc[5, "t_s"] = odo.loc[4, "t_s"]
    e = refused(odometer=odo)
    assert (e.line, e.field, e.kind) == (6, "t_s", "TimeNotIncreasing")
    hd = logs["heading"].iloc[:5].copy()
    hd.loc[1, "heading_std_deg"] = 0.0
    e = refused(heading=hd)
    assert (e.path, e.line, e.field) == ("<heading array>", 2, "heading_std_deg")
    hd = logs["heading"].iloc[:5].copy()
    hd.loc[2, "heading_deg"] = np.nan
    assert refused(heading=hd).field == "heading_deg"
    e = refused(rest=pd.DataFrame({"t0_s": [10.0], "t1_s": [5.0]}))
    assert (e.path, e.line, e.field) == ("<rest array>", 1, "t1_s")
    with pytest.raises(ValueError, match="pitch_deg and pitch_std_deg go together"):
        schuler.navigate(a, heading=logs["heading"].assign(pitch_deg=0.0), **kw)
    with pytest.raises(ValueError, match="missing column"):
        schuler.navigate(a, odometer=logs["odometer"].rename(columns={"speed_mps": "speed"}), **kw)

    s = schuler.Session(odometer=True, heading=True, rest=True, **kw)
    for push, field in [
        (lambda: s.push_odometer(1.0, np.nan), "speed_mps"),
        (lambda: s.push_heading(1.0, 1000.0, 0.1), "heading_deg"),
        (lambda: s.push_heading(1.0, 10.0, 0.1, pitch_deg=95.0, pitch_std_deg=0.1), "pitch_deg"),
        (lambda: s.push_rest(5.0, 4.0), "t1_s"),
    ]:
        with pytest.raises(schuler.InputError) as e:
            push()
        assert e.value.field == field and e.value.path.endswith(" push>"), (field, e.value)
    # A reading of an aid the session was not set up for is refused, and says why.
    s = schuler.Session(gnss=True, **START)
    s.push_odometer(1.0, 2.0)
    assert list(s.take().refused["reason"]) == ["no odometer in the configuration"]
    # An option of an aid the session was not set up for is the CLI's error.
    with pytest.raises(schuler.SchulerError, match="odometer_std needs odometer"):
        schuler.Session(gnss=True, odometer_std="0.05 m/s", **START)
