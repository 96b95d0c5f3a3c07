"""``hstl.train``: the HSTL learner in a grid world (native) or a gymnasium environment."""

from __future__ import annotations

import os
import sys
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from . import _hstl
from ._hstl import Policy, Spec, World

_MAX_SEED = 2**64 - 1


def train(
    spec: Union[Spec, str, "os.PathLike[str]"],
    world: Union[World, str, "os.PathLike[str]", None] = None,
    seed: int = 0,
    episodes: Optional[int] = None,
    progress: Optional[bool] = None,
    *,
    env: Any = None,
    valuation: Optional[Callable[[int], Union[Mapping[str, float], Sequence[float]]]] = None,
) -> Policy:
    """Trains ``spec`` with the hierarchical learner and returns the ``hstl.Policy``.

    ``spec`` is a ``hstl.Spec`` or a spec file's path; ``world`` a ``hstl.World``, a
    built-in world's name (``"paper"`` or ``"four-rooms"``) or a world file's path. By
    default the world is the one the spec names (``world "...";``, a path relative to the
    spec file), or ``"paper"`` when it names none; ``world=`` overrides it. The spec is
    checked against the world first (raising ``hstl.SpecError`` with the diagnostics of
    ``hstlc check --world``), and the policy's ``policy.json`` is byte for byte what
    ``hstlc train SPEC --world WORLD --seed SEED --episodes EPISODES`` writes.
    ``episodes`` overrides the spec's ``learn { episodes }`` (1 to ``MAX_EPISODES``); every
    random draw comes from one generator seeded with ``seed`` (0 to 2**64 - 1), so the
    same seed gives the same Q-tables, bit for bit.

    ``env=`` trains in a gymnasium environment instead: its observation and action spaces
    must be ``Discrete`` (observations are the learner's states) and ``valuation(obs)``
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
            world = world_of(spec, world)
            return _hstl._train_world(spec, world, seed, episodes, bar.callback)
        if valuation is None:
            raise TypeError(
                "train(env=...) needs valuation=, a function from an observation to the spec's state variables"
            )
        if world is not None:
            raise TypeError("pass either world= or env=, not both")
        return _hstl._train_env(spec, env, valuation, seed, *_spaces(env), episodes, bar.callback)


def world_of(spec: Spec, world: Union[World, str, "os.PathLike[str]", None]) -> World:
    """The world to train ``spec`` in: ``world`` when given, else the one the spec names (a
    path relative to its file), else ``paper``."""
    if world is not None:
        return world if isinstance(world, World) else World._resolve(os.fspath(world))
    named = spec.world
    if named is None:
        return World.builtin("paper")
    try:
        return World.builtin(named)
    except ValueError:
        pass
    folder = "" if spec.filename.startswith("<") else os.path.dirname(spec.filename)
    return World._resolve(os.path.join(folder, named))


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
            "  help: the learner is tabular: wrap the environment so that it numbers its states and actions"
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
