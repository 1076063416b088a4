"""Monte-Carlo campaigns from Python: ``schuler.montecarlo`` against the CLI's
``schuler montecarlo`` table (the same rows, bit for bit), and ``schuler.dask`` on a
local Dask cluster against the local campaign (the same table)."""

import math
import pathlib

import numpy as np
import pandas as pd
import pytest

import schuler
import schuler.dask
from conftest import REPO

CAMPAIGN = REPO / "examples" / "montecarlo.toml"


def _read_runs(path: pathlib.Path) -> pd.DataFrame:
    # The CSV holds each float's shortest exact form; pandas 3 reads it back exactly
    # (its default parser rounds correctly).
    return pd.read_csv(path)


def _assert_same_bits(a: pd.DataFrame, b: pd.DataFrame):
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b)
    assert (a["seed"].to_numpy(np.uint64) == b["seed"].to_numpy(np.uint64)).all()
    for c in schuler.CAMPAIGN_COLUMNS:
        x, y = a[c].to_numpy(np.float64), b[c].to_numpy(np.float64)
        # Bit equality, NaN included (a run without outage has NaN outage maxima).
        assert (x.view(np.uint64) == y.view(np.uint64)).all() or np.array_equal(x, y, equal_nan=True), c


def test_montecarlo_equals_the_cli_table(cli, tmp_path):
    cli("montecarlo", "--config", CAMPAIGN, "--runs", 4, "--seed", 11, "--out", tmp_path)
    table = schuler.montecarlo(CAMPAIGN, runs=4, seed=11)
    assert list(table["seed"]) == [11, 12, 13, 14]
    _assert_same_bits(table, _read_runs(tmp_path / "runs.csv"))
    # The same campaign as TOML text, on one thread: the same table.
    one = schuler.montecarlo(CAMPAIGN.read_text(), runs=4, seed=11, threads=1)
    _assert_same_bits(table, one)


def test_options_win_over_the_campaign_and_are_checked_before_any_run():
    base = schuler.montecarlo(CAMPAIGN, runs=2, seed=3)
    # A navigation-grade noise model told to the filter of a tactical IMU: the same
    # samples, an overconfident filter (NEES far above its 3 dof).
    wrong = schuler.montecarlo(CAMPAIGN, runs=2, seed=3, imu_grade="navigation")
    assert (wrong["nees_attitude"] > 3 * base["nees_attitude"]).any()
    with pytest.raises(schuler.SchulerError, match="^option `imu_grade`: unknown variant `no-such-grade`"):
        schuler.montecarlo(CAMPAIGN, runs=1, seed=3, imu_grade="no-such-grade")
    with pytest.raises(TypeError, match=r"^unknown option `imu_grades` \(did you mean `imu_grade`\?\)$"):
        schuler.montecarlo(CAMPAIGN, runs=1, seed=3, imu_grades="tactical")


def test_dask_cluster_gives_the_local_table():
    distributed = pytest.importorskip("dask.distributed")
    runs = 20
    local = schuler.montecarlo(CAMPAIGN, runs=runs, seed=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = schuler.dask.montecarlo(client, CAMPAIGN, runs=runs, seed=1, per_task=3)
    _assert_same_bits(local, remote)
    assert math.isfinite(remote["nees_position"].mean())


def test_dask_navigates_a_fleet_of_logs(drive):
    distributed = pytest.importorskip("dask.distributed")
    from conftest import START

    logs = [
        {"imu": drive / "imu.txt", "gnss": drive / "gnss.txt", "end": 300.0},
        {"imu": drive / "imu.txt", "end": 200.0},
    ]
    shared = dict(START, output_rate=1.0, lever_arm=(0.5, 0.0, -1.0))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            results = schuler.dask.navigate_files(client, logs, **shared)
    for log, r in zip(logs, results):
        alone = schuler.navigate(**{**shared, **log})
        pd.testing.assert_frame_equal(r.trajectory, alone.trajectory, check_exact=True)
