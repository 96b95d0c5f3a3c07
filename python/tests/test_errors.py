"""Every kind of bad input raises a Python exception with the command line's words, and
nothing crashes the interpreter or leaks a Rust panic."""

from __future__ import annotations

import collections

import os
import pickle
import random
import subprocess
import warnings

import numpy as np
import pandas as pd
import pytest

import hstl
from conftest import CLI_FIXTURES, run_cli

SPEC = hstl.Spec.parse(
    "spec S { state { x: int in 0..=9, y: float } let A = x > 3; let B = y < 2;"
    " task eventually[0..=3] (A && B); }",
    filename="s.hstl",
)
NAN_HELP = (
    "\n  help: robustness has no meaning for NaN: drop the step or give it a number "
    "(`inf` and `-inf` are allowed)"
)
ORDER_HELP = "\n  help: give one value per state variable, in the order `x`, `y`"

GOOD = {"x": [1.0, 5.0, 6.0], "y": [0.0, 1.0, 3.0]}

BAD_TRACES = [
    # (what, call, exception, message)
    (
        "ragged dict",
        lambda: SPEC.signal({"x": [1, 2, 3], "y": [1, 2]}),
        ValueError,
        "state variable `y` has 2 samples, but `x` has 3 samples"
        "\n  help: give every state variable one sample per step",
    ),
    (
        "empty trace",
        lambda: SPEC.signal({"x": [], "y": []}),
        ValueError,
        "the trace has no samples\n  help: give every state variable at least one sample",
    ),
    (
        "NaN in a dict",
        lambda: SPEC.signal({"x": [1, 2, 3], "y": [0, np.nan, 1]}),
        ValueError,
        "`y` is NaN at step 1" + NAN_HELP,
    ),
    (
        "NaN in a 2-D array",
        lambda: SPEC.signal(np.array([[1.0, 0.0], [np.nan, 1.0]])),
        ValueError,
        "`x` is NaN at step 1" + NAN_HELP,
    ),
    (
        "NaN read by robustness",
        lambda: SPEC.robustness({"x": [1, 2, 3, np.nan, 5], "y": [0] * 5}),
        ValueError,
        "`x` is NaN at step 3" + NAN_HELP,
    ),
    (
        "NaN in a DataFrame",
        lambda: SPEC.signal(pd.DataFrame({"x": [1.0, None], "y": [0.0, 1.0]})),
        ValueError,
        "`x` is NaN at step 1" + NAN_HELP,
    ),
    (
        "missing variable in a dict",
        lambda: SPEC.signal({"x": [1, 2], "t": [0, 1]}),
        KeyError,
        "missing state variable `y`"
        "\n  help: the trace has `x`, `t`; the spec's state variables are `x`, `y`",
    ),
    (
        "missing column in a DataFrame",
        lambda: SPEC.signal(pd.DataFrame({"x": [1.0], "z": [2.0]})),
        KeyError,
        "missing state variable `y`"
        "\n  help: the trace has `x`, `z`; the spec's state variables are `x`, `y`",
    ),
    (
        "missing field in a structured array",
        lambda: SPEC.signal(np.rec.fromarrays([[1.0]], names="x")),
        KeyError,
        "missing state variable `y`\n  help: the trace has `x`; the spec's state variables are `x`, `y`",
    ),
    (
        "missing name in columns",
        lambda: SPEC.signal(np.zeros((3, 2)), columns=["x", "z"]),
        KeyError,
        "missing state variable `y`\n  help: the trace has `x`, `z`; the spec's state variables are `x`, `y`",
    ),
    (
        "strings",
        lambda: SPEC.signal({"x": ["a", "b"], "y": [1, 2]}),
        TypeError,
        "state variable `x` holds values of dtype <U1, not numbers\n  help: give int or float values",
    ),
    (
        "complex numbers",
        lambda: SPEC.signal({"x": np.array([1j, 2]), "y": [1, 2]}),
        TypeError,
        "state variable `x` holds values of dtype complex128, not numbers\n  help: give int or float values",
    ),
    (
        "None among numbers",
        lambda: SPEC.signal({"x": [1, None], "y": [1, 2]}),
        TypeError,
        "state variable `x` holds values of dtype object, not numbers\n  help: give int or float values",
    ),
    (
        "ragged nested lists",
        lambda: SPEC.signal({"x": [[1, 2], [3]], "y": [1, 2]}),
        ValueError,
        None,  # numpy's own words follow ours; checked by prefix below
    ),
    (
        "2-D column in a dict",
        lambda: SPEC.signal({"x": np.zeros((2, 2)), "y": [1, 2]}),
        ValueError,
        "state variable `x` must be 1-D, one sample per step; got shape (2, 2)",
    ),
    (
        "scalar column",
        lambda: SPEC.signal({"x": 3, "y": [1, 2]}),
        ValueError,
        "state variable `x` must be 1-D, one sample per step; got shape ()",
    ),
    (
        "1-D array as a trace",
        lambda: SPEC.signal(np.array([1.0, 2.0])),
        ValueError,
        "a trace array must be 2-D (steps, columns); got shape (2,)\n  help: for one state variable pass"
        ' `{"x": array}` or `array[:, None]`; for many traces call `signal_batch`',
    ),
    (
        "3-D array as a trace",
        lambda: SPEC.signal(np.zeros((2, 3, 2))),
        ValueError,
        "a trace array must be 2-D (steps, columns); got shape (2, 3, 2)\n  help: for one state variable pass"
        ' `{"x": array}` or `array[:, None]`; for many traces call `signal_batch`',
    ),
    (
        "2-D array of the wrong width",
        lambda: SPEC.signal(np.zeros((4, 3))),
        ValueError,
        "the array has 3 columns, but the spec has 2 state variables"
        "\n  help: name the columns with `columns=[...]`, or give them in the order `x`, `y`",
    ),
    (
        "columns of the wrong length",
        lambda: SPEC.signal(np.zeros((4, 3)), columns=["x", "y"]),
        ValueError,
        "`columns` names 2 columns, but the array has 3\n  help: give one name per column of the array",
    ),
    (
        "columns as one string",
        lambda: SPEC.signal(np.zeros((4, 2)), columns="xy"),
        TypeError,
        "`columns` must be a sequence of names; got str",
    ),
    (
        "columns with a mapping",
        lambda: SPEC.signal(GOOD, columns=["x", "y"]),
        TypeError,
        "`columns` names the columns of a 2-D array; a mapping names its own columns\n  help: leave out `columns`",
    ),
    (
        "a list as a trace",
        lambda: SPEC.signal([[1, 2], [3, 4]]),
        TypeError,
        "a trace is a mapping from state variable names to arrays, or a 2-D array; got list"
        '\n  help: pass a dict such as `{"x": xs, "y": ys}`, a pandas DataFrame, or a numpy array of shape'
        " (steps, columns)",
    ),
    (
        "a number as a trace",
        lambda: SPEC.robustness(3.0),
        TypeError,
        "a trace is a mapping from state variable names to arrays, or a 2-D array; got float"
        '\n  help: pass a dict such as `{"x": xs, "y": ys}`, a pandas DataFrame, or a numpy array of shape'
        " (steps, columns)",
    ),
    (
        "a string array as a 2-D trace",
        lambda: SPEC.signal(np.array([["a", "b"]])),
        TypeError,
        "the trace holds values of dtype <U1, not numbers\n  help: give int or float values",
    ),
    (
        "unknown formula",
        lambda: SPEC.signal(GOOD, "Nope"),
        ValueError,
        "s.hstl: spec `S` has no `let` named `Nope`; its lets are `A`, `B`"
        "\n  help: leave out `formula` to score the task",
    ),
    (
        "unknown formula for the horizon",
        lambda: SPEC.horizon("Nope"),
        ValueError,
        "s.hstl: spec `S` has no `let` named `Nope`; its lets are `A`, `B`"
        "\n  help: leave out `formula` to score the task",
    ),
    (
        "formula that is not a string",
        lambda: SPEC.signal(GOOD, 3),
        TypeError,
        None,
    ),
    (
        "batch of different lengths",
        lambda: SPEC.signal_batch([GOOD, {"x": [1], "y": [2]}]),
        ValueError,
        "trace 1 has 1 steps, but trace 0 has 3"
        "\n  help: cut or pad the traces to one length, or score each with `signal`",
    ),
    (
        "batch with NaN",
        lambda: SPEC.signal_batch([GOOD, GOOD, {"x": [1, 2, np.nan], "y": [1, 2, 3]}]),
        ValueError,
        "trace 2: `x` is NaN at step 2" + NAN_HELP,
    ),
    (
        "batch with a missing variable",
        lambda: SPEC.signal_batch([GOOD, {"x": [1, 2, 3]}]),
        KeyError,
        "trace 1: missing state variable `y`\n  help: the trace has `x`; the spec's state variables are `x`, `y`",
    ),
    (
        "batch with a bad dtype",
        lambda: SPEC.signal_batch([GOOD, {"x": ["a"], "y": [1]}]),
        TypeError,
        "trace 1: state variable `x` holds values of dtype <U1, not numbers\n  help: give int or float values",
    ),
    (
        "2-D array as a batch",
        lambda: SPEC.signal_batch(np.zeros((3, 2))),
        ValueError,
        "a batch array must be 3-D (traces, steps, columns) of numbers; got shape (3, 2)"
        "\n  help: for one trace call `signal`",
    ),
    (
        "3-D batch of the wrong width",
        lambda: SPEC.signal_batch(np.zeros((2, 3, 4))),
        ValueError,
        "the batch array has 4 columns, but the spec has 2 state variables"
        "\n  help: name the columns with `columns=[...]`, or give them in the order `x`, `y`",
    ),
    (
        "batch mapping of different shapes",
        lambda: SPEC.signal_batch({"x": np.zeros((2, 3)), "y": np.zeros((2, 4))}),
        ValueError,
        "state variable `y` has shape (2, 4), but `x` has (2, 3)"
        "\n  help: give every state variable one sample per trace and step",
    ),
    (
        "batch mapping of 1-D arrays",
        lambda: SPEC.signal_batch({"x": [1, 2], "y": [1, 2]}),
        ValueError,
        "in a batch, state variable `x` must be 2-D (traces, steps); got shape (2,)"
        "\n  help: for one trace call `signal`",
    ),
    (
        "a string as a batch",
        lambda: SPEC.signal_batch("traces"),
        TypeError,
        "a batch is a list of traces or a 3-D array; got str",
    ),
    (
        "a number as a batch",
        lambda: SPEC.signal_batch(3),
        TypeError,
        "a batch is a list of traces or a 3-D array; got int"
        "\n  help: pass a list of dicts or DataFrames, or an array (traces, steps, columns)",
    ),
    (
        "no threads",
        lambda: SPEC.signal_batch([GOOD], threads=0),
        ValueError,
        "`threads` must be at least 1",
    ),
    (
        "negative threads",
        lambda: SPEC.signal_batch([GOOD], threads=-1),
        OverflowError,
        None,
    ),
]


@pytest.mark.parametrize("what, call, kind, message", BAD_TRACES, ids=[b[0] for b in BAD_TRACES])
def test_bad_traces_raise_with_their_message(what, call, kind, message):
    with pytest.raises(kind) as e:
        call()
    if message is not None:
        assert str(e.value) == message
    elif what == "ragged nested lists":
        assert str(e.value).startswith("state variable `x` is not an array of numbers: ")


def test_a_missing_variable_is_a_key_error_that_reads_well():
    with pytest.raises(hstl.MissingVariableError) as e:
        SPEC.signal({"x": [1]})
    assert isinstance(e.value, KeyError)
    assert str(e.value).startswith("missing state variable `y`")


def test_nan_past_the_horizon_does_not_stop_robustness():
    # Step 0 of `eventually[0..=3]` reads steps 0 to 3 only; `signal` reads them all.
    trace = {"x": [1, 2, 3, 4, np.nan], "y": [0, 0, 0, 0, 0]}
    assert SPEC.robustness(trace) == 1.0
    with pytest.raises(ValueError, match="`x` is NaN at step 4"):
        SPEC.signal(trace)


def test_a_nan_computed_by_an_expression_raises_naming_the_step_and_the_expression(hstlc, tmp_path):
    # The example: a min over the window would skip the NaN and give 1.
    text = "spec S { state { x: float } task always[0..=2] (sqrt(x) > 1); }"
    spec = hstl.Spec.parse(text)
    message = (
        "`sqrt(x)` is NaN at step 1: the square root of -1\n  help: robustness has no meaning "
        "for NaN: write the expression so that it is defined on every state the trace can hold "
        "(for example `sqrt(abs(x))`), or fix the trace"
    )
    for call in (spec.signal, spec.robustness):
        with pytest.raises(ValueError) as e:
            call({"x": [4.0, -1.0, 9.0]})
        assert str(e.value) == message
    online = spec.online()
    online.update({"x": 4.0})
    with pytest.raises(ValueError) as e:
        online.update({"x": -1.0})
    assert str(e.value) == message
    # The command line refuses the same trace in the same words, at the line of the step.
    (tmp_path / "s.hstl").write_text(text)
    (tmp_path / "t.csv").write_text("x\n4\n-1\n9\n")
    cli = subprocess.run(
        [hstlc, "monitor", "s.hstl", "--trace", "t.csv"], cwd=tmp_path, capture_output=True, text=True
    )
    assert cli.returncode == 2
    assert cli.stderr == "error: t.csv:3:1: " + message + "\n"


def test_bad_states_for_the_online_monitor():
    online = SPEC.online()
    assert online.update({"x": 1, "y": 0}) is None
    cases = [
        ({"x": np.nan, "y": 0}, ValueError, "`x` is NaN at step 1" + NAN_HELP),
        ({"x": 1}, KeyError, "missing state variable `y`\n  help: the trace has `x`; the spec's state variables are `x`, `y`"),
        ({"x": "a", "y": 0}, TypeError, "`x` must be a number; got str"),
        ([1.0], ValueError, "the state has 1 value, the spec has 2 state variables" + ORDER_HELP),
        ([1.0, 2.0, 3.0], ValueError, "the state has 3 values, the spec has 2 state variables" + ORDER_HELP),
        ((1.0,), ValueError, "the state has 1 value, the spec has 2 state variables" + ORDER_HELP),
        (np.array([1, 2, 3]), ValueError, "the state has 3 values, the spec has 2 state variables" + ORDER_HELP),
        (np.array([np.nan, 0.0]), ValueError, "`x` is NaN at step 1" + NAN_HELP),
        (("a", 0), TypeError, "`x` must be a number; got str"),
        ("xy", TypeError, "a state is a mapping or a sequence of numbers; got str"),
        (3, TypeError, 'a state is a mapping or a sequence of numbers; got int\n  help: pass a dict such as `{"x": 1, "y": 2}`'),
    ]
    for state, kind, message in cases:
        with pytest.raises(kind) as e:
            online.update(state)
        assert str(e.value) == message, state
    assert online.steps == 1, "a refused state changes nothing"
    assert online.update(np.array([2.0, 0.0])) is None


def test_every_kind_of_state_gives_the_same_values():
    states = [(3, 0), (1, 2), (7, 1), (0, 5)]
    kinds = [
        lambda x, y: {"x": x, "y": y},
        lambda x, y: (x, y),
        lambda x, y: [float(x), y],
        lambda x, y: np.array([x, y]),  # int64, read directly
        lambda x, y: np.array([x, y], dtype=np.float64),
        lambda x, y: np.array([x, y], dtype=np.float32),  # converted element by element
        lambda x, y: np.array([[x, 9], [y, 9]])[:, 0],  # a strided view
        lambda x, y: collections.OrderedDict(y=y, x=x),
    ]
    results = []
    for kind in kinds:
        online = SPEC.online()
        verdicts = [online.update(kind(x, y)) for x, y in states]
        results.append([v for v in verdicts if v] + online.finish())
    assert all(r == results[0] for r in results) and len(results[0]) == len(states)


SPEC_TEXTS = [
    (
        "a spec with errors",
        "spec S { state { x: int in 0..=9 } let A = x > ; task eventually[0..3] A; }",
        "<string>:1:48: HSTL001 error: expected an expression, found `;`\nchecked 1 file: 1 error, 0 warnings",
    ),
    (
        "no spec",
        "// nothing here\n",
        "<string>: the file holds no spec\n  help: write `spec Name { ... }` in it",
    ),
]


@pytest.mark.parametrize("what, text, message", SPEC_TEXTS, ids=[s[0] for s in SPEC_TEXTS])
def test_bad_spec_texts_raise_spec_error(what, text, message):
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.parse(text)
    assert str(e.value) == message


def test_several_specs_need_a_name():
    text = (
        "spec First { state { x: int in 0..=9 } let Hi = x > 5; task eventually[0..3] Hi; }\n"
        "spec Second { state { x: int in 0..=9 } let Lo = x < 2; task always[0..3] Lo; }\n"
    )
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.parse(text, filename="two.hstl")
    assert str(e.value) == "two.hstl: the file holds 2 specs\n  help: pick one with `name=`: `First`, `Second`"
    assert e.value.diagnostics == []
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.parse(text, filename="two.hstl", name="Third")
    assert str(e.value) == "two.hstl: no spec named `Third`\n  help: the file holds `First`, `Second`"
    assert hstl.Spec.parse(text, name="Second").name == "Second"


def test_unreadable_files(tmp_path):
    missing = tmp_path / "nowhere.hstl"
    with pytest.raises(FileNotFoundError) as e:
        hstl.Spec.load(missing)
    assert str(e.value) == (
        f"cannot read `{missing}`: no such file or directory"
        "\n  help: check the path; it is read relative to the working directory"
    )
    with pytest.raises(IsADirectoryError) as e:
        hstl.Spec.load(tmp_path)
    assert str(e.value) == f"cannot read `{tmp_path}`: is a folder"
    latin1 = tmp_path / "latin1.hstl"
    latin1.write_bytes(b"spec S {}\n// caf\xe9\n")
    with pytest.raises(ValueError) as e:
        hstl.Spec.load(latin1)
    assert str(e.value) == f"{latin1}:2:7: the file is not UTF-8 text\n  help: save it as UTF-8; hstl reads no other encoding"
    if os.geteuid() != 0:  # root reads any file
        locked = tmp_path / "locked.hstl"
        locked.write_text("spec S {}")
        locked.chmod(0)
        with pytest.raises(PermissionError):
            hstl.Spec.load(locked)
    with pytest.raises(TypeError):
        hstl.Spec.load(3)


def cli_first_line(hstlc, *args):
    result = subprocess.run([str(hstlc), *args], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2, result.stderr
    line = result.stderr.splitlines()[0]
    assert line.startswith("error: "), result.stderr
    return line[len("error: "):]


def test_files_past_the_clis_limits_are_refused_as_it_refuses_them(hstlc, tmp_path):
    """A spec or world file over 64 MiB and a policy over 1 GiB (sparse files: refused by
    their size, nothing is read), a folder, and text that is not UTF-8."""
    big_spec, big_world, big_policy = tmp_path / "big.hstl", tmp_path / "big.toml", tmp_path / "big.json"
    for path, size in [(big_spec, (64 << 20) + 1), (big_world, (64 << 20) + 1), (big_policy, (1 << 30) + 1)]:
        with open(path, "wb") as f:
            f.truncate(size)
    small = str(CLI_FIXTURES / "small.hstl")
    cases = [
        (lambda: hstl.Spec.load(big_spec), ValueError, ["check", str(big_spec)]),
        (lambda: hstl.World.load(big_world), ValueError, ["check", small, "--world", str(big_world)]),
        (lambda: hstl.Policy.load(big_policy), ValueError, ["eval", str(big_policy)]),
        (lambda: hstl.World.load(tmp_path), IsADirectoryError, ["check", small, "--world", f"{tmp_path}/"]),
        (lambda: hstl.Policy.load(tmp_path), IsADirectoryError, ["eval", str(tmp_path)]),
    ]
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(b'map = """\n..\n"""\n# caf\xe9\n')
    cases.append((lambda: hstl.World.load(latin1), ValueError, ["check", small, "--world", str(latin1)]))
    for call, kind, cli in cases:
        with pytest.raises(kind) as e:
            call()
        assert str(e.value).splitlines()[0] == cli_first_line(hstlc, *cli).replace(f"`{tmp_path}/`", f"`{tmp_path}`"), cli
    # A byte order mark (as some Windows editors write) is no part of the text.
    bom = tmp_path / "bom.hstl"
    bom.write_bytes(b"\xef\xbb\xbf" + (CLI_FIXTURES / "small.hstl").read_bytes())
    assert hstl.Spec.load(bom).source == (CLI_FIXTURES / "small.hstl").read_text()


def random_value(rng: random.Random):
    """Anything a confused caller might pass."""
    pick = rng.randrange(16)
    n = rng.randrange(0, 5)
    return [
        lambda: None,
        lambda: rng.random(),
        lambda: "x",
        lambda: [rng.random() for _ in range(n)],
        lambda: {"x": [rng.random() for _ in range(n)], "y": [rng.random() for _ in range(rng.randrange(0, 5))]},
        lambda: {"x": np.full(n, rng.choice([np.nan, np.inf, -np.inf, 1.0])), "y": np.zeros(n)},
        lambda: np.zeros((n, rng.randrange(0, 4))),
        lambda: np.zeros((n, rng.randrange(0, 3), rng.randrange(0, 4))),
        lambda: np.zeros((rng.randrange(0, 3),) * rng.randrange(0, 5)),
        lambda: np.array(["a"] * n),
        lambda: {"x": object(), "y": [1]},
        lambda: {1: [1.0], 2: [2.0]},
        lambda: pd.DataFrame({"x": np.arange(n, dtype=float), "y": np.arange(n)}),
        lambda: [{"x": [1.0] * n, "y": [2.0] * n}] * rng.randrange(0, 3),
        lambda: {"x": np.zeros((2, n)), "y": np.zeros((2, n))},
        lambda: np.zeros((n, 2), dtype=np.float32)[::-1],
    ][pick]()


def test_random_garbage_raises_ordinary_exceptions_only():
    # A Rust panic would surface as pyo3's PanicException, a BaseException: pytest would
    # report it here rather than pass the `except Exception`.
    rng = random.Random(12)
    calls = [
        lambda v, f: SPEC.robustness(v, f),
        lambda v, f: SPEC.signal(v, f),
        lambda v, f: SPEC.signal_batch(v, f),
        lambda v, f: SPEC.signal_batch(v, f, threads=rng.randrange(1, 5)),
        lambda v, f: SPEC.signal(v, f, columns=random_value(rng)),
        lambda v, f: SPEC.online(f).update(v),
        lambda v, f: hstl.Spec.parse(v if isinstance(v, str) else "spec {", name=f),
    ]
    outcomes = {"ok": 0, "raised": 0}
    for _ in range(3000):
        value = random_value(rng)
        formula = rng.choice([None, None, "A", "B", "Nope", 3])
        try:
            rng.choice(calls)(value, formula)
            outcomes["ok"] += 1
        except Exception:
            outcomes["raised"] += 1
    assert outcomes["ok"] > 0 and outcomes["raised"] > 0


INT_SPEC = hstl.Spec.parse(
    "spec Cells { state { x: int in 0..=9, k: int, r: float } let A = x > 3; task A; }"
)


@pytest.mark.parametrize(
    "trace, message",
    [
        (
            {"x": [1, 1.5], "k": [0, 0], "r": [0.5, 0.5]},
            "`x` is 1.5 at step 1, not a whole number"
            "\n  help: `x` is an `int` state variable: give whole numbers such as `3`",
        ),
        (
            {"x": [1, 12], "k": [0, 0], "r": [0.5, 0.5]},
            "`x` is 12 at step 1, outside its range 0..=9"
            "\n  help: the spec declares `x: int in 0..=9`: widen the range or fix the trace",
        ),
        (
            {"x": [1, 2], "k": [0, np.inf], "r": [0.5, 0.5]},
            "`k` is inf at step 1, not a whole number"
            "\n  help: `k` is an `int` state variable: give whole numbers such as `3`",
        ),
    ],
)
def test_int_variables_hold_whole_numbers_in_their_range_as_hstlc_monitor_asks(trace, message):
    # The CLI refuses these rows at line:column; Python refuses them at their step.
    with pytest.raises(ValueError) as e:
        INT_SPEC.signal(trace)
    assert str(e.value) == message
    rows = np.stack([np.asarray(trace[v], dtype=float) for v in ("x", "k", "r")], axis=1)
    with pytest.raises(ValueError) as e:
        INT_SPEC.signal(rows)
    assert str(e.value) == message
    online = INT_SPEC.online()
    online.update({v: trace[v][0] for v in trace})
    with pytest.raises(ValueError) as e:
        online.update({v: trace[v][1] for v in trace})
    assert str(e.value) == message
    # Fractions in a `float` variable are fine.
    assert INT_SPEC.signal({"x": [4, 5], "k": [-3, 8], "r": [0.25, np.inf]}).tolist() == [1.0, 2.0]


INCLUSIVE = """spec S {
    state { x: int in 0..=14, y: int in 0..=14 }
    let Top = x >= 8;
    task eventually[0..] Top;
}"""


def test_spec_warnings_reach_python_as_spec_warnings():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        spec = hstl.Spec.parse(INCLUSIVE, filename="inclusive.hstl")
    assert [w.category for w in caught] == [hstl.SpecWarning]
    w = caught[0]
    assert issubclass(w.category, UserWarning)
    assert str(w.message).startswith("inclusive.hstl:3:15: HSTL150 warning: ")
    assert "\n  help: " in str(w.message)
    assert w.message.diagnostic == spec.diagnostics[0] and w.message.diagnostic.code == "HSTL150"
    assert w.filename == __file__, "the warning points at the caller's line"
    # Filterable: an error, or nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error", hstl.SpecWarning)
        with pytest.raises(hstl.SpecWarning, match="HSTL150"):
            hstl.Spec.parse(INCLUSIVE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", category=hstl.SpecWarning)
        hstl.Spec.parse(INCLUSIVE)
        # Unpickling does not warn again.
        pickle.loads(pickle.dumps(spec))


def test_check_lists_every_diagnostic_of_a_path_or_a_text(tmp_path):
    path = tmp_path / "inclusive.hstl"
    path.write_text(INCLUSIVE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        from_path = hstl.check(path)
        assert hstl.check(str(path)) == from_path
        from_text = hstl.check(INCLUSIVE)
    assert [d.code for d in from_path] == ["HSTL150"] and from_path[0].file == str(path)
    assert all(isinstance(d, hstl.Diagnostic) for d in from_text) and from_text[0].file == "<string>"
    assert hstl.check(CLI_FIXTURES / "reach.hstl") == []
    # A spec that does not check: its errors, as SpecError.diagnostics lists them.
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.load(CLI_FIXTURES / "errors.hstl")
    assert hstl.check(CLI_FIXTURES / "errors.hstl") == e.value.diagnostics
    with pytest.raises(FileNotFoundError, match="cannot read `nope.hstl`"):
        hstl.check("nope.hstl")
    with pytest.raises(TypeError, match="`path_or_text` must be a path or spec text; got int\n  help: "):
        hstl.check(3)


def test_check_against_a_world_adds_the_worlds_diagnostics():
    far = """spec S { state { x: int in 0..=14, y: int in 0..=14 }
        let Far = x > 40; task always[0..] eventually[0..=20] Far; option Far; }"""
    alone = hstl.check(far)
    for world in ("paper", hstl.World.builtin("paper")):
        in_world = hstl.check(far, world=world)
        assert any(d.code == "HSTL031" and "world `paper`" in d.message for d in in_world)
    assert not any(d.code == "HSTL031" for d in alone)
    with pytest.raises(hstl.WorldError):
        hstl.check(far, world="nowhere")


def test_explain_gives_hstlc_explains_text(hstlc):
    text = hstl.explain("hstl150")
    assert text.startswith("HSTL150 (inclusive-bound-on-int): ")
    assert text + "\n" == run_cli(hstlc, "explain", "HSTL150").stdout
    with pytest.raises(ValueError, match="unknown diagnostic code `HSTL9`\n  help: known codes: HSTL001, "):
        hstl.explain("HSTL9")


def test_a_formula_alone_is_a_spec_with_every_method():
    spec = hstl.formula("always[0..=2] (x > 0.5 && eventually[0..3] y < speed * 2)")
    assert spec.state_vars == ["x", "y", "speed"] and spec.name == "Formula" and spec.filename == "<formula>"
    trace = {"x": [1.0, 2.0, 0.7, 3.0], "y": [0.0, 1.0, 5.0, 1.0], "speed": [1.0, 1.0, 1.0, 1.0]}
    whole = hstl.Spec.parse(
        "spec W { state { x: float, y: float, speed: float } "
        "task always[0..=2] (x > 0.5 && eventually[0..3] y < speed * 2); }"
    )
    assert spec.robustness(trace) == whole.robustness(trace)
    assert spec.signal(trace).tolist() == whole.signal(trace).tolist()
    online = spec.online()
    for t in range(4):
        online.update({k: v[t] for k, v in trace.items()})
    assert [v for _, v in online.finish()] == whole.signal(trace).tolist()
    back = pickle.loads(pickle.dumps(spec))
    assert back == spec and back.state_vars == spec.state_vars


def test_a_formula_that_does_not_check_says_where_in_it():
    with pytest.raises(hstl.SpecError) as e:
        hstl.formula("always[0..=10] x >")
    assert str(e.value).startswith("<formula>:1:")
    assert all(d.file == "<formula>" and d.line == 1 for d in e.value.diagnostics)
    with pytest.raises(hstl.SpecError, match="a formula has no `;`"):
        hstl.formula("x > 1; y > 2")
    with pytest.raises(hstl.SpecError, match="reads no state variable"):
        hstl.formula("true")
