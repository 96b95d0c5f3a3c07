"""Monitor traces of the case study's task from Python: one trace, a batch, and online.

Run it after installing the package (see README.md, "Python"):

    python examples/python/monitor.py
"""

from pathlib import Path

import numpy as np
import numpy.typing as npt

import hstl

SPECS = Path(__file__).resolve().parents[1] / "specs"

# The paper's persistent surveillance task: visit A, B and C within every 40 steps.
spec = hstl.Spec.load(SPECS / "surveillance_ot1.hstl")
print(f"{spec.name}: state {spec.state_vars}, lets {spec.lets}")


def walk(steps: int, rng: np.random.Generator) -> npt.NDArray[np.float64]:
    """A random walk on the 15 x 15 grid, as an array of shape (steps, 2): columns x, y."""
    moves = rng.integers(-1, 2, size=(steps, 2))
    return np.clip(7 + np.cumsum(moves, axis=0), 0, 14).astype(np.float64)


rng = np.random.default_rng(0)
trace = walk(2000, rng)

# One trace: a 2-D array whose columns are the state variables in order (or a dict of
# arrays, or a pandas DataFrame).
print(f"robustness at step 0: {spec.robustness(trace)}")
signal = np.asarray(spec.signal(trace, formula="A"))  # the `let` A at every step
print(f"A holds at {np.count_nonzero(signal > 0)} of {len(signal)} steps")

# A batch: 200 rollouts of 500 steps, scored on every core.
rollouts = np.stack([walk(500, rng) for _ in range(200)])
scores = np.asarray(spec.signal_batch(rollouts))[:, 0]
print(f"best rollout: {int(np.argmax(scores))} with robustness {scores.max()}")

# Online: one state at a time; a verdict for step t arrives once its window is complete.
online = spec.online(formula="A")
verdicts = [online.update({"x": x, "y": y}) for x, y in trace[:5]]
print(f"online verdicts of A for the first 5 states: {verdicts}")

# A spec with an error raises SpecError, with the diagnostics of `hstlc check`.
try:
    hstl.Spec.parse("spec Broken { state { x: int in 0..=9 } task eventually[0..5] Missing; }")
except hstl.SpecError as e:
    print(e)
    print(f"first diagnostic: {e.diagnostics[0].code} at {e.diagnostics[0].line}:{e.diagnostics[0].column}")
