#!/usr/bin/env python3
"""Cross-check of schuler's PX4 ULog reader against pyulog, PX4's own ULog decoder.

For each file, every record schuler reads (the `ulog_dump` example: one CSV line per
record) is compared with the record built here from the topics pyulog
(https://github.com/PX4/pyulog) decodes from the same file, by the conversions the
reader's documentation gives (crates/schuler-io/src/logs/ulog/topics.rs and clock.rs):

- sensor_combined: increments gyro_rad * gyro_integral_dt and accelerometer_m_s2 *
  accelerometer_integral_dt (µs if an integer type, s if a float), samples without
  accelerometer data (relative timestamp 0x7fffffff) or with a zero interval left out;
- the GNSS topic (vehicle_gps_position if the log defines it, else sensor_gps): 3-D
  fixes only, position in 1e-7 deg and mm or in deg and m, standard deviations eph, eph,
  epv, velocity with s_variance_m_s when vel_ned_valid;
- vehicle_air_data baro_alt_meter; vehicle_attitude q as roll, pitch, yaw (Z-Y-X);
  vehicle_global_position lat, lon, alt_ellipsoid (alt without it); vehicle_local_position
  vx, vy, vz when v_xy_valid and v_z_valid;
- times: timestamp_sample where the topic has it and it is not 0, else timestamp; GPS
  seconds of week through the first 3-D fix's time_utc_usec plus the leap seconds, when
  there is one, else device seconds.

Times must be equal exactly (both compute them from integer microseconds). Values must
agree to 1e-12 relative (both take the same float32, double or integer fields to double,
but may round an operation differently, e.g. degrees through radians and back), Euler
angles to 1e-9 rad (schuler goes through the direction cosine matrix, this script
through the closed-form atan2/asin; their rounding differs by a few 1e-16 rad, more
near ±90° pitch). Record counts per stream, dropout count and total duration must be
equal. Exit status 1 on any difference.

    python3 -m venv /tmp/venv-ulog && /tmp/venv-ulog/bin/pip install -r scripts/requirements-ulog.txt
    cargo build -p schuler-io --example ulog_dump
    /tmp/venv-ulog/bin/python crates/schuler-io/tests/pyulog_check.py \\
        --dump target/debug/examples/ulog_dump tests/data/ulog/*.ulg.gz
"""

from __future__ import annotations

import argparse
import gzip
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from pyulog import ULog

GPS_EPOCH_UNIX = 315_964_800
WEEK_US = 604_800 * 1_000_000
# GPS - UTC [s] from each UNIX time on (IERS Bulletin C; 18 since 2017-01-01).
LEAP = [(362_793_600, 1), (394_329_600, 2), (425_865_600, 3), (489_024_000, 4),
        (567_993_600, 5), (631_152_000, 6), (662_688_000, 7), (709_948_800, 8),
        (741_484_800, 9), (773_020_800, 10), (820_454_400, 11), (867_715_200, 12),
        (915_148_800, 13), (1_136_073_600, 14), (1_230_768_000, 15),
        (1_341_100_800, 16), (1_435_708_800, 17), (1_483_228_800, 18)]
RELATIVE_TIMESTAMP_INVALID = 0x7FFFFFFF


def leap_at(unix: int) -> int:
    n = 0
    for start, count in LEAP:
        if unix >= start:
            n = count
    return n


def field_type(d, name: str) -> str | None:
    for f in d.field_data:
        if f.field_name == name:
            return f.type_str
    return None


def device_us(d) -> list[int]:
    """timestamp_sample where the topic has it and it is not 0, else timestamp."""
    ts = [int(x) for x in d.data["timestamp"]]
    if "timestamp_sample" in d.data:
        return [int(s) if int(s) != 0 else t for s, t in zip(d.data["timestamp_sample"], ts)]
    return ts


def topic(ulog: ULog, name: str):
    for d in ulog.data_list:
        if d.name == name and d.multi_id == 0:
            return d
    return None


def gnss_fix_rows(d) -> list[int]:
    dd = d.data
    return [i for i in range(len(dd["timestamp"]))
            if int(dd["fix_type"][i]) >= 3 and float(dd["eph"][i]) > 0 and float(dd["epv"][i]) > 0]


def expected(ulog: ULog) -> tuple[str, dict[str, list[list[float | None]]]]:
    """The time scale and the records schuler should give, per (kind, stream)."""
    gnss_name = ("vehicle_gps_position" if "vehicle_gps_position" in ulog.message_formats
                 else "sensor_gps")
    gnss = topic(ulog, gnss_name)
    offset, week = None, None
    if gnss is not None:
        us = device_us(gnss)
        for i in gnss_fix_rows(gnss):
            utc = int(gnss.data["time_utc_usec"][i])
            if utc // 1_000_000 > GPS_EPOCH_UNIX:
                gps_us = utc - GPS_EPOCH_UNIX * 1_000_000 + leap_at(utc // 1_000_000) * 1_000_000
                offset = gps_us - us[i]
                start = ulog.start_timestamp + offset
                week = (start if start >= 0 else gps_us) // WEEK_US
                break

    def t(us: int) -> float:
        if offset is None:
            return us / 1e6
        return (us + offset - week * WEEK_US) / 1e6

    out: dict[str, list[list[float | None]]] = {}
    d = topic(ulog, "sensor_combined")
    if d is not None:
        dd = d.data

        def interval(name: str) -> np.ndarray:
            v = dd[name].astype(np.float64)
            return v if field_type(d, name) in ("float", "double") else v / 1e6

        dt, dt_a = interval("gyro_integral_dt"), interval("accelerometer_integral_dt")
        rows = []
        for i, us in enumerate(device_us(d)):
            if int(dd["accelerometer_timestamp_relative"][i]) == RELATIVE_TIMESTAMP_INVALID \
                    or not (dt[i] > 0 and dt_a[i] > 0):
                continue
            g = [float(dd[f"gyro_rad[{k}]"][i]) * float(dt[i]) for k in range(3)]
            a = [float(dd[f"accelerometer_m_s2[{k}]"][i]) * float(dt_a[i]) for k in range(3)]
            rows.append([t(us), float(dt[i]), *g, *a])
        out["imu,sensor_combined"] = rows
    if gnss is not None:
        dd = gnss.data
        if "latitude_deg" in dd:
            lat, lon, h = (dd["latitude_deg"].astype(np.float64), dd["longitude_deg"].astype(np.float64),
                           dd["altitude_ellipsoid_m"].astype(np.float64))
        else:
            lat, lon = dd["lat"].astype(np.float64) / 1e7, dd["lon"].astype(np.float64) / 1e7
            h = dd["alt_ellipsoid"].astype(np.float64) / 1e3
        us = device_us(gnss)
        rows = []
        for i in gnss_fix_rows(gnss):
            eph, epv, s = float(dd["eph"][i]), float(dd["epv"][i]), float(dd["s_variance_m_s"][i])
            if int(dd["vel_ned_valid"][i]) != 0 and s > 0:
                vel = [float(dd[f"vel_{c}_m_s"][i]) for c in "ned"] + [s, s, s]
            else:
                vel = [None] * 6
            rows.append([t(us[i]), float(lat[i]), float(lon[i]), float(h[i]), eph, eph, epv, *vel])
        out[f"gnss,{gnss_name}"] = rows
    d = topic(ulog, "vehicle_air_data")
    if d is not None:
        out["baro,vehicle_air_data"] = [[t(us), float(d.data["baro_alt_meter"][i])]
                                       for i, us in enumerate(device_us(d))]
    d = topic(ulog, "vehicle_attitude")
    if d is not None:
        rows = []
        for i, us in enumerate(device_us(d)):
            q = [float(d.data[f"q[{k}]"][i]) for k in range(4)]
            n = math.sqrt(sum(c * c for c in q))
            if not (math.isfinite(n) and n > 0.5):
                continue
            w, x, y, z = (c / n for c in q)
            roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
            pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
            yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
            rows.append([t(us), None, None, None, None, None, None, roll, pitch, yaw])
        out["ref,vehicle_attitude"] = rows
    d = topic(ulog, "vehicle_global_position")
    if d is not None:
        dd = d.data
        h = dd["alt_ellipsoid"] if "alt_ellipsoid" in dd else dd["alt"]
        has_vel = all(f"vel_{c}" in dd for c in "ned")
        rows = []
        for i, us in enumerate(device_us(d)):
            vel = [float(dd[f"vel_{c}"][i]) for c in "ned"] if has_vel else [None] * 3
            rows.append([t(us), float(dd["lat"][i]), float(dd["lon"][i]), float(h[i]), *vel,
                         None, None, None])
        out["ref,vehicle_global_position"] = rows
    d = topic(ulog, "vehicle_local_position")
    if d is not None:
        dd = d.data
        rows = []
        for i, us in enumerate(device_us(d)):
            if any(f in dd and int(dd[f][i]) == 0 for f in ("v_xy_valid", "v_z_valid")):
                continue
            rows.append([t(us), None, None, None, float(dd["vx"][i]), float(dd["vy"][i]),
                         float(dd["vz"][i]), None, None, None])
        out["ref,vehicle_local_position"] = rows
    scale = "Device" if offset is None else f"GpsSecondsOfWeek {{ week: {week} }}"
    return scale, out


def ours(dump: list[str], path: Path) -> tuple[str, dict[str, list[list[float | None]]], str]:
    text = subprocess.run(dump + [str(path)], check=True, capture_output=True, text=True).stdout
    scale, report = "", ""
    out: dict[str, list[list[float | None]]] = {}
    for line in text.splitlines():
        if line.startswith("# time_scale "):
            scale = line[len("# time_scale "):]
        elif line.startswith("# report "):
            report = line
        elif not line.startswith("#"):
            kind, stream, *values = line.split(",")
            out.setdefault(f"{kind},{stream}", []).append(
                [float(v) if v else None for v in values])
    return scale, out, report


def close(a: float | None, b: float | None, tol: float) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a == b or abs(a - b) <= tol * max(abs(a), abs(b), 1.0)


def check(dump: list[str], path: Path) -> list[str]:
    problems: list[str] = []
    with tempfile.NamedTemporaryFile(suffix=".ulg") as plain:
        if path.suffix == ".gz":
            plain.write(gzip.decompress(path.read_bytes()))
            plain.flush()
            ulog = ULog(plain.name)
        else:
            ulog = ULog(str(path))
    scale, want = expected(ulog)
    got_scale, got, report = ours(dump, path)
    if got_scale != scale:
        problems.append(f"time scale {got_scale} against {scale}")
    n_drop = len(ulog.dropouts)
    total = sum(d.duration for d in ulog.dropouts) / 1000
    m = re.search(r"dropouts: (\d+), dropout_total_s: ([0-9.e+-]+),", report)
    if not m or int(m.group(1)) != n_drop or abs(float(m.group(2)) - total) > 1e-9:
        problems.append(f"dropouts: pyulog has {n_drop}, {total} s in all; ours: {report}")
    for key in sorted(set(want) | set(got)):
        w, g = want.get(key, []), got.get(key, [])
        if len(w) != len(g):
            problems.append(f"{key}: {len(g)} records, pyulog gives {len(w)}")
            continue
        tol = 1e-9 if key == "ref,vehicle_attitude" else 1e-12
        bad = 0
        for i, (rw, rg) in enumerate(zip(w, g)):
            if len(rw) != len(rg) or rw[0] != rg[0] or not all(
                    close(a, b, tol) for a, b in zip(rw[1:], rg[1:])):
                if bad < 3:
                    problems.append(f"{key} record {i}: ours {rg}, pyulog {rw}")
                bad += 1
        if bad:
            problems.append(f"{key}: {bad} of {len(w)} records differ")
        print(f"{path.name}: {key}: {len(g)} records agree" if not bad else
              f"{path.name}: {key}: {bad} differ")
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dump", help="the ulog_dump executable (default: cargo run)")
    ap.add_argument("files", nargs="+", type=Path)
    args = ap.parse_args()
    dump = [args.dump] if args.dump else [
        "cargo", "run", "-q", "-p", "schuler-io", "--example", "ulog_dump", "--"]
    failed = False
    for path in args.files:
        problems = check(dump, path)
        for p in problems:
            print(f"{path}: {p}", file=sys.stderr)
        failed |= bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
