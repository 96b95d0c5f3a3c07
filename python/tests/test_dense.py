"""Dense-time specs from Python: the same change points as `hstlc monitor`, bit for bit,
on the repository's example log, generated irregular logs and nanosecond stamps; rtamt's
dense-time oracle cases; the errors; the online monitor."""

from __future__ import annotations

import copy
import csv
import io
import json
import math
import multiprocessing
import pickle
import random
import struct

import numpy as np
import pytest

import hstl

from conftest import CLI_FIXTURES, REPO, run_cli

BRAKING = REPO / "examples" / "dense" / "braking"
DENSE_ORACLE = REPO / "robustness" / "tests" / "data" / "rtamt-dense-sample.jsonl"


def bits(x: float) -> int:
    return struct.unpack("<q", struct.pack("<d", x))[0]


def read_csv(text: str, time: str) -> dict:
    """A CSV log as arrays, as `hstlc monitor` reads it: the time column as int64 when every
    stamp is digits (else float64), an empty cell as NaN; every number through `float()`,
    which rounds correctly as Rust's parser does."""
    rows = list(csv.reader(io.StringIO(text)))
    header, rows = rows[0], [r for r in rows[1:] if r]
    out = {}
    for k, name in enumerate(header):
        cells = [r[k].strip() for r in rows]
        if name == time and all(c.lstrip("-").isdigit() for c in cells):
            out[name] = np.array([int(c) for c in cells], dtype=np.int64)
        else:
            out[name] = np.array([float(c) if c else math.nan for c in cells])
    return out


def cli_rows(hstlc, *args, cwd=CLI_FIXTURES) -> list[tuple[str, str]]:
    r = run_cli(hstlc, "monitor", *args, cwd=cwd)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "t,robustness"
    return [tuple(line.split(",")) for line in lines[1:]]


def assert_same_rows(py, cli):
    """Python's `(times, values)` against the CLI's `t,robustness` rows, bit for bit: an
    int time equals the printed whole number, a float time and every value the double the
    printed text reads back as (an empty value is NaN)."""
    times, values = py
    assert len(times) == len(values) == len(cli), (list(zip(times, values)), cli)
    for t, v, (ct, cv) in zip(times.tolist(), values.tolist(), cli):
        if isinstance(t, int):
            assert t == int(ct), (t, ct)
        else:
            assert bits(t) == bits(float(ct)), (t, ct)
        if cv == "":
            assert math.isnan(v)
        else:
            assert bits(v) == bits(float(cv)), (v, cv)


def test_braking_example_equals_hstlc_monitor(hstlc):
    spec = hstl.Spec.load(BRAKING.with_suffix(".hstl"))
    text = BRAKING.with_suffix(".csv").read_text()
    trace = read_csv(text, "t")
    assert spec.time_var == "t" and spec.state_vars == ["dist", "speed"]
    hstl_file, csv_file = str(BRAKING.with_suffix(".hstl")), str(BRAKING.with_suffix(".csv"))
    for formula in (None, "Near", "Brakes"):
        extra = ["--formula", formula] if formula else []
        cli = cli_rows(hstlc, hstl_file, "--trace", csv_file, "--signal", *extra)
        assert_same_rows(spec.signal(trace, formula), cli)
        assert_same_rows(spec.signal(trace, formula, relative=True), cli_rows(hstlc, hstl_file, "--trace", csv_file, "--signal", "--relative", *extra))
        value = run_cli(hstlc, "monitor", hstl_file, "--trace", csv_file, *extra).stdout.strip()
        assert bits(spec.robustness(trace, formula)) == bits(float(value))


def test_a_dataframe_with_nan_cells_is_the_csv_with_empty_cells(hstlc):
    pd = pytest.importorskip("pandas")
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    df = pd.read_csv(CLI_FIXTURES / "dense.csv")
    assert df.isna().any().any()
    assert_same_rows(spec.signal(df), cli_rows(hstlc, "dense.hstl", "--trace", "dense.csv", "--signal"))


def irregular_log(seed: int, n: int = 400) -> str:
    """A log whose variables are sampled at their own irregular times: the union of the
    stamps, each row filling only the variables sampled then."""
    rng = random.Random(seed)
    t, rows = 0.0, []
    for k in range(n):
        t = round(t + rng.choice([0.01, 0.02, 0.05, 0.13, 0.3, 0.7]) * rng.randint(1, 3), 2)
        x = "" if k and rng.random() < 0.6 else str(round(rng.uniform(-3, 3), 1))
        y = "" if k and rng.random() < 0.3 else str(rng.choice([-1, 0.5, 2, 6]))
        rows.append(f"{t},{x},{y}")
    return "t,x,y\n" + "\n".join(rows) + "\n"


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("formula", [None, "Fast", "Soon"])
def test_irregular_per_variable_stamps_equal_hstlc_monitor(hstlc, tmp_path, seed, formula):
    text = irregular_log(seed)
    (tmp_path / "log.csv").write_text(text)
    spec_file = str(CLI_FIXTURES / "dense.hstl")
    extra = ["--formula", formula] if formula else []
    spec = hstl.Spec.load(spec_file)
    trace = read_csv(text, "t")
    cli = cli_rows(hstlc, spec_file, "--trace", "log.csv", "--signal", *extra, cwd=tmp_path)
    assert len(cli) > 3
    assert_same_rows(spec.signal(trace, formula), cli)
    complete = cli_rows(hstlc, spec_file, "--trace", "log.csv", "--signal", "--windows", "complete", *extra, cwd=tmp_path)
    assert_same_rows(spec.signal(trace, formula, windows="complete"), complete)
    # The online monitor gives the same change points, row by row.
    m = spec.online(formula)
    got = []
    for k in range(len(trace["t"])):
        row = {v: trace[v][k] for v in spec.state_vars}
        got += m.update(float(trace["t"][k]), row)
    got += m.finish()
    times, values = spec.signal(trace, formula)
    assert [(bits(t), bits(v)) for t, v in got] == [(bits(t), bits(v)) for t, v in zip(times, values)]


def test_signal_batch_is_signal_of_each(hstlc):
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    traces = [read_csv(irregular_log(s, 50 + 20 * s), "t") for s in range(4)]
    batch = spec.signal_batch(traces, threads=2)
    assert len(batch) == 4
    for trace, (times, values) in zip(traces, batch):
        t, v = spec.signal(trace)
        assert t.tolist() == times.tolist() and v.tolist() == values.tolist()
    with pytest.raises(ValueError, match="^trace 1: row 2"):
        spec.signal_batch([traces[0], {"t": [0.0, 1.0, 1.0], "x": [1, 2, 3], "y": [1, 2, 3]}])


def rtamt_points(pairs, t0, t_last):
    """rtamt's output list read as a function on [t0, t_last], as change points."""
    k = sum(1 for t, _ in pairs if t <= t0)
    out = [(t0, pairs[k - 1][1] if k else None)]
    for t, v in pairs[k:]:
        if t > t_last:
            break
        if out[-1][1] != v:
            out.append((t, v))
    return out


def test_rtamt_dense_oracle_cases():
    """The 150 rtamt 0.4.10 dense-time cases copied into the repository: times bit for
    bit, values equal (the sign of a zero is not pinned)."""
    lines = [json.loads(line) for line in DENSE_ORACLE.read_text().splitlines() if line.strip()]
    assert len(lines) == 150
    number = lambda v: float(v)  # noqa: E731 - "inf" and "-inf" are strings
    failures = []
    for case in lines:
        spec = hstl.Spec.parse(case["hstl"])
        trace = read_csv(case["csv"], "t")
        times, values = spec.signal(trace)
        want = rtamt_points([(number(t), number(v)) for t, v in case["signal"]], case["t0"], case["t_last"])
        got = list(zip(times.tolist(), values.tolist()))
        if len(got) != len(want) or any(bits(g[0]) != bits(w[0]) or g[1] != w[1] for g, w in zip(got, want)):
            failures.append((case["id"], case["task"], got, want))
        assert spec.robustness(trace) == values[0]
    assert not failures, failures[:3]


NS_SPEC = """spec Ns {
    state { t: time, x: float }
    task always[0..=500000000] (x > 0 || eventually[0..=250000000] x > 1);
}"""


def test_nanosecond_stamps_near_2_pow_62_are_never_rounded(hstlc, tmp_path):
    base = 2**62 + 123_456_789
    offsets = [0, 1, 250_000_000, 250_000_001, 700_000_000, 1_000_000_003, 1_600_000_000]
    xs = [1.0, -1.0, 2.0, -0.5, 0.5, -2.0, 3.0]
    stamps = np.array([base + o for o in offsets], dtype=np.int64)
    assert float(stamps[1]) == float(stamps[0])  # a double cannot tell them apart
    spec = hstl.Spec.parse(NS_SPEC)
    (tmp_path / "s.hstl").write_text(NS_SPEC)
    (tmp_path / "log.csv").write_text("t,x\n" + "".join(f"{s},{x}\n" for s, x in zip(stamps.tolist(), xs)))
    times, values = spec.signal({"t": stamps, "x": xs})
    assert times.dtype == np.int64
    cli = cli_rows(hstlc, "s.hstl", "--trace", "log.csv", "--signal", cwd=tmp_path)
    assert_same_rows((times, values), cli)
    assert all((t - base) in offsets or (t - base + 250_000_000) in offsets or (t - base + 500_000_000) in offsets for t in times.tolist())
    rel = spec.signal({"t": stamps, "x": xs}, relative=True)
    assert rel[0].dtype == np.float64 and rel[0].tolist() == [t - base for t in times.tolist()]
    assert_same_rows(rel, cli_rows(hstlc, "s.hstl", "--trace", "log.csv", "--signal", "--relative", cwd=tmp_path))
    # uint64 stamps (as some loggers write them) and datetime64[ns] are the same numbers.
    assert spec.signal({"t": stamps.astype(np.uint64), "x": xs})[0].tolist() == times.tolist()
    pd = pytest.importorskip("pandas")
    small = stamps - 2**62 + 1_700_000_000_000_000_000
    df = pd.DataFrame({"t": pd.to_datetime(small, unit="ns"), "x": xs})
    assert spec.signal(df)[0].tolist() == (times - 2**62 + 1_700_000_000_000_000_000).tolist()
    # Online: whole-number times as Python ints.
    m = spec.online()
    got = []
    for s, x in zip(stamps.tolist(), xs):
        got += m.update(s, {"x": x})
    got += m.finish()
    assert [t for t, _ in got] == times.tolist() and all(isinstance(t, int) for t, _ in got)


def test_stamps_that_cannot_be_represented_are_refused():
    spec = hstl.Spec.parse(NS_SPEC)
    # A first stamp below 2^53 makes the stamps doubles: a later one beyond is not exact.
    with pytest.raises(ValueError, match=r"row 1 \(counted from 0\): the time stamp 9007199254740993 in column `t` is not exactly a double"):
        spec.signal({"t": np.array([0, 2**53 + 1]), "x": [1.0, 2.0]})
    m = spec.online()
    m.update(2**62, {"x": 1.0})
    with pytest.raises(ValueError, match=r"row 1 \(counted from 0\): the time stamp in column `t` is a decimal, but the trace's stamps are whole numbers"):
        m.update(2.0**62 + 2048, {"x": 1.0})
    decimal = hstl.Spec.parse("spec D { state { t: time, x: float } task always[0..=0.5] x > 0; }")
    with pytest.raises(ValueError, match="between two whole-number stamps"):
        decimal.signal({"t": np.array([2**62, 2**62 + 3], dtype=np.int64), "x": [1.0, -1.0]})
    assert decimal.signal({"t": np.array([2**62, 2**62 + 3], dtype=np.int64), "x": [1.0, -1.0]}, relative=True)[0].tolist() == [0.0, 2.5]


@pytest.mark.parametrize(
    "trace, kind, message",
    [
        ({"t": [0.0, 2.0, 1.0], "x": [1.0, 2.0, 3.0], "y": [0.0, 0.0, 0.0]}, ValueError, r"row 2 \(counted from 0\): the time stamp 1 in column `t` goes back from the previous one, 2"),
        ({"t": [0.0, 1.0, 1.0], "x": [1.0, 2.0, 3.0], "y": [0.0, 0.0, 0.0]}, ValueError, r"row 2 \(counted from 0\): the time stamp 1 in column `t` repeats the previous one, 1"),
        ({"x": [1.0], "y": [0.0]}, hstl.MissingVariableError, "the time column `t` is missing"),
        ({"t": [0.0, 1.0], "x": [math.nan, 1.0], "y": [0.0, 0.0]}, ValueError, r"row 0 \(counted from 0\), column `x`: `x` has no sample at the first time stamp"),
        ({"t": [0.0, math.nan], "x": [1.0, 1.0], "y": [0.0, 0.0]}, ValueError, r"row 1 \(counted from 0\): the time stamp NaN in column `t` is not a finite number"),
        ({"t": [0.0, 1.0], "x": [1.0, 1.0, 2.0], "y": [0.0, 0.0]}, ValueError, "`x` has 3 samples, but the time column `t` has 2"),
        ({"t": [], "x": [], "y": []}, ValueError, "no sample"),
        ({"t": ["a"], "x": [1.0], "y": [0.0]}, TypeError, "dtype"),
        (np.zeros((3, 3)), TypeError, "a dense-time trace is a mapping"),
    ],
)
def test_bad_traces_say_what_and_where(trace, kind, message):
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    with pytest.raises(kind, match=message) as info:
        spec.signal(trace)
    assert "help:" in str(info.value) or kind is TypeError or "no sample" in message or "samples" in message
    assert "DenseProblem" not in str(info.value) and "Some(" not in str(info.value)


def test_max_gap_and_relative(hstlc):
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    trace = read_csv((CLI_FIXTURES / "dense.csv").read_text(), "t")
    for gap in (1.5, "1.5", 2):
        assert spec.signal(trace, max_gap=gap)[0].tolist() == spec.signal(trace)[0].tolist()
    with pytest.raises(ValueError, match=r"row 4 \(counted from 0\): the time stamp 3.5 in column `t` comes 1.5 after the previous one, 2 \(row 3\): more than `max_gap=1.4`"):
        spec.robustness(trace, max_gap=1.4)
    with pytest.raises(ValueError, match="is not a time"):
        spec.signal(trace, max_gap="soon")
    discrete = hstl.formula("x > 1")
    with pytest.raises(ValueError, match="`max_gap` is for dense-time specs"):
        discrete.signal({"x": [1.0]}, max_gap=1)
    with pytest.raises(ValueError, match="`relative` is for dense-time specs"):
        discrete.signal({"x": [1.0]}, relative=True)
    m = spec.online(max_gap=1)
    m.update(0.0, {"x": 1.0, "y": 5.0})
    with pytest.raises(ValueError, match="more than `max_gap=1`"):
        m.update(1.5, {"x": 2.0})
    assert m.steps == 1  # the refused row changed nothing
    m.update(1.0, {"x": 2.0})


def test_complete_windows(hstlc):
    spec = hstl.Spec.load(CLI_FIXTURES / "dense_complete.hstl")
    trace = read_csv((CLI_FIXTURES / "dense_dip.csv").read_text(), "t")
    assert spec.robustness(trace) == -0.5
    assert spec.robustness(trace, windows="complete") == 1.0
    assert_same_rows(spec.signal(trace, windows="complete"), cli_rows(hstlc, "dense_complete.hstl", "--trace", "dense_dip.csv", "--signal", "--windows", "complete"))
    short = {"t": [0.0, 0.5], "x": [2.0, 2.0]}
    assert math.isnan(spec.robustness(short, windows="complete"))
    times, values = spec.signal(short, windows="complete")
    assert times.tolist() == [0.0] and math.isnan(values[0])


def as_bits(points) -> list:
    """Change points to the bit: an int time as itself, a float time and every value as
    its bits (so NaN, the undetermined mark of complete windows, compares)."""
    return [(t if isinstance(t, int) else ("f", bits(t)), bits(v)) for t, v in points]


def dense_rows(trace: dict, start: int, end: int) -> list:
    """Rows `start..end` of an array trace as `update(t, state)` arguments (an int stamp
    stays an int)."""
    t = trace["t"].tolist()
    names = [k for k in trace if k != "t"]
    return [(t[k], {n: float(trace[n][k]) for n in names}) for k in range(start, end)]


def continue_dense(args) -> list:
    """In a spawned process: the pickled monitor's change points over the rest of the
    rows, then `finish()`."""
    blob, rows = args
    m = pickle.loads(blob)
    out = []
    for t, state in rows:
        out += m.update(t, state)
    return as_bits(out + m.finish())


def pickled_halves_continue_exactly(spec, trace, formula=None, **opts):
    """The monitor pickled (every protocol) and deep-copied after each of a few rows, then
    continued: the same change points to the bit as the monitor that was never
    interrupted; and once in a spawned process."""
    n = len(trace["t"])
    m = spec.online(formula, **opts)
    want = []
    for t, state in dense_rows(trace, 0, n):
        want += m.update(t, state)
    want = as_bits(want + m.finish())
    for cut in sorted({0, 1, n // 3, n // 2, n - 1, n}):
        m = spec.online(formula, **opts)
        head = []
        for t, state in dense_rows(trace, 0, cut):
            head += m.update(t, state)
        copies = [copy.deepcopy(m)] + [pickle.loads(pickle.dumps(m, p)) for p in range(2, pickle.HIGHEST_PROTOCOL + 1)]
        for twin in copies + [m]:
            assert twin.steps == cut and twin.time_var == "t"
            rest = []
            for t, state in dense_rows(trace, cut, n):
                rest += twin.update(t, state)
            assert as_bits(head + rest + twin.finish()) == want, (formula, opts, cut)
    m = spec.online(formula, **opts)
    head = []
    for t, state in dense_rows(trace, 0, n // 2):
        head += m.update(t, state)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        (rest,) = pool.map(continue_dense, [(pickle.dumps(m), dense_rows(trace, n // 2, n))])
    assert as_bits(head) + rest == want
    return want


def test_online_monitor_pickles_and_copies_mid_stream():
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    trace = read_csv(irregular_log(7, 120), "t")
    want = list(zip(*[a.tolist() for a in spec.signal(trace)]))
    got = pickled_halves_continue_exactly(spec, trace)
    assert got == as_bits(want)
    for formula in ("Soon", "Fast"):
        pickled_halves_continue_exactly(spec, trace, formula, max_gap=2.5, relative=True)
    m = spec.online()
    with pytest.raises(TypeError, match=r"update\(t, state\)"):
        m.update({"x": 1.0, "y": 2.0})
    with pytest.raises(ValueError, match=r"row 0 \(counted from 0\), column `y`: `y` has no sample"):
        m.update(0.0, {"x": 1.0})
    assert m.steps == 0
    with pytest.raises(TypeError, match="for discrete-time monitors"):
        m.provisional()


def test_pickled_monitors_keep_nanosecond_stamps_and_complete_windows(hstlc, tmp_path):
    spec = hstl.Spec.parse(NS_SPEC)
    base = 2**62 + 123_456_789
    rng = random.Random(3)
    stamps, xs, k = [], [], 0
    for _ in range(80):
        k += rng.randint(1, 400_000_000)
        stamps.append(base + k)
        xs.append(rng.choice([-1.0, 0.5, 2.0, 3.0]))
    trace = {"t": np.array(stamps, dtype=np.int64), "x": np.array(xs)}
    got = pickled_halves_continue_exactly(spec, trace)
    assert all(isinstance(t, int) and t > 2**62 for t, _ in got)
    assert got == as_bits(list(zip(*[a.tolist() for a in spec.signal(trace)])))
    complete = pickled_halves_continue_exactly(spec, trace, windows="complete")
    (tmp_path / "s.hstl").write_text(NS_SPEC)
    (tmp_path / "log.csv").write_text("t,x\n" + "".join(f"{s},{x}\n" for s, x in zip(stamps, xs)))
    cli = cli_rows(hstlc, "s.hstl", "--trace", "log.csv", "--online", "--windows", "complete", cwd=tmp_path)
    assert complete == [(int(t), bits(float(v)) if v else bits(math.nan)) for t, v in cli]
    assert math.isnan(struct.unpack("<d", struct.pack("<q", complete[-1][1]))[0])
    pickled_halves_continue_exactly(spec, trace, windows="complete", relative=True, max_gap=400_000_000)


def test_tampered_dense_pickles_are_refused_in_words():
    spec = hstl.Spec.load(CLI_FIXTURES / "dense.hstl")
    m = spec.online("Soon", max_gap=2.5)
    for t, state in dense_rows(read_csv(irregular_log(3, 40), "t"), 0, 30):
        m.update(t, state)
    restore, (s, formula, state) = m.__reduce__()
    restore(s, formula, state)  # the state as saved restores

    def refused(change, kind=ValueError, match="."):
        tampered = dict(state)
        change(tampered)
        with pytest.raises(kind, match=match) as info:
            restore(s, formula, tampered)
        text = str(info.value)
        assert "Some(" not in text and "Err(" not in text and "DenseProblem" not in text, text
        return text

    blob = state["monitor"]
    # Cut short, one byte changed, a huge count, garbage: the checksum.
    for cut in range(0, len(blob), 13):
        refused(lambda d: d.update(monitor=blob[:cut]), match="cut short|no saved dense-time monitor")
    flipped = bytearray(blob)
    flipped[64] ^= 0xFF
    refused(lambda d: d.update(monitor=bytes(flipped)), match="checksum")
    huge = bytearray(blob)
    huge[56:64] = struct.pack("<Q", 2**63)
    refused(lambda d: d.update(monitor=bytes(huge)), match="checksum")
    # The plain fields: wrong types, NaN, stamps that go back, sizes beyond what is held.
    refused(lambda d: d.update(rows="many"), match="`rows` is 'many', not a count of rows")
    refused(lambda d: d.update(rows=-1), match="`rows` is -1")
    refused(lambda d: d.update(rows=2**70), match="`rows`")
    refused(lambda d: d.update(rows=31), match="damaged: it has 31 rows")
    refused(lambda d: d.update(t0=math.nan), match="first stamp")
    refused(lambda d: d.update(last=state["last"] - 1.0), match="stamps .* do not agree")
    refused(lambda d: d.update(last=math.nan), match="do not agree")
    refused(lambda d: d.update(last="soon"), match="`last` stamp")
    refused(lambda d: d.update(limit=2**62), match="budget")
    refused(lambda d: d.update(max_gap="-1"), match="gap bound")
    refused(lambda d: d.update(windows="open"), match="`windows`")
    refused(lambda d: d.update(held=[(1.0, math.nan)]), match="clipped|in order")
    refused(lambda d: d.update(held="x"), match="`held`")
    refused(lambda d: d.update(stopped=3), match="stopped at row 3")
    refused(lambda d: d.pop("monitor"), match="`monitor` is missing")
    # Another formula's state.
    with pytest.raises(ValueError, match="another formula"):
        restore(s, "Fast", state)


def test_the_dense_logs_example_monitors_a_ros2_bag_and_a_can_log(tmp_path, capsys):
    """examples/python/dense_logs.py, run as it is: the bag keeps the braking rule, the
    CAN log (braking 0.4 s after coming near) breaks it. Needs `rosbags` and `python-can`,
    which are not in requirements-dev.txt (they bring compiled dependencies)."""
    pytest.importorskip("pandas")
    pytest.importorskip("rosbags")
    pytest.importorskip("can")
    import importlib.util

    path = REPO / "examples" / "python" / "dense_logs.py"
    module_spec = importlib.util.spec_from_file_location("dense_logs", path)
    module = importlib.util.module_from_spec(module_spec)
    module_spec.loader.exec_module(module)
    ros, can_value = module.main(tmp_path)
    out = capsys.readouterr().out
    assert ros > 0 > can_value
    assert "time column int64, first stamp 1700000000000000000" in out
    assert "violated: from 0.7 s" in out
    # The bag read back is the same trace as the samples written: its stamps exact.
    df = module.read_ros2_bag(tmp_path / "approach_bag")
    assert df["t"].iloc[1] - df["t"].iloc[0] == 100_000_000
