"""Continuous worlds from Python: train the case study on the plane natively, run it in
gymnasium, and train MountainCar's patrol on a gymnasium `Box` observation space.

Run it after installing the package (see README.md, "Python"):

    python examples/python/continuous.py                  # the specs' own episodes
    python examples/python/continuous.py --episodes 40    # quicker, weaker policies
"""

import argparse
import tempfile
from pathlib import Path
from typing import Optional

import gymnasium
import numpy as np

import hstl

SPECS = Path(__file__).resolve().parents[1] / "specs"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--episodes", type=int, default=None, help="override the specs' learn { episodes }")
args = parser.parse_args()
episodes: Optional[int] = args.episodes

# The case study on `paper-plane` (the spec names its world): the approximate learner,
# natively, the same policy.json byte for byte as
# `hstlc train examples/specs/surveillance_plane.hstl --seed 0`.
policy = hstl.train(SPECS / "surveillance_plane.hstl", seed=0, episodes=episodes)
report = policy.evaluate()  # as `hstlc eval`: 100 greedy runs of 2000 steps
print(f"`{policy.spec_name}` on {policy.env_name}: window rate W = {report['window_rate']:.3f} "
      f"(planned reference {report['reference']:.3f}; no exact optimum on a continuous world)")
out = Path(tempfile.mkdtemp()) / "policy.json"
policy.save(out)
assert hstl.Policy.load(out) == policy  # the tiling and the weights, the same bits

# The same world in gymnasium: observations are (x, y) as float64, actions the headings.
# With seed s, the states and actions are those of `hstlc eval --runs DIR --starts 1 --seed s`.
env = hstl.STLReward(gymnasium.make("hstl/Plane-v0"), policy.spec, reward="window")
obs, info = env.reset(seed=1)
policy.reset()
kept = 0.0
for _ in range(500):
    obs, reward, terminated, truncated, info = env.step(policy.act(obs))
    kept += reward
print(f"in gymnasium: {kept:.0f} of 500 steps kept every window (reward='window')")

# Any gymnasium environment with a bounded Box observation space: the approximate
# learner through Python, one call a step. MountainCarEnv is gymnasium's MountainCar-v0
# dynamics, bit for bit, without its goal; its observation (x, v) is the spec's state, in
# order, so no valuation= is needed.
car = hstl.MountainCarEnv()
car_policy = hstl.train(SPECS / "mountain_car_patrol.hstl", env=car, seed=0, episodes=episodes or 100)
car_report = car_policy.evaluate(starts=5, env=hstl.MountainCarEnv())
print(f"MountainCar patrol through gymnasium: window rate {car_report['window_rate']:.3f} over 5 runs")

# The registered patrol: both hill tops within every 200 steps, rewarded per kept step.
patrol = gymnasium.make("hstl/MountainCarPatrol-v0", window=200)
obs, info = patrol.reset(seed=0)
car_policy.reset()
total = 0.0
for _ in range(1000):
    obs, earned, ended, cut, info = patrol.step(car_policy.act(np.asarray(obs)))
    total += float(earned)
print(f"hstl/MountainCarPatrol-v0: {total:.0f} of 1000 steps kept both windows")
