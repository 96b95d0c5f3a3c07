"""The prototype of `plan: model` (issue 15): the case study's options level planned over
exact leg models and the known counters, then simulated as `hstlc eval` measures W.

Each leg's duration and arrival cell distributions are computed exactly from the paper's
slip model (p = 0.7) under the learned legs of POLICY.json (or, with SHORT=1, the
least-expected-time legs); value iteration (discount GAMMA) runs over the region cells with
the exact counters of the other regions; the greedy policy chooses at every step from the
exact counters (B = 0) or from B buckets (BS="0 8"; REP=1 values a bucket by its middle
counter, otherwise by the mean over its counters). Needs numpy; minutes of CPU.

    python bench/learner/plan_sim.py out/case-study/surveillance_auto/policy.json 0.98
"""
import os, sys, time, random
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ceiling_vi import DEST, N, S, SHIFT, T, P, load

DMAX = 160
REP = os.environ.get('REP') == '1'

def leg_model(region, act):
    """f[s, d]: P(first entry into region at step d | start s), g[s, e]: P(entry cell e)."""
    f = np.zeros((S, DMAX + 1)); g = np.zeros((S, S))
    dist = np.eye(S)  # rows: start s0
    for d in range(1, DMAX + 1):
        nd = np.zeros((S, S))
        for dd in range(4):
            # mass at cell c moves to DEST[c, dd] with prob P[act[c], dd]
            w = dist * P[act, dd][None, :]
            np.add.at(nd.T, DEST[:, dd], w.T)
        arrived = nd * region[None, :]
        f[:, d] = arrived.sum(1); g += arrived
        dist = nd * (~region)[None, :]
        if dist.sum() < 1e-9: break
    g /= np.maximum(g.sum(1, keepdims=True), 1e-300)
    return f, g

def reward_table(gamma):
    m = np.arange(1, DMAX + 1)
    t = np.arange(T)
    okj = (t[:, None] + m[None, :] < N)
    disc = gamma ** (m - 1)
    R = np.zeros((T, T, T, DMAX + 1))
    for d in range(1, DMAX + 1):
        mm = m[:d]
        oko = (t[:, None] + mm[None, :] < N) | (mm[None, :] == d)
        a = okj[:, :d][:, None, None, :] & okj[:, :d][None, :, None, :] & oko[None, None, :, :]
        R[..., d] = (a * disc[:d]).sum(-1)
    return R

class Planner:
    def __init__(self, path, gamma):
        self.regions, self.legs = load(path)
        if os.environ.get("SHORT") == "1":
            from ceiling_vi import shortest
            self.legs = [shortest(r) for r in self.regions]
        self.k = len(self.regions); self.gamma = gamma
        self.models = [leg_model(self.regions[o], self.legs[o]) for o in range(self.k)]
        self.R = reward_table(gamma)
        self.cells = [[s for s in range(S) if self.regions[o][s]] for o in range(self.k)]
        # Vreg[o]: [S, T, T] over o's two other counters (in region order); only region cells used
        self.V = [np.zeros((S, T, T)) for _ in range(self.k)]
        self.support = [[np.nonzero(self.models[o][0][s] > 1e-7)[0] for s in range(S)] for o in range(self.k)]

    def q(self, s, o, tau):
        """tau: list of k same-shaped int arrays."""
        f, g = self.models[o]
        a, b = [j for j in range(self.k) if j != o]
        U = np.tensordot(g[s], self.V[o], axes=(0, 0))
        out = np.zeros(tau[0].shape)
        for d in self.support[o][s]:
            out += f[s, d] * (self.R[tau[a], tau[b], tau[o], d]
                              + self.gamma ** d * U[np.minimum(tau[a] + d, N), np.minimum(tau[b] + d, N)])
        return out

    def solve(self, sweeps=400, tol=1e-3):
        t0 = time.time()
        g2 = np.meshgrid(np.arange(T), np.arange(T), indexing="ij")
        for it in range(sweeps):
            diff = 0
            for i in range(self.k):
                a, b = [j for j in range(self.k) if j != i]
                tau = [None] * self.k
                tau[i] = np.zeros((T, T), int); tau[a] = g2[0]; tau[b] = g2[1]
                for s in self.cells[i]:
                    v = np.max([self.q(s, o, tau) for o in range(self.k) if o != i], axis=0)
                    diff = max(diff, np.abs(v - self.V[i][s]).max())
                    self.V[i][s] = v
            if it % 10 == 0: print(it, round(diff, 5), round(time.time() - t0, 1), "s", flush=True)
            if diff < tol: break
        print("solved", it, round(time.time() - t0, 1), "s")

def bucket(t, b):
    return b if t >= N else t * b // N

def simulate(pl, b=0, runs=100):
    k, regions, legs = pl.k, pl.regions, pl.legs
    g3 = list(np.meshgrid(*[np.arange(T)] * k, indexing="ij"))
    Q = {}
    for s in range(S):
        for o in range(k):
            if not regions[o][s]:
                Q[s, o] = pl.q(s, o, g3)
    if b:
        codes = [np.array([t for t in range(T) if bucket(t, b) == c]) for c in range(b + 1)]
        for key, q in Q.items():
            qb = np.zeros((b + 1,) * 3)
            for i, ia in enumerate(codes):
                for j, ib in enumerate(codes):
                    for c, ic in enumerate(codes):
                        if REP:
                            qb[i, j, c] = q[ia[len(ia) // 2], ib[len(ib) // 2], ic[len(ic) // 2]]
                        else:
                            qb[i, j, c] = q[np.ix_(ia, ib, ic)].mean()
            Q[key] = qb
    rng = random.Random(7)
    kept = total = 0
    for _ in range(runs):
        s = rng.randrange(S)
        tau = tuple(0 if r[s] else N for r in regions)
        for t in range(2000):
            allowed = [o for o in range(k) if not regions[o][s]]
            key = tuple(bucket(x, b) for x in tau) if b else tau
            o = max(allowed, key=lambda o: Q[s, o][key])
            a = legs[o][s]
            if rng.random() >= 0.7:
                a = rng.choice([x for x in range(4) if x != a])
            s = DEST[s, a]
            tau = tuple(0 if r[s] else SHIFT[x] for r, x in zip(regions, tau))
            if t >= 100:
                total += 1
                kept += all(x < N for x in tau)
    return kept / total

if __name__ == "__main__":
    path = sys.argv[1]; gamma = float(sys.argv[2]) if len(sys.argv) > 2 else 0.99
    t0 = time.time()
    pl = Planner(path, gamma)
    print("models", round(time.time() - t0, 1), "s", flush=True)
    pl.solve()
    for b in [int(x) for x in os.environ.get('BS', '0 8').split()]:
        print("B", b, "W", round(simulate(pl, b), 4), flush=True)
