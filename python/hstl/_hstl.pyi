"""Type stubs of the native module ``hstl._hstl`` (re-exported by ``hstl``)."""

from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

#: One trace: a mapping from state variable names to 1-D arrays or sequences of numbers
#: (a dict, a pandas DataFrame, a numpy structured array), or a 2-D array of shape
#: (steps, columns).
Trace = Union[Mapping[str, Any], npt.ArrayLike]
#: Many traces: a sequence of traces, a 3-D array of shape (traces, steps, columns), or a
#: mapping from state variable names to 2-D arrays of shape (traces, steps).
Batch = Union[Sequence[Trace], Mapping[str, Any], npt.ArrayLike]
#: One state for the online monitor: names to numbers, or numbers in state-variable order.
State = Union[Mapping[str, float], Sequence[float], npt.ArrayLike]

class Diagnostic:
    """One diagnostic, positioned as ``hstlc check --format json`` gives it (1-based,
    columns in characters, the end exclusive)."""

    file: str
    severity: str
    code: str
    message: str
    line: int
    column: int
    end_line: int
    end_column: int
    help: Optional[str]
    def __init__(
        self,
        file: str,
        severity: str,
        code: str,
        message: str,
        line: int,
        column: int,
        end_line: int,
        end_column: int,
        help: Optional[str] = None,
    ) -> None: ...

class Spec:
    """A checked hstl spec, ready to monitor traces."""

    @staticmethod
    def load(path: Union[str, PathLike[str]], name: Optional[str] = None) -> Spec: ...
    @staticmethod
    def parse(text: str, filename: str = "<string>", name: Optional[str] = None) -> Spec: ...
    @property
    def name(self) -> str: ...
    @property
    def filename(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def lets(self) -> list[str]: ...
    @property
    def diagnostics(self) -> list[Diagnostic]: ...
    def horizon(self, formula: Optional[str] = None) -> Optional[int]: ...
    def robustness(
        self,
        trace: Trace,
        formula: Optional[str] = None,
        *,
        columns: Optional[Sequence[str]] = None,
    ) -> float: ...
    def signal(
        self,
        trace: Trace,
        formula: Optional[str] = None,
        *,
        columns: Optional[Sequence[str]] = None,
    ) -> npt.NDArray[np.float64]: ...
    def signal_batch(
        self,
        traces: Batch,
        formula: Optional[str] = None,
        *,
        columns: Optional[Sequence[str]] = None,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.float64]: ...
    def online(self, formula: Optional[str] = None) -> OnlineMonitor: ...

class OnlineMonitor:
    """A monitor fed one state at a time; see ``help(hstl.OnlineMonitor)``."""

    @property
    def horizon(self) -> Optional[int]: ...
    @property
    def steps(self) -> int: ...
    @property
    def state_vars(self) -> list[str]: ...
    def update(self, state: State) -> Optional[Tuple[int, float]]: ...
    def provisional(self) -> Optional[float]: ...
    def finish(self) -> list[Tuple[int, float]]: ...
