"""Dense time side by side: hstl (command line and Python package), rtamt's dense-time
monitor and tidystl on the dense benchmark walk, formulas D1 to D4, in rows per second, and
whether rtamt's values equal hstl's.

Usage: dense.py DENSE_WALK.csv HSTLC [--steps N] [--repeats N] [--peers rtamt,tidystl]

The walk comes from `cargo run --release -p hstl-robustness --example dense_walk --
DENSE_WALK.csv` (the `dense` bench's data). The peers, being Python, get its first N rows
(--steps); hstl runs on the same N rows (values checked there) and on the whole walk.

- hstl CLI: `hstlc monitor bench/peers/dense.hstl --trace F.csv --formula Dk --signal`, wall
  clock of the process (reading the CSV, the signal, writing its change points to a file).
- hstl Python: `hstl.Spec.parse(text).signal(df, formula="Dk")` on a pandas DataFrame
  already in memory (the CSV read by pandas is timed apart).
- rtamt 0.4.10: `StlDenseTimeSpecification`, offline `evaluate` on one `[[t, v], ...]` list
  per variable (lists built before timing). Its result is compared with hstl's as functions
  on [t0, t_last]: every change point of either, times and values exactly (0.0 == -0.0).
- tidystl: `tidystl.robustness(tidystl.parse(spec), Signal)`. Its semantics is
  piecewise-linear (values interpolated between samples), not piecewise-constant, so its
  values are not compared; it has no past operators (no D4).
"""

import argparse
import csv
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SPEC = HERE / "dense.hstl"
CASES = ["D1", "D2", "D3", "D4"]

REGION = "(x > 3) and (x < 9) and (y > 10) and (y < 14)"
RTAMT = {
    "D1": f"always[0,0.4]({REGION})",
    "D2": "(x > 5) until[0,0.2] (y > 10)",
    "D3": "always[0,0.4]((x > 7) implies (eventually[0.1,0.3](y < 7)))",
    "D4": f"historically[0,0.4]({REGION})",
}
TIDYSTL = {
    "D1": f"G[0,0.4]({REGION})",
    "D2": "(x > 5) U[0,0.2] (y > 10)",
    "D3": "G[0,0.4]((not (x > 7)) or (F[0.1,0.3](y < 7)))",
    "D4": None,
}


def read(path, steps=None):
    ts, xs, ys = [], [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            ts.append(float(row["t"]))
            xs.append(float(row["x"]))
            ys.append(float(row["y"]))
            if steps is not None and len(ts) == steps:
                break
    return np.array(ts), np.array(xs), np.array(ys)


def write(path, t, x, y):
    with open(path, "w") as f:
        f.write("t,x,y\n")
        for a, b, c in zip(t.tolist(), x.tolist(), y.tolist()):
            # repr is the shortest text that reads back as the same double.
            f.write(f"{a!r},{b!r},{c!r}\n")


def run_hstlc(hstlc, csv_path, case):
    with tempfile.NamedTemporaryFile("w+", suffix=".csv") as out:
        t0 = time.perf_counter()
        subprocess.run(
            [hstlc, "monitor", str(SPEC), "--trace", str(csv_path), "--formula", case, "--signal"],
            stdout=out,
            check=True,
        )
        dt = time.perf_counter() - t0
        out.seek(0)
        rows = [line.split(",") for line in out.read().splitlines()[1:]]
    pts = (np.array([float(r[0]) for r in rows]), np.array([float(r[1]) for r in rows]))
    return dt, pts


def run_hstl_py(spec, df, case):
    t0 = time.perf_counter()
    times, values = spec.signal(df, formula=case)
    return time.perf_counter() - t0, (np.asarray(times), np.asarray(values))


def run_rtamt(t, x, y, case):
    import rtamt

    s = rtamt.StlDenseTimeSpecification()
    s.declare_var("x", "float")
    s.declare_var("y", "float")
    s.spec = RTAMT[case]
    s.parse()
    tl = t.tolist()
    xs = ["x", [[a, b] for a, b in zip(tl, x.tolist())]]
    ys = ["y", [[a, b] for a, b in zip(tl, y.tolist())]]
    t0 = time.perf_counter()
    out = s.evaluate(xs, ys)
    dt = time.perf_counter() - t0
    return dt, (np.array([p[0] for p in out]), np.array([p[1] for p in out]))


def run_tidystl(t, x, y, case):
    import tidystl

    if TIDYSTL[case] is None:
        return None
    f = tidystl.parse(TIDYSTL[case])
    sig = tidystl.Signal.from_dict(t, {"x": x, "y": y})
    t0 = time.perf_counter()
    r = tidystl.robustness(f, sig)
    dt = time.perf_counter() - t0
    assert r.shape == (1, len(t))
    return dt


def at(points, ts):
    """A step-function list (a value from each time to the next, the last forever) at `ts`;
    NaN before its first time."""
    times, values = points
    k = np.searchsorted(times, ts, side="right") - 1
    return np.where(k >= 0, values[np.maximum(k, 0)], np.nan)


def same_function(a, b, t_first, t_last):
    """Whether two step-function lists are the same function on [t_first, t_last]; the
    number of times where they differ."""
    ts = np.union1d(a[0], b[0])
    ts = np.union1d(ts[(ts >= t_first) & (ts <= t_last)], [t_first])
    va, vb = at(a, ts), at(b, ts)
    bad = ~((va == vb) | (np.isnan(va) & np.isnan(vb)))
    return int(bad.sum())


def rate(n, dt):
    return f"{n / dt / 1e6:.3f}M" if n / dt >= 1e6 else f"{n / dt / 1e3:.1f}k"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("walk")
    ap.add_argument("hstlc")
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--peers", default="rtamt,tidystl")
    a = ap.parse_args()
    peers = a.peers.split(",") if a.peers else []

    import hstl
    import pandas as pd

    spec = hstl.Spec.parse(SPEC.read_text(), filename=str(SPEC))
    t_read = time.perf_counter()
    full = pd.read_csv(a.walk)
    t_read = time.perf_counter() - t_read
    n_full = len(full)
    t, x, y = read(a.walk, a.steps)
    n = len(t)
    with tempfile.TemporaryDirectory() as tmp:
        small_csv = Path(tmp) / "dense_walk_prefix.csv"
        write(small_csv, t, x, y)
        small = pd.DataFrame({"t": t, "x": x, "y": y})
        print(f"rows: {n_full} (hstl), {n} (peers and the value checks); pandas read_csv of the "
              f"whole walk {t_read:.2f} s")
        head = ["case", f"hstlc CLI ({n_full})", f"hstl Python ({n_full})", f"hstlc CLI ({n})",
                f"hstl Python ({n})"] + [f"{p} ({n})" for p in peers] + ["rtamt = hstl"]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for case in CASES:
            best = lambda f: min((f() for _ in range(a.repeats)), key=lambda r: r[0])
            cli_full, _ = best(lambda: run_hstlc(a.hstlc, a.walk, case))
            py_full, _ = best(lambda: run_hstl_py(spec, full, case))
            cli_small, cli_pts = best(lambda: run_hstlc(a.hstlc, small_csv, case))
            py_small, py_pts = best(lambda: run_hstl_py(spec, small, case))
            # The command line and the package give the same change points.
            assert same_function(cli_pts, py_pts, t[0], t[-1]) == 0, case
            cells = [case, rate(n_full, cli_full), rate(n_full, py_full), rate(n, cli_small),
                     rate(n, py_small)]
            check = "n/a"
            for p in peers:
                try:
                    if p == "rtamt":
                        dt, pts = run_rtamt(t, x, y, case)
                        bad = same_function(pts, py_pts, t[0], t[-1])
                        check = "yes" if bad == 0 else f"no: differ at {bad} times"
                        cells.append(rate(n, dt))
                    elif p == "tidystl":
                        dt = run_tidystl(t, x, y, case)
                        cells.append("n/a (no past operators)" if dt is None else rate(n, dt))
                except Exception as e:  # A peer that fails is reported, not fatal.
                    cells.append(f"failed: {type(e).__name__}: {str(e)[:60]}")
            cells.append(check)
            print("| " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
