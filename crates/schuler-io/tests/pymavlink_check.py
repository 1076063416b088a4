#!/usr/bin/env python3
"""Cross-check of schuler's ArduPilot DataFlash reader against pymavlink's DFReader,
ArduPilot's own log decoder.

For each file, every record schuler reads (the `dataflash_dump` example: one CSV line
per record) is compared with the record built here from the messages pymavlink
(https://github.com/ArduPilot/pymavlink) decodes from the same file, by the
conversions the reader's documentation gives (crates/schuler-io/src/logs/dataflash/
mod.rs and records.rs):

- streams: the message name, with `[i]` for types whose FMTU marks an instance column;
- IMU, IMU2, IMU3: increments GyrX..Z and AccX..Z times the spacing of the stream's
  TimeUS; the first sample, and one whose spacing is not positive or above 0.5 s,
  only starts the stream;
- GPS with Status >= 3, completed by the GPA of the same instance and TimeUS: Lat,
  Lng, AEl (Alt where GPA has no AEl or it is INT32_MIN), standard deviations HAcc,
  HAcc, VAcc, velocity Spd cos GCrs, Spd sin GCrs, VZ with SAcc (VZ 0 with 100 m/s
  when VV is 0; no velocity when SAcc is 0); no record when HAcc or VAcc is 0;
- BARO, BAR2, BAR3: Alt;
- XKF1 / NKF1 of core 0: Roll, Pitch, Yaw (minus 360 above 180) in radians, VN, VE,
  VD, and from the last ORGN of Type 0: the location PN, PE north and east of it on
  ArduPilot's sphere (LATLON_TO_M), height Alt - PD;
- times: GPS seconds of week through the first GPS with Status >= 3 and GWk > 0
  (GWk * 604800e6 + GMS * 1000 against its TimeUS), the week that of the log's first
  time; device seconds without such a fix.

Times must be equal exactly (both divide the same integer microseconds by 1e6).
Values must agree to 1e-12 relative: both take the same scaled fields (pymavlink
applies the format characters' 0.01 and 1e-7, as the reader does) but may round an
operation differently (degrees through radians and back in the dump). Record counts
per stream and the stream names must be equal. Exit status 1 on any difference.

    python3 -m venv /tmp/venv-df && /tmp/venv-df/bin/pip install -r scripts/requirements-dataflash.txt
    cargo build -p schuler-io --example dataflash_dump
    /tmp/venv-df/bin/python crates/schuler-io/tests/pymavlink_check.py \\
        --dump target/debug/examples/dataflash_dump tests/data/dataflash/*.bin.gz
"""

from __future__ import annotations

import argparse
import gzip
import math
import subprocess
import sys
import tempfile
from pathlib import Path

from pymavlink import DFReader

WEEK_US = 604_800 * 1_000_000
LATLON_TO_M = 0.011131884502145034
UNMEASURED_VD_STD = 100.0
INT32_MIN_SCALED = -(2**31) * 0.01
MAX_IMU_GAP_S = 0.5


def us_of(m) -> int | None:
    cols = m.fmt.columns
    if "TimeUS" in cols:
        return int(m.TimeUS)
    if "TimeMS" in cols:
        return int(m.TimeMS) * 1000
    return None


def stream_name(m) -> str:
    if m.fmt.instance_field is not None:
        return f"{m.fmt.name}[{int(getattr(m, m.fmt.instance_field))}]"
    return m.fmt.name


def instance(m):
    return None if m.fmt.instance_field is None else int(getattr(m, m.fmt.instance_field))


def messages(path: Path) -> list:
    reader = DFReader.DFReader_binary(str(path), zero_time_base=False)
    out = []
    while True:
        m = reader.recv_msg()
        if m is None:
            return out
        out.append(m)


def expected(msgs: list) -> tuple[str, dict[str, list[list[float | None]]], set[str]]:
    """The time scale, the records schuler should give per (kind, stream), the streams."""
    start, offset, week = None, None, None
    for m in msgs:
        if m.fmt.name == "FMT":
            continue
        if start is None:
            start = us_of(m)
        if m.fmt.name == "GPS" and int(m.Status) >= 3 and int(m.GWk) > 0:
            gps_us = int(m.GWk) * WEEK_US + int(m.GMS) * 1000
            offset = gps_us - int(m.TimeUS)
            s = (start if start is not None else int(m.TimeUS)) + offset
            week = (s if s >= 0 else gps_us) // WEEK_US
            break

    def t(us: int) -> float:
        if offset is None:
            return us / 1e6
        return (us + offset - week * WEEK_US) / 1e6

    out: dict[str, list[list[float | None]]] = {}
    streams: set[str] = set()
    last_us: dict[str, int] = {}
    pending: dict = {}
    origin = None
    for m in msgs:
        name, s = m.fmt.name, stream_name(m)
        streams.add(s)
        if name in ("IMU", "IMU2", "IMU3"):
            us = int(m.TimeUS)
            last = last_us.get(s)
            last_us[s] = us
            if last is None or us <= last or (us - last) * 1e-6 > MAX_IMU_GAP_S:
                continue
            dt = (us - last) / 1e6
            g = [float(getattr(m, f"Gyr{c}")) * dt for c in "XYZ"]
            a = [float(getattr(m, f"Acc{c}")) * dt for c in "XYZ"]
            out.setdefault(f"imu,{s}", []).append([t(us), dt, *g, *a])
        elif name == "GPS":
            pending.pop(instance(m), None)
            if int(m.Status) >= 3:
                pending[instance(m)] = (s, m)
        elif name == "GPA":
            p = pending.get(instance(m))
            if p is None or int(p[1].TimeUS) != int(m.TimeUS):
                continue
            del pending[instance(m)]
            gs, g = p
            hacc, vacc, sacc = float(m.HAcc), float(m.VAcc), float(m.SAcc)
            if not (hacc > 0 and vacc > 0):
                continue
            cols = m.fmt.columns
            h = float(m.AEl) if "AEl" in cols and float(m.AEl) != INT32_MIN_SCALED else float(g.Alt)
            if sacc > 0:
                crs = math.radians(float(g.GCrs))
                vn, ve = float(g.Spd) * math.cos(crs), float(g.Spd) * math.sin(crs)
                if "VV" in cols and int(m.VV) == 0:
                    vel = [vn, ve, 0.0, sacc, sacc, UNMEASURED_VD_STD]
                else:
                    vel = [vn, ve, float(g.VZ), sacc, sacc, sacc]
            else:
                vel = [None] * 6
            out.setdefault(f"gnss,{gs}", []).append(
                [t(int(g.TimeUS)), float(g.Lat), float(g.Lng), h, hacc, hacc, vacc, *vel])
        elif name in ("BARO", "BAR2", "BAR3"):
            out.setdefault(f"baro,{s}", []).append([t(int(m.TimeUS)), float(m.Alt)])
        elif name == "ORGN":
            if int(m.Type) == 0:
                origin = (float(m.Lat), float(m.Lng), float(m.Alt))
        elif name in ("XKF1", "NKF1") and (instance(m) or 0) == 0:
            yaw = float(m.Yaw)
            yaw = yaw - 360.0 if yaw > 180.0 else yaw
            if origin is not None:
                lat0, lon0, alt0 = origin
                dlat = float(m.PN) / LATLON_TO_M * 1e-7
                scale = max(math.cos(math.radians(lat0 + dlat / 2.0)), 0.01)
                dlon = float(m.PE) / LATLON_TO_M * 1e-7 / scale
                pos = [lat0 + dlat, lon0 + dlon, alt0 - float(m.PD)]
            else:
                pos = [None] * 3
            out.setdefault(f"ref,{s}", []).append(
                [t(int(m.TimeUS)), *pos, float(m.VN), float(m.VE), float(m.VD),
                 math.radians(float(m.Roll)), math.radians(float(m.Pitch)), math.radians(yaw)])
    scale = "Device" if offset is None else f"GpsSecondsOfWeek {{ week: {week} }}"
    return scale, out, streams


def ours(dump: list[str], path: Path) -> tuple[str, dict[str, list[list[float | None]]], set[str]]:
    text = subprocess.run(dump + [str(path)], check=True, capture_output=True, text=True).stdout
    scale = ""
    out: dict[str, list[list[float | None]]] = {}
    streams: set[str] = set()
    for line in text.splitlines():
        if line.startswith("# time_scale "):
            scale = line[len("# time_scale "):]
        elif line.startswith("# stream "):
            streams.add(line.split(" ")[3])
        elif not line.startswith("#"):
            kind, stream, *values = line.split(",")
            out.setdefault(f"{kind},{stream}", []).append(
                [float(v) if v else None for v in values])
    return scale, out, streams


def close(a: float | None, b: float | None, tol: float) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a == b or abs(a - b) <= tol * max(abs(a), abs(b), 1.0)


def check(dump: list[str], path: Path) -> list[str]:
    problems: list[str] = []
    with tempfile.NamedTemporaryFile(suffix=".bin") as plain:
        if path.suffix == ".gz":
            plain.write(gzip.decompress(path.read_bytes()))
            plain.flush()
            msgs = messages(Path(plain.name))
        else:
            msgs = messages(path)
    scale, want, want_streams = expected(msgs)
    got_scale, got, got_streams = ours(dump, path)
    if got_scale != scale:
        problems.append(f"time scale {got_scale} against {scale}")
    if got_streams != want_streams:
        problems.append(f"streams: ours only {sorted(got_streams - want_streams)}, "
                        f"pymavlink only {sorted(want_streams - got_streams)}")
    for key in sorted(set(want) | set(got)):
        w, g = want.get(key, []), got.get(key, [])
        if len(w) != len(g):
            problems.append(f"{key}: {len(g)} records, pymavlink gives {len(w)}")
            continue
        bad = 0
        for i, (rw, rg) in enumerate(zip(w, g)):
            if len(rw) != len(rg) or rw[0] != rg[0] or not all(
                    close(a, b, 1e-12) for a, b in zip(rw[1:], rg[1:])):
                if bad < 3:
                    problems.append(f"{key} record {i}: ours {rg}, pymavlink {rw}")
                bad += 1
        if bad:
            problems.append(f"{key}: {bad} of {len(w)} records differ")
        print(f"{path.name}: {key}: {len(g)} records agree" if not bad else
              f"{path.name}: {key}: {bad} differ")
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dump", help="the dataflash_dump executable (default: cargo run)")
    ap.add_argument("files", nargs="+", type=Path)
    args = ap.parse_args()
    dump = [args.dump] if args.dump else [
        "cargo", "run", "-q", "-p", "schuler-io", "--example", "dataflash_dump", "--"]
    failed = False
    for path in args.files:
        problems = check(dump, path)
        for p in problems:
            print(f"{path}: {p}", file=sys.stderr)
        failed |= bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
