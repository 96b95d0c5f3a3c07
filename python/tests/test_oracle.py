"""The rtamt cases of hstl-robustness's oracle file (computed with rtamt 0.4.10): every
value through Python equals the expected value exactly, whatever form the trace takes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import hstl
from conftest import case_spec_text, oracle_cases, same

CASES = oracle_cases()


def test_the_oracle_file_holds_100_cases():
    assert len(CASES) == 100


def forms(trace):
    """The same trace as every kind of input `signal` takes: (description, trace, columns)."""
    x = np.array(trace["x"], dtype=np.float64)
    y = np.array(trace["y"], dtype=np.float64)
    rows = np.stack([x, y], axis=1)
    yield "dict of lists", {"x": trace["x"], "y": trace["y"]}, None
    yield "dict of float64 arrays", {"x": x, "y": y}, None
    yield "dict of int64 arrays", {"x": x.astype(np.int64), "y": y.astype(np.int64)}, None
    yield "dict of float32 arrays", {"x": x.astype(np.float32), "y": y.astype(np.float32)}, None
    yield "dict of strided views", {"x": np.repeat(x, 2)[::2], "y": np.repeat(y, 2)[::2]}, None
    yield "pandas DataFrame", pd.DataFrame({"t": np.arange(len(x)), "y": y, "x": x}), None
    yield "structured array", np.rec.fromarrays([y, x], names="y,x"), None
    yield "2-D array (C order)", rows, None
    yield "2-D array (Fortran order)", np.asfortranarray(rows), None
    extra = np.stack([y, np.zeros_like(x), x], axis=1)
    yield "2-D array with named columns", extra, ["y", "t", "x"]
    yield "2-D array, Fortran order, named columns", np.asfortranarray(extra), ["y", "t", "x"]


@pytest.mark.parametrize("case", CASES, ids=[f"case{c['id']}" for c in CASES])
def test_every_value_equals_the_oracle(case):
    spec = hstl.Spec.parse(case_spec_text(case["task"]))
    for what, trace, columns in forms(case["trace"]):
        rho = spec.robustness(trace, columns=columns)
        assert same(rho, case["robustness"]), (what, rho, case["robustness"])
        got = spec.signal(trace, columns=columns)
        assert got.dtype == np.float64 and got.shape == (len(case["signal"]),), what
        assert all(same(g, w) for g, w in zip(got.tolist(), case["signal"])), (what, got, case["signal"])
    online = spec.online()
    verdicts = [v for x, y in zip(case["trace"]["x"], case["trace"]["y"]) for v in [online.update({"x": x, "y": y})] if v]
    verdicts += online.finish()
    assert [s for s, _ in verdicts] == list(range(len(case["signal"])))
    assert all(same(v, w) for (_, v), w in zip(verdicts, case["signal"]))
