"""Writes mountain_car_reference.json: gymnasium's MountainCar-v0 state sequences.

Documentation of where the reference came from; not run in CI. To regenerate:

    python3 -m venv /tmp/gymvenv && /tmp/gymvenv/bin/pip install gymnasium numpy
    /tmp/gymvenv/bin/python runtime/tests/data/mountain_car_reference.py

The environment is stepped unwrapped (no 200-step time limit) from set start states. Its
state is float64 (numpy float64 and Python floats; only the observation is cast to
float32), so each state is recorded from `env.unwrapped.state` with `repr`, which reads
back to the same double.
"""

import json
import pathlib
import random

import gymnasium
import numpy as np
from gymnasium.envs.classic_control.mountain_car import MountainCarEnv


def run(start, policy, steps):
    env = MountainCarEnv()
    env.reset(seed=0)
    env.state = np.array(start, dtype=np.float64)
    actions, states = [], []
    for t in range(steps):
        position, velocity = env.state
        action = policy(t, float(position), float(velocity))
        actions.append(action)
        env.step(action)
        position, velocity = env.state
        states.append([repr(float(position)), repr(float(velocity))])
    return {
        "start": [repr(float(start[0])), repr(float(start[1]))],
        # One digit per step: 0 left, 1 none, 2 right.
        "actions": "".join(str(a) for a in actions),
        "states": states,
    }


def pump(t, x, v):
    """Push with the velocity: swings up and passes x = 0.5, then hits the right edge."""
    return 2 if v >= 0 else 0


rng = random.Random(2016)
noise = [rng.randrange(3) for _ in range(300)]

cases = {
    "pump_from_the_valley": run([-0.5, 0.0], pump, 300),
    "swing_into_the_left_wall": run(
        [-0.5, 0.0], lambda t, x, v: 2 if v >= 0 and x < -0.1 else 0, 300
    ),
    "random_from_the_left": run([-1.1, -0.05], lambda t, x, v: noise[t], 300),
    "coast_from_near_the_right_edge": run([0.55, 0.02], lambda t, x, v: 1, 250),
    "pump_from_a_random_start": run([-0.4123456789, 0.0], pump, 300),
    "right_from_top_speed": run([-0.3, -0.07], lambda t, x, v: 2, 200),
}

out = {
    "gymnasium": gymnasium.__version__,
    "numpy": np.__version__,
    "env": "MountainCar-v0 (MountainCarEnv, unwrapped)",
    "cases": cases,
}
path = pathlib.Path(__file__).with_name("mountain_car_reference.json")
# One state per line, so that a diff shows which step changed.
text = json.dumps(out, indent=1)
text = text.replace('[\n     "', '["').replace('",\n     "', '", "').replace('"\n    ]', '"]')
path.write_text(text + "\n")
for name, case in cases.items():
    xs = [float(s[0]) for s in case["states"]]
    vs = [float(s[1]) for s in case["states"]]
    walls = sum(x == -1.2 for x in xs)
    past = sum(x >= 0.5 for x in xs)
    print(f"{name}: x in [{min(xs):.4f}, {max(xs):.4f}], v in [{min(vs):.4f}, {max(vs):.4f}],"
          f" {walls} steps at the left wall, {past} at x >= 0.5")
