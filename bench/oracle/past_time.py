"""Generates robustness cases for the past-time operators with rtamt (not run in CI).

Run it in a throwaway venv with rtamt 0.4.10 (see ../../shared/PEERS.md, or
`python -m venv /tmp/rtamt && /tmp/rtamt/bin/pip install rtamt==0.4.10`):

    /tmp/rtamt/bin/python bench/oracle/past_time.py > robustness/tests/data/rtamt-past-cases.jsonl

Each line holds the formula in hstl syntax (`task`), as rtamt read it (`rtamt_formula`),
the trace, and rtamt's whole signal (`signal`; infinities as the strings "inf"/"-inf").
Formulas mix once, historically, since, prev and next with the future operators, over
random intervals of every hstl form ([a..b], [a..=b], [a..], none); traces are short and
drawn from few values so that ties and empty windows are common. The seed is fixed, so the
file is reproducible.
"""

import json
import math
import random
import sys

import rtamt

SEED = 20261202
CASES = 1500


def interval(rng, n, past):
    """An hstl interval and its rtamt spelling for a trace of n steps, or (None, None)."""
    form = rng.choice(["none", "excl", "incl", "incl", "open"])
    if form == "none":
        return "", ""
    a = rng.choice([0, 0, 1, 2, 3])
    if form == "excl":
        b = a + rng.randint(1, 5)
        return f"[{a}..{b}]", f"[{a},{b - 1}]"
    if form == "incl":
        b = a + rng.randint(0, 5)
        if a == b and rng.random() < 0.5:
            b += 1
        return f"[{a}..={b}]", f"[{a},{b}]"
    # [a..]: rtamt has no spelling for a > 0; on n steps it equals [a', max(a', n-1)].
    if a == 0:
        return "[0..]", ""
    a2 = min(a, n)
    return f"[{a}..]", f"[{a2},{max(a2, n - 1)}]"


def atom(rng):
    var = rng.choice(["x", "y"])
    op = rng.choice([">", "<", ">=", "<="])
    c = rng.choice([0, 1, 2, 3, -1])
    return f"({var} {op} {c})", f"({var} {op} {c})"


def formula(rng, depth, n, need_past):
    if depth == 0:
        return atom(rng)
    past = ["once", "historically", "since", "prev"]
    other = ["next", "always", "eventually", "until", "not", "and", "or"]
    kind = rng.choice(past if need_past else past + other + past)
    sub = lambda: formula(rng, depth - 1, n, False)
    if kind in ("once", "historically", "always", "eventually"):
        h, r = interval(rng, n, kind in ("once", "historically"))
        fh, fr = sub()
        return f"({kind}{h} {fh})", f"({kind}{r}({fr}))"
    if kind in ("since", "until"):
        h, r = interval(rng, n, kind == "since")
        ah, ar = sub()
        bh, br = sub()
        return f"({ah} {kind}{h} {bh})", f"(({ar}) {kind}{r} ({br}))"
    if kind in ("prev", "next"):
        fh, fr = sub()
        return f"({kind} {fh})", f"({kind}({fr}))"
    if kind == "not":
        fh, fr = sub()
        return f"(!{fh})", f"(not({fr}))"
    ah, ar = sub()
    bh, br = sub()
    sym = "&&" if kind == "and" else "||"
    return f"({ah} {sym} {bh})", f"(({ar}) {kind} ({br}))"


def number(v):
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return float(v)


def main():
    rng = random.Random(SEED)
    out = sys.stdout
    written = 0
    while written < CASES:
        # rtamt 0.4.10 cannot evaluate a one-sample trace.
        n = rng.choice([2, 3, 5, 8, 12])
        depth = rng.choice([1, 1, 2, 2, 3])
        task, rt = formula(rng, depth, n, True)
        values = rng.choice([[0, 1, 2, 3], [-1, 0, 1, 2, 3, 4], [0.5, 1.5, 2.5, -0.5]])
        trace = {v: [rng.choice(values) for _ in range(n)] for v in ("x", "y")}
        spec = rtamt.StlDiscreteTimeOfflineSpecification()
        spec.declare_var("x", "float")
        spec.declare_var("y", "float")
        spec.spec = rt
        spec.parse()
        signal = spec.evaluate(
            {"time": list(range(n)), "x": [float(v) for v in trace["x"]], "y": [float(v) for v in trace["y"]]}
        )
        line = {
            "id": written,
            "task": task,
            "rtamt_formula": rt,
            "trace": trace,
            "signal": [number(v) for _, v in signal],
        }
        out.write(json.dumps(line) + "\n")
        written += 1


if __name__ == "__main__":
    main()
