"""Train the case study from Python, evaluate it, and run it in gymnasium.

Run it after installing the package (see README.md, "Python"):

    python examples/python/train.py                  # the spec's 1200 episodes, W* too
    python examples/python/train.py --episodes 50 --no-optimum --out /tmp/policy.json
"""

import argparse
import tempfile
from pathlib import Path

import gymnasium

import hstl

SPECS = Path(__file__).resolve().parents[1] / "specs"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--episodes", type=int, default=None, help="override the spec's learn { episodes }")
parser.add_argument("--no-optimum", action="store_true", help="skip W* (value iteration, a few seconds)")
parser.add_argument("--out", type=Path, default=None, help="where to save policy.json")
args = parser.parse_args()

# The case study's O_T1 options, with legs that stop on entering their region: the same
# policy.json, byte for byte, as `hstlc train examples/specs/surveillance_entry.hstl`.
spec = hstl.Spec.load(SPECS / "surveillance_entry.hstl")
policy = hstl.train(spec, world="paper", seed=0, episodes=args.episodes)
tail = policy.curve[-100:].mean()
print(f"trained `{policy.spec_name}` on {policy.env_name}: {len(policy.curve)} episodes, "
      f"{policy.steps} steps, reward per episode {tail:.1f} (last 100)")

# What `hstlc eval` reports: the window rate of 100 greedy runs of 2000 steps, and W*.
report = policy.evaluate(optimum=not args.no_optimum)
print(f"window rate {report['window_rate']:.4f}; hand-written baseline {report['baseline']:.4f}")
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
# back into Python): FrozenLake's 4 x 4 lake, cell `o` at row o // 4, column o % 4.
lake = hstl.Spec.parse("""
    spec Lake {
        state { row: int in 0..=3, col: int in 0..=3 }
        let Goal = row > 2 && col > 2;
        task eventually[0..50] Goal;
        option Goal;
        learn { episodes: 200, choices: 4, max_steps: 50 }
    }""")
frozen = hstl.train(lake, env=gymnasium.make("FrozenLake-v1"), valuation=lambda o: {"row": o // 4, "col": o % 4},
                    seed=0, episodes=args.episodes)
lake_report = frozen.evaluate(starts=20, steps=50, env=gymnasium.make("FrozenLake-v1"),
                              valuation=lambda o: {"row": o // 4, "col": o % 4})
print(f"FrozenLake: goal reached in {lake_report['satisfied']} of 20 greedy runs")
