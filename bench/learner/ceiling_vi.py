"""The case study's options-level ceiling (issue 15): the optimal window rate when the
robot may only follow legs, choosing a leg at every step from the exact counters.

Average-reward relative value iteration over (cell, tau_A, tau_B, tau_C) on the paper's
15 x 15 grid (p = 0.7), 225 * 41^3 states, with each cell's actions restricted to:
  all       the four moves (the unrestricted optimum: converges to W* = 0.7816)
  learned   the greedy action of each learned leg in POLICY.json
  shortest  each region's least-expected-time action
Prints the gain bracket every 20 sweeps (stops when narrower than 0.006, about 300 sweeps
of 2 s) and saves the values to V_<legs>.npy for ceiling_sim.py. Needs numpy.

    python bench/learner/ceiling_vi.py learned out/train/policy.json
"""
import json, struct, sys, numpy as np, time
W = H = 15; S = W*H; N = 40; T = N + 1
pol = json.load(open(sys.argv[2]))
h2f = lambda h: struct.unpack('>d', bytes.fromhex(h))[0]
R = []
for prim in pol['primitives']:
    m = np.zeros(S, bool)
    for c in prim['terminate']: m[c['y']*W + c['x']] = True
    R.append(m)
moves = [(0,1),(0,-1),(-1,0),(1,0)]
dest = np.zeros((S,4), int)
for s in range(S):
    x, y = s % W, s // W
    for d,(dx,dy) in enumerate(moves):
        nx, ny = x+dx, y+dy
        dest[s,d] = ny*W+nx if 0 <= nx < W and 0 <= ny < H else s
P = np.full((4,4), 0.1); np.fill_diagonal(P, 0.7)
def mintime(Rm):
    V = np.zeros(S)
    for _ in range(3000):
        Vn = np.where(Rm[dest], 0.0, V[dest])   # S x 4
        Q = 1 + Vn @ P.T                          # Q[s,a]
        V2 = Q.min(1)
        if np.abs(V2-V).max() < 1e-12: break
        V = V2
    return Q.argmin(1)
learned = [np.array([max(range(4), key=lambda a: (h2f(pol['q_tables']['flat'][n][s*4+a]), -a)) for s in range(S)]) for n in ['A','B','C']]
which = sys.argv[1]
if which == 'all': acts = [np.tile(np.arange(4), (S,1))]; acts = [acts[0][:,a] for a in range(4)]
elif which == 'shortest': acts = [mintime(r) for r in R]
else: acts = learned
shift = np.minimum(np.arange(T)+1, N)
zero = np.zeros(T, int)
idx = [[(zero if R[j][s] else shift) for j in range(3)] for s in range(S)]
psi = np.zeros((S,T,T,T))
ok = np.arange(T) < N
for s in range(S):
    a,b,c = [(np.ones(T,bool) if R[j][s] else ok[shift]) for j in range(3)]
    psi[s] = a[:,None,None] & b[None,:,None] & c[None,None,:]
V = np.zeros((S,T,T,T)); t0 = time.time()
for it in range(5000):
    G = np.empty_like(V)
    for s in range(S):
        G[s] = V[s][np.ix_(*idx[s])] + psi[s]
    best = np.full_like(V, -np.inf)
    for act in acts:      # act[s] = action of this option at cell s
        Q = np.zeros_like(V)
        for d in range(4):
            Q += P[act, d][:,None,None,None] * G[dest[np.arange(S), d]]
        np.maximum(best, Q, out=best)
    diff = best - V
    lo, hi = diff.min(), diff.max()
    V = best - best[0,N,N,N]
    if it % 20 == 0: print(it, round(lo,5), round(hi,5), round(time.time()-t0), flush=True)
    if hi - lo < 6e-3: break
print(which, 'gain in', lo, hi)
np.save(f'V_{which}.npy', V.astype(np.float32))
