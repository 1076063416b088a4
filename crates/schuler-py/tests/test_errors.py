"""Bad input raises exceptions naming the file (or array), the line (or row) and the
field, with the CLI's words; bad options name the keyword's flag."""

import numpy as np
import pytest

import schuler
from conftest import START


def test_bad_line_in_a_file(drive, tmp_path):
    lines = (drive / "imu.txt").read_text().splitlines()[:500]
    fields = lines[99].split()
    fields[5] = "abc"
    lines[99] = " ".join(fields)
    bad = tmp_path / "bad_imu.txt"
    bad.write_text("\n".join(lines) + "\n")
    for call in (lambda: schuler.read_imu(bad), lambda: schuler.navigate(bad, **START)):
        with pytest.raises(schuler.InputError) as e:
            call()
        assert e.value.path == str(bad)
        assert e.value.line == 100
        assert e.value.field == "dvel_y"
        assert "not a number" in str(e.value) and str(bad) in str(e.value)
        assert isinstance(e.value, ValueError)


def test_time_going_backwards_in_a_gnss_file(drive, tmp_path):
    lines = (drive / "gnss.txt").read_text().splitlines()[:20]
    lines[10], lines[11] = lines[11], lines[10]
    bad = tmp_path / "gnss.txt"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(schuler.InputError) as e:
        schuler.read_gnss(bad)
    assert e.value.line == 12 and e.value.path == str(bad)


def test_bad_values_in_arrays(drive):
    a = np.loadtxt(drive / "imu.txt", max_rows=2000)
    a[1234, 4] = np.nan
    with pytest.raises(schuler.InputError) as e:
        schuler.navigate(a, **START)
    assert (e.value.path, e.value.line, e.value.field) == ("<imu array>", 1235, "dvel_x_mps")
    a = np.loadtxt(drive / "imu.txt", max_rows=2000)
    a[700, 0] = a[699, 0]
    with pytest.raises(schuler.InputError) as e:
        schuler.navigate(a, **START)
    assert (e.value.line, e.value.field, e.value.kind) == (701, "t_s", "TimeNotIncreasing")
    g = schuler.read_gnss(drive / "gnss.txt")
    g.loc[5, "h_m"] = np.inf
    with pytest.raises(schuler.InputError) as e:
        schuler.navigate(a[:600], gnss=g, **START)
    assert (e.value.path, e.value.line, e.value.field) == ("<gnss array>", 6, "h_m")


def test_options_are_the_cli_flags(drive):
    with pytest.raises(TypeError, match="^unknown option `no_such_option`$"):
        schuler.navigate(drive / "imu.txt", no_such_option=1, **START)
    # A misspelt keyword gets the nearest one, as Python names it (no flag, no usage).
    with pytest.raises(TypeError, match=r"^unknown option `lever_arms` \(did you mean `lever_arm`\?\)$"):
        schuler.navigate(drive / "imu.txt", lever_arms=(1, 2, 3), **START)
    with pytest.raises(schuler.SchulerError, match="^option `lever_arm`: invalid length 2"):
        schuler.navigate(drive / "imu.txt", lever_arm=(1, 2), **START)
    with pytest.raises(TypeError, match="^option `lever_arm`: cannot pass a dict"):
        schuler.navigate(drive / "imu.txt", lever_arm={"x": 1}, **START)
    # The textbook's channel and the Allan fit name a misspelt keyword the same way.
    with pytest.raises(TypeError, match=r"^unknown option `gyro_drifts` \(did you mean `gyro_drift`\?\)$"):
        schuler.channel(gyro_drifts="0.01deg/h")
    with pytest.raises(TypeError, match=r"^unknown option `gyro_units` \(did you mean `gyro_unit`\?\)$"):
        schuler.allan_fit(drive / "imu.txt", gyro_units="deg/s")
    with pytest.raises(schuler.SchulerError, match=r"init_pos: latitude 95"):
        schuler.navigate(drive / "imu.txt", init_pos=(95, 0, 0), init_att=(0, 0, 0))
    with pytest.raises(schuler.SchulerError, match="no initial attitude"):
        schuler.navigate(drive / "imu.txt", init_pos=(45, 7, 0))
    with pytest.raises(schuler.SchulerError, match="arw"):
        schuler.navigate(drive / "imu.txt", gnss=drive / "gnss.txt", arw="0.1 m", **START)
    with pytest.raises(schuler.SchulerError, match="no IMU sample"):
        schuler.navigate(drive / "imu.txt", start=1e6, end=2e6, **START)
