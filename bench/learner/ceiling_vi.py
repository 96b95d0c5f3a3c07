"""The case study's options-level ceiling (issue 15): the optimal window rate when the
robot may only follow legs, choosing a leg at every step from the exact counters.

Average-reward relative value iteration over (cell, tau_A, tau_B, tau_C) on the paper's
15 x 15 grid (p = 0.7, windows of 40 steps), 225 * 41^3 states, the regions read off the
primitives' termination sets in POLICY.json, each cell's actions restricted to:
  all       the four moves (the unrestricted optimum: its gain is W*, as hstlc computes it)
  learned   the greedy action of each learned leg in POLICY.json
  shortest  each region's least-expected-time action
Prints the gain bracket every 20 sweeps (stops when narrower than 0.006, about 300 sweeps
of 2 s) and saves the values to V_<legs>.npy for ceiling_sim.py. Needs numpy.

    python bench/learner/ceiling_vi.py learned out/case-study/surveillance_auto/policy.json
"""
import json
import struct
import sys
import time

import numpy as np

W = H = 15
S = W * H
N = 40  # every region's window
T = N + 1  # counter values 0..N, N = expired
MOVES = [(0, 1), (0, -1), (-1, 0), (1, 0)]  # Up, Down, Left, Right
P = np.full((4, 4), 0.1)  # P[a, d]: intended a, taken d
np.fill_diagonal(P, 0.7)
SHIFT = np.minimum(np.arange(T) + 1, N)


def hex_f64(h):
    return struct.unpack(">d", bytes.fromhex(h))[0]


def destinations():
    dest = np.zeros((S, 4), int)
    for s in range(S):
        x, y = s % W, s // W
        for d, (dx, dy) in enumerate(MOVES):
            nx, ny = x + dx, y + dy
            dest[s, d] = ny * W + nx if 0 <= nx < W and 0 <= ny < H else s
    return dest


DEST = destinations()


def load(path):
    """The regions (a mask per primitive) and the learned legs (an action per cell)."""
    pol = json.load(open(path))
    regions = []
    for prim in pol["primitives"]:
        m = np.zeros(S, bool)
        for c in prim["terminate"]:
            m[c["y"] * W + c["x"]] = True
        regions.append(m)
    legs = []
    for prim in pol["primitives"]:
        q = pol["q_tables"]["flat"][prim["name"]]
        # The first of the largest, as the runtime's argmax.
        legs.append(np.array([max(range(4), key=lambda a: (hex_f64(q[s * 4 + a]), -a)) for s in range(S)]))
    return regions, legs


def shortest(region):
    """The least-expected-time action to enter `region`, per cell."""
    v = np.zeros(S)
    while True:
        q = 1 + np.where(region[DEST], 0.0, v[DEST]) @ P.T
        v2 = q.min(1)
        if np.abs(v2 - v).max() < 1e-12:
            return q.argmin(1)
        v = v2


def actions(which, regions, legs):
    if which == "all":
        return [np.full(S, a) for a in range(4)]
    if which == "shortest":
        return [shortest(r) for r in regions]
    return legs


def successor_terms(v, regions):
    """G[s'] over the counters before a step into s': psi after it plus V after it."""
    ok = np.arange(T) < N
    g = np.empty_like(v)
    for s in range(S):
        idx = [np.zeros(T, int) if r[s] else SHIFT for r in regions]
        kept = [np.ones(T, bool) if r[s] else ok[SHIFT] for r in regions]
        g[s] = v[s][np.ix_(*idx)] + (kept[0][:, None, None] & kept[1][None, :, None] & kept[2][None, None, :])
    return g


def option_values(g, acts):
    """Q[o, s, tau]: follow action acts[o][s] for one step, then the values g."""
    return np.stack([sum(P[act, d][:, None, None, None] * g[DEST[:, d]] for d in range(4)) for act in acts])


def solve(acts, regions):
    v = np.zeros((S, T, T, T))
    t0 = time.time()
    for it in range(5000):
        best = option_values(successor_terms(v, regions), acts).max(0)
        diff = best - v
        lo, hi = diff.min(), diff.max()
        v = best - best[0, N, N, N]
        if it % 20 == 0:
            print(it, round(lo, 5), round(hi, 5), f"{time.time() - t0:.0f} s", flush=True)
        if hi - lo < 6e-3:
            return v, lo, hi
    return v, lo, hi


if __name__ == "__main__":
    which, path = sys.argv[1], sys.argv[2]
    regions, legs = load(path)
    v, lo, hi = solve(actions(which, regions, legs), regions)
    print(which, "gain in", lo, hi)
    np.save(f"V_{which}.npy", v.astype(np.float32))
