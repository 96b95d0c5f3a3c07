"""`signal_batch` equals the per-trace signals, whatever the batch's form and threads."""

from __future__ import annotations

import threading

import numpy as np
import pandas as pd
import pytest

import hstl
from conftest import CLI_FIXTURES

SPEC = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")


def walks(traces: int, steps: int, seed: int = 7) -> np.ndarray:
    """Random walks on the 15 x 15 grid, shape (traces, steps, 2)."""
    rng = np.random.default_rng(seed)
    moves = rng.integers(-1, 2, size=(traces, steps, 2))
    return np.clip(7 + np.cumsum(moves, axis=1), 0, 14).astype(np.float64)


CUBE = walks(25, 300)


@pytest.mark.parametrize("formula", [None, "A"])
@pytest.mark.parametrize("threads", [None, 1, 2, 3, 64])
def test_every_form_of_batch_equals_each_signal(formula, threads):
    want = np.stack([SPEC.signal(t, formula) for t in CUBE])
    forms = {
        "3-D array": (CUBE, None),
        "3-D array, other column order": (CUBE[:, :, ::-1].copy(), ["y", "x"]),
        "3-D array, not contiguous": (np.concatenate([CUBE, CUBE], axis=2)[:, :, :2], None),
        "3-D int array": (CUBE.astype(np.int32), None),
        "list of dicts": ([{"x": t[:, 0], "y": t[:, 1]} for t in CUBE], None),
        "list of DataFrames": ([pd.DataFrame({"y": t[:, 1], "x": t[:, 0]}) for t in CUBE], None),
        "list of 2-D arrays": (list(CUBE), None),
        "generator of 2-D arrays": ((t for t in CUBE), None),
        "mapping of 2-D arrays": ({"x": CUBE[:, :, 0], "y": CUBE[:, :, 1]}, None),
    }
    for what, (batch, columns) in forms.items():
        got = SPEC.signal_batch(batch, formula, columns=columns, threads=threads)
        assert got.dtype == np.float64 and got.shape == want.shape, what
        assert np.array_equal(got, want), what


def test_empty_batches():
    assert SPEC.signal_batch([]).shape == (0, 0)
    assert SPEC.signal_batch(np.zeros((0, 5, 2))).shape == (0, 5)


def test_the_first_bad_trace_is_reported_whatever_the_threads():
    cube = CUBE.copy()
    cube[17, 3, 1] = np.nan
    cube[9, 250, 0] = np.nan
    for threads in [1, 2, 5, 25]:
        with pytest.raises(ValueError, match=r"^trace 9: `x` is NaN at step 250"):
            SPEC.signal_batch(cube, threads=threads)


def test_one_spec_serves_many_python_threads_at_once():
    want = [SPEC.signal(t) for t in CUBE]
    results = {}

    def work(i):
        results[i] = [SPEC.signal_batch(CUBE, threads=2), SPEC.signal(CUBE[i % 25]), SPEC.robustness(CUBE[i % 25])]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i, (batch, signal, rho) in results.items():
        assert np.array_equal(batch, np.stack(want))
        assert np.array_equal(signal, want[i % 25]) and rho == want[i % 25][0]
