"""The online monitor gives every step of `signal`, each as soon as it is final."""

from __future__ import annotations

import numpy as np
import pytest

import hstl
from conftest import CLI_FIXTURES

SPEC = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")
rng = np.random.default_rng(3)
TRACE = np.clip(7 + np.cumsum(rng.integers(-1, 2, size=(500, 2)), axis=0), 0, 14).astype(float)


@pytest.mark.parametrize("formula", ["A", "B"])
@pytest.mark.filterwarnings("ignore:.*unused `let`:hstl.SpecWarning")
def test_a_bounded_formula_gives_each_verdict_h_states_late(formula):
    bounded = hstl.Spec.parse(
        "spec W { state { x: int in 0..=14, y: int in 0..=14 } let A = x > 3 && y > 10;"
        " let B = (x > 5) until[0..=20] (y > 10); task always[0..=40] A; }"
    )
    monitor = bounded.online(formula)
    h = monitor.horizon
    assert h == bounded.horizon(formula)
    want = bounded.signal(TRACE, formula)
    got = []
    for t, (x, y) in enumerate(TRACE):
        v = monitor.update({"x": x, "y": y})
        if t < h:
            assert v is None
        else:
            assert v == (t - h, want[t - h])
            got.append(v)
        assert monitor.steps == t + 1
    got += monitor.finish()
    assert [s for s, _ in got] == list(range(len(TRACE)))
    assert np.array_equal([v for _, v in got], want)
    # finish() starts a new trace at step 0.
    assert monitor.steps == 0 and monitor.provisional() is None


def test_an_unbounded_task_has_running_values_and_final_ones_at_the_end():
    monitor = SPEC.online()
    assert monitor.horizon is None
    for t, state in enumerate(TRACE[:120]):
        assert monitor.update(state) is None  # a sequence in `state_vars` order
        assert monitor.provisional() == SPEC.robustness(TRACE[: t + 1])
    verdicts = monitor.finish()
    assert np.array_equal([v for _, v in verdicts], SPEC.signal(TRACE[:120]))


def test_repr_and_state_vars():
    monitor = SPEC.online("A")
    assert monitor.state_vars == ["x", "y"]
    assert repr(monitor) == "<hstl.OnlineMonitor horizon 0, 0 steps>"


@pytest.mark.filterwarnings("ignore:.*unused `let`:hstl.SpecWarning")
def test_complete_windows_give_the_determined_steps_and_pickle():
    import math
    import pickle

    spec = hstl.Spec.parse(
        "spec W { state { x: int in 0..=14, y: int in 0..=14 }"
        " let A = eventually[0..=12] (x > 3 && y > 10); task always[0..=40] A; }"
    )
    want = spec.signal(TRACE, "A", windows="complete").tolist()
    determined = [(t, v) for t, v in enumerate(want) if not math.isnan(v)]
    assert len(determined) < len(want)
    monitor = spec.online("A", windows="complete")
    got = []
    for k, (x, y) in enumerate(TRACE):
        v = monitor.update({"x": x, "y": y})
        got += [] if v is None else [v]
        if k == 250:
            monitor = pickle.loads(pickle.dumps(monitor))
    assert got + monitor.finish() == determined
    with pytest.raises(ValueError, match="unknown windows"):
        spec.online(windows="open")
