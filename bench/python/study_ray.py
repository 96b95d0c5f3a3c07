"""Times ``hstl.study`` on a local Ray cluster against ``hstlc study`` on the same cores
(not for CI; see BENCHMARKS.md, "Sweeps on Ray").

Usage: study_ray.py HSTLC [--seeds N] [--cpus N] [--spec FILE] [--tasks N] [--repeats N]

- Ray's start-up: ``ray.init(num_cpus=N)`` of a new local cluster, its first tasks (the
  workers start and import hstl), and its shutdown;
- the cost of one Ray task beside a seed's training: a round trip of an empty task, and of
  a task that takes the spec and world from the object store and checks the spec (what
  every batch does before it trains), each the mean over ``--tasks`` tasks;
- a sweep of ``--seeds`` seeds of the case study (``surveillance_ot1.hstl``, W* skipped:
  it is solved once and is not what is compared), its folder written, three ways:
  ``hstlc study --threads N`` (the release binary given), ``hstl.study(backend="local",
  num_cpus=N)`` and ``hstl.study(backend="ray")`` on the cluster already started (the
  start-up is reported above), interleaved, the best of ``--repeats``; the per-seed
  figures of the two backends compared.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import ray

import hstl
from hstl import _hstl, _study

ROOT = Path(__file__).resolve().parents[2]


def _noop() -> int:
    return 0


def _check(spec, world) -> int:
    _hstl._study_task(spec, world, None)
    return 0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("hstlc")
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--cpus", type=int, default=2)
    ap.add_argument("--tasks", type=int, default=400)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--spec", default=str(ROOT / "examples/specs/surveillance_ot1.hstl"))
    args = ap.parse_args()
    print(f"load before: {os.getloadavg()[0]:.2f}")

    start = time.perf_counter()
    ray.init(num_cpus=args.cpus, include_dashboard=False, logging_level="warning", _node_ip_address="127.0.0.1")
    started = time.perf_counter() - start
    print(f"ray.init(num_cpus={args.cpus}): {started:.2f} s")

    spec = hstl.Spec.load(args.spec)
    world = hstl.World.builtin("paper")
    noop = ray.remote(num_cpus=1)(_noop)
    check = ray.remote(num_cpus=1)(_check)
    spec_ref, world_ref = ray.put(spec), ray.put(world)
    # Warm the workers (they start on the first tasks and import hstl), then time.
    t = time.perf_counter()
    ray.get([check.remote(spec_ref, world_ref) for _ in range(4 * args.cpus)])
    print(f"first {4 * args.cpus} tasks (the workers start): {time.perf_counter() - t:.2f} s")
    for name, f, fargs in (("empty task", noop, ()), ("spec check task", check, (spec_ref, world_ref))):
        t = time.perf_counter()
        ray.get([f.remote(*fargs) for _ in range(args.tasks)])
        per = (time.perf_counter() - t) / args.tasks
        # Tasks run `cpus` at a time: the cost a task adds to a core is `per * cpus`.
        print(f"{name}: {per * 1e3:.2f} ms per task over the cluster, {per * args.cpus * 1e3:.2f} ms of a core")

    def cli(tmp: str) -> None:
        subprocess.run(
            [args.hstlc, "study", args.spec, "--seeds", str(args.seeds), "--threads", str(args.cpus),
             "--no-optimum", "--out", os.path.join(tmp, "cli")],
            check=True,
            stdout=subprocess.DEVNULL,
        )

    def local(tmp: str):
        return hstl.study(args.spec, seeds=args.seeds, optimum=False, num_cpus=args.cpus, out=os.path.join(tmp, "local"))

    def on_ray(tmp: str):
        return hstl.study(args.spec, seeds=args.seeds, optimum=False, backend="ray", out=os.path.join(tmp, "ray"))

    # Interleaved, best of --repeats: the machine is shared, and its load moves.
    times = {"cli": [], "local": [], "ray": []}
    rows = {}
    for _ in range(args.repeats):
        for name, run in (("cli", cli), ("local", local), ("ray", on_ray)):
            with tempfile.TemporaryDirectory() as tmp:
                t = time.perf_counter()
                rows[name] = run(tmp)
                times[name].append(time.perf_counter() - t)
    best = {k: min(v) for k, v in times.items()}
    shown = lambda k: ", ".join(f"{t:.2f}" for t in times[k])
    print(f"hstlc study --seeds {args.seeds} --threads {args.cpus} --no-optimum --out: best {best['cli']:.2f} s ({shown('cli')})")
    print(f"hstl.study(backend='local', out=): best {best['local']:.2f} s ({best['local'] / best['cli']:.2f}x hstlc; {shown('local')})")
    batch = _study._batch_size(args.seeds, args.cpus)
    print(
        f"hstl.study(backend='ray', out=), cluster up, batches of {batch}: best {best['ray']:.2f} s "
        f"({best['ray'] / best['cli']:.2f}x hstlc; {shown('ray')}); with the start-up: {(best['ray'] + started) / best['cli']:.2f}x"
    )
    local, on_ray = rows["local"], rows["ray"]
    same = all(
        {k: v for k, v in a.items() if k != "seconds"} == {k: v for k, v in b.items() if k != "seconds"}
        for a, b in zip(local, on_ray)
    )
    print(f"per-seed figures of the two backends identical: {same}")
    train = sum(r["seconds"] for r in on_ray)
    print(f"training time, summed over seeds: {train:.2f} s ({train / args.seeds:.3f} s a seed)")
    t = time.perf_counter()
    ray.shutdown()
    print(f"ray.shutdown(): {time.perf_counter() - t:.2f} s")
    print(f"load after: {os.getloadavg()[0]:.2f}")
    if not same:
        sys.exit(1)


if __name__ == "__main__":
    main()
