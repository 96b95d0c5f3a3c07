"""Simulates the greedy policy of ceiling_vi.py's values: at every step the leg of greatest
value from the exact counters (B = 0), or from their B buckets (B > 0: the options value of
each bucket code taken as the mean over the counter values it holds). 100 runs of 2000
steps from random cells, 100 burn-in, as `hstlc eval` measures the window rate W (compare
it with the W* that `hstlc eval` prints).

    python bench/learner/ceiling_sim.py learned POLICY.json 8
"""
import random
import sys

import numpy as np

from ceiling_vi import DEST, N, S, SHIFT, T, actions, load, option_values, successor_terms


def bucket(t, b):
    return b if t >= N else t * b // N


def main():
    which, path = sys.argv[1], sys.argv[2]
    b = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    regions, legs = load(path)
    acts = actions(which, regions, legs)
    q = option_values(successor_terms(np.load(f"V_{which}.npy").astype(np.float64), regions), acts)
    if b:
        codes = [np.array([t for t in range(T) if bucket(t, b) == k]) for k in range(b + 1)]
        qb = np.zeros(q.shape[:2] + (b + 1,) * 3)
        for i, ia in enumerate(codes):
            for j, ib in enumerate(codes):
                for k, ic in enumerate(codes):
                    qb[:, :, i, j, k] = q[:, :, ia][:, :, :, ib][:, :, :, :, ic].mean(axis=(2, 3, 4))
    rng = random.Random(7)
    kept = total = 0
    for _ in range(100):
        s = rng.randrange(S)
        tau = tuple(0 if r[s] else N for r in regions)
        for t in range(2000):
            allowed = [o for o in range(len(acts)) if not regions[o][s]] or list(range(len(acts)))
            if b:
                o = max(allowed, key=lambda o: qb[(o, s) + tuple(bucket(x, b) for x in tau)])
            else:
                o = max(allowed, key=lambda o: q[(o, s) + tau])
            a = acts[o][s]
            if rng.random() >= 0.7:
                a = rng.choice([x for x in range(4) if x != a])
            s = DEST[s, a]
            tau = tuple(0 if r[s] else SHIFT[x] for r, x in zip(regions, tau))
            if t >= 100:
                total += 1
                kept += all(x < N for x in tau)
    print(which, "B", b, "W", round(kept / total, 4))


if __name__ == "__main__":
    main()
