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

def read_imu(path: str, flags: List[str]) -> Dict[str, F64]: ...
def read_gnss(path: str, flags: List[str]) -> Dict[str, F64]: ...
def read_baro(path: str) -> Dict[str, List[float]]: ...
def read_nav(path: str) -> Dict[str, F64]: ...
def navigate(
    flags: List[str],
    imu: Optional[Sequence[F64]] = None,
    imu_dt: Optional[F64] = None,
    gnss: Optional[Sequence[F64]] = None,
    baro: Optional[Tuple[F64, F64]] = None,
) -> Dict[str, Any]: ...

class Session:
    def __init__(self, flags: List[str], gnss: bool = False, baro: bool = False) -> None: ...
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
    flags: List[str] = ...,
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
    flags: List[str] = ...,
    threads: Optional[int] = None,
) -> Dict[str, Any]: ...
