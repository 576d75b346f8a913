"""Loads an RGL .bsdf file in Mitsuba 3's `measured` plugin (scalar_rgb) and answers tests/exports/rgl.rs.

Reads JSON from stdin: {"file": PATH, "eval": [[wix, wiy, wiz, wox, woy, woz], ...],
"albedo": [[theta_i_rad, n], ...]}. Writes JSON to stdout: {"eval": [[r, g, b], ...] (Mitsuba's
BSDF value times cos(theta_o)), "albedo": [[r, g, b], ...]}, each albedo the mean sample weight
of `bsdf.sample` over the centres of an n x n grid of the sample square (no random numbers).
Exits with 3 if Mitsuba 3 is not installed.
"""
import json
import math
import sys

try:
    import mitsuba as mi
except ImportError:
    sys.exit(3)

mi.set_variant("scalar_rgb")
query = json.load(sys.stdin)
bsdf = mi.load_dict({"type": "measured", "filename": query["file"]})
ctx = mi.BSDFContext()
si = mi.SurfaceInteraction3f()


def rgb(value):
    return [float(value[0]), float(value[1]), float(value[2])]


values = []
for wix, wiy, wiz, wox, woy, woz in query["eval"]:
    si.wi = mi.Vector3f(wix, wiy, wiz)
    values.append(rgb(bsdf.eval(ctx, si, mi.Vector3f(wox, woy, woz))))

albedos = []
for theta, n in query["albedo"]:
    si.wi = mi.Vector3f(math.sin(theta), 0.0, math.cos(theta))
    total = [0.0, 0.0, 0.0]
    for a in range(n):
        for b in range(n):
            _, weight = bsdf.sample(ctx, si, 0.5, mi.Point2f((a + 0.5) / n, (b + 0.5) / n))
            total = [t + w for t, w in zip(total, rgb(weight))]
    albedos.append([t / (n * n) for t in total])

json.dump({"eval": values, "albedo": albedos}, sys.stdout)
