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
    array), as a callable valuation: what a user's own function costs (numpy's fancy
    indexing and a call a step); `STLReward` reads a dict of indices, the form below, in
    Rust without either."""

    def __init__(self, columns: list[int]) -> None:
        self.columns = np.array(columns)

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return obs[self.columns]


class Passthrough(gymnasium.Wrapper):
    """A wrapper that does nothing: the floor of any Python wrapper's cost per step."""

    def step(self, action):
        return self.env.step(action)


def push_alone(spec, columns, results):
    """CPU seconds per step of the call into Rust alone (`EpisodeMonitor._step`, what
    STLReward's `step` calls: the observation's entries read by index, the push, the new
    info) on recorded step results, episodes of 1,000 steps."""
    from hstl._hstl import EpisodeMonitor

    monitor = EpisodeMonitor(spec)
    monitor._observe(columns)
    t0 = time.process_time()
    for i, r in enumerate(results):
        if i % 1000 == 0:
            monitor.reset()
        monitor._step(r)
    return (time.process_time() - t0) / len(results)


def run_manual(env, actions, steps, episode, spec, columns):
    """The bare step and the call into Rust, no wrapper: what the call costs between MuJoCo
    steps (more than alone: the two share the core's caches)."""
    from hstl._hstl import EpisodeMonitor

    monitor = EpisodeMonitor(spec)
    monitor._observe(columns)
    env.reset(seed=0)
    t0 = time.process_time()
    for i in range(steps):
        monitor._step(env.step(actions[i]))
        if (i + 1) % episode == 0:
            env.reset()
            monitor.reset()
    return (time.process_time() - t0) / steps


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
    ap.add_argument("--vector", type=int, default=8, help="environments in the vector of the second table (0: no second table)")
    ap.add_argument("--block", type=int, default=25, help="vector steps in each block of the second table's pairs")
    ap.add_argument("--vector-only", action="store_true", help="only the second table")
    args = ap.parse_args()
    if args.vector_only:
        return vector_part(args)
    print(f"machine: {machine()}; {args.steps} random steps a repeat, median of {args.repeats} repeats, "
          f"episodes of {args.episode_steps} steps\n")
    print("| environment | bare, us/step | + STLReward, us/step | STLReward adds | + rtamt online monitor, us/step | rtamt adds | goal <= 2% | an empty wrapper adds | _step alone, us | _step between bare steps adds, us |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for env_id in args.envs.split(","):
        file, picks, rtamt_formula = TASKS[env_id]
        spec = hstl.Spec.load(SPECS / file)
        bare = gymnasium.make(env_id, max_episode_steps=None).unwrapped
        columns = list(picks.values())
        # The documented form: each state variable's index in the observation.
        wrapped = hstl.STLReward(gymnasium.make(env_id).unwrapped, spec, valuation=dict(picks))
        rng = np.random.default_rng(0)
        space = bare.action_space
        actions = rng.uniform(space.low, space.high, size=(max(args.steps, 5000),) + space.shape).astype(space.dtype)
        # Warm up each (imports, caches).
        run_bare(bare, actions, 1000, args.episode_steps)
        run_bare(wrapped, actions, 1000, args.episode_steps)
        empty = Passthrough(gymnasium.make(env_id).unwrapped)
        recorded = []
        bare.reset(seed=0)
        for a in actions[:5000]:
            recorded.append(bare.step(a))
        times = {"bare": [], "stl": [], "rtamt": [], "empty": [], "push": [], "manual": []}
        for _ in range(args.repeats):
            times["bare"].append(run_bare(bare, actions, args.steps, args.episode_steps))
            times["stl"].append(run_bare(wrapped, actions, args.steps, args.episode_steps))
            times["empty"].append(run_bare(empty, actions, args.steps, args.episode_steps))
            times["push"].append(push_alone(spec, columns, recorded))
            times["manual"].append(run_manual(bare, actions, args.steps, args.episode_steps, spec, columns))
            if not args.no_rtamt:
                times["rtamt"].append(run_rtamt(bare, actions, args.steps, args.episode_steps, rtamt_formula, picks))
        med = {k: statistics.median(v) * 1e6 for k, v in times.items() if v}
        # The overhead within each repeat (paired), then its median: steadier under load.
        paired = [s / b - 1 for s, b in zip(times["stl"], times["bare"])]
        added = statistics.median(paired)
        r_added = statistics.median([r / b - 1 for r, b in zip(times["rtamt"], times["bare"])]) if times["rtamt"] else float("nan")
        met = "met" if added <= 0.02 else "not met"
        e_added = statistics.median([e / b - 1 for e, b in zip(times["empty"], times["bare"])])
        print(f"| {env_id} | {med['bare']:.1f} | {med['stl']:.1f} | {100 * added:+.1f}% (repeats {min(paired) * 100:+.1f}% to {max(paired) * 100:+.1f}%) "
              f"| {med.get('rtamt', float('nan')):.1f} | {100 * r_added:+.0f}% | {met} | {100 * e_added:+.1f}% | {med['push']:.2f} | {med['manual'] - med['bare']:.1f} |", flush=True)
        rows.append([env_id, args.steps, args.repeats, med["bare"], med["stl"], added, min(paired), max(paired),
                     med.get("rtamt", float("nan")), r_added, e_added, med["push"], med["manual"] - med["bare"], machine()])
        bare.close()
        wrapped.close()
    write_csv(OUT / "physics.csv", ["env", "steps", "repeats", "bare_us", "stlreward_us", "stlreward_added",
                                     "added_min", "added_max", "rtamt_us", "rtamt_added", "empty_wrapper_added", "push_us", "push_between_steps_us", "machine"], rows)
    print(f"\nwrote {OUT / 'physics.csv'}")
    if args.vector:
        vector_part(args)


class Stepper:
    """A vector environment stepped through the action list from where it stopped."""

    def __init__(self, vec, actions) -> None:
        self.vec, self.actions, self.i = vec, actions, 0
        vec.reset(seed=0)

    def block(self, steps: int) -> float:
        """CPU seconds of the next `steps` vector steps (each environment resets itself)."""
        vec, actions = self.vec, self.actions
        t0 = time.process_time()
        for _ in range(steps):
            vec.step(actions[self.i % len(actions)])
            self.i += 1
        return time.process_time() - t0


def median_and_interval(ratios: list[float], rng: np.random.Generator) -> tuple[float, float, float]:
    """The median of the paired ratios and its 95% bootstrap interval (2,000 resamples)."""
    values = np.array(ratios)
    boot = np.median(rng.choice(values, size=(2000, len(values))), axis=1)
    return float(np.median(values)), float(np.quantile(boot, 0.025)), float(np.quantile(boot, 0.975))


def vector_part(args) -> None:
    """The second table: `STLVectorReward` on a `SyncVectorEnv` of `--vector` copies, one
    call into Rust a vector step, against the bare vector. The two are stepped in short
    blocks, alternately (the order swapped every pair), so that the machine's load changes
    hit both alike; the figure is the median of the pairs' ratios with its bootstrap
    interval, which a loaded machine widens instead of biasing."""
    n = args.vector
    block = args.block
    pairs = max(args.steps * args.repeats // (n * block), 50)
    print(f"\n{n} environments in a gymnasium SyncVectorEnv, {pairs} pairs of blocks of {block} vector steps "
          f"(bare and wrapped alternately), the median of the pairs' ratios\n")
    print("| environment | bare vector, us/step of one env | + STLVectorReward, us/step of one env | STLVectorReward adds: median of pairs [95% interval] | goal <= 2% |")
    print("|---|---|---|---|---|")
    rows = []
    for env_id in args.envs.split(","):
        file, picks, _ = TASKS[env_id]
        spec = hstl.Spec.load(SPECS / file)

        def make(env_id=env_id):
            return gymnasium.make(env_id, max_episode_steps=args.episode_steps)

        bare = gymnasium.vector.SyncVectorEnv([make for _ in range(n)])
        wrapped = hstl.STLVectorReward(gymnasium.vector.SyncVectorEnv([make for _ in range(n)]), spec, dict(picks))
        space = bare.action_space
        rng = np.random.default_rng(0)
        actions = rng.uniform(space.low, space.high, size=(4000,) + space.shape).astype(space.dtype)
        sides = {"bare": Stepper(bare, actions), "stl": Stepper(wrapped, actions)}
        for side in sides.values():
            side.block(200)
        totals = {"bare": 0.0, "stl": 0.0}
        ratios = []
        for k in range(pairs):
            order = ("bare", "stl") if k % 2 == 0 else ("stl", "bare")
            t = {name: sides[name].block(block) for name in order}
            totals["bare"] += t["bare"]
            totals["stl"] += t["stl"]
            ratios.append(t["stl"] / t["bare"] - 1)
        added, low, high = median_and_interval(ratios, rng)
        per_env = {k: v / (pairs * block * n) * 1e6 for k, v in totals.items()}
        met = "met" if high <= 0.02 else ("not met" if low > 0.02 else "not decided")
        print(f"| {env_id} | {per_env['bare']:.1f} | {per_env['stl']:.1f} | {100 * added:+.2f}% [{100 * low:+.2f}%, {100 * high:+.2f}%] | {met} |", flush=True)
        rows.append([env_id, n, block, pairs, per_env["bare"], per_env["stl"], added, low, high, machine()])
        bare.close()
        wrapped.close()
    write_csv(OUT / "physics_vector.csv", ["env", "envs", "block", "pairs", "bare_us_per_env", "stl_us_per_env",
                                            "added_median", "added_low95", "added_high95", "machine"], rows)
    print(f"\nwrote {OUT / 'physics_vector.csv'}")


if __name__ == "__main__":
    sys.exit(main())
