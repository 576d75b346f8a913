"""Independent numpy re-implementation of the Wang et al. 2022 position-free chains
(supplement Eq. 12-17 and the released code's transmission Beta term) for a GGX dielectric or
conductor (F = 1), written from the formulas, sharing no code with smithwalk. Own-side frame:
inside directions are point-reflected (-v).

It gives the reference values of tests/physics/wang_models.rs (`the_correlated_central_spike_is_the_models`):
the energy of the innermost cos ring (|cos theta| in [31/32, 1]) of the transmitted orders 3 and
4+, dielectric eta 1.5, GGX alpha 0.5, theta_i 0.5 rad, as the mean and standard error over 10
seeds of 4*10^5 chains each:

    for s in 11 12 13 14 15 16 17 18 19 20; do for m in corr uncorr; do
        SEED=$s OUT=/tmp/wang python scripts/wang_chain_reference.py $m diel 0.5 0.5
    done; done

Each run saves its tallies [order][R/T][ring] to $OUT/py-MODEL-MATERIAL-ALPHA-THETA-SEED.npy
and prints the rings per order. Models: corr (correlated), uncorr (uncorrelated), corrclamp
(a diagnostic, not the paper's: the arriving rate raised to at least 1 at reflections).
Needs numpy."""
import sys, numpy as np
import math
_lg = np.frompyfunc(math.lgamma, 1, 1)
lgam = lambda x: _lg(x).astype(float)
betaln = lambda a, b: lgam(a) + lgam(b) - lgam(a + b)

model = sys.argv[1] if len(sys.argv) > 1 else "corr"
mat = sys.argv[2] if len(sys.argv) > 2 else "diel"
alpha = float(sys.argv[3]) if len(sys.argv) > 3 else 0.5
theta = float(sys.argv[4]) if len(sys.argv) > 4 else 0.5
import os
eta, N, seed = 1.5, int(os.environ.get("N", 400_000)), int(os.environ.get("SEED", 1))
nb = 32; maxk = 4
rng = np.random.default_rng(seed)

def Lam(w):  # true full-sphere GGX Lambda
    t = alpha**2 * (w[:, 0]**2 + w[:, 1]**2)
    n = np.sqrt(t + w[:, 2]**2)
    return np.where(w[:, 2] > 0, t / (2*w[:, 2]*(n + w[:, 2])), (n - w[:, 2]) / (2*w[:, 2]))

def rate(d):  # depth rate of travel direction d (own frame)
    return np.abs(Lam(d))

def vndf(w):  # Dupuy & Benyoub 2023 spherical caps, full sphere
    ws = np.stack([alpha*w[:, 0], alpha*w[:, 1], w[:, 2]], 1)
    ws /= np.linalg.norm(ws, axis=1)[:, None]
    phi = 2*np.pi*rng.random(len(w)); u = rng.random(len(w))
    z = (1 - u)*(1 + ws[:, 2]) - ws[:, 2]
    s = np.sqrt(np.clip(1 - z*z, 0, None))
    h = np.stack([s*np.cos(phi), s*np.sin(phi), z], 1) + ws
    m = np.stack([alpha*h[:, 0], alpha*h[:, 1], h[:, 2]], 1)
    return m / np.linalg.norm(m, axis=1)[:, None]

def fresnel(c, e):
    s2 = (1 - c*c) / (e*e)
    tir = s2 >= 1
    ct = np.sqrt(np.clip(1 - s2, 0, None))
    rs = (c - e*ct) / (c + e*ct); rp = (e*c - ct) / (e*c + ct)
    return np.where(tir, 1.0, 0.5*(rs*rs + rp*rp)), ct

wi = np.array([np.sin(theta), 0, np.cos(theta)])
d = np.tile(-wi, (N, 1)); inside = np.zeros(N, bool); W = np.ones(N)
alive = np.ones(N, bool)
# tallies[k][hemi][ring]: energy, hemi 0 = R (outside), 1 = T
tal = np.zeros((maxk + 1, 2, nb)); tal_last = np.zeros((maxk+1, 2, nb)); byrate = np.zeros((maxk+1, 2, 4))
edges = np.array([0.005, 0.05, 0.5]); trunc = np.zeros((maxk+1, 2))
lam_in = rate(d)
for order in range(1, 60):
    idx = np.nonzero(alive & (W > 1e-9))[0]
    if len(idx) == 0: break
    win = -d[idx]
    m = vndf(win)
    c = np.einsum('ij,ij->i', win, m)
    e = np.where(inside[idx], 1/eta, eta)
    F, ct = fresnel(c, e)
    if mat == 'cond': F = np.ones_like(F)
    refl = rng.random(len(idx)) < F
    r = 2*c[:, None]*m - win
    t = -win/e[:, None] + (c/e - ct)[:, None]*m
    newd = np.where(refl[:, None], r, -t)  # refracted: flip into the new side's frame
    newin = np.where(refl, inside[idx], ~inside[idx])
    lo = Lam(newd); up = newd[:, 2] > 0
    li = lam_in[idx]
    if model.startswith("corr"):
        lr = np.maximum(li, 1.0) if model == "corrclamp" else li
        pr = lr / (lr + lo)
        pt = np.exp(np.log(li) + betaln(li, 1 + np.where(up, lo, 0)))
        p = np.where(up, np.where(refl, pr, pt), 0.0)
    else:
        p = np.where(up, 1/(1 + np.where(up, lo, 0)), 0.0)
    esc = W[idx]*p
    k = min(order, maxk)
    ring = np.minimum((newd[:, 2]*nb).astype(int), nb - 1)
    hemi = newin.astype(int)
    # last-vertex arrival: was the arriving direction upward (own frame) ?
    arr_up = d[idx][:, 2] > 0
    sel = up
    np.add.at(tal[k], (hemi[sel], ring[sel]), esc[sel])
    np.add.at(tal_last[k], (hemi[sel & arr_up & refl], ring[sel & arr_up & refl]), esc[sel & arr_up & refl])
    s1 = sel & (ring == nb - 1)
    s2 = s1 & (W[idx] < 1e-4)
    np.add.at(trunc[k], hemi[s2], esc[s2])
    np.add.at(byrate[k], (hemi[s1], np.searchsorted(edges, li[s1])), esc[s1])
    W[idx] = W[idx]*(1 - p)
    d[idx] = newd; inside[idx] = newin; lam_in[idx] = rate(newd)
    alive[idx] = np.isfinite(W[idx])
tal /= N; tal_last /= N; byrate /= N; trunc /= N
np.save(os.path.join(os.environ.get("OUT", "."), f"py-{model}-{mat}-{alpha}-{theta}-{seed}.npy"), tal)
for k in range(1, maxk + 1):
    for h, hn in enumerate("RT"):
        rings = tal[k, h][::-1]
        print(f"{hn} order {k}{'+' if k == maxk else ''}: E={rings.sum():.5f} innermost rings {rings[:3]}  "
              f"ring 1 by rate_in <.005,<.05,<.5,>=.5: {byrate[k,h]} from weight<1e-4: {trunc[k,h]:.3g}")
