"""A STAND-IN for `hstl/Plane-v0`, in pure Python, to write and test the long-horizon
wrappers before the plane environment is merged. It is NOT the plane task: its figures are
never reported as the plane's.

A point on a square field of side `side` (the long-horizon task's field: side T/5), eight
headings of step 1, slip (another heading drawn uniformly) with probability `slip`,
Gaussian noise of sd `noise` on each coordinate, positions clipped to the field; a reset
draws the start uniformly in `[0, side/10]^2`. Every draw from the generator `reset(seed=)`
seeds (gymnasium's `np_random`). Observation `Box([0, 0], [side, side])` (x, y); actions
`Discrete(8)`, heading `a * 45` degrees.
"""

from __future__ import annotations

import math
from typing import Any, Optional

import gymnasium
import numpy as np
from gymnasium import spaces

STANDIN_ID = "field/StandinPlane-v0"


class StandinPlane(gymnasium.Env):
    metadata = {"render_modes": []}

    def __init__(self, side: float = 10.0, slip: float = 0.05, noise: float = 0.05) -> None:
        if not side > 0:
            raise ValueError(f"side must be positive; got {side}")
        self.side, self.slip, self.noise = float(side), float(slip), float(noise)
        self.observation_space = spaces.Box(0.0, self.side, shape=(2,), dtype=np.float64)
        self.action_space = spaces.Discrete(8)
        self._dirs = np.array([(math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)) for k in range(8)])
        self._pos = np.zeros(2)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self._pos = self.np_random.uniform(0.0, self.side / 10, size=2)
        return self._pos.copy(), {}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        a = int(action)
        if not 0 <= a < 8:
            raise ValueError(f"action {action!r} is not in Discrete(8)")
        if self.np_random.random() < self.slip:
            a = (a + 1 + int(self.np_random.integers(0, 7))) % 8
        move = self._dirs[a] + self.np_random.normal(0.0, self.noise, size=2)
        self._pos = np.clip(self._pos + move, 0.0, self.side)
        return self._pos.copy(), 0.0, False, False, {}


def register() -> None:
    if STANDIN_ID not in gymnasium.registry:
        gymnasium.register(STANDIN_ID, entry_point=StandinPlane)
