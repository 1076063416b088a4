"""Type stubs of the native module ``schuler._schuler`` (dicts of numpy arrays; the
package's Python layer makes DataFrames of them)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

class SchulerError(ValueError): ...

class InputError(SchulerError):
    path: str
    line: int
    field: Optional[str]
    kind: str

#: Columns of a campaign's table (``runs.csv``) after ``seed``.
CAMPAIGN_COLUMNS: List[str]
#: Columns of a navigation table: ``t_s``, ``lat_deg`` [deg], ... ``yaw_deg`` [deg].
NAV_COLUMNS: List[str]

#: A run's description: ``schuler nav``'s flags with underscores as keys, plain values.
Options = Dict[str, Any]

def read_imu(path: str, options: Options) -> Dict[str, F64]: ...
def read_gnss(path: str, options: Options) -> Dict[str, F64]: ...
def read_baro(path: str) -> Dict[str, List[float]]: ...
def read_nav(path: str) -> Dict[str, F64]: ...
def navigate(
    options: Options,
    imu: Optional[Sequence[F64]] = None,
    imu_dt: Optional[F64] = None,
    gnss: Optional[Sequence[F64]] = None,
    baro: Optional[Tuple[F64, F64]] = None,
    rest: Optional[Sequence[F64]] = None,
    odometer: Optional[Sequence[F64]] = None,
    heading: Optional[Sequence[F64]] = None,
) -> Dict[str, Any]:
    """``schuler nav``; ``rest``: ``t0_s, t1_s`` [s]; ``odometer``: ``t_s, speed_mps``
    [s, m/s]; ``heading``: ``t_s, heading_deg, heading_std_deg[, pitch_deg,
    pitch_std_deg]`` [s, deg]."""
    ...

class Session:
    def __init__(
        self,
        options: Options,
        gnss: bool = False,
        baro: bool = False,
        rest: bool = False,
        odometer: bool = False,
        heading: bool = False,
    ) -> None: ...
    def push_imu(
        self, t: float, dtheta: Sequence[float], dvel: Sequence[float], dt: Optional[float] = None
    ) -> None: ...
    def push_imu_block(self, cols: Sequence[F64], dt: Optional[F64] = None) -> None: ...
    def push_gnss(
        self,
        t: float,
        lat_deg: float,
        lon_deg: float,
        h_m: float,
        std_ned_m: Sequence[float],
        vel_ned_mps: Optional[Sequence[float]] = None,
        vel_std_ned_mps: Optional[Sequence[float]] = None,
    ) -> None: ...
    def push_baro(self, t: float, h_m: float) -> None: ...
    def push_rest(self, t0_s: float, t1_s: float) -> None:
        """At rest from ``t0_s`` to ``t1_s`` [s]."""
        ...
    def push_odometer(self, t: float, speed_mps: float) -> None:
        """Forward speed [m/s] at ``t`` [s]."""
        ...
    def push_heading(
        self,
        t: float,
        heading_deg: float,
        heading_std_deg: float,
        pitch_deg: Optional[float] = None,
        pitch_std_deg: Optional[float] = None,
    ) -> None:
        """Dual-antenna baseline heading and pitch with their std [deg] at ``t`` [s]."""
        ...
    def take(self) -> Dict[str, Any]: ...
    def finish(self) -> Dict[str, Any]: ...

def simulate_scenario(
    text: Optional[str] = None, format: str = "toml", path: Optional[str] = None
) -> Dict[str, Any]: ...
def compare(
    nav: Any,
    truth: Any,
    start: Optional[float] = None,
    end: Optional[float] = None,
    outages: Sequence[Tuple[float, float]] = (),
) -> Dict[str, Any]: ...
def allan(
    path: Optional[str] = None,
    options: Optional[Options] = None,
    imu: Optional[Sequence[F64]] = None,
    imu_dt: Optional[F64] = None,
    per_decade: float = 10.0,
    max_tau: Optional[float] = None,
) -> Dict[str, F64]: ...
def montecarlo_seeds(
    seeds: List[int],
    path: Optional[str] = None,
    text: Optional[str] = None,
    format: str = "toml",
    base: Optional[str] = None,
    options: Optional[Options] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]: ...
def allan_fit(
    flags: List[str], imu: Optional[Sequence[F64]] = None, imu_dt: Optional[F64] = None
) -> Dict[str, Any]:
    """``schuler allan`` (``flags[0]`` the file): ``curves``, ``fits`` (SI),
    ``report``, ``noise_toml``, ``warnings``."""
    ...

def align(
    options: Options, imu: Optional[Sequence[F64]] = None, imu_dt: Optional[F64] = None
) -> Dict[str, Any]:
    """``schuler align``: ``summary`` (align.json text), ``convergence`` [s, deg,
    deg/h, mGal], ``report``."""
    ...

def channel(flags: List[str]) -> Dict[str, Any]:
    """``schuler channel``: ``errors`` [s, m, m/s, rad], ``summary`` (JSON text)."""
    ...

def closed_form(
    t: F64,
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
) -> Dict[str, F64]:
    """(18)-(23) and (32) at ``t`` [s], SI in and out."""
    ...
