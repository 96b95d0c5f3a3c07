"""Simulates the greedy policy of ceiling_vi.py's values: at every step the leg of greatest
value from the exact counters (B = 0), or from their B buckets (B > 0: the options value of
each bucket code taken as the mean over the counter values it holds). 100 runs of 2000
steps from random cells, 100 burn-in, as `hstlc eval` measures the window rate.

    python bench/learner/ceiling_sim.py learned POLICY.json 8
"""
import json, struct, sys, numpy as np, random
import os
exec(open(os.path.join(os.path.dirname(__file__), 'ceiling_vi.py')).read().split("which = sys.argv[1]")[0])   # dest, P, R, learned, mintime
which = sys.argv[1]; B = int(sys.argv[3]) if len(sys.argv) > 3 else 0
acts = learned if which == 'learned' else [mintime(r) for r in R]
V = np.load(f'V_{which}.npy').astype(np.float64)
shift = np.minimum(np.arange(T)+1, N)
def nxt_tau(s2, tau): return tuple(0 if R[j][s2] else shift[tau[j]] for j in range(3))
def qval(s, tau, o):
    a = acts[o][s]; tot = 0.0
    for d in range(4):
        s2 = dest[s, d]; t2 = nxt_tau(s2, tau)
        tot += P[a, d] * ((all(t < N for t in t2)) + V[(s2,)+t2])
    return tot
# Q for all (s, tau, o) vectorised, for the bucketed projection
if B:
    G = np.empty_like(V)
    zero = np.zeros(T, int)
    for s in range(S):
        idx = [(zero if R[j][s] else shift) for j in range(3)]
        ok = np.arange(T) < N
        a_, b_, c_ = [(np.ones(T,bool) if R[j][s] else ok[shift]) for j in range(3)]
        G[s] = V[s][np.ix_(*idx)] + (a_[:,None,None] & b_[None,:,None] & c_[None,None,:])
    Qo = np.stack([sum(P[acts[o], d][:,None,None,None] * G[dest[np.arange(S), d]] for d in range(4)) for o in range(3)])  # 3,S,T,T,T
    bk = np.array([B if t >= N else t*B//N for t in range(T)])
    nb = B + 1
    # mean Q over the clock combinations of each bucket code, restricted to plausible clocks (all)
    Qb = np.zeros((3, S, nb, nb, nb))
    cnt = np.zeros((nb, nb, nb))
    for a in range(T):
        for b in range(T):
            Qb[:, :, bk[a], bk[b], :] += np.add.reduceat(Qo[:, :, a, b, :], np.r_[0, [t for t in range(1, T) if bk[t] != bk[t-1]]], axis=2) if False else 0
    # simpler: loop codes
    Qb = np.zeros((3, S, nb, nb, nb))
    for ba in range(nb):
        ia = np.where(bk == ba)[0]
        for bb in range(nb):
            ib = np.where(bk == bb)[0]
            for bc in range(nb):
                ic = np.where(bk == bc)[0]
                Qb[:, :, ba, bb, bc] = Qo[:, :, ia][:, :, :, ib][:, :, :, :, ic].mean(axis=(2, 3, 4))
rng = random.Random(7); kept = tot = 0
for run in range(100):
    s = rng.randrange(S)
    tau = tuple(0 if R[j][s] else N for j in range(3))
    for t in range(2000):
        allowed = [o for o in range(3) if not R[o][s]] or [0,1,2]
        if B:
            b = tuple(B if x >= N else x*B//N for x in tau)
            o = max(allowed, key=lambda o: Qb[(o, s) + b])
        else:
            o = max(allowed, key=lambda o: qval(s, tau, o))
        a = acts[o][s]
        if rng.random() >= 0.7: a = rng.choice([x for x in range(4) if x != a])
        s = dest[s, a]; tau = nxt_tau(s, tau)
        if t >= 100: tot += 1; kept += all(x < N for x in tau)
print(which, 'B', B, round(kept/tot, 4), round(kept/tot/0.7816, 3))
