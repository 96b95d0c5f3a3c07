#!/usr/bin/env python3
"""The reward's cost on physics: `hstl.STLReward` on gymnasium's MuJoCo environments.

For each environment, in one run: the time of a step of the bare environment, of the same
environment wrapped in `STLReward` (a small STL task over its observations), and of the bare
step plus rtamt's online monitor computing the same task's robustness (the reference).
CPU time of the process (time.process_time: the machine is shared). Random actions from one seeded generator, episodes of --episode-steps steps, --steps steps a
repeat; the figure is the median over --repeats repeats, the three setups interleaved in
each repeat so that load changes hit them alike. Writes out/physics.csv.

Goal (issue 27): the STL reward adds at most 2% to a step.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import gymnasium
import numpy as np

import hstl
from common import OUT, SPECS, machine, write_csv

# Each task over the observation's entries (gymnasium's documented observation layout): the
# spec file for hstl, and rtamt's online form of the same task. rtamt's online monitor takes
# past-time formulas (its `update` returns the value at the newest step), so the future
# windows are read backwards: `always[0..] eventually[0..=N] R` as `historically once[0,N] R`,
# the task's verdict on the prefix so far, what STLReward keeps in `info["task_robustness"]`.
TASKS = {
    # obs[1] is the pole's angle (rad): stay upright (within 0.2 rad, InvertedPendulum's own
    # limit) and visit both sides of the rail's middle (obs[0], the cart) every 100 steps.
    "InvertedPendulum-v5": ("inverted_pendulum.hstl", {"cart": 0, "angle": 1},
                            "(historically((angle < 0.2) and (angle > -0.2))) and "
                            "(historically((once[0,100](cart > 0.0)) and (once[0,100](cart < 0.0))))"),
    # obs[0] is the torso's height (z), obs[8] its forward speed: the height in a band at
    # every step, and forward speed above 1 within every 50 steps.
    "HalfCheetah-v5": ("half_cheetah.hstl", {"z": 0, "vx": 8},
                       "(historically((z < 0.5) and (z > -0.5))) and (historically(once[0,50](vx > 1.0)))"),
}


class Columns:
    """The state variables as the observation's entries, in `spec.state_vars` order (a numpy
    array: the cheapest form `STLReward` reads)."""

    def __init__(self, columns: list[int]) -> None:
        self.columns = np.array(columns)

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return obs[self.columns]


def rtamt_monitor(formula: str, names: list[str]):
    import rtamt

    spec = rtamt.StlDiscreteTimeSpecification()
    for n in names:
        spec.declare_var(n, "float")
    spec.spec = formula
    spec.parse()
    return spec


def run_bare(env, actions, steps, episode):
    env.reset(seed=0)
    t0 = time.process_time()
    for i in range(steps):
        env.step(actions[i])
        if (i + 1) % episode == 0:
            env.reset()
    return (time.process_time() - t0) / steps


def run_rtamt(env, actions, steps, episode, formula, picks):
    names = list(picks)
    spec = rtamt_monitor(formula, names)
    obs, _ = env.reset(seed=0)
    t = 0
    t0 = time.process_time()
    for i in range(steps):
        obs, *_ = env.step(actions[i])
        spec.update(t, [(n, float(obs[k])) for n, k in picks.items()])
        t += 1
        if (i + 1) % episode == 0:
            env.reset()
            spec.reset()
            t = 0
    return (time.process_time() - t0) / steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--episode-steps", type=int, default=1000)
    ap.add_argument("--envs", default=",".join(TASKS))
    ap.add_argument("--no-rtamt", action="store_true")
    args = ap.parse_args()
    print(f"machine: {machine()}; {args.steps} random steps a repeat, median of {args.repeats} repeats, "
          f"episodes of {args.episode_steps} steps\n")
    print("| environment | bare, us/step | + STLReward, us/step | STLReward adds | + rtamt online monitor, us/step | rtamt adds | goal <= 2% |")
    print("|---|---|---|---|---|---|---|")
    rows = []
    for env_id in args.envs.split(","):
        file, picks, rtamt_formula = TASKS[env_id]
        spec = hstl.Spec.load(SPECS / file)
        bare = gymnasium.make(env_id, max_episode_steps=None).unwrapped
        wrapped = hstl.STLReward(gymnasium.make(env_id).unwrapped, spec, valuation=Columns(list(picks.values())))
        rng = np.random.default_rng(0)
        space = bare.action_space
        actions = rng.uniform(space.low, space.high, size=(args.steps,) + space.shape).astype(space.dtype)
        # Warm up each (imports, caches).
        run_bare(bare, actions, 1000, args.episode_steps)
        run_bare(wrapped, actions, 1000, args.episode_steps)
        times = {"bare": [], "stl": [], "rtamt": []}
        for _ in range(args.repeats):
            times["bare"].append(run_bare(bare, actions, args.steps, args.episode_steps))
            times["stl"].append(run_bare(wrapped, actions, args.steps, args.episode_steps))
            if not args.no_rtamt:
                times["rtamt"].append(run_rtamt(bare, actions, args.steps, args.episode_steps, rtamt_formula, picks))
        med = {k: statistics.median(v) * 1e6 for k, v in times.items() if v}
        # The overhead within each repeat (paired), then its median: steadier under load.
        paired = [s / b - 1 for s, b in zip(times["stl"], times["bare"])]
        added = statistics.median(paired)
        r_added = statistics.median([r / b - 1 for r, b in zip(times["rtamt"], times["bare"])]) if times["rtamt"] else float("nan")
        met = "met" if added <= 0.02 else "not met"
        print(f"| {env_id} | {med['bare']:.1f} | {med['stl']:.1f} | {100 * added:+.1f}% (repeats {min(paired) * 100:+.1f}% to {max(paired) * 100:+.1f}%) "
              f"| {med.get('rtamt', float('nan')):.1f} | {100 * r_added:+.0f}% | {met} |", flush=True)
        rows.append([env_id, args.steps, args.repeats, med["bare"], med["stl"], added, min(paired), max(paired),
                     med.get("rtamt", float("nan")), r_added, machine()])
        bare.close()
        wrapped.close()
    write_csv(OUT / "physics.csv", ["env", "steps", "repeats", "bare_us", "stlreward_us", "stlreward_added",
                                     "added_min", "added_max", "rtamt_us", "rtamt_added", "machine"], rows)
    print(f"\nwrote {OUT / 'physics.csv'}")


if __name__ == "__main__":
    sys.exit(main())
