#!/usr/bin/env python3
"""Long horizons (TGPO, arXiv 2510.00225, figure 2): the timed multi-goal task (reach A,
then B within T/3 steps, then C within T/3 steps, never touching O; written by
scripts/bench-continuous's `horizon_task`) at horizons T, learned by SB3 PPO with the STL
reward at episode end (`STLReward(reward="sparse")`: the task's robustness over the
episode, the tau-MDP's convention) on two observations:

- tau-MDP: the state and the last `--tau` states (`wrappers.TauMDP`);
- F-MDP: the state and a flag per subformula A, B, C reached so far, in order
  (`wrappers.FlagMDP`);

given `--budget-factor` times hstl's CPU time at that T (hstl: `hstlc study` on the plane
world, `--seeds` seeds, one thread; its CPU time per seed counts training, the 1,000
evaluation runs and the pictures, so PPO's budget is if anything generous) or `--seconds`
each, PPO's budget counted in its own process CPU time. CPU time, not wall clock, so that a
loaded machine (the field runs under `nice`) shortens neither side.

The run resumes: out/horizons/<env>/runs.csv is rewritten whole after every run, and a
second call with the same settings (kept in settings.json beside it) skips what is there,
so the hours the full run takes can be spread over several sittings. `--fresh` starts over. Success: the share of
`--eval-runs` greedy runs of T steps whose task robustness is positive.

`--env` picks the environment: `hstl/Plane-v0` (issue 27 item 1, once merged; made with
`world=` the task's field.toml, observation (x, y)) or, until then, the pure-Python
STAND-IN `field/StandinPlane-v0` (standin.py), whose figures are labelled as such and are
NOT the plane task's. hstl's own figure is always its learner on the plane world.

Writes out/horizons/<env>/runs.csv (one row per method, T and seed) and success.png.
"""

from __future__ import annotations

import argparse
import json
import resource
import math
import pathlib
import statistics
import subprocess
import sys
import time
import warnings
from typing import Any

import gymnasium
import numpy as np

import hstl
from common import OUT, ROOT, band_plot, machine, read_csv, torch_one_thread, write_csv
from standin import STANDIN_ID, register
from tasks import horizon_task
from wrappers import Columns, sparse_task_env

HEADER = ["env", "method", "T", "seed", "steps", "train_secs", "success", "budget_secs", "cpu_secs"]
HSTL = "hstl (plane world)"
PUBLISHED = {"tau-MDP PPO (TGPO fig. 2, their tasks)": [1.0, 0.96, 0.37, 0.07],
             "F-MDP PPO (TGPO fig. 2, their tasks)": [0.89, 0.40, 0.20, 0.19]}


def base_env(env_id: str, t: int, folder: Any) -> gymnasium.Env:
    side = t / 5
    if env_id == STANDIN_ID:
        register()
        return gymnasium.make(env_id, side=side, slip=0.05, noise=0.05, disable_env_checker=True).unwrapped
    # hstl/Plane-v0 (or any env taking the world file): the task's own field.
    import hstl  # noqa: F401  (registers hstl/...)

    return gymnasium.make(env_id, world=str(folder / "field.toml"), disable_env_checker=True).unwrapped


def children_cpu() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def hstl_study(spec: Any, seeds: int, out: Any) -> tuple[list[dict[str, str]], float]:
    """The seeds' rows of `hstlc study`, and its CPU seconds per seed."""
    hstlc = ROOT / "bench" / "field" / ".venv" / "bin" / "hstlc"
    before = children_cpu()
    r = subprocess.run([str(hstlc), "study", str(spec), "--seeds", str(seeds), "--threads", "1", "--no-optimum",
                        "--out", str(out), "--force"], capture_output=True, text=True, cwd=spec.parent)
    if r.returncode != 0:
        sys.exit(f"hstlc study {spec} failed:\n{r.stdout}\n{r.stderr}")
    cpu = (children_cpu() - before) / seeds
    folder = next(p for p in out.iterdir() if p.is_dir())
    return read_csv(folder / "seeds.csv"), cpu


def success(make: Any, act: Any, runs: int, t: int, seed: int) -> float:
    envs = [make() for _ in range(runs)]
    obs = np.stack([e.reset(seed=seed * 100_003 + i)[0] for i, e in enumerate(envs)])
    rob = np.full(runs, -math.inf)
    for _ in range(t):
        actions = act(obs)
        for i, e in enumerate(envs):
            o, _, term, trunc, info = e.step(actions[i])
            obs[i] = o
            rob[i] = info["task_robustness"]
    return float(np.mean(rob > 0))


def run_ppo(env_id: str, kind: str, t: int, folder: Any, spec: hstl.Spec, seed: int, seconds: float, max_steps: int,
            tau: int, eval_runs: int) -> list[Any]:
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.env_util import make_vec_env

    torch_one_thread()

    def make() -> gymnasium.Env:
        return sparse_task_env(base_env(env_id, t, folder), spec, Columns([0, 1]), t, observation=kind, tau=tau,
                               flags=["A", "B", "C"], ordered=True)

    class Clock(BaseCallback):
        """Stops learning once the process has spent `seconds` of CPU time in it."""

        def __init__(self) -> None:
            super().__init__()
            self.start = time.perf_counter()
            self.cpu = time.process_time()

        def _on_step(self) -> bool:
            return time.process_time() - self.cpu < seconds

    venv = make_vec_env(make, n_envs=8, seed=seed)
    model = PPO("MlpPolicy", venv, n_steps=256, batch_size=256, gamma=0.99, ent_coef=0.01, seed=seed,
                verbose=0, device="cpu")
    clock = Clock()
    model.learn(total_timesteps=max_steps, callback=clock)
    secs = time.perf_counter() - clock.start
    cpu = time.process_time() - clock.cpu
    rate = success(make, lambda o: model.predict(o, deterministic=True)[0], eval_runs, t, seed ^ 0x5EED)
    return [env_id, f"PPO {kind}", t, seed, model.num_timesteps, round(secs, 2), rate, round(seconds, 2),
            round(cpu, 2)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default=STANDIN_ID)
    ap.add_argument("--horizons", default="50,200,500,1000")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--budget-factor", type=float, default=10.0)
    ap.add_argument("--seconds", type=float, default=None, help="PPO's CPU seconds per run (instead of the factor)")
    ap.add_argument("--max-steps", type=int, default=10_000_000)
    ap.add_argument("--tau", type=int, default=10)
    ap.add_argument("--eval-runs", type=int, default=100)
    ap.add_argument("--kinds", default="tau,flags")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--fresh", action="store_true", help="start over instead of resuming")
    ap.add_argument("--out", default=None, help="the folder (default out/horizons/<env>)")
    args = ap.parse_args()
    warnings.filterwarnings("ignore", module="gymnasium")
    stand_in = args.env == STANDIN_ID
    name = args.env.replace("/", "_")
    out = pathlib.Path(args.out).resolve() if args.out else OUT / "horizons" / name
    if args.plot_only:
        plot(out, stand_in)
        return
    print(f"machine: {machine()}; env {args.env}{' (STAND-IN, not the plane task)' if stand_in else ''}", flush=True)
    settings = {"env": args.env, "seeds": args.seeds, "budget_factor": args.budget_factor, "seconds": args.seconds,
                "max_steps": args.max_steps, "tau": args.tau, "eval_runs": args.eval_runs}
    rows = resume(out, settings, args.fresh)
    done = {(r[1], int(r[2]), int(r[3])) for r in rows}
    for t in [int(x) for x in args.horizons.split(",")]:
        folder = out / f"T{t}"
        spec_path = horizon_task(t, folder)
        spec = hstl.Spec.load(spec_path)
        ours = [r for r in rows if r[1] == HSTL and int(r[2]) == t]
        if len(ours) != args.seeds:
            rows = [r for r in rows if not (r[1] == HSTL and int(r[2]) == t)]
            seeds_rows, cpu = hstl_study(spec_path, args.seeds, folder / "study")
            ours = [[args.env, HSTL, t, r["seed"], "", r["train_secs"], r["P"], "", round(cpu, 2)] for r in seeds_rows]
            rows += ours
            write_csv(out / "runs.csv", HEADER, rows)
        hstl_cpu = statistics.fmean(float(r[8]) for r in ours)
        print(f"T={t}: hstl success {[r[6] for r in ours]}, {hstl_cpu:.1f} CPU s a seed", flush=True)
        budget = args.seconds if args.seconds is not None else args.budget_factor * hstl_cpu
        for kind in args.kinds.split(","):
            for seed in range(args.seeds):
                if (f"PPO {kind}", t, seed) in done:
                    continue
                row = run_ppo(args.env, kind, t, folder, spec, seed, budget, args.max_steps, args.tau, args.eval_runs)
                rows.append(row)
                write_csv(out / "runs.csv", HEADER, rows)
                print(f"T={t}: PPO {kind} seed {seed}: {row[4]} steps in {row[8]} CPU s ({row[5]} s), "
                      f"success {row[6]:.3f}", flush=True)
    plot(out, stand_in)


def resume(out: Any, settings: dict[str, Any], fresh: bool) -> list[list[Any]]:
    """The rows of an earlier run with the same settings, or none (`--fresh`, or no run)."""
    saved = out / "settings.json"
    if fresh or not (out / "runs.csv").exists() or not saved.exists():
        out.mkdir(parents=True, exist_ok=True)
        saved.write_text(json.dumps(settings, indent=1) + "\n")
        (out / "runs.csv").unlink(missing_ok=True)
        return []
    before = json.loads(saved.read_text())
    if before != settings:
        sys.exit(f"{out}: an earlier run used other settings ({before}); pass --fresh to start over")
    rows = [[r[h] for h in HEADER] for r in read_csv(out / "runs.csv")]
    print(f"resuming: {len(rows)} runs already in {out / 'runs.csv'}", flush=True)
    return rows


def plot(out: Any, stand_in: bool) -> None:
    rows = read_csv(out / "runs.csv")
    series: dict[str, dict[str, list[tuple[float, float]]]] = {}
    for r in rows:
        label = r["method"] + (" on the STAND-IN" if stand_in and r["method"].startswith("PPO") else "")
        series.setdefault(label, {}).setdefault(r["seed"], []).append((float(r["T"]), float(r["success"])))
    horizons = sorted({float(r["T"]) for r in rows})
    for name, vals in PUBLISHED.items():
        pts = [(t, v) for t, v in zip([50.0, 200.0, 500.0, 1000.0], vals) if t in horizons]
        if pts:
            series[name] = {"0": pts}
    title = "Timed multi-goal task: success against horizon T"
    if stand_in:
        title += "\nPPO on a pure-Python STAND-IN, not the plane task: not a result"
    band_plot(out / "success.png", {k: list(v.values()) for k, v in series.items()}, "horizon T (steps)",
              "success (greedy runs satisfying the task)", title, logx=True)
    print(f"wrote {out / 'runs.csv'} and success.png")


if __name__ == "__main__":
    main()
