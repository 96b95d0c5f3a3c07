"""The long-horizon task, written by scripts/bench-continuous's own `horizon_task` (so the
field and hstl's figures are over one text): reach A, then B within T/3 steps, then C
within T/3 steps, never touching O, on a square field of side T/5."""

from __future__ import annotations

import importlib.machinery
import importlib.util
import pathlib
from types import ModuleType

from common import ROOT


def bench_continuous() -> ModuleType:
    path = ROOT / "scripts" / "bench-continuous"
    loader = importlib.machinery.SourceFileLoader("bench_continuous", str(path))
    spec = importlib.util.spec_from_loader("bench_continuous", loader)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def horizon_task(t: int, folder: pathlib.Path) -> pathlib.Path:
    """Writes `field.toml` and `timed_T.hstl` into `folder`; the spec's path."""
    return bench_continuous().horizon_task(t, folder)
