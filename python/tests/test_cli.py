"""Python against the command line: `signal` and `robustness` equal `hstlc monitor` (and
`--signal`) bit for bit, `SpecError` equals `hstlc check` (concise and JSON), and errors
read as the CLI's."""

from __future__ import annotations

import csv
import json
import random
import struct

import numpy as np
import pandas as pd
import pytest

import hstl
from conftest import CLI_FIXTURES, run_cli

SURVEILLANCE = CLI_FIXTURES / "surveillance.hstl"


def bits(values) -> list[int]:
    return [struct.unpack("<q", struct.pack("<d", float(v)))[0] for v in values]


def read_csv(path, names):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {n: np.array([float(r[n]) for r in rows]) for n in names}


def cli_signal(hstlc, spec, trace, formula):
    args = ["monitor", str(spec), "--trace", str(trace), "--signal"]
    if formula:
        args += ["--formula", formula]
    out = run_cli(hstlc, *args)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == "t,robustness"
    steps = [line.split(",") for line in lines[1:]]
    assert [int(t) for t, _ in steps] == list(range(len(steps)))
    return [float(v) for _, v in steps]


def cli_robustness(hstlc, spec, trace, formula):
    args = ["monitor", str(spec), "--trace", str(trace)]
    if formula:
        args += ["--formula", formula]
    out = run_cli(hstlc, *args)
    assert out.returncode == 0, out.stderr
    return float(out.stdout)


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    """A 3000-step walk on the grid with non-integer noise and a few infinite samples,
    written with Python's shortest round-trip repr."""
    rng = random.Random(2016)
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    x, y = 7.0, 7.0
    with open(path, "w") as f:
        f.write("t,x,y\n")
        for t in range(3000):
            x = min(14.0, max(0.0, x + rng.choice([-1, 0, 1]) + rng.uniform(-0.3, 0.3)))
            y = min(14.0, max(0.0, y + rng.choice([-1, 0, 1]) + rng.uniform(-0.3, 0.3)))
            xv = repr(x) if t % 997 else "inf"
            f.write(f"{t},{xv},{y!r}\n")
    return path


@pytest.fixture(scope="module")
def surveillance_reals(tmp_path_factory):
    """The surveillance task over `float` state variables, without options: what `hstlc
    monitor` takes traces with fractions and infinities for (an `int` variable holds whole
    numbers)."""
    lines = [line.strip() for line in SURVEILLANCE.read_text().splitlines()]
    items = [line for line in lines if line.startswith(("let ", "task "))]
    path = tmp_path_factory.mktemp("reals") / "surveillance_reals.hstl"
    path.write_text("spec Surveillance {\n    state { x: float, y: float }\n" + "".join(f"    {i}\n" for i in items) + "}\n")
    return path


@pytest.mark.parametrize("formula", [None, "A", "B", "C"])
@pytest.mark.parametrize("trace", ["trace.csv", "infinite.csv", "walk"])
def test_signal_and_robustness_equal_hstlc_monitor(hstlc, walk_csv, surveillance_reals, trace, formula):
    path = walk_csv if trace == "walk" else CLI_FIXTURES / trace
    spec_file = SURVEILLANCE if trace == "trace.csv" else surveillance_reals
    spec = hstl.Spec.load(spec_file)
    columns = read_csv(path, spec.state_vars)
    want = cli_signal(hstlc, spec_file, path, formula)
    got = spec.signal(columns, formula)
    assert bits(got) == bits(want)
    assert bits(spec.signal(pd.DataFrame(columns), formula)) == bits(want)
    rows = np.stack([columns["x"], columns["y"]], axis=1)
    assert bits(spec.signal(rows, formula)) == bits(want)
    assert bits(spec.signal_batch([columns, columns], formula).ravel()) == bits(want) * 2
    assert bits([spec.robustness(columns, formula)]) == bits([cli_robustness(hstlc, spec_file, path, formula)])


def test_spec_error_is_check_concise_and_json(hstlc, monkeypatch):
    monkeypatch.chdir(CLI_FIXTURES)
    concise = run_cli(hstlc, "check", "--format", "concise", "errors.hstl")
    listed = json.loads(run_cli(hstlc, "check", "--format", "json", "errors.hstl").stdout)
    assert concise.returncode == 1 and len(listed) >= 3
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.load("errors.hstl")
    assert str(e.value) == concise.stdout.rstrip("\n")
    fields = ["file", "severity", "code", "message", "line", "column", "end_line", "end_column", "help"]
    assert [{f: getattr(d, f) for f in fields} for d in e.value.diagnostics] == listed
    # Parsing the same text reports the same, under the name given.
    with pytest.raises(hstl.SpecError) as parsed:
        hstl.Spec.parse((CLI_FIXTURES / "errors.hstl").read_text(), filename="errors.hstl")
    assert str(parsed.value) == str(e.value) and parsed.value.diagnostics == e.value.diagnostics


def test_warnings_come_with_the_spec_as_check_lists_them(hstlc, monkeypatch):
    monkeypatch.chdir(CLI_FIXTURES)
    listed = json.loads(run_cli(hstlc, "check", "--format", "json", "warnings.hstl").stdout)
    with pytest.warns(hstl.SpecWarning) as issued:
        spec = hstl.Spec.load("warnings.hstl")
    assert listed and all(d["severity"] == "warning" for d in listed)
    # Each is issued as a Python warning, and hstl.check lists the same.
    assert [w.message.diagnostic for w in issued] == spec.diagnostics == hstl.check("warnings.hstl")
    assert [d.code for d in spec.diagnostics] == [d["code"] for d in listed]
    assert [(d.line, d.column, d.end_line, d.end_column) for d in spec.diagnostics] == [
        (d["line"], d["column"], d["end_line"], d["end_column"]) for d in listed
    ]


def first_line_of_cli_error(result) -> str:
    line = result.stderr.splitlines()[0]
    assert line.startswith("error: "), result.stderr
    return line[len("error: "):]


@pytest.mark.parametrize(
    "cli, call, kind",
    [
        (
            ["monitor", "surveillance.hstl", "--trace", "trace.csv", "--formula", "Nope"],
            lambda: hstl.Spec.load("surveillance.hstl").signal({"x": [1], "y": [2]}, "Nope"),
            ValueError,
        ),
        (
            ["check", "nowhere.hstl"],
            lambda: hstl.Spec.load("nowhere.hstl"),
            FileNotFoundError,
        ),
        (
            ["monitor", "two_specs.hstl", "--trace", "x.csv"],
            lambda: hstl.Spec.load("two_specs.hstl"),
            hstl.SpecError,
        ),
        (
            ["monitor", "two_specs.hstl", "--spec", "Third", "--trace", "x.csv"],
            lambda: hstl.Spec.load("two_specs.hstl", name="Third"),
            hstl.SpecError,
        ),
    ],
    ids=["unknown formula", "missing file", "two specs", "unknown spec"],
)
def test_errors_read_as_the_cli_prints_them(hstlc, monkeypatch, cli, call, kind):
    monkeypatch.chdir(CLI_FIXTURES)
    result = run_cli(hstlc, *cli)
    assert result.returncode == 2
    with pytest.raises(kind) as e:
        call()
    assert str(e.value).splitlines()[0] == first_line_of_cli_error(result)


PATROL = CLI_FIXTURES / "patrol.hstl"


@pytest.mark.filterwarnings("ignore::hstl.SpecWarning")
@pytest.mark.parametrize("csv_name", ["cycle.csv", "cycle_short.csv"])
@pytest.mark.parametrize("formula", [None, "SoonA"])
def test_windows_complete_is_hstlc_monitor_windows_complete(hstlc, csv_name, formula):
    spec = hstl.Spec.load(PATROL)
    trace_path = CLI_FIXTURES / csv_name
    trace = read_csv(trace_path, ["x", "y"])
    extra = ["--formula", formula] if formula else []
    out = run_cli(hstlc, "monitor", str(PATROL), "--trace", str(trace_path), "--windows", "complete", "--signal", *extra)
    assert out.returncode == 0, out.stderr
    # Undetermined steps: empty fields in the CLI, NaN in Python.
    want = [float(line.split(",")[1] or "nan") for line in out.stdout.splitlines()[1:]]
    signal = spec.signal(trace, formula, windows="complete")
    assert bits(signal) == bits(want)
    batch = spec.signal_batch([trace, trace], formula, windows="complete", threads=2)
    assert bits(batch[1]) == bits(want)
    step0 = run_cli(hstlc, "monitor", str(PATROL), "--trace", str(trace_path), "--windows", "complete", *extra)
    first = step0.stdout.strip()
    value = spec.robustness(trace, formula, windows="complete")
    assert (np.isnan(value) and first == "undetermined") or value == float(first)
    # Clipped stays the default.
    assert bits(spec.signal(trace, formula, windows="clipped")) == bits(spec.signal(trace, formula))


@pytest.mark.filterwarnings("ignore::hstl.SpecWarning")
def test_windows_must_be_clipped_or_complete():
    spec = hstl.Spec.load(PATROL)
    with pytest.raises(ValueError, match='unknown windows `full`\n  help: pass "clipped"'):
        spec.signal({"x": [1.0], "y": [1.0]}, windows="full")
