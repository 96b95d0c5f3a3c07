"""Long `signal` calls: Ctrl-C ends them, and another thread's writes never reach them.

Issue 30: the arrays were read in place with the GIL released, so a NaN written by
another Python thread after the NaN check reached the result, and Ctrl-C waited for the
whole evaluation.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time

from pathlib import Path

import numpy as np
import pytest

import hstl


def chain_spec(lets: int, dense: bool = False) -> str:
    """A spec whose task is a chain of `lets` windowed operators over `x` and `y` (with a
    time column `t` and windows in seconds when `dense`)."""
    window = "[0..=0.03]" if dense else "[0..=3]"
    body = [f"let a0 = eventually{window} x > 0;"]
    for i in range(1, lets):
        op = "eventually" if i % 2 else "always"
        body.append(f"let a{i} = {op}{window} (a{i - 1} || y > {i % 7});")
    state = "t: time, x: float, y: float" if dense else "x: float, y: float"
    return f"spec Chain {{\n state {{ {state} }}\n" + "\n".join(body) + f"\n task a{lets - 1};\n}}\n"


def state_spec(terms: int, arithmetic: bool) -> str:
    """A spec whose task is one state formula of `terms` disjunctions: a single group of
    the evaluator over the whole trace, and with `arithmetic` comparisons that can be NaN
    (`x * 3 + y > 1`), which every step is scanned for before the evaluation."""
    if arithmetic:
        parts = [f"(x * {i % 13 + 1} + y > {i % 17})" for i in range(terms)]
    else:
        parts = [f"(x > {i % 17} || y < {i % 13})" for i in range(terms)]
    return "spec Big {\n state { x: float, y: float }\n task " + " && ".join(parts) + ";\n}\n"


LONG_SPECS = {
    "steps": lambda: chain_spec(2000),
    "dense": lambda: chain_spec(2000, dense=True),
    # Issue 30: one group over the whole trace, and the NaN scan, looked at no stop flag.
    "one-group": lambda: state_spec(6000, arithmetic=False),
    "nan-scan": lambda: state_spec(3000, arithmetic=True),
}


@pytest.mark.parametrize("kind", list(LONG_SPECS))
def test_ctrl_c_ends_a_long_signal_call(tmp_path: Path, kind: str) -> None:
    # Many seconds of evaluation on the development machine; Ctrl-C after 1.5 s. A child
    # process, so that a call that does not stop fails at the timeout instead of hanging.
    # The dense evaluator stops between the formula's nodes, the discrete one between its
    # groups and pieces and within a group every 512 steps, the NaN scan every 4096.
    code = (
        "import sys, time, numpy as np, hstl\n"
        "spec = hstl.Spec.load(sys.argv[1])\n"
        "rng = np.random.default_rng(1)\n"
        "n = 4_000_000\n"
        "trace = {'x': rng.normal(size=n), 'y': 5 * rng.normal(size=n)}\n"
        "if spec.time_var: trace['t'] = np.arange(n) * 0.01\n"
        "print('started', flush=True)\n"
        "start = time.perf_counter()\n"
        "try:\n"
        "    spec.signal(trace)\n"
        "    print('finished', flush=True)\n"
        "except KeyboardInterrupt:\n"
        "    took = time.perf_counter() - start\n"
        "    cpu = time.process_time()\n"
        "    time.sleep(1.0)\n"
        "    print(f'interrupted {took:.3f} {time.process_time() - cpu:.3f}', flush=True)\n"
    )
    path = tmp_path / "chain.hstl"
    path.write_text(LONG_SPECS[kind]())
    # Ctrl-C as at a terminal, whatever the test runner inherited (a background job has
    # SIGINT ignored, and Python then installs no handler).
    child = subprocess.Popen(
        [sys.executable, "-c", code, str(path)],
        stdout=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )

    assert child.stdout is not None
    assert child.stdout.readline().strip() == "started"
    time.sleep(1.5)
    child.send_signal(signal.SIGINT)
    try:
        out, _ = child.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        child.kill()
        raise AssertionError("the signal call went on after Ctrl-C")
    words = out.split()
    assert words[:1] == ["interrupted"], out
    # The evaluation takes ten times longer than this: the call ended on the signal.
    assert float(words[1]) < 6.0, out
    # And the evaluation stopped too: the second after it took next to no CPU time.
    assert float(words[2]) < 0.5, out


def test_a_nan_written_by_another_thread_never_reaches_the_result() -> None:
    # A state formula: a NaN sample gives a NaN step (the windows' folds would skip it).
    spec = hstl.Spec.parse("spec S { state { x: float } task x > 0; }")
    n = 1_000_000
    x = np.full(n, 1.0)
    stop = threading.Event()

    def flip() -> None:
        # NaN in and out of one sample for as long as the calls run.
        while not stop.is_set():
            x[n // 2] = np.nan
            x[n // 2] = 1.0

    writer = threading.Thread(target=flip)
    writer.start()
    outcomes = []
    try:
        for _ in range(40):
            try:
                signal_ = spec.signal({"x": x})
            except ValueError as e:
                # The copy caught the NaN: the call says so.
                assert "NaN" in str(e), e
                outcomes.append("refused")
            else:
                assert not np.isnan(signal_).any(), "a NaN reached the result"
                outcomes.append("scored")
    finally:
        stop.set()
        writer.join()
    assert len(outcomes) == 40
