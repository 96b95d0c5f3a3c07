"""Type stubs of the native module ``hstl._hstl`` (re-exported by ``hstl``)."""

from os import PathLike
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

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
#: How the windows at the end of a trace count: cut there (``"clipped"``, the default), or a
#: step counts only if its windows lie inside the trace (``"complete"``; later steps NaN).
Windows = Literal["clipped", "complete"]
#: A dense-time signal: the change points' times (int64 nanoseconds-style whole numbers for
#: whole-number stamps of 2^53 or more, float64 otherwise or with ``relative=True``) and
#: the value from each until the next (float64; a last NaN over complete windows: the times
#: from there on are undetermined).
DenseSignal = Tuple[npt.NDArray[Union[np.int64, np.uint64, np.float64]], npt.NDArray[np.float64]]
#: The largest gap allowed between consecutive stamps, in the time column's unit (a number,
#: or its text such as ``"0.5"``); None: any.
MaxGap = Union[int, float, str, None]
#: A dense-time row's stamp: an int stays a whole number (never rounded), a float is a
#: double.
Stamp = Union[int, float]
#: A dense-time row for ``OnlineMonitor.update(t, state)``: names to numbers (a variable
#: left out, None or NaN has no new sample), or one number per state variable (NaN: none).
DenseState = Union[Mapping[str, Optional[float]], Sequence[float]]
#: The most values a dense-time ``OnlineMonitor`` holds (2^27, 1 GiB of doubles).
MAX_ONLINE_VALUES: int
#: What ``hstl.STLReward`` rewards a step with (see its docs).
RewardForm = Literal["robustness", "increment", "window", "sparse"]

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

def check(
    path_or_text: Union[str, PathLike[str]], world: Union["World", str, PathLike[str], None] = None
) -> list[Diagnostic]:
    """Every diagnostic of a spec file or text (errors, warnings and notes, in source
    order), as ``hstlc check --format json`` gives them; the specs with options are checked
    against ``world`` too when one is given. A ``str`` with a newline or ``{`` is spec
    text, another ``str`` or an ``os.PathLike`` a path."""

def formula(text: str) -> Spec:
    """A spec whose task is the one formula ``text`` (``"always[0..=10] x > 0.5"``): its
    state variables are the names the formula reads, floats in order of appearance; its
    name ``Formula``, its filename ``<formula>``."""

def explain(code: str) -> str:
    """The long explanation of a diagnostic code (``"HSTL150"``), as ``hstlc explain``
    prints it; ``ValueError`` for an unknown code."""

def cli(argv: Sequence[str]) -> int:
    """Runs the ``hstlc`` command line with ``argv`` (the program's name first) on this
    process's standard input, output and error, and returns its exit status: the native
    binary's own code (``hstlc::run``). The ``hstlc`` command of the wheel calls it."""

class Spec:
    """A checked hstl spec, ready to monitor traces."""

    @staticmethod
    def load(path: Union[str, PathLike[str]], name: Optional[str] = None) -> Spec: ...
    @staticmethod
    def parse(text: str, filename: str = "<string>", name: Optional[str] = None) -> Spec: ...
    @staticmethod
    def _unpickle(text: str, filename: str, name: Optional[str]) -> Spec: ...
    @staticmethod
    def _unpickle_formula(text: str) -> Spec: ...
    @property
    def name(self) -> str: ...
    @property
    def filename(self) -> str: ...
    @property
    def world(self) -> Optional[str]: ...
    @property
    def source(self) -> str: ...
    @property
    def is_continuous(self) -> bool: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def time_var(self) -> Optional[str]:
        """The time variable of a dense-time spec (its trace column holds each row's
        stamp); None for a discrete-time spec."""
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
        windows: Windows = "clipped",
        max_gap: MaxGap = None,
    ) -> float:
        """The robustness at step 0 (a dense-time spec: at the first stamp); NaN when
        undetermined over complete windows. ``max_gap`` (dense-time specs) refuses a gap
        between consecutive stamps larger than it."""
    def signal(
        self,
        trace: Trace,
        formula: Optional[str] = None,
        *,
        columns: Optional[Sequence[str]] = None,
        windows: Windows = "clipped",
        max_gap: MaxGap = None,
        relative: bool = False,
    ) -> Union[npt.NDArray[np.float64], DenseSignal]:
        """A discrete-time spec: one float64 value per step. A dense-time spec: the
        ``(times, values)`` of the signal's change points, the rows of ``hstlc monitor
        --signal`` (``relative=True``: times from the first stamp, ``--relative``)."""
    def signal_batch(
        self,
        traces: Batch,
        formula: Optional[str] = None,
        *,
        columns: Optional[Sequence[str]] = None,
        threads: Optional[int] = None,
        windows: Windows = "clipped",
        max_gap: MaxGap = None,
        relative: bool = False,
    ) -> Union[npt.NDArray[np.float64], list[DenseSignal]]:
        """A discrete-time spec: an array (traces, steps). A dense-time spec: a list of
        traces in, a list of ``(times, values)`` out, as ``signal`` gives them."""
    def online(
        self,
        formula: Optional[str] = None,
        *,
        windows: Windows = "clipped",
        max_gap: MaxGap = None,
        relative: bool = False,
    ) -> OnlineMonitor:
        """An online monitor; a dense-time spec's takes ``update(t, state)``.
        ``windows="complete"``: values only where every window lies inside the trace."""

class OnlineMonitor:
    """A monitor fed one state at a time; see ``help(hstl.OnlineMonitor)``. It pickles
    and deep-copies mid-trace, dense-time ones included."""

    @property
    def horizon(self) -> Optional[int]: ...
    @property
    def steps(self) -> int: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def time_var(self) -> Optional[str]:
        """The time variable of a dense-time monitor; None for a discrete-time one."""
    @overload
    def update(self, state: State, row: None = None) -> Optional[Tuple[int, float]]:
        """Discrete time: the verdict this state completes, ``(step, value)``, or None."""
    @overload
    def update(self, state: Stamp, row: DenseState) -> list[Tuple[Stamp, float]]:
        """Dense time: ``update(t, state)`` appends the row stamped ``t`` and returns the
        change points it decided, ``[(t, value), ...]``."""
    def provisional(self) -> Optional[float]:
        """Discrete time only: the value the first open step would have if the trace
        ended now."""
    def finish(self) -> list[Tuple[Any, float]]:
        """Ends the trace: the verdicts still open (``(step, value)``; dense time: the
        change points up to the last stamp, ``(t, value)``)."""
    def __deepcopy__(self, memo: dict[int, Any]) -> OnlineMonitor: ...
    def __copy__(self) -> OnlineMonitor: ...
    @staticmethod
    def _restore(
        spec: Spec,
        formula: Optional[str],
        skipped: int,
        states: Sequence[float],
        windows: Windows = "clipped",
    ) -> OnlineMonitor: ...
    @staticmethod
    def _restore_dense(spec: Spec, formula: Optional[str], state: dict[str, object]) -> OnlineMonitor: ...

#: The most training episodes ``hstl.train`` takes (as ``learn { episodes }``).
MAX_EPISODES: int
#: Every built-in world's name: grids, planes, then the others.
BUILTIN_WORLDS: list[str]
#: ``hstl.study`` measures the policy of seed ``s`` as ``policy.evaluate(seed=s ^ EVAL_SEED)``.
EVAL_SEED: int
#: The `learn` values `hstl.tune` takes from a config (see `hstl.tune.LEARN_KEYS`).
LEARN_KEYS: list[str]

#: A world file's path, as ``World.load`` and ``hstl.train`` take it.
PathArg = Union[str, PathLike[str]]

class World:
    """A grid world: built in, or read from a world file; see ``help(hstl.World)``."""

    @staticmethod
    def load(path: PathArg) -> World: ...
    @staticmethod
    def builtin(name: str) -> World: ...
    @staticmethod
    def parse(text: str, filename: str = "<string>", name: str = "world") -> World: ...
    @property
    def name(self) -> str: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def slip(self) -> float: ...
    @property
    def map(self) -> list[str]: ...
    @property
    def free_cells(self) -> list[Tuple[int, int]]: ...
    @property
    def starts(self) -> list[Tuple[int, int]]: ...
    @property
    def num_states(self) -> int: ...
    @property
    def actions(self) -> list[str]: ...
    @property
    def file(self) -> Optional[str]: ...
    def is_free(self, x: int, y: int) -> bool: ...
    @staticmethod
    def _resolve(arg: str) -> World: ...
    def _reset(self, generator: Generator) -> Tuple[int, int, int]: ...
    def _step(self, state: int, action: int, generator: Generator) -> Tuple[int, int, int]: ...
    def _index(self, x: int, y: int) -> Optional[int]: ...

class ContinuousWorld:
    """A continuous world: a plane world or ``mountain-car``; see ``help(hstl.ContinuousWorld)``."""

    @staticmethod
    def load(path: PathArg) -> ContinuousWorld: ...
    @staticmethod
    def builtin(name: str) -> ContinuousWorld: ...
    @staticmethod
    def parse(text: str, filename: str = "<string>", name: str = "world") -> ContinuousWorld: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def actions(self) -> list[str]: ...
    @property
    def low(self) -> list[float]: ...
    @property
    def high(self) -> list[float]: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def params_json(self) -> str: ...
    @staticmethod
    def _resolve(arg: str) -> ContinuousWorld: ...
    def _reset(self, generator: Generator) -> list[float]: ...
    def _step(self, state: Sequence[float], action: int, generator: Generator) -> list[float]: ...
    def _start(self, state: Sequence[float]) -> list[float]: ...

def _mountain_car_patrol(window: int) -> str: ...

class Generator:
    """The one random generator of a ``GridWorldEnv`` (ChaCha8, as the learner's); it
    pickles and copies by its whole state."""

    def __init__(self, seed: int) -> None: ...
    @staticmethod
    def _from_state(key: Sequence[int], stream: int, pos_high: int, pos_low: int) -> Generator: ...

class Policy:
    """A trained policy and its ``policy.json``; see ``help(hstl.Policy)``."""

    @staticmethod
    def load(path: PathArg) -> Policy: ...
    @staticmethod
    def from_json(text: str, filename: str = "<string>") -> Policy: ...
    def save(self, path: PathArg) -> None: ...
    @property
    def json(self) -> str: ...
    @property
    def spec(self) -> Spec: ...
    @property
    def spec_name(self) -> str: ...
    @property
    def world(self) -> Union[World, ContinuousWorld, None]: ...
    @property
    def learned_function(self) -> bool: ...
    @property
    def env_name(self) -> str: ...
    @property
    def seed(self) -> Optional[int]: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def actions(self) -> list[str]: ...
    @property
    def options(self) -> list[str]: ...
    @property
    def curve(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def steps(self) -> Optional[int]: ...
    @property
    def q_tables(self) -> dict[str, Any]: ...
    def act(self, state: Union[int, State]) -> int: ...
    def reset(self) -> None: ...
    def evaluate(
        self,
        starts: int = 100,
        steps: Optional[int] = None,
        burn_in: int = 100,
        seed: int = 0,
        optimum: bool = True,
        *,
        env: Any = None,
        valuation: Any = None,
    ) -> dict[str, Any]: ...

class EpisodeBatch:
    """Scores the episodes of a vector of environments, one call a vector step, for
    ``hstl.STLVectorReward``."""

    def __init__(
        self,
        spec: Spec,
        envs: int,
        indices: Sequence[int],
        formula: Optional[str] = None,
        reward: RewardForm = "robustness",
        offset: float = 0.0,
        scale: float = 1.0,
    ) -> None: ...
    def _reset(self, result: Tuple[Any, dict[str, Any]]) -> Tuple[Any, dict[str, Any]]: ...
    def _step(
        self, result: Tuple[Any, Any, Any, Any, dict[str, Any]]
    ) -> Tuple[Any, npt.NDArray[np.float64], Any, Any, dict[str, Any]]: ...
    @property
    def envs(self) -> int: ...
    @property
    def persistent(self) -> bool: ...

class EpisodeMonitor:
    """Scores an episode state by state, for ``hstl.STLReward``; it pickles and
    deep-copies mid-episode."""

    def __init__(
        self,
        spec: Spec,
        formula: Optional[str] = None,
        reward: RewardForm = "robustness",
        offset: float = 0.0,
        scale: float = 1.0,
    ) -> None: ...
    def reset(self) -> None: ...
    def push(self, state: State, last: bool = False) -> Tuple[float, float, Optional[bool]]: ...
    def _observe(self, indices: Sequence[int]) -> None: ...
    def _step(
        self, result: Tuple[Any, Any, Any, Any, Any], valuation: Optional[Callable[[Any], Any]] = None
    ) -> Tuple[Any, float, bool, bool, dict[str, Any]]: ...
    def _reset(
        self, result: Tuple[Any, Any], valuation: Optional[Callable[[Any], Any]] = None
    ) -> Tuple[Any, dict[str, Any]]: ...
    @staticmethod
    def _restore(
        spec: Spec,
        formula: Optional[str],
        reward: RewardForm,
        offset: float,
        scale: float,
        states: Sequence[float],
        picks: Optional[Sequence[int]] = None,
    ) -> EpisodeMonitor: ...
    @property
    def reward(self) -> RewardForm: ...
    @property
    def offset(self) -> float: ...
    @property
    def scale(self) -> float: ...
    @property
    def state_vars(self) -> list[str]: ...
    @property
    def persistent(self) -> bool: ...
    @property
    def steps(self) -> int: ...

def _train_world(
    spec: Spec,
    world: World,
    seed: int,
    episodes: Optional[int] = None,
    progress: Any = None,
) -> Policy: ...
def _train_continuous(
    spec: Spec,
    world: ContinuousWorld,
    seed: int,
    episodes: Optional[int] = None,
    progress: Any = None,
) -> Policy: ...
def _train_box(
    spec: Spec,
    env: Any,
    valuation: Any,
    seed: int,
    name: str,
    low: Sequence[float],
    high: Sequence[float],
    actions: int,
    action_start: int,
    episodes: Optional[int] = None,
    progress: Any = None,
) -> Policy: ...
def _resolve_any_world(arg: str) -> Union[World, ContinuousWorld]: ...
def _train_env(
    spec: Spec,
    env: Any,
    valuation: Any,
    seed: int,
    name: str,
    observations: int,
    observation_start: int,
    actions: int,
    action_start: int,
    episodes: Optional[int] = None,
    progress: Any = None,
) -> Policy: ...

# Studies and Ray Tune (hstl.study, hstl.tune): the facade's hstl::study and hstl::train.

#: One seed's figures: ``seed``, ``window_rate`` (or None), ``reward``, ``seconds``,
#: ``steps`` and ``curve``.
SeedRun = dict[str, Any]

def _study_task(
    spec: Spec, world: Union[World, ContinuousWorld], episodes: Optional[int] = None
) -> Tuple[str, int, Optional[str]]:
    """Checks the spec against the world: (name, episodes, a key of its regions or None)."""
    ...

def _study_seeds(
    spec: Spec,
    world: Union[World, ContinuousWorld],
    seeds: Sequence[int],
    episodes: Optional[int] = None,
    threads: int = 1,
) -> list[SeedRun]:
    """Trains the spec for each seed on ``threads`` threads, the GIL released."""
    ...

def _study_optimum(spec: Spec, world: Union[World, ContinuousWorld]) -> Optional[float]:
    """W* of the spec's regions in the world, or None for a task without regions."""
    ...

def _study_summary(runs: Sequence[SeedRun], optimum: Optional[float] = None) -> dict[str, Any]:
    """Mean, sd, min and max of ``seconds``, ``reward``, ``window_rate`` and ``ratio``."""
    ...

class _StudyOut:
    """A study's output folder, each spec's folder locked from now on and written whole."""

    def __init__(self, out: PathArg, paths: Sequence[PathArg], force: bool = False) -> None: ...
    def write(
        self,
        specs: Sequence[Spec],
        world: World,
        runs: Sequence[Sequence[SeedRun]],
        episodes: Optional[int] = None,
        optima: Optional[Sequence[Optional[float]]] = None,
    ) -> list[PathLike[str]]: ...

def _train_chunks(
    spec: Spec,
    world: World,
    seed: int,
    chunk: int,
    report: Any,
    learn: Optional[Mapping[str, float]] = None,
) -> int:
    """Trains in chunks of episodes, ``report(episodes, reward, window_rate, robustness)``
    after each (True stops); the episodes trained."""
    ...
