#!/usr/bin/env python3
"""Classic control, persistent: hstl's learner against stable-baselines3 (DQN, PPO) on
patrol tasks, measured alike: the window rate W, the share of steps whose windows are all
kept over greedy runs (100 runs of 2,000 steps, the first 100 of each not counted, as
`hstlc study` and `policy.evaluate` count it).

MountainCar patrol (examples/specs/mountain_car_patrol.hstl: both hill tops within every
200 steps). hstl: `hstlc train` (the wheel's command) on its built-in `mountain-car` world
(gymnasium's MountainCar-v0 dynamics, pinned by a Rust test) over a ladder of episode
budgets, each rung a training of its own, `--seed s`; steps as it prints them, and the
CPU time of the whole command (training, its evaluation and pictures). SB3: gymnasium's `MountainCarEnv` with its goal termination removed
(`NoTermination`), a TimeLimit of the evaluation's run length (2,000 steps), and
`hstl.STLReward` over the task as the reward (the form picked by `--part forms`, the best of
the four); hyperparameters rl-baselines3-zoo's for MountainCar-v0. Checkpoints along
training, each evaluated greedily (its evaluation time not counted). Times are CPU seconds
on one core (SB3 on one torch thread), not wall clock, so that a shared machine slows
neither side's figures.

CartPole patrol (specs/cartpole_patrol.hstl): the same for SB3 on CartPole-v1 without the
pole-fall termination (the fall is the task's `always[0..] !fallen`); hstl's side is `hstl.train(env=Box)` on
the same environment, its speeds clipped to the spec's ranges (`hstl_env_hook`).

Writes out/patrol/<task>/<method>_s<seed>.csv (one per run, so that a partial run keeps
what it finished) and out/patrol/<task>/curves.csv; `--part plot` draws the pictures.
"""

from __future__ import annotations

import argparse
import math
import re
import resource
import statistics
import subprocess
import sys
import time
import warnings
from typing import Any, Callable

import gymnasium
import numpy as np

import hstl
from common import OUT, ROOT, SPECS, band_plot, machine, read_csv, torch_one_thread, write_csv
from wrappers import Bounded, Columns, NoTermination

RUN_STEPS, BURN_IN = 2000, 100
FORMS = ["robustness", "increment", "window", "sparse"]


class Task:
    def __init__(
        self,
        name: str,
        spec_path: Any,
        make_base: Callable[[], gymnasium.Env],
        columns: list[int],
        bounds: tuple[list[float], list[float]] | None = None,
    ) -> None:
        self.name = name
        #: hstl's learner needs a bounded `Box`: these (the spec's declared ranges) where the
        #: environment's space is not.
        self.bounds = bounds
        self.spec_path = spec_path
        self.spec = hstl.Spec.load(spec_path)
        self.make_base = make_base
        self.columns = columns


def mountain_car() -> gymnasium.Env:
    from gymnasium.envs.classic_control import MountainCarEnv

    return NoTermination(MountainCarEnv())


def cartpole() -> gymnasium.Env:
    from gymnasium.envs.classic_control import CartPoleEnv

    return NoTermination(CartPoleEnv())


TASKS = {
    "mountain_car": Task("mountain_car", ROOT / "examples" / "specs" / "mountain_car_patrol.hstl", mountain_car, [0, 1]),
    "cartpole": Task("cartpole", SPECS / "cartpole_patrol.hstl", cartpole, [0, 1, 2, 3],
                     ([-4.8, -10.0, -0.42, -10.0], [4.8, 10.0, 0.42, 10.0])),
}


def make_env(task: Task, reward: str) -> gymnasium.Env:
    env = gymnasium.wrappers.TimeLimit(task.make_base(), RUN_STEPS)
    return hstl.STLReward(env, task.spec, valuation=Columns(task.columns), reward=reward)


# --- evaluation ------------------------------------------------------------------------


def window_rate(task: Task, act: Callable[[np.ndarray], np.ndarray], runs: int, seed: int) -> tuple[float, float]:
    """W over `runs` greedy runs of RUN_STEPS states (the reset's included, as the Rust
    evaluation counts them), the first BURN_IN not counted; and the mean of the runs' task
    robustness. `act` maps a batch of observations to actions; the runs step in lockstep."""
    envs = [make_env(task, "window") for _ in range(runs)]
    obs = np.empty((runs,) + envs[0].observation_space.shape)
    kept = 0
    for i, e in enumerate(envs):
        o, info = e.reset(seed=seed * 100_003 + i)
        obs[i] = o
        kept += bool(info.get("window_kept")) and BURN_IN == 0
    rob = np.zeros(runs)
    for t in range(1, RUN_STEPS):
        actions = act(obs)
        for i, e in enumerate(envs):
            o, _, _, _, info = e.step(actions[i])
            obs[i] = o
            if t >= BURN_IN and info["window_kept"]:
                kept += 1
            rob[i] = info["task_robustness"]
    return kept / (runs * (RUN_STEPS - BURN_IN)), float(np.mean(rob))


# --- SB3 -------------------------------------------------------------------------------


def sb3_model(method: str, task: Task, reward: str, seed: int) -> tuple[Any, Any]:
    """The model and its VecNormalize (or None), rl-baselines3-zoo's MountainCar-v0 and
    CartPole-v1 hyperparameters (policy sizes and schedules as there)."""
    from stable_baselines3 import DQN, PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecNormalize

    if method == "dqn":
        venv = make_vec_env(lambda: make_env(task, reward), n_envs=1, seed=seed)
        if task.name == "mountain_car":
            kw = dict(learning_rate=4e-3, batch_size=128, buffer_size=10_000, learning_starts=1000, gamma=0.98,
                      target_update_interval=600, train_freq=16, gradient_steps=8, exploration_fraction=0.2,
                      exploration_final_eps=0.07, policy_kwargs=dict(net_arch=[256, 256]))
        else:
            kw = dict(learning_rate=2.3e-3, batch_size=64, buffer_size=100_000, learning_starts=1000, gamma=0.99,
                      target_update_interval=10, train_freq=256, gradient_steps=128, exploration_fraction=0.16,
                      exploration_final_eps=0.04, policy_kwargs=dict(net_arch=[256, 256]))
        return DQN("MlpPolicy", venv, seed=seed, verbose=0, device="cpu", **kw), None
    if method == "ppo":
        if task.name == "mountain_car":
            venv = make_vec_env(lambda: make_env(task, reward), n_envs=16, seed=seed)
            norm = VecNormalize(venv, gamma=0.99)
            kw = dict(n_steps=16, gae_lambda=0.98, gamma=0.99, n_epochs=4, ent_coef=0.0)
        else:
            venv = make_vec_env(lambda: make_env(task, reward), n_envs=8, seed=seed)
            norm = VecNormalize(venv, gamma=0.98)
            kw = dict(n_steps=32, batch_size=256, gae_lambda=0.8, gamma=0.98, n_epochs=20, ent_coef=0.0,
                      learning_rate=1e-3, clip_range=0.2)
        return PPO("MlpPolicy", norm, seed=seed, verbose=0, device="cpu", **kw), norm
    raise ValueError(f"method must be dqn or ppo; got {method}")


def checkpoints(budget: int) -> list[int]:
    """Geometric checkpoints from budget/32 to budget."""
    pts = sorted({max(1000, int(budget / 2**k)) for k in range(5, -1, -1)})
    return [p for p in pts if p <= budget]


def run_sb3(task: Task, method: str, reward: str, seed: int, budget: int, runs: int, final_runs: int) -> list[list[Any]]:
    torch_one_thread()
    model, norm = sb3_model(method, task, reward, seed)

    def act(obs: np.ndarray) -> np.ndarray:
        o = norm.normalize_obs(obs) if norm is not None else obs
        return model.predict(o, deterministic=True)[0]

    rows, trained, secs = [], 0, 0.0
    pts = checkpoints(budget)
    for p in pts:
        t0 = time.process_time()
        model.learn(total_timesteps=p - trained, reset_num_timesteps=False)
        secs += time.process_time() - t0
        trained = model.num_timesteps
        w, rob = window_rate(task, act, final_runs if p == pts[-1] else runs, seed ^ 0x5EED)
        rows.append([task.name, method, reward, seed, trained, round(secs, 3), w, rob])
        print(f"  {task.name} {method} reward={reward} seed {seed}: {trained} steps, {secs:.1f} s, W = {w:.3f}", flush=True)
    return rows


# --- hstl ------------------------------------------------------------------------------

TRAINED = re.compile(r"(\d+) episodes, (\d+) steps in ([0-9.]+) s")
RATE = re.compile(r"window rate ([0-9.]+) over")


def children_cpu() -> float:
    """CPU seconds of the finished child processes (hstlc train: its training, the
    evaluation after it and the pictures, so hstl's time is if anything overstated)."""
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def run_hstl_native(task: Task, seed: int, ladder: list[int | None]) -> list[list[Any]]:
    """`hstlc train` at each rung of episodes (None: the spec's own preset), one core."""
    rows = []
    hstlc = str(ROOT / "bench" / "field" / ".venv" / "bin" / "hstlc")
    for episodes in ladder:
        out = OUT / "patrol" / task.name / "hstl_runs" / f"s{seed}_e{episodes or 'preset'}"
        cmd = [hstlc, "train", str(task.spec_path), "--seed", str(seed), "--out", str(out)]
        if episodes is not None:
            cmd += ["--episodes", str(episodes)]
        before = children_cpu()
        r = subprocess.run(cmd, capture_output=True, text=True)
        cpu = children_cpu() - before
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stdout}\n{r.stderr}")
        m, w = TRAINED.search(r.stdout), RATE.search(r.stdout)
        if not m or not w:
            sys.exit(f"cannot read hstlc train's output:\n{r.stdout}")
        rows.append([task.name, "hstl", "window (learner)", seed, int(m.group(2)), round(cpu, 3), float(w.group(1)), math.nan])
        print(f"  {task.name} hstl seed {seed}: {m.group(1)} episodes, {m.group(2)} steps, {m.group(3)} s, W = {w.group(1)}", flush=True)
    return rows


def hstl_env_hook(task: Task, seed: int, episodes: int | None) -> list[list[Any]]:
    """hstl's learner on the gymnasium environment itself (`hstl.train(env=Box)`, issue 27
    item 2, branch py-plane). PENDING until that lands: today `hstl.train(env=)` takes
    `Discrete` observations only, and this records a `pending` row instead of a figure."""
    base = task.make_base()
    if task.bounds is not None:
        base = Bounded(base, *task.bounds)
    env = gymnasium.wrappers.TimeLimit(base, RUN_STEPS)
    valuation = Columns(task.columns)
    try:
        t0 = time.process_time()
        policy = hstl.train(task.spec, env=env, valuation=valuation, seed=seed, episodes=episodes, progress=False)
        secs = time.process_time() - t0
    except (TypeError, ValueError) as e:
        first = str(e).splitlines()[0]
        print(f"  {task.name} hstl seed {seed}: PENDING (hstl.train(env=Box) not available: {first})", flush=True)
        return [[task.name, "hstl", "pending: hstl.train(env=Box)", seed, 0, 0.0, math.nan, math.nan]]
    result = policy.evaluate(starts=100, steps=RUN_STEPS, burn_in=BURN_IN, seed=seed ^ hstl.EVAL_SEED, env=env,
                             valuation=valuation)
    return [[task.name, "hstl", "window (learner)", seed, policy.steps, round(secs, 3), result["window_rate"], math.nan]]


# --- parts -----------------------------------------------------------------------------

HEADER = ["task", "method", "reward", "seed", "steps", "train_cpu_secs", "W", "task_robustness_mean"]


def save(task: Task, name: str, rows: list[list[Any]]) -> None:
    write_csv(OUT / "patrol" / task.name / f"{name}.csv", HEADER, rows)


def best_form(task: Task) -> str:
    path = OUT / "patrol" / task.name / "forms.csv"
    if not path.exists():
        return "window"
    rows = read_csv(path)
    score: dict[str, list[float]] = {}
    for r in rows:
        score.setdefault(r["reward"], []).append(float(r["W"]) + 1e-3 * math.tanh(float(r["task_robustness_mean"])))
    return max(score, key=lambda k: sum(score[k]) / len(score[k]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=["forms", "hstl", "sb3", "hook", "plot"], required=True)
    ap.add_argument("--task", choices=list(TASKS), default="mountain_car")
    ap.add_argument("--methods", default="dqn,ppo")
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--budget", type=int, default=200_000, help="SB3 environment steps per run")
    ap.add_argument("--runs", type=int, default=20, help="greedy runs per checkpoint (the last: --final-runs)")
    ap.add_argument("--final-runs", type=int, default=100)
    ap.add_argument("--ladder", default="1,2,5,10,20,50,100,preset", help="hstl's episode budgets")
    ap.add_argument("--reward", default=None, help="SB3's STLReward form (default: the best of --part forms)")
    args = ap.parse_args()
    warnings.filterwarnings("ignore", module="gymnasium")
    task = TASKS[args.task]
    seeds = [int(s) for s in args.seeds.split(",")]
    print(f"machine: {machine()}", flush=True)
    if args.part == "forms":
        rows = []
        for method in args.methods.split(","):
            for form in FORMS:
                rows += run_sb3(task, method, form, seeds[0], args.budget, args.runs, args.runs)[-1:]
        write_csv(OUT / "patrol" / task.name / "forms.csv", HEADER, rows)
        print(f"best form: {best_form(task)}")
    elif args.part == "hstl":
        ladder = [None if r == "preset" else int(r) for r in args.ladder.split(",")]
        for s in seeds:
            save(task, f"hstl_s{s}", run_hstl_native(task, s, ladder))
    elif args.part == "hook":
        for s in seeds:
            save(task, f"hstl_s{s}", hstl_env_hook(task, s, None))
    elif args.part == "sb3":
        form = args.reward or best_form(task)
        for method in args.methods.split(","):
            for s in seeds:
                save(task, f"{method}_s{s}", run_sb3(task, method, form, s, args.budget, args.runs, args.final_runs))
    elif args.part == "plot":
        plot(task)


def plot(task: Task) -> None:
    folder = OUT / "patrol" / task.name
    rows = []
    for p in sorted(folder.glob("*_s*.csv")):
        rows += read_csv(p)
    write_csv(folder / "curves.csv", HEADER, [[r[h] for h in HEADER] for r in rows])
    series_steps: dict[str, dict[str, list[tuple[float, float]]]] = {}
    series_secs: dict[str, dict[str, list[tuple[float, float]]]] = {}
    for r in rows:
        if r["W"] in ("", "nan"):
            continue
        label = r["method"] if r["method"] == "hstl" else f"SB3 {r['method'].upper()} (STLReward {r['reward']})"
        series_steps.setdefault(label, {}).setdefault(r["seed"], []).append((float(r["steps"]), float(r["W"])))
        series_secs.setdefault(label, {}).setdefault(r["seed"], []).append((max(float(r["train_cpu_secs"]), 1e-2), float(r["W"])))
    title = {"mountain_car": "MountainCar patrol (both hill tops every 200 steps)",
             "cartpole": "CartPole patrol (balance; each end of the track every 200 steps)"}[task.name]
    band_plot(folder / "steps.png", {k: list(v.values()) for k, v in series_steps.items()}, "environment steps",
              "window rate W (greedy runs of 2000 steps)", title, logx=True)
    band_plot(folder / "cpu.png", {k: list(v.values()) for k, v in series_secs.items()}, "training CPU time, s (one core)",
              "window rate W", title, logx=True)
    print(f"wrote {folder / 'curves.csv'}, steps.png, cpu.png\n")
    table(task, rows)


def table(task: Task, rows: list[dict[str, str]]) -> None:
    """The Markdown tables: each method's last checkpoint (mean ± sd, min-max over seeds),
    hstl at equal environment steps and at equal CPU time with each SB3 method, and the
    time to each method's plateau."""
    from common import fmt_spread, spread

    runs: dict[str, dict[str, list[dict[str, str]]]] = {}
    for r in rows:
        runs.setdefault(r["method"], {}).setdefault(r["seed"], []).append(r)
    lines = [f"machine: {machine()}", "",
             "| method | reward | seeds | env steps (mean) | training CPU s (mean) | W at the end, mean ± sd (min-max) |",
             "|---|---|---|---|---|---|"]
    for method, seeds in runs.items():
        last = [s_[-1] for s_ in seeds.values()]
        if any(r["W"] in ("", "nan") for r in last):
            lines.append(f"| {method} | {last[0]['reward']} | {len(last)} | | | pending |")
            continue
        lines.append(f"| {method} | {last[0]['reward']} | {len(last)} | {spread([float(r['steps']) for r in last])[0]:,.0f} "
                     f"| {spread([float(r['train_cpu_secs']) for r in last])[0]:.1f} | {fmt_spread([float(r['W']) for r in last])} |")
    hstl_runs = runs.get("hstl", {})
    if hstl_runs and all(r["W"] not in ("", "nan") for v in hstl_runs.values() for r in v):
        lines += ["", "| SB3 method | its steps, s and W (mean) | hstl at equal steps: W (its rungs with at most those steps, best) | hstl at equal CPU time: W | hstl's time to its plateau, s (mean) | SB3's time to its own best, s (mean) |",
                  "|---|---|---|---|---|---|"]

        def plateau_secs(seed_rows: list[dict[str, str]]) -> float:
            best = max(float(r["W"]) for r in seed_rows)
            return next(float(r["train_cpu_secs"]) for r in seed_rows if float(r["W"]) >= 0.95 * best)

        h_plateau = statistics.fmean(plateau_secs(v) for v in hstl_runs.values())
        for method, seeds in runs.items():
            if method == "hstl":
                continue
            last = [v[-1] for v in seeds.values()]
            steps = statistics.fmean(float(r["steps"]) for r in last)
            secs = statistics.fmean(float(r["train_cpu_secs"]) for r in last)
            w = statistics.fmean(float(r["W"]) for r in last)

            def best_within(key: str, limit: float) -> list[float]:
                out = []
                for v in hstl_runs.values():
                    ok = [float(r["W"]) for r in v if float(r[key]) <= limit]
                    out.append(max(ok) if ok else math.nan)
                return out

            at_steps = best_within("steps", steps)
            at_secs = best_within("train_cpu_secs", secs)
            fmt = lambda xs: ("no rung that small" if any(math.isnan(x) for x in xs) else fmt_spread(xs))  # noqa: E731
            sb3_plateau = statistics.fmean(plateau_secs(v) for v in seeds.values())
            lines.append(f"| {method} | {steps:,.0f} steps, {secs:.0f} s, W {w:.3f} | {fmt(at_steps)} | {fmt(at_secs)} "
                         f"| {h_plateau:.1f} | {sb3_plateau:.1f} |")
    text = "\n".join(lines) + "\n"
    (OUT / "patrol" / task.name / "table.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
