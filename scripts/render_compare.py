"""Image-space comparison of multiple-scattering BSDFs in Mitsuba 3 (docs/rendering.md,
"Image-space comparison").

    python3 scripts/render_compare.py --out out/render-compare --spp 256 --resolution 256

Needs the smithwalk Python package, ``mitsuba==3.9.1`` (libLLVM 19 for ``llvm_ad_rgb``),
``matplotlib`` and ``flip-evaluator`` (NVIDIA FLIP). Nothing is downloaded.

One scene: four GGX conductor spheres (alpha 0.2, 0.5, 0.8, 1.0; gold, Mitsuba's ``"Au"``,
or ``--material none``, a lossless mirror) in a 2 x 2 grid under an environment map made
here with numpy (a sky gradient over a dark ground and four bright discs), rendered by
Mitsuba's path tracer with, in turn:

* ``reference``: ``smithwalk_conductor``, all orders (the Smith microsurface's random walk);
* ``reference-seed2``: the same with another sampler seed (its error is the noise floor);
* ``order-1``, ``order-2``, ``order-3+``: ``smithwalk_conductor`` keeping one order (or
  order 3 and above) alone;
* ``roughconductor``: Mitsuba's single-scattering ``roughconductor`` (GGX, visible normals);
* ``kulla-conty``: ``roughconductor`` plus Kulla & Conty 2017's compensation lobe
  ``f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))`` times
  ``F_avg^2 E_avg / (1 - F_avg (1 - E_avg))``, ``F_avg = 2 ∫ F(mu) mu dmu`` of the
  conductor's Fresnel, with ``E(mu, alpha)`` and ``E_avg(alpha)`` the order-1 rows (``R_1``) of
  a ``smithwalk lut`` table (``--lut``, default ``data/lut/ggx-conductor``, made with
  ``configs/lut-conductor.toml``), read bilinearly and clamped to its nodes as
  ``smithwalk compare --albedo-table`` reads it (docs/compensation.md).

Writes into ``--out``: ``<name>.exr`` (linear RGB) and ``<name>.png`` (sRGB of the linear
values clipped to [0, 1]) per image, ``compare.png`` (the images in a row; beneath, the
relative luminance difference from the reference and the FLIP error map), ``numbers.json``
and ``numbers.csv`` (per image: mean LDR FLIP and relative RMSE against the reference over
the pixels the spheres cover fully, per sphere the mean luminance relative to the reference,
and the render time), and prints the table.

FLIP is LDR-FLIP of the PNGs' sRGB values (flip_evaluator, default 67 pixels per degree).
relRMSE = sqrt(sum (x - r)^2 / sum r^2) over those pixels and the three channels, r the
reference. Both include the noise of both images: ``reference-seed2`` shows how much.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
ALPHAS = (0.2, 0.5, 0.8, 1.0)
# Samples per pixel per pass: an image is the mean of passes of at most this many, each with
# its own sampler seed, which bounds the wavefront (one pass of 256 x 256 x 192 held 7 GB).
PASS_SPP = 32
# Sphere centres (x, y) in the plane z = 0, radius 1, in the order of ALPHAS.
CENTRES = ((-1.15, 1.15), (1.15, 1.15), (-1.15, -1.15), (1.15, -1.15))
# Images: name -> what the figure calls it.
NAMES = {
    "reference": "reference (all orders)",
    "reference-seed2": "reference, seed 2",
    "order-1": "order 1 alone",
    "order-2": "order 2 alone",
    "order-3+": "orders 3+ alone",
    "roughconductor": "Mitsuba roughconductor",
    "kulla-conty": "Kulla-Conty (smithwalk lut)",
}


def arguments(argv=None):
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter
    )
    parser.add_argument("--out", type=Path, default=Path("out/render-compare"), help="output directory")
    parser.add_argument("--spp", type=int, default=256, help="samples per pixel (default 256)")
    parser.add_argument("--resolution", type=int, default=256, help="image width and height in pixels (default 256)")
    parser.add_argument(
        "--variant", default="llvm_ad_rgb", choices=["llvm_ad_rgb", "cuda_ad_rgb"], help="Mitsuba variant"
    )
    parser.add_argument("--material", default="Au", help='conductor of Mitsuba\'s table ("Au") or "none" (F = 1)')
    parser.add_argument(
        "--max-depth", type=int, default=8, help="path tracer's max_depth (2: one bounce off a sphere; default 8)"
    )
    parser.add_argument("--lut", type=Path, default=REPO / "data" / "lut" / "ggx-conductor", help="smithwalk lut dir")
    parser.add_argument("--seed", type=int, default=1, help="sampler seed (reference-seed2 uses seed + 1)")
    parser.add_argument("--images", default=",".join(NAMES), help="comma-separated subset of: " + ", ".join(NAMES))
    args = parser.parse_args(argv)
    if args.spp < 1 or args.resolution < 8 or args.max_depth < 2 and args.max_depth != -1:
        parser.error("--spp >= 1, --resolution >= 8 and --max-depth >= 2 (or -1) are required")
    args.images = [name.strip() for name in args.images.split(",")]
    unknown = [name for name in args.images if name not in NAMES]
    if unknown or "reference" not in args.images:
        parser.error(f"--images: unknown {unknown} (allowed: {', '.join(NAMES)}); reference is required")
    return args


# --- scene --------------------------------------------------------------------------------


def environment(width=512):
    """A lat-long environment (height width/2, Mitsuba's envmap layout: +y up, row 0 the
    zenith): a blue sky brightening to the horizon, a dark brown ground, four bright discs."""
    height = width // 2
    theta = (np.arange(height) + 0.5) / height * math.pi  # from +y
    phi = (np.arange(width) + 0.5) / width * 2 * math.pi
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    up = np.cos(theta)
    sky = np.clip(up, 0, 1)[..., None]
    image = np.where(
        up[..., None] > 0,
        (1 - sky) * np.array([0.9, 0.95, 1.0]) + sky * np.array([0.15, 0.3, 0.8]),
        np.array([0.12, 0.09, 0.06]) * (1 + up[..., None]),
    )
    direction = np.stack([np.sin(theta) * np.cos(phi), up, np.sin(theta) * np.sin(phi)], axis=-1)
    # (direction as theta from +y and phi in degrees, angular radius in degrees, RGB radiance)
    discs = [
        ((40, 20), 10, (30, 26, 18)),
        ((70, 110), 14, (4, 8, 16)),
        ((50, 200), 8, (40, 28, 22)),
        ((75, 290), 12, (10, 20, 12)),
    ]
    for (t, p), radius, radiance in discs:
        t, p = math.radians(t), math.radians(p)
        centre = np.array([math.sin(t) * math.cos(p), math.cos(t), math.sin(t) * math.sin(p)])
        inside = direction @ centre > math.cos(math.radians(radius))
        image[inside] = radiance
    return image.astype(np.float32)


def scene_dict(mi, bsdfs, args):
    """The scene with `bsdfs[i]` on the sphere of ALPHAS[i]."""
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": args.max_depth},
        "sky": {"type": "envmap", "bitmap": mi.Bitmap(environment()), "scale": 0.6},
        "sensor": {
            "type": "perspective",
            "fov": 34,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0.0, 9], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": args.resolution,
                "height": args.resolution,
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": "independent", "sample_count": min(args.spp, PASS_SPP)},
        },
    }
    for i, ((x, y), bsdf) in enumerate(zip(CENTRES, bsdfs)):
        scene[f"sphere{i}"] = {"type": "sphere", "center": [x, y, 0], "radius": 1.0, "bsdf": bsdf}
    return scene


def smithwalk_bsdfs(args, orders):
    return [
        {"type": "smithwalk_conductor", "distribution": "ggx", "alpha": a, "material": args.material, "orders": orders}
        for a in ALPHAS
    ]


def roughconductor_bsdfs(args):
    return [
        {"type": "roughconductor", "distribution": "ggx", "alpha": a, "material": args.material, "sample_visible": True}
        for a in ALPHAS
    ]


def coverage(mi, scene, res, sub=4):
    """Per pixel, the fraction of `sub` x `sub` points whose camera ray hits each sphere:
    shape (len(ALPHAS), res, res)."""
    sensor = scene.sensors()[0]
    offsets = (np.arange(sub) + 0.5) / sub
    col, row, dx, dy = np.meshgrid(np.arange(res), np.arange(res), offsets, offsets, indexing="ij")
    u = ((col + dx) / res).ravel().astype(np.float32)
    v = ((row + dy) / res).ravel().astype(np.float32)
    ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(u, v), mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    valid = np.asarray(si.is_valid())
    p = np.asarray(si.p).T if np.asarray(si.p).shape[0] == 3 else np.asarray(si.p)
    which = np.argmin([np.hypot(p[:, 0] - x, p[:, 1] - y) for x, y in CENTRES], axis=0)
    hits = np.zeros((len(ALPHAS), u.size))
    for k in range(len(ALPHAS)):
        hits[k] = valid & (which == k)
    # Axes (col, row, dx, dy) -> (sphere, row, col).
    return hits.reshape(len(ALPHAS), res, res, sub * sub).mean(axis=-1).transpose(0, 2, 1)


# --- Kulla-Conty ----------------------------------------------------------------------------


def read_lut(directory):
    """The table's `R_1` rows: (alpha nodes, mu nodes, E[alpha, mu], E_avg alpha nodes, E_avg),
    the quantity `smithwalk compare --albedo-table` reads."""

    def rows(path, columns):
        with open(path, newline="") as f:
            table = [r for r in csv.DictReader(f) if r.get("quantity", "R_1") == "R_1"]
        if not table:
            sys.exit(f"{path}: no rows of quantity R_1 (a `smithwalk lut` table of the F = 1 conductor)")
        return np.array([[float(r[c]) for c in columns] for r in table])

    e_rows = rows(directory / "lut.csv", ["alpha", "mu", "E"])
    alpha, mu = np.unique(e_rows[:, 0]), np.unique(e_rows[:, 1])
    e = np.full((alpha.size, mu.size), np.nan)
    e[np.searchsorted(alpha, e_rows[:, 0]), np.searchsorted(mu, e_rows[:, 1])] = e_rows[:, 2]
    if np.isnan(e).any():
        sys.exit(f"{directory / 'lut.csv'}: E is not given at every (alpha, mu) node")
    avg = rows(directory / "lut_avg.csv", ["alpha", "E_avg"])
    avg = avg[np.argsort(avg[:, 0])]
    return alpha, mu, e, avg[:, 0], avg[:, 1]


def conductor_fresnel(eta, k, c):
    """Unpolarised reflectance of a conductor of complex index eta + i k at cosine `c`
    (the formula of crates/microsurface/src/fresnel.rs)."""
    c2 = c * c
    s2 = 1 - c2
    t0 = eta * eta - k * k - s2
    a2b2 = np.sqrt(t0 * t0 + 4 * eta * eta * k * k)
    a = np.sqrt(np.maximum(0.5 * (a2b2 + t0), 0))
    rs = (a2b2 - 2 * a * c + c2) / (a2b2 + 2 * a * c + c2)
    t1 = c2 * a2b2 + s2 * s2
    t2 = 2 * a * c * s2
    return 0.5 * (rs + rs * (t1 - t2) / (t1 + t2))


def fresnel_average(eta, k):
    """F_avg = 2 ∫_0^1 F(mu) mu dmu per channel, Gauss-Legendre with 64 nodes."""
    x, w = np.polynomial.legendre.leggauss(64)
    mu = 0.5 * (x + 1)
    return np.array([np.sum(0.5 * w * 2 * conductor_fresnel(e, kk, mu) * mu) for e, kk in zip(eta, k)])


def register_kulla_conty(mi, dr, table):
    """Registers `kulla_conty_conductor`: Mitsuba's `roughconductor` (GGX, `alpha`, `material`)
    plus Kulla & Conty's compensation lobe from `table` (read_lut's tuple), the model of
    src/analysis/compensation.rs with `--albedo-table`: E(mu) bilinear in (alpha, mu),
    E_avg linear in alpha, both clamped to the nodes; F_avg of Mitsuba's RGB eta, k."""
    alpha_nodes, mu_nodes, e_grid, avg_alpha, avg_e = table

    def floats(a):
        a = np.asarray(a, dtype=np.float32)
        return mi.Float(a) if dr.is_jit_v(mi.Float) else mi.Float(float(a.reshape(-1)[0]))

    class KullaConty(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            alpha = props.get("alpha", 0.1)
            material = props.get("material", "none")
            self.inner = mi.load_dict(
                {"type": "roughconductor", "distribution": "ggx", "alpha": alpha, "material": material}
            )
            # Bilinear = linear in alpha per mu node, then linear in mu (np.interp clamps).
            self.e_row = np.array([np.interp(alpha, alpha_nodes, e_grid[:, j]) for j in range(mu_nodes.size)])
            e_avg = float(np.interp(alpha, avg_alpha, avg_e))
            if material == "none":
                f_avg = np.ones(3)
            else:
                params = mi.traverse(self.inner)
                eta = np.asarray(params["eta.value"], dtype=np.float64).reshape(-1)[:3]
                k = np.asarray(params["k.value"], dtype=np.float64).reshape(-1)[:3]
                f_avg = fresnel_average(eta, k)
            lost = 1 - e_avg
            self.scale = (f_avg**2 * e_avg / (1 - f_avg * lost)) / (math.pi * lost) if lost > 0 else np.zeros(3)
            self.e_avg, self.f_avg = e_avg, f_avg
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_components = [flags]
            self.m_flags = flags

        def e(self, mu):
            return floats(np.interp(np.asarray(mu, dtype=np.float64), mu_nodes, self.e_row))

        def lobe(self, si, wo, active):
            """f_ms times the Fresnel factor times cos(theta_o), and the ms sampling weight."""
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            on = active & (cos_i > 0) & (cos_o > 0)
            e_i, e_o = self.e(dr.maximum(cos_i, 0)), self.e(dr.maximum(cos_o, 0))
            value = mi.Color3f(*(float(s) for s in self.scale)) * (1 - e_i) * (1 - e_o) * cos_o
            return dr.select(on, value, 0.0), e_i

        def eval_pdf(self, ctx, si, wo, active=True):
            ss, ss_pdf = self.inner.eval_pdf(ctx, si, wo, active)
            ms, e_i = self.lobe(si, wo, active)
            p = dr.clip(e_i, 0.1, 0.9)  # probability of sampling the single-scattering lobe
            cos_o = mi.Frame3f.cos_theta(wo)
            pdf = p * ss_pdf + (1 - p) * dr.maximum(cos_o, 0) / math.pi
            return ss + ms, dr.select(active & (cos_o > 0), pdf, 0.0)

        def eval(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[0]

        def pdf(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[1]

        def sample(self, ctx, si, sample1, sample2, active=True):
            bs, _ = self.inner.sample(ctx, si, sample1, sample2, active)
            p = dr.clip(self.e(dr.maximum(mi.Frame3f.cos_theta(si.wi), 0)), 0.1, 0.9)
            # sample1 chooses the lobe; sample2 drives the chosen one (roughconductor has one
            # component and does not read sample1).
            cosine = mi.warp.square_to_cosine_hemisphere(sample2)
            bs.wo = dr.select(sample1 < p, bs.wo, cosine)
            value, pdf = self.eval_pdf(ctx, si, bs.wo, active)
            ok = active & (pdf > 0)
            bs.pdf = dr.select(ok, pdf, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            return bs, dr.select(ok, value / dr.select(ok, pdf, 1.0), 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"KullaConty[E_avg={self.e_avg:.5f}, F_avg={self.f_avg}]"

    mi.register_bsdf("kulla_conty_conductor", lambda props: KullaConty(props))


# --- images and numbers -----------------------------------------------------------------------


def srgb(linear):
    """sRGB encoding of linear values clipped to [0, 1] (what the PNGs hold)."""
    x = np.clip(linear, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def luminance(image):
    return image @ np.array([0.2126, 0.7152, 0.0722])


def numbers(image, reference, masks, flip):
    """FLIP (mean over the sphere pixels), relRMSE, and per sphere the mean luminance over
    the reference's, with its error map."""
    inside = masks.any(axis=0)
    error_map, _, _ = flip.evaluate(srgb(reference), srgb(image), "LDR", applyMagma=False)
    error_map = np.asarray(error_map).reshape(image.shape[:2])
    d = (image - reference)[inside]
    rel_rmse = math.sqrt(np.sum(d * d) / np.sum(reference[inside] ** 2))
    ratio = [float(luminance(image)[m].mean() / luminance(reference)[m].mean()) for m in masks]
    return {"flip": float(error_map[inside].mean()), "rel_rmse": rel_rmse, "luminance_ratio": ratio}, error_map


def figure(out, images, errors, results, covered, args):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(images)
    n = len(names)
    shown = None
    fig, axes = plt.subplots(3, n, figsize=(2.0 * n, 6.6), squeeze=False)
    reference = luminance(images["reference"])
    for j, name in enumerate(names):
        axes[0, j].imshow(srgb(images[name]))
        r = results[name]
        axes[0, j].set_title(NAMES[name] + (f"\n{r['seconds']:.0f} s" if "seconds" in r else ""), fontsize=7)
        if name == "reference":
            axes[1, j].text(0.5, 0.5, "relative luminance\ndifference\n(blue: darker)", ha="center", va="center")
            axes[2, j].text(0.5, 0.5, "LDR-FLIP\nerror map", ha="center", va="center")
        else:
            rel = (luminance(images[name]) - reference) / np.maximum(reference, 1e-3)
            rel = np.where(covered, rel, np.nan)  # the background is the same environment
            shown = axes[1, j].imshow(rel, cmap="RdBu_r", vmin=-1, vmax=1)
            axes[1, j].set_title(f"relRMSE {r['rel_rmse']:.3f}", fontsize=7)
            axes[2, j].imshow(errors[name], cmap="magma", vmin=0, vmax=1)
            axes[2, j].set_title(f"FLIP {r['flip']:.3f}", fontsize=7)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes[1:, 0]:
        ax.axis("off")
    if shown is not None:
        fig.colorbar(shown, ax=axes[1, :], fraction=0.01, pad=0.01)
    material = "gold" if args.material == "Au" else args.material
    fig.suptitle(
        f"GGX {material}, alpha {', '.join(map(str, ALPHAS))} (left to right, top to bottom); "
        f"{args.resolution}x{args.resolution}, {args.spp} spp, max_depth {args.max_depth}",
        fontsize=8,
    )
    fig.savefig(out / "compare.png", dpi=110, bbox_inches="tight")
    plt.close(fig)


def render(mi, scene, spp, seed):
    """The mean of passes of at most PASS_SPP samples per pixel (weighted by their counts);
    pass p of image seed s has sampler seed s * 2^20 + p."""
    total, done, p = 0.0, 0, 0
    while done < spp:
        count = min(PASS_SPP, spp - done)
        image = np.array(mi.render(scene, seed=seed * 2**20 + p, spp=count), dtype=np.float64)[..., :3]
        total, done, p = total + count * image, done + count, p + 1
    return total / spp


def main(argv=None):
    args = arguments(argv)
    for llvm in ("/usr/lib/llvm-19/lib/libLLVM.so.1", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"):
        if Path(llvm).exists():
            os.environ.setdefault("DRJIT_LIBLLVM_PATH", llvm)
            break
    import drjit as dr
    import flip_evaluator as flip
    import mitsuba as mi

    mi.set_variant(args.variant)
    import smithwalk.mitsuba

    smithwalk.mitsuba.register()
    register_kulla_conty(mi, dr, read_lut(args.lut))
    args.out.mkdir(parents=True, exist_ok=True)

    bsdfs = {
        "reference": smithwalk_bsdfs(args, "all"),
        "reference-seed2": smithwalk_bsdfs(args, "all"),
        "order-1": smithwalk_bsdfs(args, "1"),
        "order-2": smithwalk_bsdfs(args, "2"),
        "order-3+": smithwalk_bsdfs(args, "3+"),
        "roughconductor": roughconductor_bsdfs(args),
        "kulla-conty": [{"type": "kulla_conty_conductor", "alpha": a, "material": args.material} for a in ALPHAS],
    }
    images, results = {}, {}
    for name in [n for n in NAMES if n in args.images]:
        scene = mi.load_dict(scene_dict(mi, bsdfs[name], args))
        seed = args.seed + 1 if name == "reference-seed2" else args.seed
        start = time.perf_counter()
        image = render(mi, scene, args.spp, seed)
        seconds = time.perf_counter() - start
        if not np.isfinite(image).all():
            sys.exit(f"{name}: the render has {np.sum(~np.isfinite(image))} values that are not finite")
        mi.Bitmap(image.astype(np.float32)).write(str(args.out / f"{name}.exr"))
        png = (np.round(srgb(image) * 255)).astype(np.uint8)
        mi.Bitmap(png, mi.Bitmap.PixelFormat.RGB).write(str(args.out / f"{name}.png"))
        images[name], results[name] = image, {"seconds": seconds}
        print(f"{name}: {seconds:.1f} s", flush=True)
        if name == "reference":
            cover = coverage(mi, scene, args.resolution)
            masks, covered = cover >= 1.0, cover.sum(axis=0) > 0
            np.save(args.out / "masks.npy", masks)

    errors = {}
    for name, image in images.items():
        if name != "reference":
            extra, errors[name] = numbers(image, images["reference"], masks, flip)
            results[name].update(extra)
    figure(args.out, images, errors, results, covered, args)

    record = {
        "command": "python3 scripts/render_compare.py " + " ".join(sys.argv[1:] if argv is None else argv),
        "resolution": args.resolution,
        "spp": args.spp,
        "variant": args.variant,
        "material": args.material,
        "max_depth": args.max_depth,
        "alphas": ALPHAS,
        "lut": str(args.lut),
        "sphere_pixels": [int(m.sum()) for m in masks],
        "flip": "LDR-FLIP (flip_evaluator) of the sRGB PNG values, mean over the sphere pixels",
        "rel_rmse": "sqrt(sum (x - r)^2 / sum r^2) over the sphere pixels and RGB",
        "images": results,
    }
    (args.out / "numbers.json").write_text(json.dumps(record, indent=2) + "\n")
    ratio_columns = [f"luminance_ratio_alpha{a}" for a in ALPHAS]
    with open(args.out / "numbers.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["image", "flip", "rel_rmse", *ratio_columns, "seconds"])
        for name, r in results.items():
            ratios = r.get("luminance_ratio", [1.0] * len(ALPHAS))
            writer.writerow([name, r.get("flip", 0.0), r.get("rel_rmse", 0.0), *ratios, r["seconds"]])

    alpha_header = " ".join(f"{'a=' + str(a):>7}" for a in ALPHAS)
    print(f"\n{'image':<16} {'FLIP':>7} {'relRMSE':>8}  luminance / reference: {alpha_header}  {'time':>7}")
    for name, r in results.items():
        ratios = " ".join(f"{x:7.3f}" for x in r.get("luminance_ratio", [1.0] * len(ALPHAS)))
        flip_text = f"{r['flip']:7.4f} {r['rel_rmse']:8.4f}" if "flip" in r else f"{'-':>7} {'-':>8}"
        print(f"{name:<16} {flip_text}  {'':>22} {ratios}  {r['seconds']:6.1f}s")
    print(f"\n{args.resolution}x{args.resolution}, {args.spp} spp; wrote {args.out}/")


if __name__ == "__main__":
    main()
