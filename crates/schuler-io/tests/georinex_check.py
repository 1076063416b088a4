#!/usr/bin/env python3
"""Cross-check of schuler's RINEX observation reader against georinex.

For each file, every observation schuler reads (the `rinex_obs_dump` example: one
`time sat code value lli ssi` line each) is compared with every observation georinex
(https://github.com/geospace-code/georinex, which expands Hatanaka files with the
`hatanaka` package, a wrapper of RNXCMP's CRX2RNX) reads from the same file: the same
(time, satellite, code) keys, and the same values, exactly (both read the decimal text
into the nearest double). Loss-of-lock and signal-strength indicators are not compared:
georinex keeps them for a few codes only. Exit status 1 on any difference.

    python3 -m venv /tmp/venv-rinex && /tmp/venv-rinex/bin/pip install georinex
    cargo build -p schuler-io --example rinex_obs_dump
    /tmp/venv-rinex/bin/python crates/schuler-io/tests/georinex_check.py \\
        --dump target/debug/examples/rinex_obs_dump tests/data/rinex_obs/*.gz

Without --dump the example runs through `cargo run` from the current directory.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import warnings
from pathlib import Path

import georinex
import numpy as np


def schuler_observations(dump: list[str], path: Path) -> dict[tuple[int, str, str], float]:
    """(time [ns since 1970, as written], satellite, code) -> value, as schuler reads them."""
    out = subprocess.run(dump + [str(path)], check=True, capture_output=True, text=True).stdout
    obs: dict[tuple[int, str, str], float] = {}
    for line in out.splitlines():
        time, sat, code, value, _lli, _ssi = line.split()
        key = (int(np.datetime64(time, "ns").astype(np.int64)), sat, code)
        if key in obs:
            raise SystemExit(f"{path}: schuler gives {key} twice")
        obs[key] = float(value)
    return obs


def georinex_observations(path: Path) -> dict[tuple[int, str, str], float]:
    """The same from georinex's dataset (NaN: no observation)."""
    ds = georinex.load(path)
    times = ds.time.values.astype("datetime64[ns]").astype(np.int64)
    sats = [str(s) for s in ds.sv.values]
    obs: dict[tuple[int, str, str], float] = {}
    for code in ds.data_vars:
        values = ds[code].values
        for i, j in zip(*np.nonzero(~np.isnan(values))):
            obs[(int(times[i]), sats[j], str(code))] = float(values[i, j])
    return obs


def align_times(ours: dict, theirs: dict) -> dict:
    """georinex's RINEX 2 epochs truncate the seconds' fraction through a float
    (`30.0020000` becomes .001999 s, then whole milliseconds): its times within 1 ms of
    one of schuler's are taken as that time, and counted."""
    our_times = np.array(sorted({k[0] for k in ours}), dtype=np.int64)
    moved: dict[int, int] = {}
    for t in {k[0] for k in theirs}:
        if our_times.size == 0:
            break
        i = int(np.clip(np.searchsorted(our_times, t), 1, our_times.size - 1))
        near = min((our_times[i - 1], our_times[i]), key=lambda u: abs(int(u) - t))
        if near != t and abs(int(near) - t) <= 1_000_000:
            moved[t] = int(near)
    if moved:
        print(f"  {len(moved)} georinex epoch times within 1 ms of schuler's taken as equal "
              f"(e.g. {np.datetime64(next(iter(moved)), 'ns')} for {np.datetime64(next(iter(moved.values())), 'ns')})")
    return {(moved.get(k[0], k[0]), k[1], k[2]): v for k, v in theirs.items()}


def compare(dump: list[str], path: Path) -> bool:
    ours = schuler_observations(dump, path)
    theirs = align_times(ours, georinex_observations(path))
    only_ours = ours.keys() - theirs.keys()
    only_theirs = theirs.keys() - ours.keys()
    differ = [k for k in ours.keys() & theirs.keys() if not math.isclose(ours[k], theirs[k], rel_tol=0, abs_tol=0)]
    ok = not (only_ours or only_theirs or differ)
    print(
        f"{path}: {len(ours)} observations from schuler, {len(theirs)} from georinex "
        f"{georinex.__version__}: {len(only_ours)} only in schuler, {len(only_theirs)} only "
        f"in georinex, {len(differ)} values differ -> {'same' if ok else 'DIFFERENT'}"
    )
    for name, keys in (("only schuler", only_ours), ("only georinex", only_theirs), ("differ", differ)):
        for k in sorted(keys)[:5]:
            print(f"  {name}: {np.datetime64(k[0], 'ns')} {k[1]} {k[2]} "
                  f"schuler={ours.get(k)} georinex={theirs.get(k)}")
    return ok


def main() -> int:
    # georinex's xarray and numpy calls warn about future defaults; the values are read.
    warnings.filterwarnings("ignore")
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("files", nargs="+", type=Path)
    parser.add_argument("--dump", help="the built rinex_obs_dump example (default: cargo run)")
    args = parser.parse_args()
    dump = [args.dump] if args.dump else ["cargo", "run", "--quiet", "-p", "schuler-io", "--example", "rinex_obs_dump", "--"]
    results = [compare(dump, f) for f in args.files]
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
