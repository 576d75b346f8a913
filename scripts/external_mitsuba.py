#!/usr/bin/env python3
"""A worked example of `smithwalk compare RUN_DIR --external FILE.csv`: Mitsuba 3's
`roughconductor` (GGX, visible-normal sampling; a single-scattering BSDF) integrated over every
bin of a smithwalk run, written as an external model file.

    pip install mitsuba==3.9.1
    smithwalk run configs/compensation.toml --out out/compensation
    python3 scripts/external_mitsuba.py out/compensation --out out/mitsuba.csv
    smithwalk compare out/compensation --models single --external out/mitsuba.csv

How the file is made (do the same with your renderer's BSDF):
- the run's bins come from its lobes.csv (one row per case, order, hemisphere, bin, channel);
- smithwalk's `wi` points towards the light and `wo` towards the detector, both away from the
  surface, with the light at azimuth phi_i and bin azimuths counted from phi_i; Mitsuba's
  `eval(ctx, si, wo)` with `si.wi` = smithwalk's `wi` returns f(wi, wo) cos(theta_o), which is
  what a bin holds per unit solid angle;
- each bin's expected energy per photon is the integral of that over the bin,
  `∫_{cos_lo}^{cos_hi} ∫_{phi_lo}^{phi_hi} f cos(theta_o) dphi dcos(theta_o)`, here by an
  n x n Gauss-Legendre rule (evaluating at the bin centre times the solid angle is a biased
  shortcut for peaked lobes);
- rows are written for order 0 (all orders: shows the energy the BSDF loses) and order 1
  (single scattering: shows Mitsuba's separable G2 against the walk's height-correlated one).

Cases that Mitsuba's roughconductor cannot express (Schlick Fresnel, Beckmann is supported,
anisotropy is, other materials are not) are skipped, with a note on stderr. Conductors with
F = 1 use `material = "none"`; exact Fresnel uses the run's eta and k per channel.
"""
import argparse
import csv
import json
import math
import os
import sys

import numpy as np

try:
    import mitsuba as mi
except ImportError:
    sys.exit("Mitsuba 3 is not installed: pip install mitsuba==3.9.1")

mi.set_variant("scalar_rgb")


def mitsuba_bsdf(case):
    material = case["material"]
    if material.get("kind") != "conductor" or case["smith"] != "exact" or case["normals"] != "vndf":
        return None
    d = {"type": "roughconductor", "distribution": case["ndf"], "alpha_u": case["alpha_x"],
         "alpha_v": case["alpha_y"]}
    if material["fresnel"] == "none":
        d["material"] = "none"
    elif material["fresnel"] == "exact":
        rgb = lambda v: {"type": "rgb", "value": v if isinstance(v, list) else [v] * 3}  # noqa: E731
        d["eta"], d["k"] = rgb(material["eta"]), rgb(material["k"])
    else:
        return None
    return mi.load_dict(d)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--nodes", type=int, default=6, help="Gauss-Legendre nodes per bin and axis")
    args = ap.parse_args()
    with open(os.path.join(args.run_dir, "run.json")) as f:
        run = json.load(f)
    cases = {c["index"]: c for c in run["cases"]}
    detector = run["config"].get("detector", {})
    n_cos, n_phi = detector.get("cos_theta_bins", 32), detector.get("phi_bins", 64)
    rgb = any(isinstance(v, list) for m in (run["config"]["material"] if isinstance(run["config"]["material"], list)
                                            else [run["config"]["material"]]) for v in m.values())
    x, w = np.polynomial.legendre.leggauss(args.nodes)
    ctx = mi.BSDFContext()
    rows = []
    for index, case in sorted(cases.items()):
        bsdf = mitsuba_bsdf(case)
        if bsdf is None:
            print(f"case {index}: not a roughconductor ({case['material'].get('name') or case['material']}); skipped",
                  file=sys.stderr)
            continue
        theta_i, phi_i = math.radians(case["theta_i_deg"]), math.radians(case["phi_i_deg"])
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(math.sin(theta_i) * math.cos(phi_i), math.sin(theta_i) * math.sin(phi_i), math.cos(theta_i))
        for ic in range(n_cos):
            lo, hi = ic / n_cos, (ic + 1) / n_cos
            for ip in range(n_phi):
                plo, phi_hi = 360.0 * ip / n_phi, 360.0 * (ip + 1) / n_phi
                energy = np.zeros(3)
                for xu, wu in zip(x, w):
                    u = lo + (hi - lo) * (xu + 1) / 2
                    s = math.sqrt(max(0.0, 1 - u * u))
                    for xp, wp in zip(x, w):
                        p = math.radians(plo + (phi_hi - plo) * (xp + 1) / 2) + phi_i
                        value = bsdf.eval(ctx, si, mi.Vector3f(s * math.cos(p), s * math.sin(p), u))
                        weight = wu * wp * (hi - lo) / 2 * math.radians(phi_hi - plo) / 2
                        energy += weight * np.array([value[0], value[1], value[2]])
                for order in (0, 1):
                    for c, channel in enumerate(["r", "g", "b"] if rgb else [""]):
                        rows.append([index, order, "R", channel, lo, hi, plo, phi_hi, energy[c]])
        print(f"case {index}: alpha {case['alpha_x']}, theta_i {case['theta_i_deg']}: "
              f"Mitsuba albedo {sum(r[-1] for r in rows[-(2 * n_cos * n_phi * (3 if rgb else 1)):] if r[1] == 0 and r[3] in ('', 'r')):.4f}",
              file=sys.stderr)
    with open(args.out, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["case", "order", "hemisphere"] + (["channel"] if rgb else []) +
                     ["cos_lo", "cos_hi", "phi_lo_deg", "phi_hi_deg", "energy"])
        for r in rows:
            out.writerow(r[:3] + ([r[3]] if rgb else []) + [repr(v) for v in r[4:]])
    print(f"wrote {len(rows)} rows to {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
