#!/usr/bin/env python3
"""Side by side with NVIDIA facet-forge (issue 38 point 5; docs/validation.md, "Side by side with
facet-forge"). Drives facet-forge through ff_driver (built from its public source, see README.md)
and smithwalk through its `peer_student_t` example and `smithwalk run`, and prints the tables of
docs/validation.md as Markdown.

    python compare.py lambda   --ff FF_DRIVER --sw PEER_STUDENT_T
    python compare.py vndf     --ff FF_DRIVER --sw PEER_STUDENT_T [--samples N]
    python compare.py orders   --ff FF_DRIVER --smithwalk SMITHWALK [--paths N] [--sigma-paths N]
                               [--jobs J] [--work DIR]

Needs numpy and scipy (`pip install numpy scipy`).
"""
import argparse
import csv
import itertools
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.stats import chi2

GAMMAS = [1.6, 2.0, 2.5, 3.0, 5.0, 10.0, 30.0, 100.0]
# polar angles: 0 to 89.9 degrees above the horizon, 90.1 to 180 below, step 0.1
ABOVE = np.round(np.arange(0, 900) * 0.1, 1)
BELOW = np.round(180.0 - ABOVE, 1)
FLOOR = 1e-6  # Lambda below this is left out of the relative errors


def run(cmd, stdin=None):
    return subprocess.run(cmd, input=stdin, capture_output=True, text=True, check=True).stdout


def lambda_table(a):
    lines = [f"student-t {g} 1 {t}" for g in GAMMAS for t in np.concatenate([ABOVE, BELOW])]
    text = "\n".join(lines) + "\n"
    sigma_ff = np.array([float(x) for x in run([a.ff, "sigma"], text).split()])
    sw = np.array([[float(v) for v in l.split()] for l in run([a.sw, "lambda"], text).splitlines()])
    lam_sw, area_sw = sw[:, 0], sw[:, 1]
    n = len(ABOVE)
    print("| gamma | max rel. error of Lambda, Lambda >= 1e-6 (theta) | Lambda >= 1e-3 (theta) "
          "| Lambda >= 1e-2 (theta) | of A above (theta) | of A below (theta) | Lambda error at 30 / 60 / 80 / 89 deg |")
    print("|---|---|---|---|---|---|---|")
    worst = {}
    u = np.cos(np.radians(ABOVE))
    for i, g in enumerate(GAMMAS):
        s = slice(2 * n * i, 2 * n * i + n)
        b = slice(2 * n * i + n, 2 * n * (i + 1))
        lam_ff = sigma_ff[s] / u - 1.0
        rel_all = np.abs(lam_ff - lam_sw[s]) / np.maximum(lam_sw[s], 1e-300)
        cells = []
        for floor in (FLOOR, 1e-3, 1e-2):
            rel = np.where(lam_sw[s] >= floor, rel_all, 0.0)
            k = int(np.argmax(rel))
            if rel[k] > worst.get(floor, (0,))[0]:
                worst[floor] = (rel[k], g, ABOVE[k])
            cells.append(f"{rel[k]:.3g} ({ABOVE[k]:.1f})")
        rel_a = np.abs(sigma_ff[s] - area_sw[s]) / area_sw[s]
        ka = int(np.argmax(rel_a))
        # below the horizon A = |u| Lambda(-w): left out where that Lambda is below the floor
        keep_b = area_sw[b] >= FLOOR * np.abs(np.cos(np.radians(BELOW)))
        rel_b = np.where(keep_b, np.abs(sigma_ff[b] - area_sw[b]) / np.where(keep_b, area_sw[b], 1.0), 0.0)
        kb = int(np.argmax(rel_b))
        at = [(lam_ff - lam_sw[s])[int(np.argmin(np.abs(ABOVE - t)))] / lam_sw[s][int(np.argmin(np.abs(ABOVE - t)))]
              for t in (30, 60, 80, 89)]
        print(f"| {g:g} | " + " | ".join(cells) + f" | {rel_a[ka]:.3g} ({ABOVE[ka]:.1f}) "
              f"| {rel_b[kb]:.3g} ({BELOW[kb]:.1f}) | " + " / ".join(f"{x:+.2g}" for x in at) + " |")
    left = int(np.sum(lam_sw[np.tile(np.r_[np.ones(n, bool), np.zeros(n, bool)], len(GAMMAS))] < FLOOR))
    for floor, (e, g, t) in worst.items():
        print(f"\nLargest relative error of Lambda where Lambda >= {floor:g}: {e:.4g} at gamma {g:g}, theta {t:.1f} deg.")
    print(f"\n{left} of {n * len(GAMMAS)} points above the horizon have Lambda < {FLOOR:g} and are left out.")
    # the driver's exact cross section (Boost.Math) against smithwalk's projected area
    exact = np.array([float(x) for x in run([a.ff, "sigma"], text.replace("student-t ", "student-t-exact-sigma ")).split()])
    pos = area_sw > 0
    dev = np.max(np.abs(exact[pos] - area_sw[pos]) / area_sw[pos])
    print(f"\nThe driver's student-t-exact-sigma against smithwalk's A on the same grid: largest relative difference {dev:.2g} "
          f"(where A > 0; {int(np.sum(~pos))} points have A = 0 in smithwalk, "
          f"{int(np.sum((~pos) & (exact != 0)))} of them not 0 in the driver).")


VNDF_CASES = [("student-t", g, t) for g in (2.5, 3.0, 10.0) for t in (0.0, 30.0, 60.0, 80.0, 100.0, 135.0, 160.0)] + \
             [("student-t", g, t) for g in (1.6, 2.0) for t in (100.0, 135.0, 160.0)] + \
             [("beckmann", 0.0, t) for t in (30.0, 60.0, 100.0, 135.0, 160.0)]
ALPHA_VNDF = 0.5


def pooled_chi_square(counts, probs, n):
    exp = probs * n
    low = exp < 5.0
    obs_c = np.r_[counts[~low], counts[low].sum()] if low.any() else counts
    exp_c = np.r_[exp[~low], exp[low].sum()] if low.any() else exp
    # the probabilities sum to 1 within the quadrature tolerance; scale to the draws
    exp_c = exp_c * n / exp_c.sum()
    if exp_c[-1] == 0.0:
        # the pooled cell holds only bins of probability 0 (normals facing away): any draw
        # there rejects outright
        if obs_c[-1] > 0:
            return float("inf"), len(obs_c) - 2, 0.0, float("inf"), len(obs_c)
        obs_c, exp_c = obs_c[:-1], exp_c[:-1]
    stat = float(np.sum((obs_c - exp_c) ** 2 / exp_c))
    dof = len(obs_c) - 1
    resid = (obs_c - exp_c) / np.sqrt(exp_c)
    return stat, dof, float(chi2.sf(stat, dof)), float(np.max(np.abs(resid))), len(obs_c)


def vndf_table(a):
    print("| ndf | gamma | theta_w (deg) | branch | chi2 / dof | cells | p-value | max abs residual | TV distance "
          "| facing away |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for ndf, g, t in VNDF_CASES:
        probs = np.array([float(x) for x in run([a.sw, "vndf-bins", ndf, str(g), str(ALPHA_VNDF), str(t)]).split()])
        seed = str(1000 + int(10 * g) * 1000 + int(t))
        p = subprocess.run([a.ff, "vndf", ndf, str(g), str(ALPHA_VNDF), str(t), str(a.samples), seed],
                           capture_output=True, text=True)
        branch = ("mixture (gamma > 2 fit)" if t < 90 else "fitted gen. gamma") if ndf == "student-t" else \
            ("Beckmann, inversion" if t < 90 else "Beckmann, below-horizon mixture")
        if p.returncode != 0:
            print(f"| {ndf} | {g:g} | {t:g} | {branch} | aborts: {p.stderr.strip().splitlines()[-1]} | | | | |")
            continue
        counts = np.array([float(x) for x in p.stdout.split()])
        invalid, away = (int(x) for x in p.stderr.split()[1::2])
        n = counts.sum()
        assert invalid == 0, f"{invalid} invalid normals"
        stat, dof, pv, res, cells = pooled_chi_square(counts, probs, n)
        tv = 0.5 * np.sum(np.abs(counts / n - probs / probs.sum()))
        print(f"| {ndf} | {g:g} | {t:g} | {branch} | {stat:.4g} / {dof} | {cells} | {pv:.3g} | {res:.3g} | {tv:.3g} | {away / n:.3g} |")
    print(f"\nalpha = {ALPHA_VNDF}, {a.samples} draws a case, 16 x 16 bins uniform in cos(theta_m) x phi_m; "
          "cells with an expected count below 5 pooled into one; TV distance = half the sum of |observed - expected| "
          "frequencies; facing away: the fraction of draws with w.m < 0, which the visible-normal density never draws.")


ORDER_CASES = [(g, al, t) for al in (0.3, 0.8) for g in (2.5, 3.0, 10.0) for t in (0, 60, 80)]
GGX_CASES = [(2.0, al, t) for al in (0.3, 0.8) for t in (0, 60, 80)]
ORDERS = ["R1", "R2", "R3", "R4+"]


def smithwalk_orders(a, ndf, gammas, paths):
    cfg = os.path.join(a.work, f"{ndf}.toml")
    gamma_line = f"gamma = [{', '.join(str(g) for g in gammas)}]\n" if ndf == "student-t" else ""
    with open(cfg, "w") as f:
        f.write(f'paths = {paths}\nseed = 1\n[surface]\nndf = "{ndf}"\n{gamma_line}alpha = [0.3, 0.8]\n'
                '[[material]]\nkind = "conductor"\nfresnel = "none"\n[incident]\ntheta_deg = [0, 60, 80]\n'
                '[detector]\ncos_theta_bins = 4\nphi_bins = 4\nmax_order = 4\n')
    out = os.path.join(a.work, ndf)
    if not os.path.exists(os.path.join(out, "summary.csv")):
        run([a.smithwalk, "run", cfg, "--out", out])
    res = {}
    with open(os.path.join(out, "summary.csv")) as f:
        for r in csv.DictReader(f):
            if r["hemisphere"] != "R" or r["order"] == "0":
                continue
            g = float(r["gamma"]) if r["gamma"] else 2.0
            key = (g, float(r["alpha_x"]), float(r["theta_i_deg"]))
            res.setdefault(key, {})[ORDERS[int(r["order"]) - 1]] = (float(r["albedo"]), float(r["albedo_stderr"]))
    return res


def ff_walk(a, ndf, case, seed):
    """One facet-forge walk, its output kept in the work directory so that a rerun reuses it."""
    g, al, t = case
    paths = a.sigma_paths if ndf == "student-t-exact-sigma" else a.paths
    path = os.path.join(a.work, f"ff-{ndf}-{g:g}-{al:g}-{t}-{paths}.txt")
    if not os.path.exists(path):
        out = run([a.ff, "walk", ndf, str(g), str(al), str(t), str(paths), str(seed)])
        with open(path, "w") as f:
            f.write(out)
    with open(path) as f:
        return {l.split()[0]: (float(l.split()[1]), float(l.split()[2])) for l in f.read().splitlines()}


def diff(x, y):
    """`x - y` of two (value, standard error) pairs: relative to y and in standard errors."""
    d, s = x[0] - y[0], np.hypot(x[1], y[1])
    return d, d / y[0] if y[0] else 0.0, d / s if s else 0.0


def cell(d):
    return f"{d[1]:+.2%} ({d[2]:+.1f})"


def orders_table(a):
    os.makedirs(a.work, exist_ok=True)
    sw = smithwalk_orders(a, "student-t", [2.5, 3.0, 10.0], a.paths)
    sw_ggx = smithwalk_orders(a, "ggx", [], a.paths)
    jobs = [("student-t", c, 7 + i) for i, c in enumerate(ORDER_CASES)] + \
           [("student-t-exact-sigma", c, 107 + i) for i, c in enumerate(ORDER_CASES)] + \
           [("ggx", c, 207 + i) for i, c in enumerate(GGX_CASES)]
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        done = dict(zip([(n, c) for n, c, _ in jobs], pool.map(lambda j: ff_walk(a, *j), jobs)))
    worst = {}

    def note(col, d, y):
        w = worst.setdefault(col, [0.0, 0.0])
        w[0] = max(w[0], abs(d[2]))
        if y >= 1e-3:
            w[1] = max(w[1], abs(d[1]))

    print("| gamma | alpha | theta_i | order | smithwalk | facet-forge | facet-forge, exact sigma "
          "| facet-forge - smithwalk | exact sigma - smithwalk (its sampler) | facet-forge - exact sigma (its Lambda) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for c in ORDER_CASES:
        for o in ORDERS:
            y, x, e = sw[(c[0], c[1], float(c[2]))].get(o, (0.0, 0.0)), done[("student-t", c)][o], done[("student-t-exact-sigma", c)][o]
            d_all, d_sampler, d_lambda = diff(x, y), diff(e, y), diff(x, e)
            for col, d in (("total", d_all), ("sampler", d_sampler), ("lambda", d_lambda)):
                note(col, d, y[0])
            print(f"| {c[0]:g} | {c[1]:g} | {c[2]} | {o} | {y[0]:.5g} ± {y[1]:.1g} | {x[0]:.5g} | {e[0]:.5g} "
                  f"| {cell(d_all)} | {cell(d_sampler)} | {cell(d_lambda)} |")
    print("\n| GGX: alpha | theta_i | order | smithwalk | facet-forge | facet-forge - smithwalk |")
    print("|---|---|---|---|---|---|")
    for c in GGX_CASES:
        for o in ORDERS:
            y, x = sw_ggx[(2.0, c[1], float(c[2]))].get(o, (0.0, 0.0)), done[("ggx", c)][o]
            d = diff(x, y)
            note("ggx", d, y[0])
            print(f"| {c[1]:g} | {c[2]} | {o} | {y[0]:.5g} ± {y[1]:.1g} | {x[0]:.5g} | {cell(d)} |")
    lost = max(max(r["lost"][0], r["beyond11"][0]) for r in done.values())
    print()
    for col, (z, rel) in worst.items():
        print(f"{col}: largest |z| {z:.1f}; largest relative difference where the albedo is >= 1e-3: {rel:.2%}")
    print(f"\n{a.paths} paths a case and code ({a.sigma_paths} for facet-forge with the exact sigma), F = 1 conductor; differences relative to the second term, "
          f"z in standard errors of the difference. Largest energy lost or beyond 11 bounces in facet-forge's walks: {lost:.2g}.")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("what", choices=["lambda", "vndf", "orders"])
    p.add_argument("--ff", required=True, help="ff_driver built from facet-forge (README.md)")
    p.add_argument("--sw", help="smithwalk's peer_student_t example binary")
    p.add_argument("--smithwalk", help="the smithwalk binary")
    p.add_argument("--samples", type=int, default=1_000_000)
    p.add_argument("--paths", type=int, default=10_000_000)
    p.add_argument("--work", default="out/facet-forge")
    p.add_argument("--sigma-paths", type=int, default=2_000_000,
                   help="paths of the walks with the exact sigma (Boost.Math makes each step dearer)")
    p.add_argument("--jobs", type=int, default=2, help="facet-forge walks run at once")
    a = p.parse_args()
    {"lambda": lambda_table, "vndf": vndf_table, "orders": orders_table}[a.what](a)


if __name__ == "__main__":
    sys.exit(main())
