#!/usr/bin/env python3
"""Hammon 2017's closed-form fit evaluated from the slides alone ("GGX Diffuse Approximation"
and "Smith: Approximate GGX G2"; shared/seeds/hammon2017-pbr-diffuse-ggx-smith.txt, lines
905-909 and 1230-1235), independently of smithwalk's code: the reference values of
tests/physics/hammon_fit.rs.

The printed value is the cosine-weighted lobe (specular + diffuse) * N.V for light towards L
and the detector towards V, isotropic GGX alpha (D(H) = alpha^2 / (pi ((N.H)^2 (alpha^2 - 1) +
1)^2)), Schlick F(L.H) from F0, and the diffuse albedo; `single` leaves out the multiple-
scattering term `multi`. Plain Python, no packages.
"""
import math


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def fit(alpha, f0, albedo, light, view, with_multi):
    l, v = direction(*light), direction(*view)
    nl, nv = l[2], v[2]
    s = [a + b for a, b in zip(l, v)]
    norm = math.sqrt(sum(c * c for c in s))
    h = [c / norm for c in s]
    nh, lh = h[2], sum(a * b for a, b in zip(l, h))
    lv = sum(a * b for a, b in zip(l, v))
    lerp = lambda a, b, t: a + (b - a) * t
    d = alpha**2 / (math.pi * (nh * nh * (alpha**2 - 1.0) + 1.0) ** 2)
    fresnel = f0 + (1.0 - f0) * (1.0 - lh) ** 5
    specular = fresnel * d / (2.0 * lerp(2.0 * nl * nv, nl + nv, alpha))
    facing = 0.5 + 0.5 * lv
    rough = facing * (0.9 - 0.4 * facing) * (0.5 + nh) / nh
    smooth = 1.05 * (1.0 - (1.0 - nl) ** 5) * (1.0 - (1.0 - nv) ** 5)
    single = lerp(smooth, rough, alpha) / math.pi
    multi = 0.1159 * alpha if with_multi else 0.0
    diffuse = albedo * (single + albedo * multi)
    return (specular + diffuse) * nv


# (alpha, f0, albedo, (theta_l, phi_l), (theta_v, phi_v)) in degrees.
CASES = [
    (0.5, 0.04, 0.8, (30.0, 0.0), (45.0, 180.0)),
    (0.2, 0.5, 0.3, (60.0, 10.0), (20.0, 250.0)),
    (1.0, 0.02, 0.95, (0.0, 0.0), (70.0, 90.0)),
    (0.8, 0.1, 0.5, (80.0, 0.0), (80.0, 180.0)),
]

if __name__ == "__main__":
    for alpha, f0, albedo, light, view in CASES:
        single, total = (fit(alpha, f0, albedo, light, view, m) for m in (False, True))
        print(f"({alpha}, {f0}, {albedo}, {light}, {view}, {single!r}, {total!r}),")
