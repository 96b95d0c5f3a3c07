"""Times the continuous worlds from Python (not for CI; see bench/python/run.sh).

Usage: continuous_bench.py HSTLC [--steps N] [--repeats N]

- `PlaneEnv` and `MountainCarEnv` steps per CPU second: bare, through `gymnasium.make`
  (the registered ids with their wrappers) and `hstl/MountainCarPatrol-v0` (the car in
  `STLReward`), beside gymnasium's own `MountainCar-v0` (pure Python) for scale;
- `hstl.train` on `surveillance_plane.hstl` (seed 0, the spec's episodes) against
  `hstlc train` (the binary given, release), with the two `policy.json` compared byte for
  byte;
- the MountainCar patrol trained natively (`world="mountain-car"`) against the same spec
  trained through `env=hstl.MountainCarEnv()` (a Python call a step): primitive steps per
  CPU second of each.
"""

from __future__ import annotations

import argparse
import subprocess
import tempfile
import time
from pathlib import Path

import gymnasium
import numpy as np

import hstl
from timing import best, children_cpu, stepper

REPO = Path(__file__).resolve().parents[2]
PLANE = REPO / "examples" / "specs" / "surveillance_plane.hstl"
CAR = REPO / "examples" / "specs" / "mountain_car_patrol.hstl"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("hstlc", type=Path)
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--car-episodes", type=int, default=100)
    args = parser.parse_args()

    rng = np.random.default_rng(0)
    plane_actions = rng.integers(0, 4, size=args.steps).tolist()
    car_actions = rng.integers(0, 3, size=args.steps).tolist()
    rows = [
        ("`PlaneEnv()` (paper-plane), bare", hstl.PlaneEnv(), plane_actions),
        ('`gymnasium.make("hstl/Plane-v0")`', gymnasium.make("hstl/Plane-v0"), plane_actions),
        ("`MountainCarEnv()`, bare", hstl.MountainCarEnv(), car_actions),
        ('`gymnasium.make("hstl/MountainCarPatrol-v0")` (`STLReward`, window reward)',
         gymnasium.make("hstl/MountainCarPatrol-v0"), car_actions),
        ("gymnasium's `MountainCar-v0`, unwrapped, pure Python, for scale",
         gymnasium.make("MountainCar-v0").unwrapped, car_actions),
    ]
    print(f"{args.steps} random actions, episodes of 2000 steps, best of {args.repeats} (CPU time)\n")
    print("| environment | steps per CPU second | CPU us/step |")
    print("|---|---|---|")
    for name, env, actions in rows:
        secs = best(stepper(env, actions, 2000), args.repeats)
        print(f"| {name} | {args.steps / secs:,.0f} | {1e6 * secs / args.steps:.1f} |")

    with tempfile.TemporaryDirectory() as tmp:
        before = children_cpu()
        t0 = time.perf_counter()
        subprocess.run([str(args.hstlc), "train", str(PLANE), "--seed", "0", "--out", f"{tmp}/cli"],
                       check=True, capture_output=True)
        cli_wall = time.perf_counter() - t0
        cli_cpu = children_cpu() - before
        t0, c0 = time.perf_counter(), time.process_time()
        policy = hstl.train(PLANE, seed=0)
        py_wall, py_cpu = time.perf_counter() - t0, time.process_time() - c0
        same = policy.json == Path(f"{tmp}/cli/policy.json").read_text()
    curve = policy.curve
    assert curve is not None
    print(f"\n`surveillance_plane.hstl`, seed 0, {len(curve)} episodes, {policy.steps:,} steps; "
          f"policy.json equal byte for byte: {same}\n")
    print("| | CPU | wall clock |")
    print("|---|---|---|")
    print(f"| `hstlc train` (the whole command: check, train, 100 greedy runs, files) | {cli_cpu:.2f} s | {cli_wall:.2f} s |")
    print(f"| `hstl.train` (check, train, `policy.json`, the replay check of `Policy`) | {py_cpu:.2f} s | {py_wall:.2f} s |")

    spec = hstl.Spec.load(CAR)
    c0 = time.process_time()
    native = hstl.train(spec, seed=0, episodes=args.car_episodes)
    native_cpu = time.process_time() - c0
    c0 = time.process_time()
    through = hstl.train(spec, env=hstl.MountainCarEnv(), seed=0, episodes=args.car_episodes)
    through_cpu = time.process_time() - c0
    w_native = native.evaluate(optimum=False)["window_rate"]
    w_through = through.evaluate(starts=10, env=hstl.MountainCarEnv())["window_rate"]
    print(f"\n`mountain_car_patrol.hstl`, seed 0, {args.car_episodes} episodes\n")
    print("| trained | primitive steps | CPU | steps per CPU second | W of the greedy policy |")
    print("|---|---|---|---|---|")
    print(f"| natively, `world=\"mountain-car\"` | {native.steps:,} | {native_cpu:.2f} s | "
          f"{native.steps / native_cpu:,.0f} | {w_native:.3f} (100 runs) |")
    print(f"| through `env=hstl.MountainCarEnv()` | {through.steps:,} | {through_cpu:.2f} s | "
          f"{through.steps / through_cpu:,.0f} | {w_through:.3f} (10 runs, through the env) |")


if __name__ == "__main__":
    main()
