"""The multiple-scattering BSDF of a Smith microsurface (theory §13) as Mitsuba 3 plugins.

After ``mi.set_variant(...)``, ``import smithwalk.mitsuba`` registers three BSDFs that scene
dictionaries and XML files can name:

* ``smithwalk_conductor``: ``distribution`` (``"beckmann"``, Mitsuba's default, ``"ggx"``, or
  ``"student-t"`` with its shape ``gamma``, a number > 1.5),
  ``alpha`` or ``alpha_u``/``alpha_v`` (value or texture, default 0.1), ``material`` (a
  conductor of Mitsuba's table, e.g. ``"Au"``; ``"none"``, the default, is a perfect mirror,
  F = 1) or ``eta`` and ``k`` (values or textures);
* ``smithwalk_dielectric``: ``distribution``, ``alpha``/``alpha_u``/``alpha_v``, ``int_ior``
  and ``ext_ior`` (a number or a name of Mitsuba's table; defaults ``"bk7"`` and ``"air"``);
* ``smithwalk_diffuse``: Lambertian facets, ``reflectance`` (value or texture, default 0.5),
  ``distribution``, ``alpha``/``alpha_u``/``alpha_v``;

and for all three ``orders``: the scattering orders kept, ``"all"`` (default), ``"k"`` or
``"k+"`` (order k and above), or a comma-separated union such as ``"1,3+"``; and ``seed``, an
integer in [0, 2^63) mixed into every stream. Parameters are Mitsuba's where Mitsuba has them,
with Mitsuba's defaults.

Each call of Mitsuba's BSDF interface is one batched call of :mod:`smithwalk.bsdf` over all the
lanes Mitsuba passes (a whole wavefront in the JIT variants, one lane in the scalar ones).
Random numbers: ``sample(ctx, si, sample1, sample2, active)`` walks from the stream
``stream(seed, [sample1, sample2.x, sample2.y])``; ``eval``, which gets no random numbers, from
``stream(seed, [wi, wo])`` (the six direction components): both are deterministic functions
of their arguments, so a render is repeatable. ``pdf`` is the deterministic MIS density of
§13.4, also put in ``BSDFSample3f.pdf``.

JIT variants need Dr.Jit's ``SymbolicLoops`` and ``SymbolicCalls`` flags off (a Python
callback must see evaluated arrays): :func:`register` turns them off.
"""

from __future__ import annotations

import numpy as np

import drjit as dr
import mitsuba as mi

from . import bsdf as _bsdf

__all__ = ["register", "parse_orders"]


def parse_orders(text):
    """The ``orders`` property (``"all"``, ``"2"``, ``"3+"``, ``"1,3+"``) as
    :mod:`smithwalk.bsdf`'s ``orders`` argument; raises ``ValueError`` naming the value."""
    text = str(text).strip()
    if text == "all":
        return None
    items = []
    for item in text.split(","):
        item = item.strip()
        if item.isdigit():
            items.append(int(item))
        elif item.endswith("+") and item[:-1].isdigit():
            items.append(item)
        else:
            raise ValueError(
                f"`orders` = {text!r} is not allowed: \"all\", an order \"k\", \"k+\" (k and above) "
                "or a comma-separated list of them"
            )
    _bsdf._orders(items)  # checks the range of each order
    return items


def _distribution(props):
    """The NDF's keywords of smithwalk.bsdf: ``ndf`` and, for Student-T, ``gamma``."""
    name = props.get("distribution", "beckmann")
    if name not in ("beckmann", "ggx", "student-t"):
        raise ValueError(f"`distribution` = {name!r} is not allowed: \"beckmann\", \"ggx\" or \"student-t\"")
    if name != "student-t":
        if "gamma" in props:
            raise ValueError(f"`gamma` is not allowed with distribution = {name!r}: only \"student-t\" has a shape")
        return {"ndf": name}
    if "gamma" not in props:
        raise ValueError("`gamma` is missing: distribution = \"student-t\" needs its shape, a number > 1.5")
    return {"ndf": name, "gamma": float(props["gamma"])}


def _roughness(props):
    """The textures of (alpha_u, alpha_v), as Mitsuba's rough BSDFs read them."""
    has_u, has_v = "alpha_u" in props, "alpha_v" in props
    if "alpha" in props and (has_u or has_v):
        raise ValueError("`alpha` with `alpha_u`/`alpha_v` is not allowed: give one or the other")
    if has_u != has_v:
        raise ValueError("`alpha_u` without `alpha_v` (or the reverse) is not allowed: give both")
    names = ("alpha_u", "alpha_v") if has_u else ("alpha", "alpha")
    textures = tuple(props.get_unbounded_texture(name, 0.1) for name in names)
    for name, texture in zip(names, textures):
        # A constant is checked now; a varying texture lane by lane, by smithwalk.bsdf.
        value = float(np.asarray(texture.mean(), dtype=np.float64).reshape(-1)[0])
        if not texture.is_spatially_varying() and not value > 0:
            raise ValueError(f"`{name}` = {value} is not allowed: a number > 0")
    return textures if has_u else (textures[0], textures[0])


def _seed(props):
    seed = props.get("seed", 0)
    if not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise ValueError(f"`seed` = {seed!r} is not allowed: an integer in [0, 2^63)")
    return seed


def _columns(value, n=None):
    """A Dr.Jit value as numpy (n, k): lanes along the rows (a JIT array of width n, or one
    scalar lane broadcast to n rows), components (vector, colour) along the columns."""
    a = np.asarray(value, dtype=np.float64)
    if dr.is_jit_v(value):
        a = a.reshape(-1, 1) if a.ndim == 1 else a.T
    else:
        a = a.reshape(1, -1)
    return np.ascontiguousarray(a if n is None else np.broadcast_to(a, (n, a.shape[1])))


def _unit(value):
    """Mitsuba's float32 directions as float64 unit vectors (n, 3): the walk assumes unit
    length, and float32 rounding alone would break reciprocity near total internal reflection."""
    a = _columns(value)
    length = np.linalg.norm(a, axis=1)[:, None]
    return a / np.where(length > 0, length, 1.0)


def _vector(cls, a):
    """numpy (n, 3) as a Mitsuba vector or colour of the variant (one lane when scalar)."""
    if dr.is_jit_v(cls):
        return cls(*(np.ascontiguousarray(a[:, j], dtype=np.float32) for j in range(3)))
    return cls(*(float(x) for x in a[0]))


def _lanes(cls, a):
    """numpy (n,) as a Mitsuba Float/UInt32 of the variant."""
    if dr.is_jit_v(cls):
        return cls(np.ascontiguousarray(a))
    return cls(a[0].item())


def register():
    """Defines the three BSDF classes for the current Mitsuba variant and registers them
    (Mitsuba needs a Python BSDF class defined after ``mi.set_variant``); in the JIT variants
    turns Dr.Jit's ``SymbolicLoops`` and ``SymbolicCalls`` off. Call again after switching
    variants."""
    variant = mi.variant()
    if variant is None:
        raise ImportError("smithwalk.mitsuba: call mi.set_variant(...) before importing it")
    if not variant.endswith("rgb"):
        raise ImportError(
            f"smithwalk.mitsuba: variant {variant!r} is not supported: scalar_rgb or llvm_ad_rgb/cuda_ad_rgb"
        )
    if variant.startswith(("llvm", "cuda")):
        dr.set_flag(dr.JitFlag.SymbolicLoops, False)
        dr.set_flag(dr.JitFlag.SymbolicCalls, False)

    class SmithwalkBSDF(mi.BSDF):
        """Shared plumbing: Mitsuba's arrays in, one batched smithwalk call, Mitsuba's out."""

        material = None  # smithwalk.bsdf's `material`
        transmits = False

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.distribution = _distribution(props)
            self.alpha_u, self.alpha_v = _roughness(props)
            self.orders = parse_orders(props.get("orders", "all"))
            self.seed = _seed(props)
            props.get("sample_visible", True)  # Mitsuba's option; the walk always samples exactly
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            if self.transmits:
                flags |= mi.BSDFFlags.GlossyTransmission | mi.BSDFFlags.BackSide | mi.BSDFFlags.NonSymmetric
            self.m_components = [flags]
            self.m_flags = flags

        def surface(self, si, active, on):
            """smithwalk.bsdf's surface keywords at the lanes of `si`. Lanes that are not
            active (`on` False) get valid placeholders, as textures may return anything
            there; active lanes pass as they are, so smithwalk.bsdf refuses bad values."""
            n = len(on)

            def lanes(texture, placeholder):
                values = _columns(texture.eval_1(si, active), n)[:, 0]
                return np.where(on, values, placeholder)

            alpha_u = lanes(self.alpha_u, 1.0)
            alpha_v = alpha_u if self.alpha_v is self.alpha_u else lanes(self.alpha_v, 1.0)
            keywords = dict(material=self.material, orders=self.orders, alpha_u=alpha_u, alpha_v=alpha_v)
            keywords.update(self.distribution)
            keywords.update(self.material_keywords(si, active, on))
            return keywords

        def material_keywords(self, si, active, on):
            return {}

        @staticmethod
        def transport(ctx):
            return "radiance" if ctx.mode == mi.TransportMode.Radiance else "importance"

        def sample(self, ctx, si, sample1, sample2, active=True):
            wi = _unit(si.wi)
            n = len(wi)
            u = np.concatenate([_columns(sample1, n), _columns(sample2, n)], axis=1)
            on = _columns(active, n)[:, 0] > 0
            surface = self.surface(si, active, on)
            wo, weight, _ = _bsdf.sample(wi, u=u, seed=self.seed, transport=self.transport(ctx), **surface)
            pdf = _bsdf.pdf(wi, wo, **surface)
            weight[~on] = 0.0
            crossed = wo[:, 2] * wi[:, 2] < 0
            eta = np.ones(n)
            if self.transmits:
                relative = surface["eta"]
                eta = np.where(crossed, np.where(wi[:, 2] > 0, relative, 1.0 / relative), 1.0)
            reflection, transmission = int(mi.BSDFFlags.GlossyReflection), int(mi.BSDFFlags.GlossyTransmission)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = _vector(mi.Vector3f, wo)
            bs.pdf = _lanes(mi.Float, np.where(on, pdf, 0.0).astype(np.float32))
            bs.eta = _lanes(mi.Float, eta.astype(np.float32))
            bs.sampled_type = _lanes(mi.UInt32, np.where(crossed, transmission, reflection).astype(np.uint32))
            bs.sampled_component = _lanes(mi.UInt32, np.zeros(n, dtype=np.uint32))
            return bs, _vector(mi.Color3f, weight)

        def eval(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[0]

        def pdf(self, ctx, si, wo, active=True):
            wi, wo = _unit(si.wi), _unit(wo)
            n = len(wi)
            on = _columns(active, n)[:, 0] > 0
            pdf = _bsdf.pdf(wi, wo, **self.surface(si, active, on))
            return _lanes(mi.Float, np.where(on, pdf, 0.0).astype(np.float32))

        def eval_pdf(self, ctx, si, wo, active=True):
            wi, wo = _unit(si.wi), _unit(wo)
            n = len(wi)
            on = _columns(active, n)[:, 0] > 0
            surface = self.surface(si, active, on)
            value = _bsdf.eval(wi, wo, seed=self.seed, transport=self.transport(ctx), **surface)
            pdf = _bsdf.pdf(wi, wo, **surface)
            value[~on] = 0.0
            return _vector(mi.Color3f, value), _lanes(mi.Float, np.where(on, pdf, 0.0).astype(np.float32))

        def traverse(self, callback):
            pass

        def to_string(self):
            ndf = ", ".join(f"{k}={v}" for k, v in self.distribution.items())
            return f"{type(self).__name__}[{ndf}, orders={self.orders}, seed={self.seed}]"

        def parameters_changed(self, keys):
            pass

    class Conductor(SmithwalkBSDF):
        material = "conductor"

        def __init__(self, props):
            SmithwalkBSDF.__init__(self, props)
            name = props.get("material", "none")
            if "eta" in props or "k" in props:
                if name != "none":
                    raise ValueError(f"`material` = {name!r} with `eta`/`k` is not allowed: give one or the other")
                if "eta" not in props:
                    # Mitsuba's default eta is 0 (with k, a complex index); the walk's exact
                    # Fresnel needs eta > 0.
                    raise ValueError("`k` without `eta` is not allowed: give `eta` (> 0) too")
                self.eta = props.get_unbounded_texture("eta")
                self.k = props.get_unbounded_texture("k", 1.0)
                self.fresnel = "exact"
            elif name == "none":
                self.fresnel = "none"
            else:
                # Mitsuba's own table of measured conductors, converted by Mitsuba to the variant.
                table = mi.traverse(mi.load_dict({"type": "conductor", "material": name}))
                self.eta_rgb = np.asarray(table["eta.value"], dtype=np.float64).reshape(-1)[:3]
                self.k_rgb = np.asarray(table["k.value"], dtype=np.float64).reshape(-1)[:3]
                self.fresnel = "table"

        def material_keywords(self, si, active, on):
            if self.fresnel == "none":
                return dict(fresnel="none")
            if self.fresnel == "table":
                return dict(fresnel="exact", eta=self.eta_rgb, k=self.k_rgb)
            n, mask = len(on), on[:, None]
            eta = np.where(mask, _columns(self.eta.eval(si, active), n), 1.0)
            k = np.where(mask, _columns(self.k.eval(si, active), n), 0.0)
            return dict(fresnel="exact", eta=eta, k=k)

    class Dielectric(SmithwalkBSDF):
        material = "dielectric"
        transmits = True

        def __init__(self, props):
            SmithwalkBSDF.__init__(self, props)
            int_ior = mi.lookup_ior(props, "int_ior", "bk7")
            ext_ior = mi.lookup_ior(props, "ext_ior", "air")
            if not (int_ior > 0 and ext_ior > 0):
                raise ValueError(f"`int_ior`/`ext_ior` = {int_ior}/{ext_ior} is not allowed: numbers > 0")
            self.eta = int_ior / ext_ior

        def material_keywords(self, si, active, on):
            return dict(eta=np.full(len(on), self.eta))

    class Diffuse(SmithwalkBSDF):
        material = "lambertian"

        def __init__(self, props):
            SmithwalkBSDF.__init__(self, props)
            self.reflectance = props.get_texture("reflectance", 0.5)

        def material_keywords(self, si, active, on):
            albedo = _columns(self.reflectance.eval(si, active), len(on))
            return dict(albedo=np.where(on[:, None], albedo, 0.0))

    mi.register_bsdf("smithwalk_conductor", lambda props: Conductor(props))
    mi.register_bsdf("smithwalk_dielectric", lambda props: Dielectric(props))
    mi.register_bsdf("smithwalk_diffuse", lambda props: Diffuse(props))


register()
