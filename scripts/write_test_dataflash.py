#!/usr/bin/env python3
"""Writes tests/data/dataflash/synthetic_circle.bin.gz, a small ArduPilot DataFlash log
in the message layouts of ArduPilot 4.5 (libraries/*/LogStructure.h), for schuler's
DataFlash reader tests (crates/schuler-io/tests/dataflash.rs, pymavlink_check.py).

Written from the format's facts with Python's struct module (no ArduPilot or
pymavlink code): FMT messages (type 128, 89 bytes, "BBnNZ") define every message,
FMTU gives the unit characters ('#' marks the instance column), then 10 s of a vehicle
driving a circle of 50 m radius at 5 m/s (turning right, yaw rate 0.1 rad/s) at a
level attitude:

- IMU, instances 0 and 1, every 10 ms: gyro (0, 0, 0.1) rad/s, specific force
  (0, 0.5, -9.81) m/s^2 in FRD, plus a deterministic noise (Python's random, seed
  32), instance 1 with a 0.01 rad/s gyro x bias;
- GPS and GPA, instance 0, every 200 ms from TimeUS 60.1 s: status 1 (no fix) for the
  first second, then 3-D fixes on the circle, GPS week 2300, milliseconds of week
  from 345 600 000 + 100 per 100 ms of TimeUS; AEl (ellipsoid height, the MSL height
  plus 48.2 m) except in one GPA, which logs INT32_MIN (unknown);
- BARO instance 0 every 100 ms; XKF1 cores 0 and 1 every 100 ms with the circle's
  attitude, velocity and position from the origin; ORGN type 0 (EKF origin) and
  type 1 (home) at TimeUS 62 s; a few PARM and one MSG.

Lat/Lng offsets use ArduPilot's sphere (LATLON_TO_M = 0.011131884502145034 m per
1e-7 deg; longitude scale cos(latitude)). Deterministic: the same bytes every run
(gzip with mtime 0).

    python3 scripts/write_test_dataflash.py
"""

from __future__ import annotations

import gzip
import math
import random
import struct
from pathlib import Path

OUT = Path(__file__).resolve().parent.parent / "tests/data/dataflash/synthetic_circle.bin.gz"

SIZES = {"b": 1, "B": 1, "M": 1, "h": 2, "H": 2, "c": 2, "C": 2, "g": 2, "i": 4, "I": 4,
         "f": 4, "e": 4, "E": 4, "L": 4, "n": 4, "q": 8, "Q": 8, "d": 8, "N": 16, "Z": 64,
         "a": 64}
STRUCT = {"b": "b", "B": "B", "M": "B", "h": "h", "H": "H", "c": "h", "C": "H", "i": "i",
          "I": "I", "f": "f", "e": "i", "E": "I", "L": "i", "n": "4s", "q": "q", "Q": "Q",
          "d": "d", "N": "16s", "Z": "64s"}

# (type, name, format, labels, units)
MESSAGES = [
    (129, "FMTU", "QBNN", "TimeUS,FmtType,UnitIds,MultIds", "s---"),
    (130, "PARM", "QNff", "TimeUS,Name,Value,Default", "s---"),
    (131, "MSG", "QZ", "TimeUS,Message", "s-"),
    (132, "IMU", "QBffffffIIfBBHH",
     "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz", "s#EEEooo--O--zz"),
    (133, "GPS", "QBBIHBcLLeffffB",
     "TimeUS,I,Status,GMS,GWk,NSats,HDop,Lat,Lng,Alt,Spd,GCrs,VZ,Yaw,U", "s#-s-S-DUmnhnh-"),
    (134, "GPA", "QBCCCCfBIHeHH",
     "TimeUS,I,VDop,HAcc,VAcc,SAcc,YAcc,VV,SMS,Delta,AEl,RTCMFU,RTCMFD", "s#-mmnd-ssm--"),
    (135, "BARO", "QBffcfIffB", "TimeUS,I,Alt,Press,Temp,CRt,SMS,Offset,GndTemp,Health",
     "s#mPOnsmO-"),
    (136, "XKF1", "QBccCfffffffccce",
     "TimeUS,C,Roll,Pitch,Yaw,VN,VE,VD,dPD,PN,PE,PD,GX,GY,GZ,OH", "s#ddhnnnnmmmkkkm"),
    (137, "ORGN", "QBLLe", "TimeUS,Type,Lat,Lng,Alt", "s-DUm"),
]
TYPES = {name: (ty, fmt) for ty, name, fmt, _, _ in MESSAGES}

LATLON_TO_M = 0.011131884502145034
LAT0, LNG0, ALT0 = 47.3977420, 8.5455940, 488.0  # origin [deg, deg, m above MSL]
UND = 48.2  # ellipsoid minus MSL height [m]
R, V = 50.0, 5.0
W = V / R


def message(ty: int, fmt: str, *values) -> bytes:
    packed = []
    for ch, v in zip(fmt, values):
        if ch in "nNZ":
            v = v.encode()
        packed.append(v)
    body = struct.pack("<" + "".join(STRUCT[c] for c in fmt), *packed)
    assert len(body) == sum(SIZES[c] for c in fmt)
    return bytes([0xA3, 0x95, ty]) + body


def fmt_message(ty: int, name: str, fmt: str, labels: str) -> bytes:
    length = 3 + sum(SIZES[c] for c in fmt)
    return message(128, "BBnNZ", ty, length, name, fmt, labels)


def location(n: float, e: float) -> tuple[int, int]:
    """Lat and Lng [1e-7 deg] n, e metres from the origin, on ArduPilot's sphere."""
    dlat = n / LATLON_TO_M
    scale = math.cos(math.radians(LAT0 + dlat * 1e-7 / 2))
    return round(LAT0 * 1e7 + dlat), round(LNG0 * 1e7 + e / LATLON_TO_M / scale)


def state(t: float) -> tuple[float, float, float, float, float]:
    """Yaw [rad], north, east position [m] and velocity [m/s] at t s after the start."""
    psi = W * t
    return psi, R * math.sin(psi), R * (1 - math.cos(psi)), V * math.cos(psi), V * math.sin(psi)


def build() -> bytes:
    rnd = random.Random(32)
    out = bytearray()
    out += fmt_message(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")
    for ty, name, fmt, labels, _ in MESSAGES:
        out += fmt_message(ty, name, fmt, labels)
    for ty, name, fmt, _, units in MESSAGES:
        out += message(129, "QBNN", 0, ty, units, "-" * len(units))
    t0 = 60_000_000
    for i, (name, value) in enumerate([("INS_LOG_BAT_OPT", 0.0), ("LOG_BITMASK", 180222.0),
                                       ("EK3_ENABLE", 1.0)]):
        out += message(130, "QNff", t0 + i, name, value, value)
    out += message(131, "QZ", t0 + 10, "ArduRover V4.5.0 (synthetic, schuler)")
    # Events on a 1-ms grid, in time order; at one time IMU first, then the others.
    for k in range(1, 10_001):
        us = t0 + k * 1000
        t = (us - t0) / 1e6
        psi, n, e, vn, ve = state(t)
        if k % 10 == 0:
            for inst, bias in ((0, 0.0), (1, 0.01)):
                g = [bias + rnd.gauss(0, 0.002), rnd.gauss(0, 0.002), W + rnd.gauss(0, 0.002)]
                a = [rnd.gauss(0, 0.02), V * W + rnd.gauss(0, 0.02), -9.81 + rnd.gauss(0, 0.02)]
                out += message(132, "QBffffffIIfBBHH", us + inst, inst, *g, *a, 0, 0,
                               35.0 + inst, 1, 1, 1000, 1000)
        if k % 200 == 100:
            lat, lng = location(n, e)
            status = 1 if t < 1.0 else 3
            gms = 345_600_000 + (us - t0) // 1000
            alt_cm = round(ALT0 * 100)
            crs = math.degrees(math.atan2(ve, vn)) % 360
            out += message(133, "QBBIHBcLLeffffB", us, 0, status, gms, 2300, 12, 80, lat, lng,
                           alt_cm, V, crs, 0.0, 0.0, 1)
            ael = alt_cm + round(UND * 100) if k != 3100 else -2**31
            out += message(134, "QBCCCCfBIHeHH", us, 0, 120, 120, 180, 30, 0.0, 1, us // 1000,
                           200, ael, 0, 0)
        if k % 100 == 50:
            out += message(135, "QBffcfIffB", us, 0, 0.1 + rnd.gauss(0, 0.05), 95000.0,
                           2500, 0.0, us // 1000, 0.0, 25.0, 1)
        if k == 2000:
            out += message(137, "QBLLe", us, 0, round(LAT0 * 1e7), round(LNG0 * 1e7),
                           round(ALT0 * 100))
            out += message(137, "QBLLe", us + 1, 1, round(LAT0 * 1e7), round(LNG0 * 1e7),
                           round(ALT0 * 100))
        if k % 100 == 0:
            yaw_cd = round(math.degrees(psi) * 100) % 36000
            for core in (0, 1):
                out += message(136, "QBccCfffffffccce", us + 5 + core, core, 0, 0, yaw_cd,
                               vn, ve, 0.0, 0.0, n, e, 0.0, 0, 0, 0, 0)
    return bytes(out)


def main() -> None:
    data = build()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_bytes(gzip.compress(data, compresslevel=9, mtime=0))
    print(f"{OUT}: {len(data)} bytes, {OUT.stat().st_size} gzipped")


if __name__ == "__main__":
    main()
