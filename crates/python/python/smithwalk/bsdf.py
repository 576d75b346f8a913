"""The multiple-scattering BSDF of a Smith microsurface (theory §13) for renderers, batched
over numpy arrays: N lanes, one direction (pair) per lane, evaluated in parallel with the GIL
released.

Every call takes the surface as keyword arguments (see :func:`sample`); each parameter is one
value for every lane or one per lane (a texture), and is broadcast to the N lanes of ``wi``:

* ``material``: ``"conductor"``, ``"dielectric"``, ``"lambertian"`` or ``"hammon"``;
* ``ndf``: ``"ggx"`` (default), ``"beckmann"`` or ``"student-t"`` (theory §1.6) with its shape
  ``gamma``: scalar or shape (N,), finite and > 1.5 (2 is GGX; large values approach Beckmann);
* ``alpha`` (isotropic) or ``alpha_u`` and ``alpha_v`` (along the tangent x and y axes):
  scalar or shape (N,), finite and > 0;
* ``fresnel`` (conductor): ``"none"`` (F = 1, a lossless mirror), ``"schlick"`` (from ``f0``)
  or ``"exact"`` (from ``eta`` and ``k``); when omitted, ``"exact"`` if ``eta`` or ``k`` is
  given, ``"schlick"`` if ``f0`` is, ``"none"`` otherwise;
* ``eta``: a conductor's real index per channel, or a dielectric's relative index
  ``n_inside / n_outside`` (scalar or (N,), not per channel); ``k``: a conductor's extinction;
  ``f0``: Schlick reflectance at normal incidence (conductor, Hammon coat); ``albedo``
  (Lambertian, Hammon base). Per-channel (RGB) fields take a scalar, shape (3,), (N, 1) or
  (N, 3): a 1-D array of length 3 is always the three channels;
* ``orders``: the scattering orders kept (None: all); an int ``k``, a string ``"k+"``
  (order k and above), or a list of them (their union): ``[1, "3+"]``. Light that escapes at
  another order has weight 0;
* ``transport``: ``"radiance"`` (default; ``wi`` points towards the camera, as in a path
  tracer: transmission is multiplied by ``(n_i / n_o)^2``) or ``"importance"`` (``wi`` points
  towards the light: the lobe of light arriving from ``wi``), as Mitsuba's ``TransportMode``;
* ``threads``: the number of worker threads (None: all cores). Results do not depend on it.

Directions are unit vectors in the surface's frame (normal +z), both pointing away from the
surface. A dielectric is lit from inside when ``wi`` is below the horizon.

Random numbers: each lane draws from its own PCG stream, ``microsurface::bsdf::stream(seed,
numbers)``: the 64-bit ``seed`` mixed with the bit patterns of the lane's ``numbers``. For
:func:`sample` those are the row ``u[i]`` of the renderer's uniforms (Mitsuba passes 3), or the
lane index ``i`` when ``u`` is None; for :func:`eval` the six components of ``wi[i]`` and
``wo[i]``. Equal seed and numbers give bit-identical results on any thread count.

Bad parameters raise ``ValueError`` naming the field, its value and what is allowed.
"""

from __future__ import annotations

import numbers

import numpy as np

from . import _native

__all__ = ["sample", "eval", "pdf"]

_MATERIALS = ("conductor", "dielectric", "lambertian", "hammon")
_NDFS = ("ggx", "beckmann", "student-t")


def _directions(name, value):
    """``value`` as a C-contiguous float64 array of shape (N, 3)."""
    a = np.ascontiguousarray(value, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"`{name}` has shape {a.shape}: an array of shape (N, 3) is allowed")
    return a


def _per_lane(name, value, n):
    """A scalar field broadcast to shape (N,)."""
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        return np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"`{name}` has shape {a.shape}: a scalar or shape ({n},) is allowed")
    return np.ascontiguousarray(a)


def _rgb(name, value, n):
    """A per-channel field broadcast to shape (N, 3)."""
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0 or a.shape == (3,) or (a.ndim == 2 and a.shape[0] == n and a.shape[1] in (1, 3)):
        return np.ascontiguousarray(np.broadcast_to(a, (n, 3)))
    raise ValueError(
        f"`{name}` has shape {a.shape}: a scalar or shape (3,), ({n}, 1) or ({n}, 3) is allowed"
    )


def _positive(name, a):
    bad = ~(np.isfinite(a) & (a > 0))
    if bad.any():
        lane = int(np.argmax(bad))
        raise ValueError(f"`{name}` = {a[lane]!r} (lane {lane}) is not allowed: a finite number > 0")


def _orders(orders):
    """``orders`` as the pair (mask, from) of ``microsurface::bsdf::Orders``."""
    if orders is None:
        return 0, 1
    items = [orders] if isinstance(orders, (numbers.Integral, str)) else list(orders)
    if not items:
        raise ValueError("`orders` = [] is not allowed: at least one order, k or \"k+\"")
    mask, start = 0, 2**32 - 1
    for item in items:
        if isinstance(item, str) and item.endswith("+") and item[:-1].isdigit() and int(item[:-1]) >= 1:
            start = min(start, int(item[:-1]))
        elif isinstance(item, numbers.Integral) and not isinstance(item, bool) and 1 <= item <= 64:
            mask |= 1 << (int(item) - 1)
        else:
            raise ValueError(
                f"`orders` item {item!r} is not allowed: an order 1 to 64 or a string \"k+\" (k >= 1)"
            )
    return mask, start


def _params(
    n,
    material,
    ndf="ggx",
    alpha=None,
    alpha_u=None,
    alpha_v=None,
    gamma=None,
    fresnel=None,
    eta=None,
    k=None,
    f0=None,
    albedo=None,
    orders=None,
):
    """The native call's parameters (a dict), every field broadcast to N lanes."""
    if material not in _MATERIALS:
        raise ValueError(f"`material` = {material!r} is not allowed: one of {', '.join(_MATERIALS)}")
    if ndf not in _NDFS:
        raise ValueError(f"`ndf` = {ndf!r} is not allowed: \"ggx\", \"beckmann\" or \"student-t\"")
    if ndf == "student-t":
        if gamma is None:
            raise ValueError("`gamma` is missing: ndf = \"student-t\" needs its shape, finite and > 1.5")
        g = _per_lane("gamma", gamma, n)
        bad = ~(np.isfinite(g) & (g > 1.5))
        if bad.any():
            lane = int(np.argmax(bad))
            raise ValueError(f"`gamma` = {g[lane]!r} (lane {lane}) is not allowed: a Student-T shape, finite and > 1.5")
    elif gamma is not None:
        raise ValueError(f"`gamma` = {gamma!r} is not allowed with ndf = {ndf!r}: only \"student-t\" has a shape")
    else:
        g = np.full(n, np.nan)
    if alpha is not None:
        if alpha_u is not None or alpha_v is not None:
            raise ValueError("`alpha` with `alpha_u`/`alpha_v` is not allowed: give one or the other")
        a = _per_lane("alpha", alpha, n)
        _positive("alpha", a)
        au = av = a
    elif alpha_u is not None and alpha_v is not None:
        au, av = _per_lane("alpha_u", alpha_u, n), _per_lane("alpha_v", alpha_v, n)
        _positive("alpha_u", au)
        _positive("alpha_v", av)
    else:
        raise ValueError("`alpha` is missing: give `alpha`, or both `alpha_u` and `alpha_v`")
    if fresnel is None:
        fresnel = "exact" if eta is not None or k is not None else "schlick" if f0 is not None else "none"
    if material == "conductor" and fresnel not in ("none", "schlick", "exact"):
        raise ValueError(f"`fresnel` = {fresnel!r} is not allowed: \"none\", \"schlick\" or \"exact\"")
    if material == "dielectric":
        if eta is None:
            raise ValueError("`eta` is missing: a dielectric needs its relative index n_inside / n_outside")
        e = _per_lane("eta", eta, n)
        _positive("eta", e)
        eta_rgb = np.ascontiguousarray(np.repeat(e[:, None], 3, axis=1))
    else:
        eta_rgb = _rgb("eta", 1.0 if eta is None else eta, n)
    return {
        "material": material,
        "fresnel": fresnel,
        "ndf": ndf,
        "alpha": (au, av),
        "gamma": g,
        "eta": eta_rgb,
        "k": _rgb("k", 0.0 if k is None else k, n),
        "f0": _rgb("f0", 1.0 if f0 is None else f0, n),
        "albedo": _rgb("albedo", 1.0 if albedo is None else albedo, n),
        "orders": _orders(orders),
    }


def _seed(seed):
    if not isinstance(seed, numbers.Integral) or isinstance(seed, bool) or not 0 <= int(seed) < 2**64:
        raise ValueError(f"`seed` = {seed!r} is not allowed: an integer in [0, 2^64)")
    return int(seed)


def _transport(transport):
    if transport not in ("radiance", "importance"):
        raise ValueError(f"`transport` = {transport!r} is not allowed: \"radiance\" or \"importance\"")
    return transport


def sample(wi, *, u=None, seed=0, transport="radiance", threads=None, **surface):
    """One photon per lane from ``wi`` (N, 3) (§13.2).

    Returns ``(wo, weight, order)``: the escape directions (N, 3), the weights
    ``f |cos theta_o| / density`` per RGB channel (N, 3) (0 for a photon absorbed or escaping at
    an order outside ``orders``; 1 exactly for a lossless reflection) and the scattering orders
    (N,) (0: never escaped). ``u`` (N, m): the renderer's uniforms per lane, mixed into the
    lane's stream with ``seed`` (see the module's docstring). Surface keywords: see the module.
    """
    wi = _directions("wi", wi)
    n = len(wi)
    if u is None:
        u = np.arange(n, dtype=np.float64)[:, None]
    u = np.ascontiguousarray(u, dtype=np.float64)
    if u.ndim != 2 or u.shape[0] != n:
        raise ValueError(f"`u` has shape {u.shape}: an array of shape ({n}, m) is allowed")
    params = _params(n, **surface)
    return _native.bsdf_sample(params, wi, u, _seed(seed), _transport(transport), threads)


def eval(wi, wo, *, seed=0, transport="radiance", threads=None, **surface):  # noqa: A001
    """``f(wi, wo) |cos theta_o|`` per lane and RGB channel (N, 3) (§13.3): the order-1 term
    exactly, higher orders by one unbiased walk per lane, seeded from ``seed`` and the lane's
    two directions (see the module's docstring). Surface keywords: see the module."""
    wi, wo = _directions("wi", wi), _directions("wo", wo)
    if wo.shape != wi.shape:
        raise ValueError(f"`wo` has shape {wo.shape}: the shape of `wi`, {wi.shape}, is allowed")
    params = _params(len(wi), **surface)
    return _native.bsdf_eval(params, wi, wo, _seed(seed), _transport(transport), threads)


def pdf(wi, wo, *, threads=None, **surface):
    """The density (N,) with which :func:`sample` is approximated for multiple importance
    sampling (§13.4); deterministic. Surface keywords: see the module."""
    wi, wo = _directions("wi", wi), _directions("wo", wo)
    if wo.shape != wi.shape:
        raise ValueError(f"`wo` has shape {wo.shape}: the shape of `wi`, {wi.shape}, is allowed")
    params = _params(len(wi), **surface)
    return _native.bsdf_pdf(params, wi, wo, threads)
