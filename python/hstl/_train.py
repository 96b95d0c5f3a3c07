"""``hstl.train``: the HSTL learner in a grid or continuous world (native) or a gymnasium
environment."""

from __future__ import annotations

import os
import sys
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from . import _hstl
from ._hstl import ContinuousWorld, Policy, Spec, World

_MAX_SEED = 2**64 - 1


#: What ``valuation=`` takes: a function from an observation to the state variables (a
#: dict, or numbers in ``spec.state_vars`` order), or for a ``Box`` observation a dict from
#: each state variable to its index in the observation.
Valuation = Union[Callable[[Any], Union[Mapping[str, float], Sequence[float]]], Mapping[str, int]]


def train(
    spec: Union[Spec, str, "os.PathLike[str]"],
    world: Union[World, ContinuousWorld, str, "os.PathLike[str]", None] = None,
    seed: int = 0,
    episodes: Optional[int] = None,
    progress: Optional[bool] = None,
    *,
    env: Any = None,
    valuation: Optional[Valuation] = None,
) -> Policy:
    """Trains ``spec`` with the hierarchical learner and returns the ``hstl.Policy``.

    ``spec`` is a ``hstl.Spec`` or a spec file's path; ``world`` a ``hstl.World`` (a grid),
    a ``hstl.ContinuousWorld`` (a plane world or ``mountain-car``), a built-in world's name
    (``"paper"``, ``"four-rooms"``, ``"paper-plane"``, ``"mountain-car"``) or a world
    file's path. By default the world is the one the spec names (``world "...";``, a path
    relative to the spec file), or when it names none ``"paper"`` (``"paper-plane"`` for a
    spec over ``float`` variables); ``world=`` overrides it. The spec is checked against the
    world first (raising ``hstl.SpecError`` with the diagnostics of ``hstlc check
    --world``), and the policy's ``policy.json`` is byte for byte what ``hstlc train SPEC
    --world WORLD --seed SEED --episodes EPISODES`` writes: Q-tables in a grid world, a
    learned function (the approximate learner's tiling and weights) in a continuous one,
    trained natively at the command line's speed.
    ``episodes`` overrides the spec's ``learn { episodes }`` (1 to ``MAX_EPISODES``); every
    random draw comes from one generator seeded with ``seed`` (0 to 2**64 - 1), so the
    same seed gives the same Q-tables, bit for bit.

    ``env=`` trains in a gymnasium environment instead, with ``Discrete`` actions. With a
    ``Box`` observation space the approximate learner runs (the spec's state variables are
    ``float`` ranges, which it tiles): the ``Box`` must be bounded (finite ``low`` and
    ``high``; an unbounded one is refused), every observation must lie in it and be
    finite, and ``valuation`` maps an observation (a float64 array) to the spec's state
    variables: a function returning a dict or numbers in ``spec.state_vars`` order, or a
    dict such as ``{"x": 0, "v": 1}`` from each variable to its index. Without
    ``valuation`` the observation's components are the state variables in order (there
    must be as many). Each value must lie in the range the spec declares. A step that is
    ``terminated`` or ``truncated`` leaves the learner's episode in that state until it
    next resets the environment (give episodes room, such as ``env.unwrapped`` or a long
    ``TimeLimit``). ``hstl.PlaneEnv`` and ``hstl.MountainCarEnv`` train this way too, one
    Python call a step; ``world=`` trains their worlds natively, much faster.

    With a ``Discrete`` observation space the tabular learner runs (observations are the
    learner's states) and ``valuation(obs)``
    gives each observation's state variables (a dict, or numbers in ``spec.state_vars``
    order; every observation its own values, each in its declared ``int`` range). Every
    step calls back into Python, so it is much slower than a native world. Each episode
    of the learner starts with ``env.reset(seed=s)``, ``s`` drawn from the one generator;
    a step that is ``terminated`` or ``truncated`` ends the learner's episode there (its
    option and the rest of its ``choices``), and the next episode resets the environment,
    so ``policy.steps`` counts only the ``env.step`` calls made; a ``terminated`` state is
    valued as one the robot never leaves (a ``truncated`` one as usual). The actions of the policy
    are the environment's (``policy.act`` returns one).

    ``progress``: a progress bar on standard error (tqdm's when it is installed); by default
    only when standard error is a terminal. The GIL is released while the learner runs;
    Ctrl-C stops it with ``KeyboardInterrupt``.
    """
    spec = spec if isinstance(spec, Spec) else Spec.load(spec)
    seed = _seed_of(seed)
    if episodes is not None:
        episodes = _count_of(episodes, "episodes")
    with _Progress(progress) as bar:
        if env is None:
            if valuation is not None:
                raise TypeError("`valuation` goes with `env=`; a world gives its own (x, y)")
            resolved = world_of(spec, world)
            if isinstance(resolved, ContinuousWorld):
                return _hstl._train_continuous(spec, resolved, seed, episodes, bar.callback)
            return _hstl._train_world(spec, resolved, seed, episodes, bar.callback)
        if world is not None:
            raise TypeError("pass either world= or env=, not both")
        if _is_box(env) and spec.is_continuous:
            return _hstl._train_box(
                spec, env, _box_valuation(valuation, spec), seed, *_box_spaces(env), episodes, bar.callback
            )
        if valuation is None:
            raise TypeError(
                "train(env=...) needs valuation=, a function from an observation to the spec's state variables"
            )
        return _hstl._train_env(spec, env, valuation, seed, *_spaces(env), episodes, bar.callback)


def world_of(
    spec: Spec, world: Union[World, ContinuousWorld, str, "os.PathLike[str]", None]
) -> Union[World, ContinuousWorld]:
    """The world to train ``spec`` in: ``world`` when given, else the one the spec names (a
    path relative to its file), else ``paper`` (``paper-plane`` for a continuous spec)."""
    if world is not None:
        if isinstance(world, (World, ContinuousWorld)):
            return world
        return _hstl._resolve_any_world(os.fspath(world))
    named = spec.world
    if named is None:
        return _hstl._resolve_any_world("paper-plane" if spec.is_continuous else "paper")
    if named in _hstl.BUILTIN_WORLDS:
        return _hstl._resolve_any_world(named)
    folder = "" if spec.filename.startswith("<") else os.path.dirname(spec.filename)
    return _hstl._resolve_any_world(os.path.join(folder, named))


def _is_box(env: Any) -> bool:
    from gymnasium import spaces

    return isinstance(getattr(env, "observation_space", None), spaces.Box)


def _box_spaces(env: Any) -> tuple[str, list[float], list[float], int, int]:
    """The environment's name, its ``Box`` observation space's bounds (flattened) and its
    ``Discrete`` action space's size and start, as the native trainer and
    ``Policy.evaluate`` take them."""
    import numpy as np
    from gymnasium import spaces

    box = getattr(env, "observation_space", None)
    if not isinstance(box, spaces.Box):
        raise TypeError(
            f"this policy acts on a `Box` observation space; the environment's is {type(box).__name__}\n"
            "  help: pass the environment the policy was trained in"
        )
    act = _discrete(env, "action_space")
    low = np.asarray(box.low, dtype=np.float64).ravel().tolist()
    high = np.asarray(box.high, dtype=np.float64).ravel().tolist()
    return _env_name(env), low, high, int(act.n), int(act.start)


def _box_valuation(valuation: Optional[Valuation], spec: Spec) -> Optional[Callable[[Any], Any]]:
    """``valuation=`` as the native trainer takes it: a callable, or None for the
    observation's components in order."""
    if valuation is None or callable(valuation):
        return valuation
    if isinstance(valuation, Mapping):
        missing = [v for v in spec.state_vars if v not in valuation]
        if missing:
            from ._errors import MissingVariableError

            raise MissingVariableError(
                f"valuation has no entry for state variable `{missing[0]}`\n"
                f"  help: the spec's state variables are {', '.join(f'`{v}`' for v in spec.state_vars)}"
            )
        from ._gym import _Picks

        return _Picks([(v, valuation[v]) for v in spec.state_vars])
    raise TypeError(
        f"valuation must be a callable or a dict from state variables to observation indices; got {type(valuation).__name__}"
    )


def _spaces(env: Any) -> tuple[str, int, int, int, int]:
    """The environment's name and its `Discrete` spaces' sizes and starts (observations,
    then actions), as the native trainer and `Policy.evaluate` take them."""
    obs, act = (_discrete(env, name) for name in ("observation_space", "action_space"))
    return _env_name(env), int(obs.n), int(obs.start), int(act.n), int(act.start)


def _seed_of(seed: Any) -> int:
    if isinstance(seed, (bool, float)) or not hasattr(seed, "__index__"):
        raise TypeError(f"`seed` must be an integer; got {type(seed).__name__}")
    if not 0 <= int(seed) <= _MAX_SEED:
        raise ValueError(f"`seed` must be in 0..={_MAX_SEED}; got {int(seed)}")
    return int(seed)


def _count_of(n: Any, name: str) -> int:
    if isinstance(n, (bool, float)) or not hasattr(n, "__index__"):
        raise TypeError(f"`{name}` must be an integer; got {type(n).__name__}")
    if not 1 <= int(n) <= _hstl.MAX_EPISODES:
        raise ValueError(
            f"`{name}` must be in 1..={_hstl.MAX_EPISODES}; got {int(n)}\n"
            "  help: leave it out to train the spec's `learn { episodes }`"
        )
    return int(n)


def _discrete(env: Any, name: str) -> Any:
    from gymnasium import spaces

    space = getattr(env, name, None)
    if not isinstance(space, spaces.Discrete):
        kind = type(space).__name__
        raise TypeError(
            f"train(env=...) needs a `Discrete` {name.replace('_', ' ')}; this environment's is {kind}\n"
            "  help: the tabular learner needs numbered states: wrap the environment so that it numbers its states "
            "and actions, or for a `Box` observation space declare the spec's state variables as `float` ranges "
            "(the approximate learner tiles them)"
        )
    return space


def _env_name(env: Any) -> str:
    spec = getattr(env, "spec", None)
    if spec is not None and getattr(spec, "id", None):
        return str(spec.id)
    return type(getattr(env, "unwrapped", env)).__name__


class _Progress:
    """A progress bar fed by the native trainer: tqdm's, or a line of its own."""

    def __init__(self, progress: Optional[bool]) -> None:
        if progress is None:
            progress = sys.stderr.isatty()
        self.enabled = bool(progress)
        self._bar: Any = None
        self._done = 0

    def __enter__(self) -> "_Progress":
        return self

    @property
    def callback(self) -> Optional[Callable[[int, int, float], None]]:
        return self._update if self.enabled else None

    def _update(self, done: int, total: int, reward: float) -> None:
        if self._bar is None:
            try:
                from tqdm.auto import tqdm
            except ImportError:
                self._bar = _Line(total)
            else:
                self._bar = tqdm(total=total, desc="training", unit="episode")
        self._bar.update(done - self._done)
        self._done = done
        self._bar.set_postfix_str(f"reward {reward:.1f}")

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.close()


class _Line:
    """A one-line bar on standard error, for when tqdm is not installed."""

    def __init__(self, total: int) -> None:
        self.total, self.n, self.note = total, 0, ""

    def update(self, n: int) -> None:
        self.n += n

    def set_postfix_str(self, note: str) -> None:
        self.note = note
        filled = 30 * self.n // max(self.total, 1)
        sys.stderr.write(f"\rtraining [{'#' * filled}{'.' * (30 - filled)}] {self.n}/{self.total} episodes, {note}")
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()
