"""Gymnasium wrappers for deep RL on STL tasks, written for any `Box` environment and any
spec: the tau-MDP and F-MDP observations of the long-horizon comparison (TGPO, arXiv
2510.00225, figure 2), and MountainCar without its goal.

The reward is `hstl.STLReward(reward="sparse")`: the task's robustness over the whole
episode, paid on its last step (the tau-MDP's convention: the formula is scored once the
trajectory is complete). Compose as

    env = TimeLimit(base, T)                       # the task's horizon
    env = hstl.STLReward(env, spec, valuation, reward="sparse")
    env = TauMDP(env, tau)    or    FlagMDP(env, spec, valuation, ["A", "B", "C"])
"""

from __future__ import annotations

from typing import Any, Callable, Optional, Sequence

import gymnasium
import numpy as np
from gymnasium import spaces

import hstl
from hstl._hstl import EpisodeMonitor


class NoTermination(gymnasium.Wrapper):
    """Never `terminated`: an environment whose goal ends episodes (MountainCar-v0 at
    x >= 0.5) goes on; the task, not the environment, says what to reach. Put a TimeLimit
    outside it."""

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        info = dict(info)
        info["env_terminated"] = bool(terminated)
        return obs, reward, False, truncated, info


class Bounded(gymnasium.ObservationWrapper):
    """The observation clipped to `[low, high]`, with that `Box` as its space: `hstl.train`
    on an environment whose space is unbounded (CartPole's speeds), with the bounds the spec
    declares (a state outside them would be refused anyway)."""

    def __init__(self, env: gymnasium.Env, low: Sequence[float], high: Sequence[float]) -> None:
        super().__init__(env)
        self._low = np.asarray(low, dtype=np.float64)
        self._high = np.asarray(high, dtype=np.float64)
        self.observation_space = spaces.Box(self._low, self._high, dtype=np.float64)

    def observation(self, observation: Any) -> Any:
        return np.clip(np.asarray(observation, dtype=np.float64), self._low, self._high)


class TauMDP(gymnasium.ObservationWrapper):
    """The tau-MDP observation: the state with the last `tau` states before it, oldest first
    (`tau + 1` observations of a `Box` space, flattened). At reset the history is the start
    state repeated."""

    def __init__(self, env: gymnasium.Env, tau: int) -> None:
        super().__init__(env)
        if not isinstance(env.observation_space, spaces.Box):
            raise TypeError(f"TauMDP needs a Box observation space; got {type(env.observation_space).__name__}")
        if tau < 0:
            raise ValueError(f"tau must be 0 or more; got {tau}")
        self.tau = tau
        box = env.observation_space
        self._shape = int(np.prod(box.shape))
        low = np.tile(box.low.reshape(-1), tau + 1)
        high = np.tile(box.high.reshape(-1), tau + 1)
        self.observation_space = spaces.Box(low, high, dtype=np.float32 if box.dtype == np.float32 else np.float64)
        self._history = np.zeros((tau + 1, self._shape), dtype=self.observation_space.dtype)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        self._history[:] = np.asarray(obs, dtype=self._history.dtype).reshape(-1)
        return self._history.reshape(-1).copy(), info

    def observation(self, observation: Any) -> Any:
        self._history[:-1] = self._history[1:]
        self._history[-1] = np.asarray(observation, dtype=self._history.dtype).reshape(-1)
        return self._history.reshape(-1).copy()


class FlagMDP(gymnasium.Wrapper):
    """The F-MDP observation: the state and one flag per subformula (a `let` of the spec),
    1 once the subformula has held at some step of the episode, 0 before. With
    `ordered=True` a flag may rise only after the one before it has (a sequence: A, then
    B, then C). A subformula's value on a step is its robustness there
    (`rho(let, t)` over the trace so far: for a state formula, the formula on `s_t`),
    computed by hstl's monitor; it holds when that is positive."""

    def __init__(
        self,
        env: gymnasium.Env,
        spec: hstl.Spec,
        valuation: Callable[[Any], Any],
        formulas: Sequence[str],
        ordered: bool = False,
    ) -> None:
        super().__init__(env)
        if not isinstance(env.observation_space, spaces.Box):
            raise TypeError(f"FlagMDP needs a Box observation space; got {type(env.observation_space).__name__}")
        unknown = [f for f in formulas if f not in spec.lets]
        if unknown:
            raise ValueError(f"spec `{spec.name}` has no let `{unknown[0]}`; its lets are {', '.join(spec.lets)}")
        if not formulas:
            raise ValueError("FlagMDP needs at least one subformula")
        self.formulas = list(formulas)
        self.ordered = ordered
        self._valuation = valuation
        self._monitors = [EpisodeMonitor(spec, f) for f in self.formulas]
        box = env.observation_space
        k = len(self.formulas)
        self.observation_space = spaces.Box(
            np.concatenate([box.low.reshape(-1), np.zeros(k)]).astype(np.float64),
            np.concatenate([box.high.reshape(-1), np.ones(k)]).astype(np.float64),
            dtype=np.float64,
        )
        self.flags = np.zeros(k)

    def _observe(self, obs: Any) -> np.ndarray:
        state = self._valuation(obs)
        for i, m in enumerate(self._monitors):
            holds = m.push(state)[0] > 0
            if holds and self.flags[i] == 0 and (not self.ordered or i == 0 or self.flags[i - 1] == 1):
                self.flags[i] = 1.0
        return np.concatenate([np.asarray(obs, dtype=np.float64).reshape(-1), self.flags])

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        self.flags[:] = 0.0
        for m in self._monitors:
            m.reset()
        return self._observe(obs), info

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        return self._observe(obs), reward, terminated, truncated, info


class Columns:
    """A valuation: the state variables as the observation's entries, in the spec's
    `state_vars` order (a module-level class, so that it pickles)."""

    def __init__(self, columns: Sequence[int]) -> None:
        self.columns = np.array(columns)

    def __call__(self, obs: Any) -> np.ndarray:
        return np.asarray(obs, dtype=np.float64)[self.columns]


def sparse_task_env(
    base: gymnasium.Env,
    spec: hstl.Spec,
    valuation: Callable[[Any], Any],
    horizon: int,
    observation: str = "tau",
    tau: int = 0,
    flags: Optional[Sequence[str]] = None,
    ordered: bool = True,
) -> gymnasium.Env:
    """`base` with the task's horizon, the STL reward at episode end, and the tau-MDP
    (`observation="tau"`) or F-MDP (`"flags"`) observation."""
    env: gymnasium.Env = gymnasium.wrappers.TimeLimit(base, horizon)
    env = hstl.STLReward(env, spec, valuation=valuation, reward="sparse")
    if observation == "tau":
        return TauMDP(env, tau)
    if observation == "flags":
        if flags is None:
            raise ValueError("observation='flags' needs flags=, the subformulas to flag")
        return FlagMDP(env, spec, valuation, flags, ordered=ordered)
    raise ValueError(f"observation must be 'tau' or 'flags'; got {observation!r}")
