"""Times the Python package on the benchmark walk, side by side with the native Rust call
and with rtamt in the same process (not for CI; see bench/python/run.sh).

Usage: bench.py WALK.csv [--repeats N] [--rtamt-steps N] [--criterion DIR]

- `signal` from Python on the 1,000,000-sample walk (a dict of contiguous float64 arrays,
  read in place, and a 2-D array), for the four formulas of BENCHMARKS.md, against the
  facade's criterion bench of the same call (`cargo bench -p hstl --bench monitor`), whose
  medians are read from DIR (target/criterion);
- rtamt 0.4.10 (pure Python) and hstl on the same prefix of the walk, in this process,
  with the values compared;
- `signal_batch` on 1,000 traces x 1,000 steps (the walk cut in pieces) on 1 and 2
  threads, against a Python loop of `signal` calls.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

import hstl

HERE = Path(__file__).resolve().parent
CASES = {"F1_w40": "F1_w40", "F1_w4000": "F1_w4000", "F2": None, "F3": "F3"}
RTAMT = {
    "F1_w40": "always[0,40]((x > 3) and (x < 9) and (y > 10) and (y < 14))",
    "F1_w4000": "always[0,4000]((x > 3) and (x < 9) and (y > 10) and (y < 14))",
    "F2": "always((eventually[0,39]((x > 3) and (x < 9) and (y > 10) and (y < 14)))"
    " and (eventually[0,39]((x > 1) and (x < 5) and (y > 1) and (y < 5)))"
    " and (eventually[0,39]((x > 9) and (x < 13) and (y > 1) and (y < 7))))",
    "F3": "(x > 5) until[0,20] (y > 10)",
}


def best(fn, repeats: int) -> float:
    """The fastest of `repeats` runs, in seconds."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def criterion_median(root: Path, group: str, name: str) -> float | None:
    """A criterion median in seconds, if the bench was run."""
    path = root / group / name / "new" / "estimates.json"
    if not path.is_file():
        return None
    return json.loads(path.read_text())["median"]["point_estimate"] / 1e9


def rtamt_signal(x, y, spec_text):
    import rtamt

    s = rtamt.StlDiscreteTimeOfflineSpecification()
    s.declare_var("x", "float")
    s.declare_var("y", "float")
    s.spec = spec_text
    s.parse()
    data = {"time": list(range(len(x))), "x": x.tolist(), "y": y.tolist()}
    t0 = time.perf_counter()
    out = s.evaluate(data)
    dt = time.perf_counter() - t0
    return dt, np.array([v for _, v in out], dtype=np.float64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("walk")
    ap.add_argument("--repeats", type=int, default=10)
    ap.add_argument("--rtamt-steps", type=int, default=100_000)
    ap.add_argument("--criterion", default=str(HERE.parents[1] / "target" / "criterion"))
    a = ap.parse_args()
    walk = np.loadtxt(a.walk, delimiter=",", skiprows=1)
    x, y = np.ascontiguousarray(walk[:, 0]), np.ascontiguousarray(walk[:, 1])
    n = len(x)
    spec = hstl.Spec.load(HERE / "bench.hstl")
    print(f"hstl {hstl.__version__}, numpy {np.__version__}, {n} samples, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.1f}")

    print("\n## signal on the whole walk (best of %d)" % a.repeats)
    print("| formula | Python, dict of float64 arrays | Python, 2-D array (steps, 2) | native (criterion median) | Python / native |")
    print("|---|---|---|---|---|")
    rows = np.stack([x, y], axis=1)
    crit = Path(a.criterion)
    for name, formula in CASES.items():
        t_dict = best(lambda: spec.signal({"x": x, "y": y}, formula), a.repeats)
        t_rows = best(lambda: spec.signal(rows, formula), a.repeats)
        native = criterion_median(crit, "monitor_signal", name)
        ratio = f"{t_dict / native:.2f}x" if native else "(run the criterion bench)"
        nat = f"{native * 1e3:.2f} ms" if native else "-"
        print(f"| {name} | {t_dict * 1e3:.2f} ms = {n / t_dict / 1e6:.0f}M/s | {t_rows * 1e3:.2f} ms | {nat} | {ratio} |")
    t0 = best(lambda: spec.robustness({"x": x, "y": y}, "F1_w40"), 1000)
    print(f"\nrobustness at step 0 (F1_w40, 1M samples): {t0 * 1e6:.1f} us")

    m = min(n, a.rtamt_steps)
    print(f"\n## rtamt 0.4.10 in this process, first {m} samples")
    try:
        import rtamt  # noqa: F401
    except ImportError:
        print("rtamt is not installed: run bench/python/run.sh")
    else:
        print("| formula | rtamt | hstl (Python) | hstl / rtamt speed | values equal |")
        print("|---|---|---|---|---|")
        xs, ys = x[:m].copy(), y[:m].copy()
        for name, formula in CASES.items():
            t_rtamt, want = rtamt_signal(xs, ys, RTAMT[name])
            t_hstl = best(lambda: spec.signal({"x": xs, "y": ys}, formula), a.repeats)
            got = spec.signal({"x": xs, "y": ys}, formula)
            equal = np.array_equal(got, want)
            print(f"| {name} | {t_rtamt:.2f} s = {m / t_rtamt / 1e3:.0f}k/s | {t_hstl * 1e3:.3f} ms = "
                  f"{m / t_hstl / 1e6:.0f}M/s | {t_rtamt / t_hstl:,.0f}x | {'yes' if equal else 'NO'} |")

    traces, steps = 1000, 1000
    print(f"\n## signal_batch, {traces} traces x {steps} steps (best of {a.repeats})")
    per_var = {"x": x[: traces * steps].reshape(traces, steps), "y": y[: traces * steps].reshape(traces, steps)}
    cube = rows[: traces * steps].reshape(traces, steps, 2)
    print("| formula | loop of `signal` | batch, 1 thread | batch, 2 threads | 2 threads, 3-D array | native 1 / 2 threads |")
    print("|---|---|---|---|---|---|")
    for name in ["F1_w40", "F2"]:
        formula = CASES[name]
        dicts = [{"x": per_var["x"][i], "y": per_var["y"][i]} for i in range(traces)]
        t_loop = best(lambda: [spec.signal(d, formula) for d in dicts], a.repeats)
        t1 = best(lambda: spec.signal_batch(per_var, formula, threads=1), a.repeats)
        t2 = best(lambda: spec.signal_batch(per_var, formula, threads=2), a.repeats)
        t3 = best(lambda: spec.signal_batch(cube, formula, threads=2), a.repeats)
        assert np.array_equal(spec.signal_batch(per_var, formula), np.stack([spec.signal(d, formula) for d in dicts]))
        n1 = criterion_median(crit, "monitor_signal_batch", f"{name}_1_threads")
        n2 = criterion_median(crit, "monitor_signal_batch", f"{name}_2_threads")
        native = f"{n1 * 1e3:.2f} / {n2 * 1e3:.2f} ms" if n1 and n2 else "-"
        print(f"| {name} | {t_loop * 1e3:.1f} ms | {t1 * 1e3:.2f} ms | {t2 * 1e3:.2f} ms ({t1 / t2:.2f}x) | "
              f"{t3 * 1e3:.2f} ms | {native} |")


if __name__ == "__main__":
    sys.exit(main())
