"""Times the peer STL monitors on the benchmark walk: full robustness signals of F1
(window 40 and 4000), F2 and F3, in samples per second.

Usage: peers.py WALK.csv [--steps N] [--rtamt-steps N] [--repeats N]

The walk comes from `cargo run --release -p hstl-robustness --example walk -- WALK.csv`.
Each peer reads the same samples; rtamt, being pure Python, gets a shorter prefix by
default. Semantics differ (see shared notes): stlrom and mstlo read until's left operand
on [t, t'], stlrom holds the last sample where hstl clips, mstlo reports only complete
windows, banquo has no bounded until. The figures compare speed, not values.
"""

import argparse
import csv
import time


def read_walk(path, steps):
    xs, ys = [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            xs.append(float(row["x"]))
            ys.append(float(row["y"]))
            if len(xs) == steps:
                break
    return xs, ys


def region(lt, gt, x0, x1, y0, y1, x="x", y="y"):
    return f"({x} {gt} {x0}) and ({x} {lt} {x1}) and ({y} {gt} {y0}) and ({y} {lt} {y1})"


A = (3, 9, 10, 14)
B = (1, 5, 1, 5)
C = (9, 13, 1, 7)


def specs_rtamt():
    r = lambda b: "(" + region("<", ">", *b) + ")"
    return {
        "F1_w40": f"always[0,40]{r(A)}",
        "F1_w4000": f"always[0,4000]{r(A)}",
        "F2": f"always((eventually[0,39]{r(A)}) and (eventually[0,39]{r(B)}) and (eventually[0,39]{r(C)}))",
        "F3": "(x > 5) until[0,20] (y > 10)",
    }


def run_rtamt(xs, ys, spec):
    import rtamt

    s = rtamt.StlDiscreteTimeOfflineSpecification()
    s.declare_var("x", "float")
    s.declare_var("y", "float")
    s.spec = spec
    s.parse()
    data = {"time": list(range(len(xs))), "x": xs, "y": ys}
    t0 = time.perf_counter()
    out = s.evaluate(data)
    dt = time.perf_counter() - t0
    assert len(out) == len(xs)
    return dt


def specs_stlrom(n):
    r = lambda b: "(" + region("<", ">", *b, x="x[t]", y="y[t]") + ")"
    return {
        "F1_w40": f"alw_[0,40] {r(A)}",
        "F1_w4000": f"alw_[0,4000] {r(A)}",
        # An `alw` without interval is not in stlrom's grammar: the window spans the walk.
        "F2": f"alw_[0,{n}] ((ev_[0,39] {r(A)}) and (ev_[0,39] {r(B)}) and (ev_[0,39] {r(C)}))",
        "F3": "(x[t] > 5) until_[0,20] (y[t] > 10)",
    }


def run_stlrom(xs, ys, spec):
    import stlrom

    d = stlrom.STLDriver()
    d.set_interpol("PREVIOUS")
    assert d.parse_string(f"signal x, y\nphi := {spec}\n")
    for t, (x, y) in enumerate(zip(xs, ys)):
        d.add_sample([t, x, y])
    m = d.get_monitor("phi")
    t0 = time.perf_counter()
    m.set_eval_time(0, len(xs) - 1)
    m.eval_rob()
    sig = m.get_signal()
    dt = time.perf_counter() - t0
    assert sig is not None
    return dt


def specs_banquo():
    r = lambda b: "(" + region("<=", ">=", *b) + ")"
    return {
        "F1_w40": f"always{{0,40}}{r(A)}",
        "F1_w4000": f"always{{0,4000}}{r(A)}",
        "F2": f"always((eventually{{0,39}}{r(A)}) and (eventually{{0,39}}{r(B)}) and (eventually{{0,39}}{r(C)}))",
        "F3": None,
    }


def run_banquo(xs, ys, spec):
    import banquo
    import banquo.stl as bstl

    f = bstl.parse(spec)
    tr = banquo.Trace({float(t): {"x": x, "y": y} for t, (x, y) in enumerate(zip(xs, ys))})
    t0 = time.perf_counter()
    out = f.evaluate(tr)
    dt = time.perf_counter() - t0
    assert out is not None
    return dt


def specs_mstlo(n):
    r = lambda b: "(" + region("<", ">", *b).replace(" and ", " && ") + ")"
    # mstlo has no unbounded `G`: F2's outer window spans the whole walk instead.
    return {
        "F1_w40": f"G[0,40]{r(A)}",
        "F1_w4000": f"G[0,4000]{r(A)}",
        "F2": f"G[0,{n}]((F[0,39]{r(A)}) && (F[0,39]{r(B)}) && (F[0,39]{r(C)}))",
        "F3": "(x > 5) U[0,20] (y > 10)",
    }


def run_mstlo(xs, ys, spec):
    import mstlo_python as m

    phi = m.parse_formula(spec)
    mon = m.Monitor(phi, semantics="DelayedQuantitative")
    batch = {"x": [(x, float(t)) for t, x in enumerate(xs)], "y": [(y, float(t)) for t, y in enumerate(ys)]}
    t0 = time.perf_counter()
    out = mon.update_batch(batch)
    dt = time.perf_counter() - t0
    assert out is not None
    return dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("walk")
    ap.add_argument("--steps", type=int, default=1_000_000)
    ap.add_argument("--rtamt-steps", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--peers", default="stlrom,banquo,mstlo,rtamt")
    a = ap.parse_args()
    xs, ys = read_walk(a.walk, a.steps)
    n = len(xs)
    peers = {
        "stlrom": (specs_stlrom(n), run_stlrom, n),
        "banquo": (specs_banquo(), run_banquo, n),
        "mstlo": (specs_mstlo(n), run_mstlo, n),
        "rtamt": (specs_rtamt(), run_rtamt, min(n, a.rtamt_steps)),
    }
    cases = ["F1_w40", "F1_w4000", "F2", "F3"]
    print(f"| peer | samples | {' | '.join(cases)} |")
    print("|---|---|" + "---|" * len(cases))
    for name in a.peers.split(","):
        specs, run, m = peers[name]
        cells = []
        for case in cases:
            spec = specs[case]
            if spec is None:
                cells.append("n/a")
                continue
            try:
                best = min(run(xs[:m], ys[:m], spec) for _ in range(a.repeats if name != "rtamt" else 1))
                cells.append(f"{m / best / 1e6:.3f}M")
            except Exception as e:  # A peer that fails is reported, not fatal.
                cells.append(f"failed: {type(e).__name__}: {str(e)[:60]}")
        print(f"| {name} | {m} | {' | '.join(cells)} |", flush=True)


if __name__ == "__main__":
    main()
