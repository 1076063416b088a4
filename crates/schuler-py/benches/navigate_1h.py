"""Benchmark: navigate 1 h at 200 Hz with 1-Hz GNSS (the filter with scale
factors off: 15 states; output at 1 Hz) from numpy arrays, against `schuler nav` on the same
files; both pinned to one core (taskset) when available, best of N runs.

    python benches/navigate_1h.py [--runs 5]

Needs the `schuler` binary ($SCHULER_BIN, else $CARGO_TARGET_DIR/release/schuler)
and the package installed. The arrays are read before the clock starts; the CLI's
time includes parsing its text files and writing nav.txt (what a user waits for)."""

import argparse
import os
import pathlib
import shutil
import subprocess
import tempfile
import time

import numpy as np

import schuler

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]


def binary() -> str:
    if os.environ.get("SCHULER_BIN"):
        return os.environ["SCHULER_BIN"]
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return str(target / "release" / "schuler")


def one_core():
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    runs = ap.parse_args().runs
    exe = binary()
    one_core()
    with tempfile.TemporaryDirectory() as tmp:
        sim = pathlib.Path(tmp) / "sim"
        subprocess.run([exe, "simulate", "--config", HERE / "drive_1h.toml", "--out", sim], check=True, capture_output=True)
        imu = np.loadtxt(sim / "imu.txt")
        gnss = schuler.read_gnss(sim / "gnss.txt")
        opts = dict(init_pos=(45.07, 7.68, 245.0), init_att=(0.0, 0.0, 10.0), output_rate=1.0, imu_grade="tactical")
        py = []
        for _ in range(runs):
            t0 = time.perf_counter()
            r = schuler.navigate(imu, gnss=gnss, **opts)
            py.append(time.perf_counter() - t0)
        cli = []
        out = pathlib.Path(tmp) / "nav"
        args = [exe, "nav", "--imu", sim / "imu.txt", "--gnss", sim / "gnss.txt", "--init-pos", "45.07,7.68,245", "--init-att", "0,0,10", "--output-rate", "1", "--imu-grade", "tactical", "--no-report", "--out", out]
        for _ in range(runs):
            shutil.rmtree(out, ignore_errors=True)
            t0 = time.perf_counter()
            subprocess.run(args, check=True, capture_output=True)
            cli.append(time.perf_counter() - t0)
        # The same numbers: the CLI's file to its printed digits.
        nav = schuler.read_nav(out / "nav.txt")
        assert len(nav) == len(r.trajectory)
        assert np.abs(nav["lat_deg"].to_numpy() - r.trajectory["lat_deg"].to_numpy()).max() <= 5.01e-12
    n = len(imu)
    print(f"{n} samples, {len(gnss)} fixes, {len(r.trajectory)} epochs")
    print(f"python navigate (arrays): best {min(py):.3f} s, median {np.median(py):.3f} s")
    print(f"schuler nav (files):      best {min(cli):.3f} s, median {np.median(cli):.3f} s")
    print(f"ratio python/cli (best): {min(py) / min(cli):.2f}")


if __name__ == "__main__":
    main()
