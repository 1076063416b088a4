"""schuler: inertial navigation from Python.

A thin layer over the Rust library's navigation session and the ``schuler`` command
line's readers and options: the same code computes both, so ``navigate`` gives the
numbers ``schuler nav`` prints.

Frames, names and units (for the whole package):

* body axes front-right-down (FRD); navigation frame north-east-down (NED);
* attitude as Z-Y-X Euler angles in the order roll, pitch, yaw, in degrees in tables
  (yaw in [0, 360)); positions geodetic: latitude, longitude [deg], ellipsoidal
  height [m] (WGS84 unless ``earth="sphere"``);
* every table column carries its unit in its name: ``_s`` seconds, ``_deg`` degrees,
  ``_rad`` radians, ``_m`` metres, ``_mps`` m/s, ``_degph`` deg/h, ``_mgal`` mGal,
  ``_ppm`` parts per million;
* IMU samples are increments over the interval ``(t - dt_s, t_s]``: angle
  ``dtheta_*_rad`` and velocity ``dvel_*_mps``;
* keyword options are ``schuler nav``'s flags with underscores
  (``init_pos=(45.07, 7.68, 245)`` is ``--init-pos 45.07,7.68,245``; ``True`` turns a
  switch on; strings with units as the CLI takes them, ``arw="0.1 deg/sqrt(h)"``).

Errors: bad input data raise :class:`InputError` (a ``ValueError``) with ``path``,
``line`` (1-based; for arrays the row) and ``field``; other refusals raise
:class:`SchulerError`; an option the CLI does not have raises ``TypeError``.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _schuler
from ._schuler import InputError, SchulerError

__all__ = [
    "AlignResult",
    "AllanFit",
    "ChannelResult",
    "Comparison",
    "align",
    "allan",
    "allan_fit",
    "channel",
    "closed_form",
    "InputError",
    "NavResult",
    "SchulerError",
    "Session",
    "SimResult",
    "compare",
    "montecarlo",
    "navigate",
    "read_baro",
    "read_gnss",
    "read_imu",
    "read_nav",
    "simulate",
]

PathLike = Union[str, "os.PathLike[str]"]
Table = Union[pd.DataFrame, Mapping[str, Any], np.ndarray]

#: IMU columns after ``t_s`` and ``dt_s``: increments in FRD [rad, m/s].
IMU_INCREMENTS = (
    "dtheta_x_rad",
    "dtheta_y_rad",
    "dtheta_z_rad",
    "dvel_x_mps",
    "dvel_y_mps",
    "dvel_z_mps",
)
#: GNSS columns: time, position, its standard deviations (required) ...
GNSS_POSITION = ("t_s", "lat_deg", "lon_deg", "h_m", "std_n_m", "std_e_m", "std_d_m")
#: ... and velocity with its standard deviations (optional; NaN: none).
GNSS_VELOCITY = ("vn_mps", "ve_mps", "vd_mps", "std_vn_mps", "std_ve_mps", "std_vd_mps")
#: Rest intervals (``--zupt``'s ``t0 t1``): the vehicle still from ``t0_s`` to ``t1_s`` [s].
REST_COLUMNS = ("t0_s", "t1_s")
#: Odometer readings (``--odometer``'s ``t speed``): forward speed [m/s] at ``t_s``.
ODOMETER_COLUMNS = ("t_s", "speed_mps")
#: Dual-antenna headings (``--dual-antenna``'s ``t heading std``) [s, deg, deg] ...
HEADING_COLUMNS = ("t_s", "heading_deg", "heading_std_deg")
#: ... and optionally the baseline's pitch and its standard deviation [deg].
HEADING_PITCH = ("pitch_deg", "pitch_std_deg")


def _value(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        raise TypeError("switches take True or False alone")
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    if isinstance(v, str):
        return v
    if isinstance(v, (list, tuple, np.ndarray)):
        return ",".join(_value(x) for x in v)
    raise TypeError(f"cannot pass {type(v).__name__} as an option value")


def _plain(name: str, v: Any) -> Any:
    """A keyword option's value as the plain data the run's description takes: bool,
    int, float, str (paths as text) or a list of them."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v)
    if isinstance(v, (str, os.PathLike)):
        return os.fspath(v)
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_plain(name, x) for x in v]
    raise TypeError(f"option `{name}`: cannot pass a {type(v).__name__} as an option value")


def _options(options: Mapping[str, Any]) -> Dict[str, Any]:
    """Keyword options as a run's description (None left out): the names are ``schuler
    nav``'s flags with underscores, read and checked by the application layer."""
    return {name: _plain(name, v) for name, v in options.items() if v is not None}


def _flags(options: Mapping[str, Any]) -> List[str]:
    """``schuler nav``'s flags of keyword options (None and False are left out)."""
    out = []
    for name, v in options.items():
        if v is None or v is False:
            continue
        flag = "--" + name.replace("_", "-")
        out.append(flag if v is True else f"{flag}={_value(v)}")
    return out


def _frame(columns: Mapping[str, Any]) -> pd.DataFrame:
    return pd.DataFrame(dict(columns))


def _f64(x: Any) -> np.ndarray:
    """A float64 view of ``x`` (a copy only if it is of another type)."""
    return np.asarray(x, dtype=np.float64)


def _columns(table: Table, names: Sequence[str], what: str) -> List[np.ndarray]:
    """The columns ``names`` of a DataFrame, a mapping or a 2-D array (by position)."""
    if isinstance(table, np.ndarray):
        a = _f64(table)
        if a.ndim != 2 or a.shape[1] < len(names):
            raise ValueError(f"{what}: a 2-D array of at least {len(names)} columns ({', '.join(names)}) expected, got shape {a.shape}")
        return [a[:, k] for k in range(len(names))]
    missing = [n for n in names if n not in table]
    if missing:
        raise ValueError(f"{what}: missing column(s) {', '.join(missing)} (expected {', '.join(names)})")
    return [_f64(table[n]) for n in names]


def _imu(imu: Table):
    """IMU columns ``t_s, dtheta..., dvel...`` and ``dt_s`` if given. A 2-D array holds
    ``t, dtheta_xyz, dvel_xyz`` (7 columns, the KF-GINS layout) or ``t, dt, ...`` (8)."""
    if isinstance(imu, np.ndarray) and imu.ndim == 2 and imu.shape[1] == 8:
        a = _f64(imu)
        return [a[:, 0]] + [a[:, k] for k in range(2, 8)], a[:, 1]
    cols = _columns(imu, ("t_s",) + IMU_INCREMENTS, "imu")
    dt = None
    if not isinstance(imu, np.ndarray) and "dt_s" in imu:
        dt = _f64(imu["dt_s"])
    return cols, dt


def _gnss(gnss: Table) -> List[np.ndarray]:
    cols = _columns(gnss, GNSS_POSITION, "gnss")
    has_vel = (
        isinstance(gnss, np.ndarray) and gnss.ndim == 2 and gnss.shape[1] >= 13
    ) or (not isinstance(gnss, np.ndarray) and all(n in gnss for n in GNSS_VELOCITY))
    if has_vel:
        cols += _columns(gnss, GNSS_POSITION + GNSS_VELOCITY, "gnss")[7:]
    return cols


def _baro(baro: Table):
    t, h = _columns(baro, ("t_s", "h_m"), "baro")
    return (t, h)


def _heading(heading: Table) -> List[np.ndarray]:
    """Heading columns, with the pitch's when the table has them (5 columns of an
    array)."""
    if isinstance(heading, np.ndarray):
        names = HEADING_COLUMNS + (HEADING_PITCH if heading.ndim == 2 and heading.shape[1] >= 5 else ())
    else:
        given = [n in heading for n in HEADING_PITCH]
        if any(given) and not all(given):
            raise ValueError(f"heading: {' and '.join(HEADING_PITCH)} go together")
        names = HEADING_COLUMNS + (HEADING_PITCH if all(given) else ())
    return _columns(heading, names, "heading")


#: The vehicle aids: keyword, the option of its file, and its columns.
_VEHICLE = (
    ("rest", "zupt", lambda t: _columns(t, REST_COLUMNS, "rest")),
    ("odometer", "odometer", lambda t: _columns(t, ODOMETER_COLUMNS, "odometer")),
    ("heading", "dual_antenna", _heading),
)


def read_imu(path: PathLike, **options: Any) -> pd.DataFrame:
    """IMU samples of a log as ``schuler nav --imu`` reads it.

    ``options``: the IMU input flags (``imu_format``, ``imu_layout``, ``imu_rate``,
    ``imu_columns``, ``gyro_unit``, ``accel_unit``, ``imu_time_unit``,
    ``imu_time_offset``, ``imu_axes``, ``imu_rotation``, ``no_layout_check``) and
    ``start``, ``end`` [s]. Columns: ``t_s`` (interval end), ``dt_s``,
    ``dtheta_{x,y,z}_rad``, ``dvel_{x,y,z}_mps`` (vehicle FRD axes).
    """
    return _frame(_schuler.read_imu(os.fspath(path), _options(options)))


def read_gnss(path: PathLike, **options: Any) -> pd.DataFrame:
    """GNSS fixes of a log as ``schuler nav --gnss`` reads it (KF-GINS text, CSV, NMEA,
    RTKLIB .pos).

    ``options``: ``gnss_format``, ``gnss_std``, ``gnss_min_quality``,
    ``gnss_time_offset``, ``gnss_vel``, ``gnss_vel_std``. Columns: ``t_s``,
    ``lat_deg``, ``lon_deg``, ``h_m``, ``std_{n,e,d}_m``, ``v{n,e,d}_mps`` and
    ``std_v{n,e,d}_mps`` (NaN where a fix has no velocity).
    """
    return _frame(_schuler.read_gnss(os.fspath(path), _options(options)))


def read_baro(path: PathLike) -> pd.DataFrame:
    """Barometric heights (``baro.csv`` of ``schuler simulate``, or ``t h`` rows):
    columns ``t_s``, ``h_m``."""
    return _frame(_schuler.read_baro(os.fspath(path)))


def read_nav(path: PathLike) -> pd.DataFrame:
    """A navigation result or truth (KF-GINS text such as ``nav.txt``, or ``nav.csv``):
    ``t_s``, ``lat_deg``, ``lon_deg``, ``h_m``, ``v{n,e,d}_mps``, ``roll_deg``,
    ``pitch_deg``, ``yaw_deg`` (yaw in [0, 360))."""
    return _frame(_schuler.read_nav(os.fspath(path)))


@dataclass
class NavResult:
    """What a navigation run gives, as DataFrames.

    ``trajectory``: ``nav.txt``'s columns at the output epochs. With a filter (aiding):
    ``std`` (``std.txt``: position [m], velocity [m/s], attitude [deg], sensor errors
    [deg/h, mGal, ppm]), ``sensor_errors`` (``imu_err.txt``), ``innovations`` (every
    tested measurement: ``kind``, ``accepted``, ``dof``, ``nis``, innovation ``z_*`` and
    predicted ``sigma_*``, NaN past ``dof``), ``refused`` (``rejected.csv``: time,
    measurement, reason, NIS, threshold), ``smoothed`` (with ``smooth=True``: the
    Rauch-Tung-Striebel trajectory with its standard deviations, else None),
    ``summary`` (counts, mean NIS per degree of freedom, hand-overs) and ``warnings``.
    ``alignment``: with ``align=True``, the alignment at rest the run started from
    (:class:`AlignResult`, ``align.json``'s content); ``start_in_motion``: with
    ``init="gnss"`` or ``"gnss-any-heading"``, the start from the fixes (``t_s``,
    ``speed_mps``, ``roll_deg``, ``pitch_deg``, ``yaw_deg``, ``att_std_deg`` about
    north, east, down).
    """

    trajectory: pd.DataFrame
    std: pd.DataFrame
    sensor_errors: pd.DataFrame
    innovations: pd.DataFrame
    refused: pd.DataFrame
    smoothed: Optional[pd.DataFrame] = None
    summary: Dict[str, Any] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)
    alignment: Optional["AlignResult"] = None
    start_in_motion: Optional[Dict[str, Any]] = None

    @classmethod
    def _of(cls, d: Dict[str, Any]) -> "NavResult":
        inn = dict(d["innovations"])
        kind = inn.pop("kind")
        innovations = _frame(inn)
        innovations.insert(1, "kind", pd.Series(kind, dtype=object))
        if len(innovations):
            innovations["accepted"] = innovations["accepted"].astype(bool)
            innovations["dof"] = innovations["dof"].astype(np.int64)
        smoothed = d.get("smoothed")
        return cls(
            trajectory=_frame(d["trajectory"]),
            std=_frame(d["std"]),
            sensor_errors=_frame(d["sensor_errors"]),
            innovations=innovations,
            refused=_frame(d["refused"]),
            smoothed=None if smoothed is None else _frame(smoothed),
            summary=d.get("summary", {}),
            warnings=list(d.get("warnings", [])),
            alignment=None if d.get("alignment") is None else AlignResult._of(d["alignment"]),
            start_in_motion=d.get("start_in_motion"),
        )


def navigate(
    imu: Union[PathLike, Table],
    gnss: Union[PathLike, Table, None] = None,
    baro: Union[PathLike, Table, None] = None,
    odometer: Union[PathLike, Table, None] = None,
    heading: Union[PathLike, Table, None] = None,
    rest: Union[PathLike, Table, None] = None,
    **options: Any,
) -> NavResult:
    """Navigate an IMU log, free-inertial or aided, as ``schuler nav`` does.

    ``imu``: a file path (read with the IMU input options), a DataFrame or mapping with
    ``t_s``, ``dtheta_*_rad``, ``dvel_*_mps`` (and ``dt_s``; else each interval is the
    time difference, the first sample's the first difference), or a 2-D float array of
    the KF-GINS layout ``t, dtheta_xyz, dvel_xyz`` (or ``t, dt, ...``). Arrays are read
    in place (no copy when already float64); the layout check of files is not applied.

    ``gnss``: a path or a table of :func:`read_gnss`'s columns (velocity optional).
    ``baro``: a path or a table with ``t_s``, ``h_m``.

    Vehicle aids, each a path (the file of the CLI's flag) or a table with the file's
    columns and units: ``odometer`` (``--odometer``): ``t_s``, ``speed_mps`` (forward
    speed of the point at ``vehicle_lever_arm``, negative reversing); ``heading``
    (``--dual-antenna``): ``t_s``, ``heading_deg`` (the antenna baseline's, from true
    north, clockwise), ``heading_std_deg``, optionally ``pitch_deg`` and
    ``pitch_std_deg`` (the baseline's direction in the body: ``dual_antenna_baseline_yaw``,
    ``dual_antenna_baseline_pitch`` [deg]); ``rest`` (``--zupt``): ``t0_s``, ``t1_s``,
    intervals the vehicle stood still (zero-velocity updates every ``zupt_interval``,
    with ``zaru=True`` zero-rate updates too). Their options are the CLI's:
    ``odometer_std``, ``odometer_scale_std``, ``zupt_std``, ``nhc=True``, ... A 2-D
    array gives the columns in that order. A bad value raises :class:`InputError`
    naming ``<odometer array>`` (``<heading array>``, ``<rest array>``), the 1-based
    row and the column.

    ``options``: ``schuler nav``'s flags with underscores, e.g. ``init_pos=(lat_deg,
    lon_deg, h_m)``, ``init_vel=(vn, ve, vd)`` [m/s], ``init_att=(roll, pitch, yaw)``
    [deg], ``output_rate`` [Hz], ``start``/``end`` [s], ``lever_arm=(x, y, z)`` [m,
    FRD], ``imu_grade="tactical"``, ``gate``, ``arw="0.1 deg/sqrt(h)"``,
    ``scale_factors=True``, ``smooth=True``, ``mechanization``, ``earth``, ...

    How the run starts, as ``schuler nav``: from ``init_pos``/``init_vel``/``init_att``;
    with ``align=True`` after aligning at rest at ``init_pos`` on the log's first
    ``coarse`` + ``fine`` seconds (the alignment options of :func:`align`; the result
    carries it as ``alignment``); with ``init="gnss"`` in motion from the fixes (the
    course gives the heading: a land vehicle driving forward), ``init="gnss-any-heading"``
    the same with the heading found by a bank of 12 filters (both need ``gnss``).
    The GIL is released while the run goes on.
    """
    opts = _options(options)
    kwargs: Dict[str, Any] = {}
    if isinstance(imu, (str, os.PathLike)):
        opts["imu"] = os.fspath(imu)
    else:
        cols, dt = _imu(imu)
        opts["imu"] = "<imu array>"
        kwargs.update(imu=cols, imu_dt=dt)
    if isinstance(gnss, (str, os.PathLike)):
        opts["gnss"] = os.fspath(gnss)
    elif gnss is not None:
        kwargs["gnss"] = _gnss(gnss)
    if isinstance(baro, (str, os.PathLike)):
        opts["baro"] = os.fspath(baro)
    elif baro is not None:
        kwargs["baro"] = _baro(baro)
    given = dict(odometer=odometer, heading=heading, rest=rest)
    for name, option, columns in _VEHICLE:
        table = given[name]
        if isinstance(table, (str, os.PathLike)):
            opts[option] = os.fspath(table)
        elif table is not None:
            kwargs[name] = columns(table)
    return NavResult._of(_schuler.navigate(opts, **kwargs))


class Session:
    """A navigation session fed sample by sample or in blocks (live data, custom
    loops). ``options`` as :func:`navigate`'s (aids are pushed, not read from files);
    ``gnss=True``, ``baro=True``, ``odometer=True``, ``heading=True``, ``rest=True``
    set the filter up for the aids that will be pushed, as their files would (the
    vehicle aids' options, ``nhc=True``, ``odometer_scale_std`` and so on, likewise).
    The start is the given state: ``align`` and ``init="gnss"`` are :func:`navigate`'s.

    Aids pushed before the IMU reaches their time are applied at their own time;
    ``take()`` returns what was produced since the last call, ``finish()`` the rest
    with ``smoothed`` and ``summary``.
    """

    def __init__(
        self,
        gnss: bool = False,
        baro: bool = False,
        odometer: bool = False,
        heading: bool = False,
        rest: bool = False,
        **options: Any,
    ) -> None:
        opts = {**_options(options), "imu": "<session>"}
        self._native = _schuler.Session(opts, gnss, baro, rest=rest, odometer=odometer, heading=heading)

    def push_imu(self, t: float, dtheta: Sequence[float], dvel: Sequence[float], dt: Optional[float] = None) -> None:
        """One IMU sample: interval end ``t`` [s], increments ``dtheta`` [rad] and
        ``dvel`` [m/s] (FRD); ``dt`` [s] defaults to the time since the last sample
        (required for the first)."""
        self._native.push_imu(float(t), [float(x) for x in dtheta], [float(x) for x in dvel], dt)

    def push_imu_block(self, imu: Table) -> None:
        """A block of IMU samples, as :func:`navigate`'s ``imu`` table (read in place)."""
        cols, dt = _imu(imu)
        self._native.push_imu_block(cols, dt)

    def push_gnss(self, t: float, lat_deg: float, lon_deg: float, h_m: float, std_ned_m: Sequence[float], vel_ned_mps: Optional[Sequence[float]] = None, vel_std_ned_mps: Optional[Sequence[float]] = None) -> None:
        """One GNSS fix [s, deg, deg, m; std m; velocity m/s]."""
        self._native.push_gnss(t, lat_deg, lon_deg, h_m, list(std_ned_m), None if vel_ned_mps is None else list(vel_ned_mps), None if vel_std_ned_mps is None else list(vel_std_ned_mps))

    def push_baro(self, t: float, h_m: float) -> None:
        """One barometric height [m] at ``t`` [s]."""
        self._native.push_baro(t, h_m)

    def push_odometer(self, t: float, speed_mps: float) -> None:
        """One odometer reading: forward speed [m/s] at ``t`` [s] (a line of
        ``--odometer``'s file; needs ``odometer=True``)."""
        self._native.push_odometer(float(t), float(speed_mps))

    def push_heading(self, t: float, heading_deg: float, heading_std_deg: float, pitch_deg: Optional[float] = None, pitch_std_deg: Optional[float] = None) -> None:
        """One dual-antenna reading at ``t`` [s]: the baseline's heading from true north
        and its standard deviation [deg], optionally its pitch and standard deviation
        [deg] (a line of ``--dual-antenna``'s file; needs ``heading=True``)."""
        opt = lambda x: None if x is None else float(x)  # noqa: E731
        self._native.push_heading(float(t), float(heading_deg), float(heading_std_deg), opt(pitch_deg), opt(pitch_std_deg))

    def push_rest(self, t0_s: float, t1_s: float) -> None:
        """The vehicle at rest from ``t0_s`` to ``t1_s`` [s] (a line of ``--zupt``'s
        file; needs ``rest=True``); pushed before the IMU reaches ``t0_s``."""
        self._native.push_rest(float(t0_s), float(t1_s))

    def take(self) -> NavResult:
        """The tables produced since the last ``take``."""
        return NavResult._of(self._native.take())

    def finish(self) -> NavResult:
        """Ends the session: the remaining tables, ``smoothed`` and ``summary``."""
        return NavResult._of(self._native.finish())


@dataclass
class SimResult:
    """What :func:`simulate` gives, as DataFrames (the data of ``schuler simulate``'s
    files): ``imu`` (measured samples, :func:`read_imu`'s columns), ``truth`` (the
    exact trajectory at every IMU sample: :func:`read_nav`'s columns, then the true
    ``w_*_radps`` and ``f_*_mps2`` in body axes), ``gnss`` (:func:`read_gnss`'s columns
    and ``outlier``; None without ``[gnss]``), ``baro`` (``t_s``, ``h_m``,
    ``outlier``; None without ``[baro]``), ``sensor_errors`` (the true biases and
    scale factors once a second, ``imu_err.txt``'s units) and ``scenario`` (every
    parameter used, seed included, as TOML)."""

    imu: pd.DataFrame
    truth: pd.DataFrame
    gnss: Optional[pd.DataFrame]
    baro: Optional[pd.DataFrame]
    sensor_errors: pd.DataFrame
    scenario: str


def simulate(scenario: Union[PathLike, str, Mapping[str, Any]]) -> SimResult:
    """Simulate a ``schuler simulate`` scenario: a ``.toml`` file, TOML text, or a dict
    of the same keys (e.g. ``{"seed": 7, "start": {...}, "motion": [...], "imu":
    {"rate_hz": 200, "preset": "tactical"}, "gnss": {...}}``). The same scenario and
    seed give the same bits. The GIL is released while it runs."""
    if isinstance(scenario, Mapping):
        d = _schuler.simulate_scenario(json.dumps(scenario), "json")
    elif isinstance(scenario, os.PathLike) or (
        isinstance(scenario, str) and "\n" not in scenario and scenario.strip().endswith(".toml")
    ):
        d = _schuler.simulate_scenario(path=os.fspath(scenario))
    else:
        d = _schuler.simulate_scenario(scenario, "toml")
    opt = lambda k: None if d.get(k) is None else _frame(d[k])  # noqa: E731
    return SimResult(
        imu=_frame(d["imu"]),
        truth=_frame(d["truth"]),
        gnss=opt("gnss"),
        baro=opt("baro"),
        sensor_errors=_frame(d["sensor_errors"]),
        scenario=d["scenario"],
    )


#: Columns of a navigation table (:func:`read_nav`, ``NavResult.trajectory``).
NAV_COLUMNS = tuple(_schuler.NAV_COLUMNS)


@dataclass
class Comparison:
    """What :func:`compare` gives: ``errors`` per matched epoch (``errors.csv``:
    position north, east, down and horizontal [m] along the truth's NED axes,
    velocity [m/s], roll, pitch, yaw [deg], ``interpolated``) and ``summary``
    (``compare.json``: matched epochs, per quantity RMS, max, 95 %, mean, CEP/CEP95 [m],
    outage maxima)."""

    errors: pd.DataFrame
    summary: Dict[str, Any]


def _nav_input(x: Union[PathLike, Table]):
    if isinstance(x, (str, os.PathLike)):
        return os.fspath(x)
    return _columns(x, NAV_COLUMNS, "navigation table")


def compare(
    nav: Union[PathLike, Table],
    truth: Union[PathLike, Table],
    start: Optional[float] = None,
    end: Optional[float] = None,
    outages: Sequence[Sequence[float]] = (),
) -> Comparison:
    """Errors of a navigation result against a truth, as ``schuler compare``: both
    files (KF-GINS text, ``nav.csv``) or tables of :func:`read_nav`'s columns; matched
    by time (the truth interpolated where its epochs differ) within ``[start, end]``
    [s]; ``outages`` as ``(from_s, to_s)`` windows for the outage maxima."""
    d = _schuler.compare(_nav_input(nav), _nav_input(truth), start, end, [tuple(map(float, o)) for o in outages])
    errors = _frame(d["errors"])
    errors["interpolated"] = errors["interpolated"].astype(bool)
    return Comparison(errors=errors, summary=json.loads(d["summary"]))


def allan(imu: Union[PathLike, Table], per_decade: float = 10.0, max_tau: Optional[float] = None, **options: Any) -> pd.DataFrame:
    """Overlapping Allan deviations of a static IMU log's six channels, as ``schuler
    allan`` computes them: ``per_decade`` cluster times a decade up to ``max_tau`` [s]
    (default a tenth of the log). ``imu``: a file (read with the IMU input
    ``options``) or a table as :func:`navigate`'s. Columns ``tau_s``, ``m`` (cluster
    size), ``gyro_{x,y,z}_radps``, ``accel_{x,y,z}_mps2``."""
    if isinstance(imu, (str, os.PathLike)):
        d = _schuler.allan(path=os.fspath(imu), options=_options(options), per_decade=per_decade, max_tau=max_tau)
    else:
        if options:
            raise TypeError("reading options apply to files only")
        cols, dt = _imu(imu)
        d = _schuler.allan(imu=cols, imu_dt=dt, per_decade=per_decade, max_tau=max_tau)
    out = _frame(d)
    out["m"] = out["m"].astype(np.int64)
    return out


#: Columns of a campaign's table (``runs.csv``), after ``seed``: the CLI's own list.
CAMPAIGN_COLUMNS = tuple(_schuler.CAMPAIGN_COLUMNS)

Campaign = Union[PathLike, str, Mapping[str, Any]]


def _campaign_source(campaign: Campaign, portable: bool = False) -> Dict[str, Any]:
    """Keyword arguments of the native campaign function for a file, TOML text or a
    dict. ``portable``: a file is sent as its text (with its folder as ``base``), so
    that a worker on another machine needs only the files the campaign names."""
    if isinstance(campaign, Mapping):
        return {"text": json.dumps(campaign), "format": "json"}
    is_path = isinstance(campaign, os.PathLike) or (
        isinstance(campaign, str) and "\n" not in campaign and campaign.strip().endswith(".toml")
    )
    if not is_path:
        return {"text": campaign, "format": "toml"}
    path = os.fspath(campaign)
    if not portable:
        return {"path": path}
    with open(path, encoding="utf-8") as f:
        return {"text": f.read(), "format": "toml", "base": os.path.dirname(os.path.abspath(path))}


def _campaign_frame(columns: Mapping[str, Any]) -> pd.DataFrame:
    return pd.DataFrame({"seed": columns["seed"], **{c: columns[c] for c in CAMPAIGN_COLUMNS}})


def montecarlo(
    campaign: Campaign,
    runs: int,
    seed: int = 1,
    threads: Optional[int] = None,
    **options: Any,
) -> pd.DataFrame:
    """A Monte-Carlo campaign, as ``schuler montecarlo``: ``runs`` runs of a campaign
    (a ``.toml`` file, TOML text or a dict: a ``schuler simulate`` scenario with a
    ``[navigate]`` table of ``schuler nav`` options and an optional ``[campaign]``
    table), run ``k`` with the scenario seed ``seed + k``: simulated, navigated from
    the truth at its first sample, compared with the truth. ``options`` are nav's
    options over ``[navigate]``'s (they win). Returns one row per run, the
    columns of ``runs.csv`` (``seed``, then :data:`CAMPAIGN_COLUMNS`: error statistics
    [m, m/s, deg], time-averaged NEES of position, velocity and attitude (3 dof each),
    mean NIS per dof, rejected measurements), the same bits for any ``threads``
    (None: one per core). The GIL is released while it runs."""
    if runs < 1:
        raise ValueError("runs must be at least 1")
    seeds = [(seed + k) % 2**64 for k in range(runs)]
    d = _schuler.montecarlo_seeds(seeds, options=_options(options), threads=threads, **_campaign_source(campaign))
    return _campaign_frame(d)


@dataclass
class AlignResult:
    """What an alignment at rest gives (:func:`align`, ``NavResult.alignment``):
    ``summary`` (``align.json``: ``roll_deg``, ``pitch_deg``, ``yaw_deg`` and their
    ``_std_deg``; ``gyro_bias_dph`` [deg/h], ``accel_bias_mgal`` [mGal] and their
    ``_std_``; ``t_start``, ``t_coarse``, ``t_end`` [s]; the coarse stage, the
    predicted limits, observability, spikes, motion), ``convergence``
    (``align_convergence.csv``: ``t_s``, the attitude's standard deviations [deg],
    the gyro biases' [deg/h] and the accelerometer biases' [mGal] through the fine
    stage) and ``report`` (the text ``schuler align`` prints, without run times)."""

    summary: Dict[str, Any]
    convergence: pd.DataFrame
    report: str

    @classmethod
    def _of(cls, d: Mapping[str, Any]) -> "AlignResult":
        return cls(summary=json.loads(d["summary"]), convergence=_frame(d["convergence"]), report=d["report"])

    @property
    def attitude_deg(self) -> "tuple[float, float, float]":
        """Roll, pitch, yaw [deg] at the end of the alignment (yaw in [0, 360))."""
        return tuple(self.summary[k] for k in ("roll_deg", "pitch_deg", "yaw_deg"))

    @property
    def attitude_std_deg(self) -> "tuple[float, float, float]":
        """Standard deviations of roll, pitch, yaw [deg]."""
        return tuple(self.summary[k] for k in ("roll_std_deg", "pitch_std_deg", "yaw_std_deg"))


def align(imu: Union[PathLike, Table], pos: Sequence[float], **options: Any) -> AlignResult:
    """Align a log recorded at rest, as ``schuler align``: coarse gyrocompassing, then
    the Kalman filter on the invariants (Earth rate known, base still).

    ``imu``: a file (read with the IMU input options) or a table as :func:`navigate`'s.
    ``pos``: the base's latitude [deg], longitude [deg] and height [m]. ``options``:
    ``schuler align``'s flags with underscores: ``coarse``, ``fine``, ``block``
    (times with units, e.g. ``"190 s"``, ``"3 min"``; ``fine="0"`` for coarse only),
    ``imu_grade``, ``heading`` (``"DEG"`` or ``"DEG,STD_DEG"``: an external heading
    instead of gyrocompassing), ``max_heading_std`` [deg], ``start`` [s], ``earth``,
    and the IMU input options. The GIL is released while it runs."""
    opts = {**_options(options), "pos": _plain("pos", pos)}
    if isinstance(imu, (str, os.PathLike)):
        return AlignResult._of(_schuler.align({**opts, "imu": os.fspath(imu)}))
    cols, dt = _imu(imu)
    return AlignResult._of(_schuler.align({**opts, "imu": "<imu array>"}, imu=cols, imu_dt=dt))


@dataclass
class AllanFit:
    """What :func:`allan_fit` gives (``schuler allan``'s outputs): ``curves``
    (``allan.csv``: ``tau_s``, ``m``, per channel ``gyro_{x,y,z}_radps`` or
    ``accel_{x,y,z}_mps2``, its 95 % interval ``..._lo_...``, ``..._hi_...`` and the
    IEEE 952 fit ``..._fit_...``), ``fits`` (one row per channel, model and term:
    ``model`` ``ieee952`` (terms ``N``, ``B``, ``K``, ``Q``) or ``gauss_markov``
    (``N``, ``sigma``, ``K`` and the correlation time ``T`` [s]); ``value``, ``lo``,
    ``hi`` in SI (gyros: N rad/sqrt(s), B and sigma rad/s, K rad/s/sqrt(s), Q rad;
    accelerometers: N m/s/sqrt(s), B and sigma m/s^2, K m/s^2/sqrt(s), Q m/s) and the
    fit's ``chi2_per_dof``), ``report`` (the tables it prints, engineering units),
    ``noise_toml`` (``imu_noise.toml``: the filter model as ``schuler nav``'s
    ``[aiding]`` keys) and ``warnings`` (a log that moves or has gaps)."""

    curves: pd.DataFrame
    fits: pd.DataFrame
    report: str
    noise_toml: str
    warnings: List[str]


def allan_fit(imu: Union[PathLike, Table], **options: Any) -> AllanFit:
    """Allan deviations and their noise fits, as ``schuler allan``: the IEEE Std 952
    terms (random walk ``N``, bias instability ``B``, rate random walk ``K``,
    quantization ``Q``) and the filter's model (white noise, a Gauss-Markov bias of
    correlation time ``T``, a bias random walk), each with its 95 % interval.
    ``imu``: a file or a table as :func:`navigate`'s; ``options``: ``max_tau`` (a
    time with units, default a tenth of the log), ``start``, ``end`` [s] and the IMU
    input options (files only). The GIL is released while it runs."""
    flags = _flags(options)
    if isinstance(imu, (str, os.PathLike)):
        d = _schuler.allan_fit([os.fspath(imu)] + flags)
    else:
        cols, dt = _imu(imu)
        d = _schuler.allan_fit(["<imu array>"] + flags, imu=cols, imu_dt=dt)
    curves = _frame(d["curves"])
    curves["m"] = curves["m"].astype(np.int64)
    fits = _frame(d["fits"])[["channel", "model", "term", "value", "lo", "hi", "chi2_per_dof"]]
    return AllanFit(curves=curves, fits=fits, report=d["report"], noise_toml=d["noise_toml"], warnings=list(d["warnings"]))


@dataclass
class ChannelResult:
    """What :func:`channel` gives (``schuler channel``'s files): ``errors``
    (``errors.csv``: ``t_s``; position ``dr_m``, velocity ``dv_mps`` and vertical
    ``alpha_rad`` errors of the nonlinear system, then of the linear model
    (``_linear_``) and of the closed form (``_closed_``, NaN when the inputs are not
    constant)) and ``summary`` (``summary.json``: inputs in SI, the measured Schuler
    period, largest differences, peaks)."""

    errors: pd.DataFrame
    summary: Dict[str, Any]


def channel(**options: Any) -> ChannelResult:
    """The textbook's single-channel INS or SINS, as ``schuler channel``: the nonlinear
    ideal and perturbed systems (6)/(9) or (7)/(26), the linear error model (13)/(28)
    and the closed form (18)-(23) side by side. ``options``: its flags with
    underscores, values with units as the CLI takes them (``system="sins"``,
    ``accel_bias="1e-3m/s^2"``, ``gyro_drift="0.01deg/h"``, ``init_tilt="20arcsec"``,
    ``init_vel_error``, ``init_pos_error``, ``level=True``, ``earth_rate=...``,
    ``turn=["1h:180deg"]``, ``rotate``, ``speed``, ``accelerate``, ``duration="4h"``,
    ``dt``, ``radius``, ``g``). A list gives a repeated flag. The GIL is released
    while it runs."""
    flags: List[str] = []
    for name, v in options.items():
        if name in ("turn", "accelerate") and isinstance(v, (list, tuple)):
            flags += [f"--{name}={_value(x)}" for x in v]
        else:
            flags += _flags({name: v})
    d = _schuler.channel(flags + ["--out=<none>"])
    return ChannelResult(errors=_frame(d["errors"]), summary=json.loads(d["summary"]))


def closed_form(
    t: Any,
    accel_bias: float = 0.0,
    drift: float = 0.0,
    alpha0: float = 0.0,
    dv0: float = 0.0,
    dr0: float = 0.0,
    dh0: float = 0.0,
    dvh0: float = 0.0,
    vertical_accel_bias: float = 0.0,
    radius: float = 6.371e6,
    g: float = 9.81,
) -> pd.DataFrame:
    """The textbook's closed-form errors at the times ``t`` [s] (an array), SI
    throughout. Horizontal channel, general solution (18)/(19) of (13) for constant
    inputs (each alone gives (20)-(23)): accelerometer bias ``accel_bias`` [m/s^2],
    platform drift ``drift`` [rad/s] (a strapdown gyro's drift with its sign
    reversed), initial vertical error ``alpha0`` [rad], velocity error ``dv0``
    [m/s], position error ``dr0`` [m]: columns ``dr_m``, ``dv_mps``, ``alpha_rad``
    oscillating with the Schuler period ``2 pi sqrt(radius / g)`` (84.4 min for the
    defaults). Free vertical channel (32) from ``dh0`` [m], ``dvh0`` [m/s] and a
    vertical accelerometer error ``vertical_accel_bias`` [m/s^2]: ``dh_m``,
    ``dvh_mps``, growing with e-fold time ``1 / (sqrt(2) omega0)`` (570 s). On a sphere
    of ``radius`` [m] with vertical specific force ``g`` [m/s^2]."""
    return _frame(
        _schuler.closed_form(
            _f64(np.atleast_1d(t)),
            accel_bias=float(accel_bias),
            drift=float(drift),
            alpha0=float(alpha0),
            dv0=float(dv0),
            dr0=float(dr0),
            dh0=float(dh0),
            dvh0=float(dvh0),
            vertical_accel_bias=float(vertical_accel_bias),
            radius=float(radius),
            g=float(g),
        )
    )
