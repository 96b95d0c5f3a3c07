"""Shared fixtures: the repository's files and the `hstlc` binary the tests compare with."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CLI_FIXTURES = REPO / "hstlc" / "tests" / "cli"
ORACLE = REPO / "robustness" / "tests" / "data" / "rtamt-cases.jsonl"


def number(v):
    """A number of the oracle file (`"inf"` and `"-inf"` are written as strings)."""
    return float(v)


def oracle_cases():
    """The rtamt cases: task, trace (x, y), robustness at step 0 and the full signal."""
    cases = []
    for line in ORACLE.read_text().splitlines():
        if line.strip():
            c = json.loads(line)
            c["robustness"] = number(c["robustness"])
            c["signal"] = [number(v) for v in c["signal"]]
            c["trace"] = {k: [number(v) for v in vs] for k, vs in c["trace"].items()}
            cases.append(c)
    return cases


def case_spec_text(task: str) -> str:
    return f"spec T {{ state {{ x: float, y: float }} task {task}; }}"


def same(a: float, b: float) -> bool:
    """Equal (so 0 == -0), or both NaN."""
    return a == b or (math.isnan(a) and math.isnan(b))


@pytest.fixture(scope="session")
def hstlc() -> Path:
    """The `hstlc` binary: $HSTLC (scripts/test-python sets it), else one built in target/."""
    given = os.environ.get("HSTLC")
    candidates = [Path(given)] if given else [REPO / "target" / p / "hstlc" for p in ("debug", "release")]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    pytest.fail(f"no hstlc binary at {', '.join(map(str, candidates))}; build it with `cargo build -p hstlc`")


def run_cli(hstlc: Path, *args: str, cwd: Path = CLI_FIXTURES) -> subprocess.CompletedProcess:
    return subprocess.run([str(hstlc), *args], cwd=cwd, capture_output=True, text=True, timeout=60)
