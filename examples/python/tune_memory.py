"""Tunes the flat and options step sizes (`flat.alpha`, `options.alpha`) of the memory
variant of the case study with Ray Tune and ASHA, and prints every trial's W and W/W*.

    pip install "ray[tune]"          # once, in the environment hstl is installed in
    python examples/python/tune_memory.py               # 8 trials, a few minutes on 2 cores
    python examples/python/tune_memory.py --samples 32 --address auto

Each trial trains the spec once (`--seed`) with the trial's step sizes and reports W, W/W*
and the reward every `--chunk` episodes; ASHA stops the trials that trail the others at
each rung, so most trials stop after a fraction of their episodes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ray import tune
from ray.tune.schedulers import ASHAScheduler

import hstl
import hstl.tune

SPEC = Path(__file__).resolve().parents[1] / "specs" / "surveillance_memory.hstl"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default=str(SPEC), help="the spec to tune (default: the memory variant)")
    ap.add_argument("--samples", type=int, default=8, help="trials (default 8)")
    ap.add_argument("--episodes", type=int, default=None, help="episodes per trial (default: the spec's)")
    ap.add_argument("--chunk", type=int, default=100, help="episodes between reports (default 100)")
    ap.add_argument("--seed", type=int, default=0, help="the seed every trial trains from (default 0)")
    ap.add_argument("--cpus", type=int, default=None, help="CPUs of a local cluster (default: all)")
    ap.add_argument("--address", default=None, help='a Ray cluster to join ("auto" after `ray start`)')
    args = ap.parse_args()

    import ray

    if args.address:
        ray.init(address=args.address)
    else:
        ray.init(num_cpus=args.cpus, include_dashboard=False, _node_ip_address="127.0.0.1")

    spec = hstl.Spec.load(args.spec)
    episodes = args.episodes or hstl._hstl._study_task(spec, hstl.World.builtin("paper"), None)[1]
    space = {
        "flat_alpha": tune.loguniform(0.02, 1.0),
        "options_alpha": tune.loguniform(0.02, 1.0),
        "episodes": episodes,
    }
    tuner = tune.Tuner(
        hstl.tune.trainable_for(spec, seed=args.seed, chunk=args.chunk),
        param_space=space,
        tune_config=tune.TuneConfig(
            metric="window_rate",
            mode="max",
            num_samples=args.samples,
            scheduler=ASHAScheduler(time_attr="episodes", max_t=episodes, grace_period=args.chunk * 2),
        ),
        run_config=tune.RunConfig(verbose=0),
    )
    results = tuner.fit()
    print(f"{len(results)} trials of `{spec.name}`, {episodes} episodes at most:")
    rows = sorted(
        (
            (r.config or {}, r.metrics)
            for r in (results[i] for i in range(len(results)))
            if r.metrics and "window_rate" in r.metrics
        ),
        key=lambda cm: -cm[1]["window_rate"],
    )
    for c, m in rows:
        print(
            f"  flat_alpha {c['flat_alpha']:.3f}  options_alpha {c['options_alpha']:.3f}:"
            f"  W {m['window_rate']:.3f}  W/W* {m.get('ratio', float('nan')):.3f}"
            f"  after {m['episodes']} episodes"
        )
    best = results.get_best_result().config
    assert best is not None  # every trial has a config
    print(f"best: flat_alpha {best['flat_alpha']:.3f}, options_alpha {best['options_alpha']:.3f}")

    # surveillance_memory_tuned.hstl is this spec with `flat: { alpha: 0.05 }`, found by hand.
    print("compare: hstlc study examples/specs/surveillance_memory*.hstl")
    ray.shutdown()


if __name__ == "__main__":
    main()
