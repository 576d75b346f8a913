#!/usr/bin/env python3
"""A worked example of `smithwalk compare RUN_DIR --external FILE.csv`: Mitsuba 3's
`roughconductor` (GGX, visible-normal sampling; a single-scattering BSDF) estimated in every
bin of a smithwalk run by its own importance sampling, written as an external model file with
standard errors.

    pip install mitsuba==3.9.1
    smithwalk run configs/compensation.toml --out out/compensation
    python3 scripts/external_mitsuba.py out/compensation --out out/mitsuba.csv
    smithwalk compare out/compensation --models single --external out/mitsuba.csv

How the file is made (do the same with your renderer's BSDF):
- the run's bins come from its run.json (detector bins, cases);
- smithwalk's `wi` points towards the light and `wo` towards the detector, both away from the
  surface, with the light at azimuth phi_i and bin azimuths counted from phi_i; Mitsuba's
  `sample(ctx, si, ...)` with `si.wi` = smithwalk's `wi` returns a direction `wo` and the weight
  `f(wi, wo) cos(theta_o) / pdf(wo)`;
- a bin's expected energy per photon, `∫_bin f cos(theta_o) dwo`, is the mean over the samples
  of the weight where `wo` falls in the bin (zero elsewhere), and its standard error comes from
  the weights' second moment: the file then has `energy_stderr`, and compare judges it as a
  Monte Carlo model. (A deterministic alternative is a quadrature of `eval` over each bin; in
  Mitsuba's scalar variant that costs about 0.2 ms per call, too slow for peaked lobes, and its
  vectorised LLVM variant failed with this host's LLVM 15.)
- rows are written for order 0 (all orders: shows the energy the BSDF loses) and order 1
  (single scattering: shows Mitsuba's masking-shadowing against the height-correlated one of
  the walk).

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
    ap.add_argument("--samples", type=int, default=20000, help="BSDF samples per case")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    with open(os.path.join(args.run_dir, "run.json")) as f:
        run = json.load(f)
    cases = {c["index"]: c for c in run["cases"]}
    detector = run["config"].get("detector", {})
    n_cos, n_phi = detector.get("cos_theta_bins", 32), detector.get("phi_bins", 64)
    materials = run["config"]["material"]
    materials = materials if isinstance(materials, list) else [materials]
    rgb = any(isinstance(v, list) for m in materials for v in m.values())
    channels = ["r", "g", "b"] if rgb else [""]
    rng = np.random.default_rng(args.seed)
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
        # Per bin: the sum and the sum of squares of the sample weights f cos / pdf.
        total = np.zeros((3, n_cos * n_phi))
        squares = np.zeros((3, n_cos * n_phi))
        for u in rng.random((args.samples, 3)):
            bs, weight = bsdf.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
            wo = bs.wo
            if not (bs.pdf > 0 and wo[2] > 0):
                continue
            ic = min(int(wo[2] * n_cos), n_cos - 1)
            phi = (math.atan2(wo[1], wo[0]) - phi_i) % (2 * math.pi)
            ip = min(int(phi / (2 * math.pi) * n_phi), n_phi - 1)
            value = np.array([weight[0], weight[1], weight[2]])
            total[:, ic * n_phi + ip] += value
            squares[:, ic * n_phi + ip] += value * value
        n = args.samples
        energy = total / n
        stderr = np.sqrt(np.maximum(0.0, squares / n - energy * energy) / (n - 1))
        for order in (0, 1):
            for c, channel in enumerate(channels):
                for i in range(n_cos):
                    for j in range(n_phi):
                        b = i * n_phi + j
                        rows.append([index, order, "R", channel, i / n_cos, (i + 1) / n_cos, 360.0 * j / n_phi,
                                     360.0 * (j + 1) / n_phi, energy[c, b], stderr[c, b]])
        albedo = energy[0].sum()
        se = math.sqrt(max(0.0, squares[0].sum() / n - albedo * albedo) / (n - 1))
        print(f"case {index}: alpha {case['alpha_x']}, theta_i {case['theta_i_deg']}: "
              f"Mitsuba albedo {albedo:.5f} +- {se:.5f}", file=sys.stderr)
    with open(args.out, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["case", "order", "hemisphere"] + (["channel"] if rgb else []) +
                     ["cos_lo", "cos_hi", "phi_lo_deg", "phi_hi_deg", "energy", "energy_stderr"])
        for r in rows:
            out.writerow(r[:3] + ([r[3]] if rgb else []) + [repr(float(v)) for v in r[4:]])
    print(f"wrote {len(rows)} rows to {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
