"""What `Spec.signal` costs a call at three trace lengths (best of 5).

Run it with two wheels installed in turn (before and after a change) to compare:
`.venv/bin/python bench/python/copy_cost.py`. BENCHMARKS.md, "The copy's cost".
"""

import time

import numpy as np

import hstl

SPEC = (
    "spec S { state { x: float, y: float } let A = x > 0; "
    "task always[0..] (A -> eventually[0..=40] y > 2); }"
)


def main() -> None:
    spec = hstl.Spec.parse(SPEC)
    rng = np.random.default_rng(1)
    for n in (1_000, 100_000, 4_000_000):
        trace = {"x": rng.normal(size=n), "y": rng.normal(size=n) * 3}
        reps = max(3, 2_000_000 // n)
        best = float("inf")
        for _ in range(5):
            start = time.perf_counter()
            for _ in range(reps):
                spec.signal(trace)
            best = min(best, (time.perf_counter() - start) / reps)
        print(f"{n} steps: {best * 1e3:.3f} ms a call, {n / best / 1e6:.1f}M steps/s")


if __name__ == "__main__":
    main()
