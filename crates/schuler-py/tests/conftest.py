"""Fixtures of the Python package's tests: the `schuler` binary built from the same
checkout (the CLI is the reference the package must equal) and a drive simulated by it.

The binary is `$SCHULER_BIN`, else `$CARGO_TARGET_DIR/release/schuler`, else the
checkout's `target/release/schuler` (`cargo build --release` makes it)."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def _binary() -> pathlib.Path:
    if os.environ.get("SCHULER_BIN"):
        return pathlib.Path(os.environ["SCHULER_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "schuler"


@pytest.fixture(scope="session")
def cli():
    """Runs the `schuler` binary with the given arguments; returns its stdout."""
    exe = _binary()
    if not exe.exists():
        pytest.fail(f"{exe} is missing: run `cargo build --release` first (or set SCHULER_BIN)")

    def run(*args):
        p = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        assert p.returncode == 0, f"schuler {' '.join(map(str, args))} failed:\n{p.stderr}"
        return p.stdout

    return run


@pytest.fixture(scope="session")
def drive(cli, tmp_path_factory):
    """`schuler simulate` of the README's example drive (20 min at 200 Hz, tactical IMU,
    GNSS at 1 Hz with a 60-s outage, barometer at 10 Hz): its output folder."""
    out = tmp_path_factory.mktemp("drive")
    cli("simulate", "--config", REPO / "examples" / "drive.toml", "--out", out)
    return out


#: The example drive's initial state (examples/drive.toml's [start]).
START = dict(init_pos=(45.07, 7.68, 245.0), init_att=(0.0, 0.0, 10.0))
