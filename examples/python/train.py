"""Train the case study from Python, evaluate it, and run it in gymnasium.

Run it after installing the package (see README.md, "Python"):

    python examples/python/train.py                  # the spec's 1200 episodes, W* too
    python examples/python/train.py --episodes 50 --no-optimum --out /tmp/policy.json
"""

import argparse
import tempfile
from typing import Any
from pathlib import Path

import gymnasium

import hstl

SPECS = Path(__file__).resolve().parents[1] / "specs"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--episodes", type=int, default=None, help="override the spec's learn { episodes }")
parser.add_argument("--no-optimum", action="store_true", help="skip W* (value iteration, a few seconds)")
parser.add_argument("--out", type=Path, default=None, help="where to save policy.json")
args = parser.parse_args()

# The case study written with `learn { preset: auto }` (the task, the regions and one
# option per region; the preset brings the tuned settings and plans the options level):
# the same policy.json, byte for byte, as `hstlc train examples/specs/surveillance_auto.hstl`.
spec = hstl.Spec.load(SPECS / "surveillance_auto.hstl")
policy = hstl.train(spec, world="paper", seed=0, episodes=args.episodes)
curve = policy.curve
assert curve is not None  # None only for a policy.json written before curves were kept
tail = curve[-100:].mean()
print(f"trained `{policy.spec_name}` on {policy.env_name}: {len(curve)} episodes, "
      f"{policy.steps} steps, reward per episode {tail:.1f} (last 100)")

# What `hstlc eval` reports: the window rate of 100 greedy runs of 2000 steps, and W*.
# With seed 0 and the spec's episodes: W = 0.750 against the hand-written nearest-cell
# cycle's 0.698, and W* = 0.782, so W/W* = 0.96. (Hand-set `learn` values do worse: the
# spec surveillance_entry.hstl gives W = 0.28 with seed 0; see README, "The case study".)
report = policy.evaluate(optimum=not args.no_optimum)
print(f"window rate W = {report['window_rate']:.4f}; hand-written baseline {report['baseline']:.4f}")
if report["optimum"] is not None:
    print(f"optimum W* = {report['optimum']:.4f}: W/W* = {report['window_rate'] / report['optimum']:.3f}")

# The policy file, written whole; it loads back as the same policy.
out = args.out or Path(tempfile.mkdtemp()) / "policy.json"
policy.save(out)
assert hstl.Policy.load(out) == policy
print(f"saved {out}")

# The policy in gymnasium: the paper's world, rewarded by region A's robustness, with the
# task's own measures in `info`.
env = hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), spec, formula="A")
obs, info = env.reset(seed=1)
policy.reset()
kept = 0
for t in range(1, 501):
    obs, reward, terminated, truncated, info = env.step(policy.act(obs))
    kept += info["window_kept"]
print(f"500 steps in gymnasium: windows kept in {kept}, task robustness {info['task_robustness']:.1f}")

# The same learner over a gymnasium environment of its own (slower: every step calls
# back into Python): FrozenLake's slippery 4 x 4 lake, cell `o` at row o // 4, column o % 4.
# The task is reach-avoid, the goal within 100 steps and never a hole (`abs(...) < 0.5`
# picks one integer cell), and `plan: model` plans the option's leg from the transitions
# training saw. A step into the goal or a hole ends FrozenLake's episode and the learner's,
# so every step it counts is one FrozenLake took.
LAKE = """spec Lake {
    state { row: int in 0..=3, col: int in 0..=3 }
    let Goal = row > 2 && col > 2;
    let Hole = (abs(row - 1) < 0.5 && (abs(col - 1) < 0.5 || abs(col - 3) < 0.5))
        || (abs(row - 2) < 0.5 && abs(col - 3) < 0.5) || (abs(row - 3) < 0.5 && abs(col) < 0.5);
    task eventually[0..100] Goal && always !Hole;
    option Goal { avoid: Hole }
    learn { episodes: 2000, choices: 1, max_steps: 100, plan: model }
}"""


def cell(o: int) -> dict[str, int]:
    return {"row": o // 4, "col": o % 4}


def lake_optimum(steps: int) -> float:
    """The best chance of reaching the goal from the start within `steps` steps: value
    iteration on FrozenLake's known model (`env.unwrapped.P`)."""
    lake: Any = gymnasium.make("FrozenLake-v1").unwrapped
    model = lake.P
    value = [0.0] * 16
    for _ in range(steps):
        value = [
            max(sum(p * (1.0 if r > 0 else 0.0 if done else value[s2]) for p, s2, r, done in model[s][a]) for a in range(4))
            for s in range(16)
        ]
    return value[0]


frozen = hstl.train(hstl.Spec.parse(LAKE), env=gymnasium.make("FrozenLake-v1"), valuation=cell, seed=0)
runs = 500
lake_report = frozen.evaluate(starts=runs, steps=100, env=gymnasium.make("FrozenLake-v1"), valuation=cell)
success, best = lake_report["satisfied"] / runs, lake_optimum(100)
print(f"FrozenLake: goal reached in {success:.3f} of {runs} greedy runs of 100 steps; the optimum is {best:.3f} "
      f"(value iteration): {success / best:.2f} of it, after {frozen.steps} training steps")
