"""Gymnasium environments and wrappers: ``GridWorldEnv``, ``PlaneEnv``, ``MountainCarEnv``
and ``STLReward``.

``hstl`` loads this module on first use of one of them, so that ``import hstl`` does not
import gymnasium. ``import hstl`` registers the built-in worlds with gymnasium (when it is
imported, or as soon as it is; see ``_registration``): ``gymnasium.make("hstl/GridWorld-v0")``
is the paper's world, ``gymnasium.make("hstl/FourRooms-v0")`` the four rooms,
``gymnasium.make("hstl/Plane-v0", world=...)`` a plane world (``paper-plane`` by default),
``gymnasium.make("hstl/MountainCar-v0")`` the car without a task and
``gymnasium.make("hstl/MountainCarPatrol-v0", window=200)`` the car rewarded for keeping
its patrol, each with ``max_episode_steps=MAX_EPISODE_STEPS``. Without ``import hstl``
first, ``gymnasium.make("hstl:hstl/GridWorld-v0")`` imports it (gymnasium's ``module:id``
form).
"""

from __future__ import annotations

import os
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Union

import gymnasium
import numpy as np
import numpy.typing as npt
from gymnasium import spaces

from ._hstl import ContinuousWorld, EpisodeBatch, EpisodeMonitor, Generator, Spec, World, _mountain_car_patrol
from ._registration import MAX_EPISODE_STEPS, REGISTERED, register

__all__ = [
    "GridWorldEnv",
    "MAX_EPISODE_STEPS",
    "MountainCarEnv",
    "PlaneEnv",
    "REGISTERED",
    "STLReward",
    "make_mountain_car_patrol",
    "register",
]

_MAX_SEED = 2**64 - 1


def _world(world: Union[World, str, "os.PathLike[str]"]) -> World:
    if isinstance(world, World):
        return world
    return World._resolve(os.fspath(world))


def _seed_of(seed: Any) -> int:
    if isinstance(seed, (bool, float)) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"`seed` must be an integer; got {type(seed).__name__}")
    if not 0 <= int(seed) <= _MAX_SEED:
        raise ValueError(f"`seed` must be in 0..={_MAX_SEED}; got {seed}")
    return int(seed)


def _generator_for(env: gymnasium.Env[Any, Any], seed: Optional[int], current: Optional[Generator]) -> Generator:
    """The generator a reset steps ``env`` with: a new one from ``seed`` when given, else the
    one it has; with neither, one from the entropy gymnasium seeded ``np_random`` with."""
    if seed is not None:
        return Generator(_seed_of(seed))
    if current is not None:
        return current
    return Generator(int(env.np_random.integers(0, 2**63)))


def _action_of(action: Any, names: Sequence[str]) -> int:
    """``action`` as an index into ``names``: an integer (Python's or numpy's, or an integer
    array of one element, as agents give), never a float or a bool, in range."""
    value = action
    if isinstance(value, np.ndarray) and value.size == 1 and np.issubdtype(value.dtype, np.integer):
        value = value.reshape(()).item()
    n = len(names)
    listed = ", ".join(f"{i} {name}" for i, name in enumerate(names))
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"action {action!r} is not an integer of Discrete({n})\n  help: give one of {listed}")
    if not 0 <= int(value) < n:
        raise ValueError(f"action {action!r} is not in Discrete({n}) ({listed})")
    return int(value)


class GridWorldEnv(gymnasium.Env):
    """A grid world as a gymnasium environment, stepped in Rust.

    ``world`` is a ``hstl.World``, a built-in world's name (``"paper"``, the paper's 15 x 15
    open grid with slip 0.3, or ``"four-rooms"``) or a world file's path. The observation
    is the robot's cell ``(x, y)``: ``MultiDiscrete([width, height])`` (int64), ``x``
    counting columns from 0 at the left and ``y`` rows from 0 at the bottom, as a spec's
    ``state { x: int in 0..=W-1, y: int in 0..=H-1 }`` names them; only free cells occur.
    The actions are ``Discrete(4)``: 0 ``Up`` (y + 1), 1 ``Down``, 2 ``Left`` (x - 1),
    3 ``Right``. With probability ``world.slip`` one of the other three is taken instead,
    each equally likely; a move into a wall or off the map stays in place.

    Every random draw (starts and slips) comes from one Rust generator (ChaCha8, the
    learner's), seeded by ``reset(seed=...)`` and continued by ``reset()``, as gymnasium's
    conventions ask; the same seed and actions give the same cells as the Rust world
    drawing from that seed (``policy.evaluate(starts=1, seed=s)`` scores exactly the run
    that ``reset(seed=s)`` and ``policy.act`` give). The reward is always 0: the world has no task (wrap it in ``hstl.STLReward``).
    Episodes never terminate; the registered ids truncate them after
    ``MAX_EPISODE_STEPS``. ``info["state"]`` is the cell's state index
    (``world.free_cells[index]``). ``reset(options={"start": (x, y)})`` starts on a given
    free cell. ``render_mode="ansi"`` renders the map as text (``R`` the robot).
    """

    metadata = {"render_modes": ["ansi"], "render_fps": 4}

    def __init__(
        self, world: Union[World, str, "os.PathLike[str]"] = "paper", render_mode: Optional[str] = None
    ) -> None:
        self.world = _world(world)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'ansi'; got {render_mode!r}")
        self.render_mode = render_mode
        self.observation_space = spaces.MultiDiscrete([self.world.width, self.world.height], dtype=np.int64)
        self.action_space = spaces.Discrete(4)
        self._generator: Optional[Generator] = None
        self._state: Optional[int] = None
        self._cell = (0, 0)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[npt.NDArray[np.int64], dict[str, Any]]:
        super().reset(seed=seed)
        self._generator = _generator_for(self, seed, self._generator)
        start = (options or {}).get("start")
        if start is None:
            state, x, y = self.world._reset(self._generator)
        else:
            x, y = (int(v) for v in start)
            index = self.world._index(x, y)
            if index is None:
                raise ValueError(f"options['start'] = ({x}, {y}) is not a free cell of world `{self.world.name}`")
            state = index
        self._state, self._cell = state, (x, y)
        return np.array(self._cell, dtype=np.int64), {"state": state}

    def step(self, action: Any) -> tuple[npt.NDArray[np.int64], float, bool, bool, dict[str, Any]]:
        if self._state is None or self._generator is None:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a = _action_of(action, ("Up", "Down", "Left", "Right"))
        state, x, y = self.world._step(self._state, a, self._generator)
        self._state, self._cell = state, (x, y)
        return np.array(self._cell, dtype=np.int64), 0.0, False, False, {"state": state}

    def render(self) -> Optional[str]:
        if self.render_mode != "ansi":
            return None
        rows = [list(line) for line in self.world.map]
        if self._state is not None:
            x, y = self._cell
            rows[self.world.height - 1 - y][x] = "R"
        return "\n".join("".join(r) for r in rows) + "\n"


def _continuous(world: Union[ContinuousWorld, str, "os.PathLike[str]"], kind: str) -> ContinuousWorld:
    w = world if isinstance(world, ContinuousWorld) else ContinuousWorld._resolve(os.fspath(world))
    if w.kind != kind:
        other = "hstl.MountainCarEnv" if w.kind == "mountain-car" else "hstl.PlaneEnv"
        raise ValueError(f"world `{w.name}` is not a {kind} world\n  help: use {other} for it")
    return w


class _ContinuousEnv(gymnasium.Env):
    """A continuous world as a gymnasium environment, stepped in Rust (see ``PlaneEnv``)."""

    metadata: dict[str, Any] = {"render_modes": [], "render_fps": 30}

    def __init__(self, world: ContinuousWorld, render_mode: Optional[str]) -> None:
        if render_mode is not None:
            raise ValueError(f"render_mode must be None; got {render_mode!r}\n  help: this environment does not render")
        self.render_mode = render_mode
        self.world = world
        self.observation_space = spaces.Box(
            low=np.array(world.low, dtype=np.float64), high=np.array(world.high, dtype=np.float64), dtype=np.float64
        )
        self.action_space = spaces.Discrete(len(world.actions))
        self._generator: Optional[Generator] = None
        self._state: Optional[list[float]] = None

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[npt.NDArray[np.float64], dict[str, Any]]:
        super().reset(seed=seed)
        self._generator = _generator_for(self, seed, self._generator)
        start = (options or {}).get("start")
        if start is None:
            self._state = self.world._reset(self._generator)
        else:
            self._state = self.world._start(np.asarray(start, dtype=np.float64).tolist())
        return np.array(self._state, dtype=np.float64), {}

    def step(self, action: Any) -> tuple[npt.NDArray[np.float64], float, bool, bool, dict[str, Any]]:
        if self._state is None or self._generator is None:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a = _action_of(action, self.world.actions)
        self._state = self.world._step(self._state, a, self._generator)
        return np.array(self._state, dtype=np.float64), 0.0, False, False, {}


class PlaneEnv(_ContinuousEnv):
    """A plane world as a gymnasium environment, stepped in Rust.

    ``world`` is a ``hstl.ContinuousWorld`` of kind ``"plane"``, a built-in plane world's
    name (``"paper-plane"``: the paper's case study as a plane, 14 x 14, step 1, 4
    headings, slip 0.3, noise 0.1) or a world file's path (``kind = "plane"``; see the
    README's "Worlds"). The observation is the robot's position ``(x, y)``: a ``Box`` over
    the world's extent, float64, so that it is the state the learner sees bit for bit
    (float32 would round it). The actions are ``Discrete(headings)``: heading ``k`` moves
    ``step`` along the direction ``k * 360 / headings`` degrees counter-clockwise from east
    (``world.actions`` names them). With probability ``slip`` another heading is taken,
    then Gaussian noise is added; a move whose segment leaves the extent or touches an
    obstacle stays where it is (the contract "plane worlds" in DESIGN.md).

    Every random draw (starts, slips and noise) comes from one Rust generator (ChaCha8,
    the learner's), seeded by ``reset(seed=...)`` and continued by ``reset()``, exactly as
    ``GridWorldEnv`` does: the same seed and actions give the same positions, bit for bit,
    as the Rust world drawing from that seed. The reward is always 0 (the world has no
    task: wrap it in ``hstl.STLReward``); episodes never terminate, and the registered id
    ``hstl/Plane-v0`` truncates them after ``MAX_EPISODE_STEPS``.
    ``reset(options={"start": (x, y)})`` starts at a given free position. The environment
    pickles and deep-copies mid-episode (the copy continues with the same draws).
    """

    def __init__(
        self, world: Union[ContinuousWorld, str, "os.PathLike[str]"] = "paper-plane", render_mode: Optional[str] = None
    ) -> None:
        super().__init__(_continuous(world, "plane"), render_mode)


class MountainCarEnv(_ContinuousEnv):
    """Gymnasium's MountainCar-v0 dynamics, stepped in Rust, without its goal.

    The observation is ``(x, v)``, position and velocity: a ``Box`` over
    ``[-1.2, 0.6] x [-0.07, 0.07]``, float64 (gymnasium's MountainCar-v0 computes its
    state in float64 and rounds the observation to float32; here the observation is the
    state itself). The actions are ``Discrete(3)``: 0 ``left``, 1 ``none``, 2 ``right``.
    The states are gymnasium's bit for bit for the same start and actions
    (``MountainCarEnv().unwrapped.state`` there equals the observation here); unlike
    gymnasium, reaching ``x >= 0.5`` ends nothing (the task says what to reach) and the
    reward is always 0 (wrap it in ``hstl.STLReward``, or make
    ``hstl/MountainCarPatrol-v0``). A reset draws ``x`` uniformly in ``[-0.6, -0.4]``
    from the environment's one Rust generator (seeded by ``reset(seed=...)``, as
    ``GridWorldEnv``'s) and sets ``v = 0``; ``reset(options={"start": (x, v)})`` starts
    at a given state. The registered id ``hstl/MountainCar-v0`` truncates episodes after
    ``MAX_EPISODE_STEPS``.
    """

    def __init__(self, render_mode: Optional[str] = None) -> None:
        super().__init__(ContinuousWorld.builtin("mountain-car"), render_mode)


def make_mountain_car_patrol(
    window: int = 200,
    spec: Union[Spec, str, "os.PathLike[str]", None] = None,
    reward: Literal["robustness", "increment", "window", "sparse"] = "window",
) -> "STLReward":
    """``hstl/MountainCarPatrol-v0``: ``MountainCarEnv`` in ``STLReward`` for the patrol
    ``always[0..] (eventually[0..window] x < -1.0 && eventually[0..window] x > 0.4)`` (both
    hill tops within every ``window`` steps; ``examples/specs/mountain_car_patrol.hstl`` is
    ``window=200``). ``spec=`` gives another spec over ``x`` and ``v`` instead;
    ``reward`` is ``STLReward``'s (by default ``"window"``: 1 for each step whose windows
    are all kept). ``info["window_kept"]`` says whether a step's windows are kept."""
    if spec is None:
        if isinstance(window, (bool, float)) or not isinstance(window, (int, np.integer)):
            raise TypeError(f"`window` must be an integer; got {type(window).__name__}")
        spec = Spec.parse(_mountain_car_patrol(int(window)), filename=f"<MountainCarPatrol window={int(window)}>")
    return STLReward(MountainCarEnv(), spec, reward=reward)


Valuation = Union[Callable[[Any], Any], Mapping[str, Any], None]


class STLReward(gymnasium.Wrapper, gymnasium.utils.RecordConstructorArgs):
    """Rewards any environment with STL robustness computed in Rust, and reports the task's
    own success apart from the reward.

    ``valuation`` maps an observation to the spec's state variables: a callable
    (observation -> a dict of state variable values, or a sequence of them in
    ``spec.state_vars`` order), or a dict from each state variable to its index (or key)
    in the observation, such as ``{"x": 0, "y": 1}``. The spec is ``stl_spec`` (``spec`` is
    gymnasium's registration of the environment). Leave it out for a
    ``GridWorldEnv`` (its observation is ``(x, y)``) or an observation that is itself a
    dict of the state variables.

    ``reward`` picks what a step earns (then ``scale * value + offset``, ``scale`` positive,
    ``offset`` added to every step):

    - ``"robustness"`` (the default): ``rho(formula, t)``, described below;
    - ``"increment"``: the change of ``rho(formula, 0)`` over the trace so far since the
      step before, so an episode's rewards add up to the formula's robustness over the
      whole episode (the last ``info["task_robustness"]`` for the task; a value that is not
      finite counts as 0): a shaped reward with the task's own optimum;
    - ``"window"``: for a persistent task, 1 for a step whose windows are all kept
      (``info["window_kept"]``) and 0 otherwise, the learner's reward: an episode's sum is
      the number of kept steps, so longer episodes never earn less;
    - ``"sparse"``: ``rho(formula, 0)`` over the episode, on its last step (``terminated``
      or ``truncated``; put ``STLReward`` outside any ``TimeLimit``) and 0 before.

    The robustness reward of the step into state ``s_t`` is ``rho(formula, t)`` over the trace so far,
    ``s_0 ..= s_t`` (``s_0`` is the state ``reset`` returns), for the task or the ``let``
    called ``formula``. The future operators' windows are clipped at the end of the trace,
    so without a past-time operator this is the formula on ``s_t`` alone: for a state
    formula, such as a region ``let A = ...``, it is the full trace's signal
    (``hstlc monitor --signal``) at ``t``; a temporal operator sees only the present
    (``eventually[0..40] A`` gives ``A`` at ``t``). A past-time operator reads the states
    before: ``once[0..10] A`` is whether ``A`` held in the last 10 steps. Pick a region as
    ``formula`` for a dense reward.

    ``info`` (of ``reset`` and ``step``) holds the task's own measure, apart from the
    reward: ``task_robustness``, ``rho(task, 0)`` over the trace so far (what
    ``hstlc monitor`` prints for it), and for a persistent task
    (``always[0..] (eventually[0..N1] R1 && ...)``) ``window_kept``: whether every region
    held within its window ending at ``t``, the steps the window rate counts. ``step``'s
    ``info["env_reward"]`` is the wrapped environment's reward.

    The wrapper records its arguments as gymnasium asks (``env.spec`` lists it, so
    ``gymnasium.make(env.spec)`` makes it again) and passes ``check_env``. It pickles and
    deep-copies mid-episode (for ``SubprocVecEnv``, Ray, ``copy.deepcopy``) when the wrapped
    environment and ``valuation`` do (a dict valuation does; a lambda does not pickle): the
    copy continues the episode with the same rewards.

    Cost per step: the reward is one evaluation of the formula on one state; the task's
    robustness is kept up to date incrementally, not by scoring the whole trace again:
    O(1) amortised for a persistent task (``always[0..] (eventually[0..N1] R1 && ...)``)
    and for a bounded task once its horizon has passed, O(h) for ``always``/``eventually``
    over another body of horizon ``h`` (see the facade's ``hstl::reward``). A step is one
    call into Rust; a ``valuation`` given as a dict of observation indices is read there
    with no Python call (the cheapest form: about 1 us a step on top of the environment's,
    bench/field/RESULTS.md), a callable is called once a step.
    """

    def __init__(
        self,
        env: gymnasium.Env,
        spec: Union[Spec, str, "os.PathLike[str]"],
        valuation: Valuation = None,
        formula: Optional[str] = None,
        reward: Literal["robustness", "increment", "window", "sparse"] = "robustness",
        offset: float = 0.0,
        scale: float = 1.0,
    ) -> None:
        gymnasium.utils.RecordConstructorArgs.__init__(
            self, spec=spec, valuation=valuation, formula=formula, reward=reward, offset=offset, scale=scale
        )
        gymnasium.Wrapper.__init__(self, env)
        # `spec` is gymnasium's (the environment's registration) on a wrapper.
        self.stl_spec = spec if isinstance(spec, Spec) else Spec.load(spec)
        self.formula = formula
        self._monitor = EpisodeMonitor(self.stl_spec, formula, reward, offset, scale)
        self.reward_form = reward
        self.reward_offset = offset
        self.reward_scale = scale
        self._valuation = _valuation_of(env, self.stl_spec, valuation)
        # Indices into the observation are read in Rust at each step, with no Python call.
        indices = self._valuation.indices() if isinstance(self._valuation, _Picks) else None
        if indices is not None:
            self._monitor._observe(indices)
        self._step_valuation: Optional[Callable[[Any], Any]] = None if indices is not None else self._valuation

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None) -> tuple[Any, dict[str, Any]]:
        obs, info = self._monitor._reset(self.env.reset(seed=seed, options=options), self._step_valuation)
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        # One call into Rust scores the step and builds its info (see EpisodeMonitor._step).
        return self._monitor._step(self.env.step(action), self._step_valuation)


class STLVectorReward(gymnasium.vector.VectorWrapper):
    """``STLReward`` for a vector of environments (``gymnasium.vector.SyncVectorEnv``,
    ``AsyncVectorEnv``, ``gymnasium.make_vec``): one call into Rust a vector step scores
    every environment's new observation, so the cost of leaving Python is paid once for
    all of them.

    Each environment's episode is scored as ``STLReward`` scores it, with the same
    ``spec``, ``formula``, ``reward``, ``offset`` and ``scale``. ``valuation`` is a dict
    from each state variable to its index in an observation (``{"x": 0, "v": 1}``); the
    observations are the vector's, an array of shape ``(num_envs, ...)`` read as float64.
    The vector must reset each environment on the step after its episode ends
    (gymnasium's default ``AutoresetMode.NEXT_STEP``): that step's observation starts the
    environment's next episode and earns 0.

    ``info`` (of ``reset`` and ``step``) gains ``task_robustness`` (an array, one value an
    environment), for a persistent task ``window_kept``, and in ``step``
    ``env_reward`` (the vector's own rewards), each with its ``_name`` mask as vector
    environments give their infos.
    """

    def __init__(
        self,
        env: gymnasium.vector.VectorEnv,
        spec: Union[Spec, str, "os.PathLike[str]"],
        valuation: Mapping[str, int],
        formula: Optional[str] = None,
        reward: Literal["robustness", "increment", "window", "sparse"] = "robustness",
        offset: float = 0.0,
        scale: float = 1.0,
    ) -> None:
        super().__init__(env)
        mode = env.metadata.get("autoreset_mode", gymnasium.vector.AutoresetMode.NEXT_STEP)
        if mode not in (gymnasium.vector.AutoresetMode.NEXT_STEP, "NextStep"):
            raise ValueError(
                f"STLVectorReward needs a vector environment that resets an environment on the step after its episode ends; this one's autoreset_mode is {mode}\n"
                "  help: make the vector with autoreset_mode=gymnasium.vector.AutoresetMode.NEXT_STEP (gymnasium's default)"
            )
        self.stl_spec = spec if isinstance(spec, Spec) else Spec.load(spec)
        vars = self.stl_spec.state_vars
        if not isinstance(valuation, Mapping):
            raise TypeError(
                f"valuation must be a dict from state variables to observation indices; got {type(valuation).__name__}\n"
                '  help: pass a dict such as {"x": 0, "v": 1}'
            )
        missing = [v for v in vars if v not in valuation]
        if missing:
            raise _missing(f"valuation has no entry for state variable `{missing[0]}`", vars)
        self.formula = formula
        self.reward_form = reward
        self._batch = EpisodeBatch(self.stl_spec, self.num_envs, [int(valuation[v]) for v in vars], formula, reward, offset, scale)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[Any, dict[str, Any]]:
        return self._batch._reset(self.env.reset(seed=seed, options=options))

    def step(self, actions: Any) -> tuple[Any, npt.NDArray[np.float64], Any, Any, dict[str, Any]]:
        # One call into Rust scores every environment and builds the new info.
        return self._batch._step(self.env.step(actions))


def _valuation_of(env: gymnasium.Env, spec: Spec, valuation: Valuation) -> Callable[[Any], Any]:
    """The function from an observation to what ``EpisodeMonitor.push`` takes."""
    if callable(valuation):
        return valuation
    vars = spec.state_vars
    if isinstance(valuation, Mapping):
        missing = [v for v in vars if v not in valuation]
        if missing:
            raise _missing(f"valuation has no entry for state variable `{missing[0]}`", vars)
        return _Picks([(v, valuation[v]) for v in vars])
    if valuation is not None:
        raise TypeError(
            f"valuation must be a callable or a dict from state variables to observation indices; got {type(valuation).__name__}"
        )
    if isinstance(env.unwrapped, GridWorldEnv):
        extra = [v for v in vars if v not in ("x", "y")]
        if extra:
            raise TypeError(
                f"spec `{spec.name}` has state variable `{extra[0]}`, which a GridWorldEnv observation (x, y) does not give\n"
                "  help: pass valuation=, a function from the observation to the state variables"
            )
        if vars == ["x", "y"]:
            return _identity
        return _Picks([(v, 0 if v == "x" else 1) for v in vars])
    if isinstance(env.unwrapped, _ContinuousEnv):
        state = env.unwrapped.world.state_vars
        extra = [v for v in vars if v not in state]
        if extra:
            raise TypeError(
                f"spec `{spec.name}` has state variable `{extra[0]}`, which a {type(env.unwrapped).__name__} "
                f"observation ({', '.join(state)}) does not give\n"
                "  help: pass valuation=, a function from the observation to the state variables"
            )
        return _Picks([(v, state.index(v)) for v in vars])
    if isinstance(env.observation_space, spaces.Dict):
        return _identity
    raise TypeError(
        f"STLReward cannot read state variables from a {type(env.observation_space).__name__} observation\n"
        '  help: pass valuation=, a function from the observation to the state variables (or a dict such as {"x": 0, "y": 1})'
    )


def _identity(obs: Any) -> Any:
    """An observation that is the state itself (a module function, so that it pickles)."""
    return obs


class _Picks:
    """The state variables picked from an observation by index or key (a class, so that it
    pickles)."""

    def __init__(self, picks: Sequence[tuple[str, Any]]) -> None:
        self.picks = list(picks)

    def __call__(self, obs: Any) -> dict[str, Any]:
        return {v: obs[k] for v, k in self.picks}

    def indices(self) -> Optional[list[int]]:
        """The picks as observation indices, in order, when every one is an int."""
        if all(type(k) is int and k >= 0 for _, k in self.picks):
            return [k for _, k in self.picks]
        return None


def _missing(message: str, vars: Sequence[str]) -> Exception:
    from ._errors import MissingVariableError

    return MissingVariableError(f"{message}\n  help: the spec's state variables are {', '.join(f'`{v}`' for v in vars)}")

