"""Campaigns and fleets of logs on a Dask distributed cluster.

The work is fanned out with ``client.map`` and gathered in order; nothing here
schedules, retries or moves data itself: Dask does. Each task is a pure function of
its arguments (a campaign's seed, or one log's files and options), so a retried or
duplicated task gives the same result and the gathered table is the same bits as
:func:`schuler.montecarlo` on one machine.

Recipe::

    from dask.distributed import Client, LocalCluster   # or Client("tcp://scheduler:8786")
    import schuler.dask

    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        table = schuler.dask.montecarlo(client, "examples/montecarlo.toml", runs=200, seed=1)
        results = schuler.dask.navigate_files(client, [
            {"imu": "day1/imu.txt", "gnss": "day1/gnss.txt"},
            {"imu": "day2/imu.txt", "gnss": "day2/gnss.txt"},
        ], init_pos=(30.5, 114.3, 20.0), init_att=(0, 0, 45), lever_arm=(0.5, 0, -1))

Every worker needs the ``schuler`` package (the same wheel as the client) and, for
files, the same paths (a shared file system). A campaign file is sent as its text, so
the workers need only the files it names (``motion_csv``).
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Sequence

import pandas as pd

from . import _campaign_frame, _campaign_source, _options, _schuler, navigate, Campaign, NavResult

__all__ = ["montecarlo", "navigate_files"]


def _run_seeds(seeds: List[int], source: Dict[str, Any], options: Dict[str, Any]) -> Dict[str, Any]:
    """One task: the rows of ``seeds`` on one thread of the worker."""
    return _schuler.montecarlo_seeds(seeds, options=options, threads=1, **source)


def montecarlo(
    client: Any,
    campaign: Campaign,
    runs: int,
    seed: int = 1,
    per_task: int = 1,
    **options: Any,
) -> pd.DataFrame:
    """:func:`schuler.montecarlo` on the cluster of ``client``: the seeds in tasks of
    ``per_task`` runs, gathered in seed order into the same table."""
    if runs < 1 or per_task < 1:
        raise ValueError("runs and per_task must be at least 1")
    seeds = [(seed + k) % 2**64 for k in range(runs)]
    chunks = [seeds[i : i + per_task] for i in range(0, runs, per_task)]
    source, opts = _campaign_source(campaign, portable=True), _options(options)
    futures = client.map(_run_seeds, chunks, source=source, options=opts)
    parts = client.gather(futures)
    return pd.concat([_campaign_frame(p) for p in parts], ignore_index=True)


def _navigate_one(inputs: Mapping[str, Any], options: Mapping[str, Any]) -> NavResult:
    """One task: :func:`schuler.navigate` of one log."""
    return navigate(**{**options, **inputs})


def navigate_files(
    client: Any,
    logs: Sequence[Mapping[str, Any]],
    **options: Any,
) -> List[NavResult]:
    """:func:`schuler.navigate` of each log of a fleet on the cluster of ``client``:
    ``logs`` holds each log's own keyword arguments (``imu``, ``gnss``, ... as paths
    the workers can read), ``options`` those shared by all; the results in the order
    of ``logs``."""
    futures = client.map(_navigate_one, list(logs), options=dict(options))
    return client.gather(futures)
