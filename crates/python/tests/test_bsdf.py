"""smithwalk.bsdf against exact identities: a lossless mirror reflects weight 1 exactly, a
lossless dielectric conserves energy, `sample`'s histogram matches `eval` integrated over the
same bins, and the results do not depend on the thread count or on how the lanes are batched.

Statistical tests use fixed seeds; each states its significance level."""

import math

import numpy as np
import pytest

from smithwalk import bsdf


def direction(theta_deg, phi_deg=0.0, n=1):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.tile([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)], (n, 1))


def test_lossless_mirror_conductor_reflects_weight_one_exactly_in_every_lane():
    # F = 1 and reflection only: every photon escapes upwards with weight 1, whatever the
    # roughness, angle or NDF (§13.2); no statistics needed.
    n = 4000
    rng = np.random.default_rng(1)
    theta = np.degrees(np.arccos(rng.uniform(0.05, 1.0, n)))
    wi = np.stack([np.sin(np.radians(theta)), np.zeros(n), np.cos(np.radians(theta))], axis=1)
    alpha = rng.uniform(0.05, 1.5, n)
    for ndf, shape in (("ggx", {}), ("beckmann", {}), ("student-t", dict(gamma=rng.uniform(1.6, 12.0, n)))):
        wo, weight, order = bsdf.sample(
            wi, u=rng.uniform(size=(n, 3)), seed=3, material="conductor", fresnel="none", alpha=alpha, ndf=ndf, **shape
        )
        assert np.all(weight == 1.0)
        assert np.all(order >= 1)
        assert np.all(wo[:, 2] > 0)
        assert np.allclose(np.linalg.norm(wo, axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("inside", [False, True])
def test_lossless_dielectric_conserves_energy(inside):
    # A lossless dielectric's walk chooses reflection or refraction with probability F and 1 - F
    # (§4.3), so in importance transport every photon carries weight 1 (to rounding, 1e-12): R + T = 1
    # per lane, and the mean of 100_000 lanes is 1 (within 4 standard errors, trivially). In
    # radiance transport a transmitted photon carries (n_i / n_o)^2 (§9.3): 1 / 1.5^2 from
    # outside, 1.5^2 from inside.
    n = 100_000
    wi = direction(40.0, 30.0, n)
    if inside:
        wi[:, 2] *= -1.0
    surface = dict(material="dielectric", eta=1.5, alpha=0.5)
    wo, weight, order = bsdf.sample(wi, seed=11, transport="importance", **surface)
    assert np.all(order >= 1)
    w = weight[:, 0]
    se = w.std(ddof=1) / math.sqrt(n)
    assert abs(w.mean() - 1.0) <= 4 * se and np.allclose(weight, 1.0, rtol=0, atol=1e-12), (w.mean(), se)
    wo_r, weight_r, _ = bsdf.sample(wi, seed=11, transport="radiance", **surface)
    assert np.array_equal(wo_r, wo)
    crossed = np.sign(wo[:, 2]) != np.sign(wi[:, 2])
    assert crossed.any() and (~crossed).any()
    factor = 1.5**2 if inside else 1.0 / 1.5**2
    assert np.allclose(weight_r[crossed], factor, rtol=1e-12, atol=0)
    assert np.allclose(weight_r[~crossed], 1.0, rtol=0, atol=1e-12)


# 0.999 quantile of chi-square with 10 degrees of freedom (tables; e.g. scipy.stats.chi2.ppf).
CHI2_10_999 = 29.588


@pytest.mark.parametrize("orders", [None, 2, [1, "3+"]])
def test_sample_histogram_matches_eval_integrated_over_the_bins(orders):
    # 10 bins of cos(theta_o) in the upper hemisphere. Sample side: mean over lanes of weight x
    # [wo in bin]. Eval side: 2 pi (c1 - c0) x mean of eval at directions uniform in the bin.
    # Both unbiased for the bin's integral of f |cos theta_o|; the statistic
    # sum (a - b)^2 / (var_a + var_b) is chi-square with 10 degrees of freedom, rejected at
    # level 1e-3.
    surface = dict(material="conductor", fresnel="schlick", f0=[0.9, 0.6, 0.3], alpha=0.7)
    n, bins = 200_000, 10
    wi = direction(50.0, 0.0, n)
    wo, weight, _ = bsdf.sample(wi, seed=5, orders=orders, **surface)
    edges = np.linspace(0.0, 1.0, bins + 1)
    index = np.clip(np.searchsorted(edges, wo[:, 2], side="right") - 1, 0, bins - 1)
    up = wo[:, 2] > 0
    rng = np.random.default_rng(9)
    m = 20_000
    for channel in range(3):
        a, var_a, b, var_b = [], [], [], []
        for j in range(bins):
            x = np.where(up & (index == j), weight[:, channel], 0.0)
            a.append(x.mean())
            var_a.append(x.var(ddof=1) / n)
            c = rng.uniform(edges[j], edges[j + 1], m)
            phi = rng.uniform(0.0, 2 * math.pi, m)
            s = np.sqrt(1 - c * c)
            d = np.stack([s * np.cos(phi), s * np.sin(phi), c], axis=1)
            f = bsdf.eval(direction(50.0, 0.0, m), d, seed=17 + j, orders=orders, **surface)[:, channel]
            area = 2 * math.pi * (edges[j + 1] - edges[j])
            b.append(area * f.mean())
            var_b.append(area**2 * f.var(ddof=1) / m)
        stat = sum((x - y) ** 2 / (vx + vy) for x, y, vx, vy in zip(a, b, var_a, var_b) if vx + vy > 0)
        print(f"orders {orders} channel {channel}: chi-square {stat:.2f} (10 dof, reject above {CHI2_10_999})")
        assert stat < CHI2_10_999, (channel, stat, a, b)


def test_results_do_not_depend_on_the_thread_count():
    n = 5000
    rng = np.random.default_rng(2)
    wi = direction(60.0, 10.0, n)
    wo = rng.normal(size=(n, 3))
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    surface = dict(material="dielectric", eta=1.33, alpha_u=0.3, alpha_v=0.8, ndf="beckmann")
    u = rng.uniform(size=(n, 3))
    one = bsdf.sample(wi, u=u, seed=np.uint64(2**63 + 5), threads=1, **surface)
    two = bsdf.sample(wi, u=u, seed=np.uint64(2**63 + 5), threads=2, **surface)
    for x, y in zip(one, two):
        assert np.array_equal(x, y)
    assert np.array_equal(bsdf.eval(wi, wo, seed=4, threads=1, **surface), bsdf.eval(wi, wo, seed=4, threads=2, **surface))
    assert np.array_equal(bsdf.pdf(wi, wo, threads=1, **surface), bsdf.pdf(wi, wo, threads=2, **surface))


def test_per_lane_parameters_equal_scalar_calls():
    n = 64
    rng = np.random.default_rng(3)
    wi = direction(30.0, 0.0, n)
    wo = direction(45.0, 120.0, n)
    u = rng.uniform(size=(n, 3))
    alpha = np.where(np.arange(n) % 2 == 0, 0.2, 0.9)
    k = np.where((np.arange(n) % 2 == 0)[:, None], [[3.0, 2.5, 2.0]], [[1.0, 1.5, 4.0]])
    lanes = dict(material="conductor", eta=[0.2, 0.9, 1.1], k=k, alpha=alpha)
    wo_s, w_s, o_s = bsdf.sample(wi, u=u, seed=8, **lanes)
    e = bsdf.eval(wi, wo, seed=8, **lanes)
    p = bsdf.pdf(wi, wo, **lanes)
    for parity, (a, kk) in enumerate([(0.2, [3.0, 2.5, 2.0]), (0.9, [1.0, 1.5, 4.0])]):
        sel = np.arange(n) % 2 == parity
        scalar = dict(material="conductor", eta=[0.2, 0.9, 1.1], k=kk, alpha=a)
        wo1, w1, o1 = bsdf.sample(wi[sel], u=u[sel], seed=8, **scalar)
        assert np.array_equal(wo1, wo_s[sel]) and np.array_equal(w1, w_s[sel]) and np.array_equal(o1, o_s[sel])
        assert np.array_equal(bsdf.eval(wi[sel], wo[sel], seed=8, **scalar), e[sel])
        assert np.array_equal(bsdf.pdf(wi[sel], wo[sel], **scalar), p[sel])


def test_order_selection_splits_the_weight():
    # Every photon escapes at one order: the weights with orders [1], [2] and ["3+"] add up to
    # the full weight, lane by lane (same streams).
    n = 2000
    wi = direction(70.0, 0.0, n)
    surface = dict(material="conductor", fresnel="none", alpha=1.0)
    full = bsdf.sample(wi, seed=1, **surface)[1]
    parts = sum(bsdf.sample(wi, seed=1, orders=o, **surface)[1] for o in (1, 2, "3+"))
    assert np.array_equal(full, parts)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(material="conductor", alpha=0.0), ["alpha", "0.0", "> 0"]),
        (dict(material="conductor", alpha=np.array([0.5, np.nan])), ["alpha", "nan", "lane 1"]),
        (dict(material="dielectric", alpha=0.5, eta=-1.0), ["eta", "-1.0", "> 0"]),
        (dict(material="conductor", alpha=np.ones(3)), ["alpha", "(3,)"]),
        (dict(material="conductor", alpha=0.5, k=np.ones((2, 2))), ["k", "(2, 2)"]),
        (dict(material="plastic", alpha=0.5), ["material", "plastic", "conductor"]),
        (dict(material="conductor", alpha=0.5, ndf="phong"), ["ndf", "phong", "ggx", "student-t"]),
        (dict(material="conductor", alpha=0.5, ndf="student-t"), ["gamma", "missing", "> 1.5"]),
        (dict(material="conductor", alpha=0.5, ndf="student-t", gamma=np.array([3.0, 1.5])), ["gamma", "1.5", "lane 1"]),
        (dict(material="conductor", alpha=0.5, gamma=3.0), ["gamma", "3.0", "ggx", "student-t"]),
        (dict(material="conductor", alpha=0.5, orders=[0]), ["orders", "0"]),
        (dict(material="conductor", alpha=0.5, seed=-1), ["seed", "-1"]),
        (dict(material="conductor", alpha=0.5, transport="light"), ["transport", "light"]),
    ],
)
def test_bad_parameters_raise_value_error_naming_field_and_value(kwargs, words):
    with pytest.raises(ValueError) as error:
        bsdf.sample(direction(30.0, 0.0, 2), **kwargs)
    for word in words:
        assert word in str(error.value)


def test_student_t_at_gamma_2_evaluates_as_ggx():
    # gamma = 2 is GGX exactly (theory §1.6): order 1 of eval is deterministic (§13.2), so the
    # two NDFs give the same values to rounding (Lambda agrees to 1e-14, D exactly in form).
    rng = np.random.default_rng(5)
    n = 200
    wi = direction(0.0, 0.0, n)
    wi[:] = rng.normal(size=(n, 3))
    wi[:, 2] = np.abs(wi[:, 2])
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    wo = rng.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    surface = dict(material="conductor", fresnel="none", alpha_u=0.3, alpha_v=0.7, orders=1)
    ggx = bsdf.eval(wi, wo, ndf="ggx", **surface)
    student = bsdf.eval(wi, wo, ndf="student-t", gamma=2.0, **surface)
    assert np.all(ggx > 0)
    np.testing.assert_allclose(student, ggx, rtol=1e-10, atol=0)


def test_bad_direction_shapes_raise_value_error():
    with pytest.raises(ValueError, match="wi"):
        bsdf.sample(np.ones((4, 2)), material="conductor", alpha=0.5)
    with pytest.raises(ValueError, match="wo"):
        bsdf.eval(direction(10.0, 0.0, 4), direction(10.0, 0.0, 3), material="conductor", alpha=0.5)
    with pytest.raises(ValueError, match="u"):
        bsdf.sample(direction(10.0, 0.0, 4), u=np.ones((3, 3)), material="conductor", alpha=0.5)
