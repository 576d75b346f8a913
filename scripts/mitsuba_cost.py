"""Cost per lane of the smithwalk Mitsuba plugins (docs/rendering.md, "Mitsuba 3").

    python3 scripts/mitsuba_cost.py            # needs mitsuba and the smithwalk package

For scalar_rgb and llvm_ad_rgb: Mitsuba's bsdf.sample and bsdf.eval of `smithwalk_conductor`
(GGX alpha 0.5, material "Au") called through Mitsuba's interface, and for reference the same
batched call of smithwalk.bsdf without Mitsuba; the best of 3 repetitions, in microseconds per
lane. Also the time of a furnace render (a sphere filling a 64 x 64 frame, 16 spp) and the
number of plugin calls it made.
"""

import math
import time

import numpy as np

import drjit as dr
import mitsuba as mi

from smithwalk import bsdf as native

PROPS = {"type": "smithwalk_conductor", "distribution": "ggx", "alpha": 0.5, "material": "Au"}


def best(f, repeat=3):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def lanes(n):
    rng = np.random.default_rng(1)
    t = math.radians(45.0)
    wi = np.tile([math.sin(t), 0.0, math.cos(t)], (n, 1))
    wo = rng.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    return wi, wo, rng.uniform(size=(n, 3))


def measure(variant, n):
    mi.set_variant(variant)
    import smithwalk.mitsuba

    smithwalk.mitsuba.register()
    bsdf = mi.load_dict(PROPS)
    ctx = mi.BSDFContext()
    wi, wo, u = lanes(n)
    jit = variant.startswith("llvm")
    if jit:
        si = dr.zeros(mi.SurfaceInteraction3f, n)
        si.wi = mi.Vector3f(*(wi[:, j].astype(np.float32) for j in range(3)))
        v = mi.Vector3f(*(wo[:, j].astype(np.float32) for j in range(3)))
        s1, s2 = mi.Float(u[:, 0]), mi.Point2f(u[:, 1], u[:, 2])

        def sample():
            dr.eval(bsdf.sample(ctx, si, s1, s2))

        def evaluate():
            dr.eval(bsdf.eval(ctx, si, v))

    else:
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wi = mi.Vector3f(*wi[0])
        points = [(float(a), mi.Point2f(float(b), float(c))) for a, b, c in u]
        directions = [mi.Vector3f(*x) for x in wo]

        def sample():
            for a, b in points:
                bsdf.sample(ctx, si, a, b)

        def evaluate():
            for d in directions:
                bsdf.eval(ctx, si, d)

    surface = dict(material="conductor", ndf="ggx", alpha=0.5, fresnel="exact", eta=[0.2, 0.5, 1.4], k=[3.6, 2.4, 1.8])
    print(
        f"{variant:12s} lanes {n:7d}: sample {best(sample) / n * 1e6:8.2f} us, eval {best(evaluate) / n * 1e6:8.2f} us per lane; "
        f"smithwalk.bsdf alone: sample {best(lambda: native.sample(wi, u=u, **surface)) / n * 1e6:.2f} us, "
        f"eval {best(lambda: native.eval(wi, wo, **surface)) / n * 1e6:.2f} us"
    )
    res, spp = 64, 16
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": -1},
            "emitter": {"type": "constant"},
            "sensor": {
                "type": "orthographic",
                "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": spp},
            },
            "sphere": {"type": "sphere", "bsdf": PROPS},
        }
    )
    seconds = best(lambda: mi.render(scene), repeat=1 if not jit else 2)
    calls, originals = [], {name: getattr(native, name) for name in ("sample", "eval", "pdf")}
    for name, original in originals.items():

        def counted(*args, _original=original, _name=name, **kwargs):
            calls.append(_name)
            return _original(*args, **kwargs)

        setattr(native, name, counted)
    mi.render(scene)
    for name, original in originals.items():
        setattr(native, name, original)
    print(f"{variant:12s} furnace render {res}x{res}, {spp} spp: {seconds:.2f} s, {len(calls)} smithwalk.bsdf calls")

if __name__ == "__main__":
    measure("scalar_rgb", 2000)
    measure("llvm_ad_rgb", 200_000)
