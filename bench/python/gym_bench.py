"""Times the Python package's gymnasium half and its training (not for CI; see
bench/python/run.sh).

Usage: gym_bench.py HSTLC [--steps N] [--repeats N] [--episodes N]

- `GridWorldEnv` steps per second: bare, through `gymnasium.make` (the registered id with
  its wrappers), and wrapped in `STLReward` (the case study's task, and region `A`), beside
  gymnasium's own FrozenLake (pure Python) for scale;
- `STLReward`'s cost per step against the episode's length (it must not grow), and against
  a wrapper that scores the whole trace so far with `spec.robustness` at every step;
- `hstl.train` on the case study (O_T1, seed 0, the spec's 1200 episodes) against
  `hstlc train` (the binary given, release), with the two `policy.json` compared byte for
  byte.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gymnasium
import numpy as np

import hstl
from timing import best, children_cpu, stepper

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "examples" / "specs" / "surveillance_ot1.hstl"


class WholeTraceReward(gymnasium.Wrapper):
    """What one would write without `STLReward`: the task's robustness over the whole trace
    so far, by `spec.robustness`, at every step."""

    def __init__(self, env, spec):
        super().__init__(env)
        self.stl, self.xs, self.ys = spec, [], []

    def reset(self, **kw):
        obs, info = self.env.reset(**kw)
        self.xs, self.ys = [float(obs[0])], [float(obs[1])]
        return obs, info

    def step(self, action):
        obs, r, te, tr, info = self.env.step(action)
        self.xs.append(float(obs[0]))
        self.ys.append(float(obs[1]))
        rho = self.stl.robustness({"x": np.array(self.xs), "y": np.array(self.ys)})
        return obs, rho, te, tr, info


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("hstlc")
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--episodes", type=int, default=None)
    a = ap.parse_args()
    spec = hstl.Spec.load(CASE)
    actions = np.random.default_rng(0).integers(0, 4, size=a.steps).tolist()
    print(f"hstl {hstl.__version__}, gymnasium {gymnasium.__version__}, {a.steps} steps, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")

    print(f"\n## steps per CPU second (best of {a.repeats}; episodes of 2000 steps)")
    print("| environment | steps/s | CPU us/step |")
    print("|---|---|---|")
    rows = [
        ("GridWorldEnv (bare)", lambda: hstl.GridWorldEnv("paper")),
        ('gymnasium.make("hstl/GridWorld-v0")', lambda: gymnasium.make("hstl/GridWorld-v0")),
        ("STLReward(GridWorldEnv, case-study task)", lambda: hstl.STLReward(hstl.GridWorldEnv(), spec)),
        ('STLReward(GridWorldEnv, formula="A")', lambda: hstl.STLReward(hstl.GridWorldEnv(), spec, formula="A")),
        ('STLReward(gymnasium.make("hstl/GridWorld-v0"), task)',
         lambda: hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), spec)),
        ('gymnasium.make("FrozenLake-v1") (pure Python, for scale)',
         lambda: gymnasium.make("FrozenLake-v1", is_slippery=True).unwrapped),
    ]
    for name, make in rows:
        env = make()
        run = stepper(env, actions if "FrozenLake" not in name else [a % 4 for a in actions], 2000)
        if "FrozenLake" in name:
            # FrozenLake ends episodes in holes: reset on termination instead.
            def run(env=env):
                env.reset(seed=0)
                for act in actions:
                    if env.step(act)[2]:
                        env.reset()
        t = best(run, a.repeats)
        print(f"| {name} | {a.steps / t:,.0f} | {t / a.steps * 1e6:.2f} |")

    print("\n## STLReward (case-study task) against the episode's length")
    print("| episode length | STLReward, CPU us/step | the whole trace by spec.robustness at each step, CPU us/step |")
    print("|---|---|---|")
    for length in [100, 2000, 20_000]:
        n = max(length, min(a.steps, 40_000))
        acts = actions[:n]
        t = best(stepper(hstl.STLReward(hstl.GridWorldEnv(), spec), acts, length), a.repeats)
        naive_steps = min(n, 4000)
        tn = best(stepper(WholeTraceReward(hstl.GridWorldEnv(), spec), acts[:naive_steps], length), 1)
        print(f"| {length} | {t / n * 1e6:.2f} | {tn / naive_steps * 1e6:.1f} (first {naive_steps} steps) |")

    print("\n## hstl.train against hstlc train: the case study (O_T1), seed 0")
    extra = ["--episodes", str(a.episodes)] if a.episodes else []
    cli_cpu, cli_wall, cli_train, py_cpu, py_wall = [], [], [], [], []
    for _ in range(a.repeats):
        with tempfile.TemporaryDirectory() as out:
            c0, t0 = children_cpu(), time.perf_counter()
            cli = subprocess.run([a.hstlc, "train", str(CASE), "--seed", "0", "--out", out, *extra],
                                 capture_output=True, text=True, check=True)
            cli_wall.append(time.perf_counter() - t0)
            cli_cpu.append(children_cpu() - c0)
            cli_bytes = (Path(out) / "policy.json").read_bytes()
        cli_train.append(float(re.search(r"steps in ([\d.]+) s", cli.stdout).group(1)))
        c0, t0 = time.process_time(), time.perf_counter()
        policy = hstl.train(CASE, seed=0, episodes=a.episodes, progress=False)
        py_wall.append(time.perf_counter() - t0)
        py_cpu.append(time.process_time() - c0)
    same = policy.json.encode() == cli_bytes
    print(f"best of {a.repeats} | CPU | wall clock | of which training (wall, as hstlc prints it) |")
    print("|---|---|---|---|")
    print(f"| hstlc train (the whole command: train, evaluate, 9 files) | {min(cli_cpu):.2f} s | {min(cli_wall):.2f} s | {min(cli_train):.2f} s |")
    print(f"| hstl.train (check, train, policy.json, replay check) | {min(py_cpu):.2f} s | {min(py_wall):.2f} s | |")
    print(f"\n{policy.steps:,} primitive steps; policy.json byte for byte equal: {'yes' if same else 'NO'}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
