//! The V-groove microsurface of Lee et al. 2018 (`microsurface::vgroove`, docs/theory.md §14)
//! against oracles that do not share its formulas: a 2-D ray tracer of one groove for the
//! bounce fractions, the Torrance–Sparrow V-cavity shadowing-masking for order 1, and two
//! quadratures (over outgoing directions and over groove normals) that agree only if the
//! inverse map and its Jacobian are right; with F = 1 the orders sum to 1.

use std::f64::consts::FRAC_PI_2;

use microsurface::DVec3;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::vgroove::{bounce_fraction, leave, order_lobe};

use crate::common::{dir, hemisphere_midpoint};

/// Traces one ray through the 2-D groove with walls tilted by `theta_s` (apex at the origin,
/// walls of length 1), entering its opening at `x` along the in-plane direction towards the
/// light at `theta_i`: (first wall hit, +1 right or -1 left; bounces). Plain segment
/// intersections, nothing from the unfolded picture.
fn trace(theta_s: f64, theta_i: f64, x: f64) -> (i32, usize) {
    let beta = FRAC_PI_2 - theta_s;
    let top = beta.cos();
    let walls = [
        (1, [beta.sin(), top], [-theta_s.sin(), theta_s.cos()]),
        (-1, [-beta.sin(), top], [theta_s.sin(), theta_s.cos()]),
    ];
    let (mut p, mut d) = ([x, top], [-theta_i.sin(), -theta_i.cos()]);
    let (mut first, mut n, mut last) = (0, 0, 0);
    loop {
        // The nearest wall ahead (a wall is the segment from the apex to its rim).
        let mut hit: Option<(f64, i32, [f64; 2])> = None;
        for &(side, rim, normal) in &walls {
            if side == last {
                continue;
            }
            // p + t d = s rim, solved for t, s.
            let det = d[0] * (-rim[1]) - d[1] * (-rim[0]);
            if det.abs() < 1e-15 {
                continue;
            }
            let t = (-p[0] * (-rim[1]) + p[1] * (-rim[0])) / det;
            let s = (d[0] * (-p[1]) - d[1] * (-p[0])) / det;
            if t > 1e-12 && (0.0..=1.0).contains(&s) && hit.is_none_or(|h| t < h.0) {
                hit = Some((t, side, normal));
            }
        }
        let Some((t, side, normal)) = hit else { return (first, n) };
        p = [p[0] + t * d[0], p[1] + t * d[1]];
        let dn = d[0] * normal[0] + d[1] * normal[1];
        d = [d[0] - 2.0 * dn * normal[0], d[1] - 2.0 * dn * normal[1]];
        if n == 0 {
            first = side;
        }
        n += 1;
        last = side;
        assert!(n < 100_000, "runaway ray");
    }
}

#[test]
fn bounce_fractions_match_a_ray_traced_groove() {
    // 200 000 rays stratified across the opening: a stratum that straddles a change of bounce
    // count is counted whole, so each fraction is off by at most (breaks + 1) strata; 4e-4 of
    // the wall's width is several such strata, and far below the smallest fraction tested.
    const RAYS: usize = 200_000;
    let mut checked = 0;
    for theta_s_deg in [10.0f64, 30.0, 45.0, 60.0, 72.0, 80.0] {
        for theta_i_deg in [-80.0f64, -45.0, -10.0, 0.0, 20.0, 50.0, 80.0] {
            let (theta_s, theta_i) = (theta_s_deg.to_radians(), theta_i_deg.to_radians());
            let beta = FRAC_PI_2 - theta_s;
            let mut counts = vec![0usize; 64];
            for i in 0..RAYS {
                let x = -beta.sin() + 2.0 * beta.sin() * (i as f64 + 0.5) / RAYS as f64;
                let (first, n) = trace(theta_s, theta_i, x);
                if first == 1 {
                    counts[n] += 1;
                }
            }
            // Each stratum carries 1/RAYS of the light entering the opening, whose width
            // across the rays is 2 sin(beta) cos(theta_i); the right wall's is cos(theta_s + theta_i).
            let wall = (theta_s + theta_i).cos();
            for (k, &count) in counts.iter().enumerate().skip(1) {
                let traced =
                    if wall > 0.0 { count as f64 * 2.0 * beta.sin() * theta_i.cos() / RAYS as f64 / wall } else { 0.0 };
                let model = bounce_fraction(theta_i, theta_s, k);
                assert!(
                    (model - traced).abs() < 4e-4,
                    "theta_s {theta_s_deg} theta_i {theta_i_deg} k {k}: model {model}, traced {traced}"
                );
                checked += usize::from(count > 0);
            }
        }
    }
    println!("{checked} (groove, incidence, order) fractions checked");
    assert!(checked >= 35);
}

/// The Torrance–Sparrow (V-cavity) shadowing-masking of a facet `h` for `wi`, `wo` ([H14]
/// eq. for V-cavities): min(1, 2 h_z wi_z / wi·h, 2 h_z wo_z / wo·h).
fn torrance_sparrow(wi: DVec3, wo: DVec3, h: DVec3) -> f64 {
    (2.0 * h.z * wi.z / wi.dot(h)).min(2.0 * h.z * wo.z / wo.dot(h)).clamp(0.0, 1.0)
}

#[test]
fn order_one_is_the_torrance_sparrow_lobe() {
    // One bounce in a V-groove is reflection on h lit and seen past the other wall: the lobe is
    // D(h) G_TS F(wi·h) / (4 cos theta_i) (f cos theta_o), to rounding.
    let ggx = Ggx(Roughness::isotropic(0.6));
    let schlick = |c: f64| 0.3 + 0.7 * (1.0 - c).powi(5);
    let mut worst: f64 = 0.0;
    for ti in [0.0, 20.0, 45.0, 70.0, 85.0] {
        for to in [5.0, 30.0, 60.0, 80.0, 89.0] {
            for po in [0.0, 40.0, 90.0, 150.0, 180.0, 250.0] {
                let (wi, wo) = (dir(ti, 10.0), dir(to, po));
                let h = (wi + wo).normalize();
                let expected = ggx.d(h) * torrance_sparrow(wi, wo, h) * schlick(wi.dot(h)) / (4.0 * wi.z);
                let got = order_lobe(&ggx, wi, wo, 1, schlick);
                worst = worst.max((got - expected).abs() / expected.max(1e-300));
                assert!((got - expected).abs() <= 1e-10 * expected.max(1e-12), "{ti} {to} {po}: {got} vs {expected}");
            }
        }
    }
    println!("worst relative difference {worst:e}");
}

/// An order-`k` lobe of one surface for a fixed `wi`: `(wo, k) -> f_k cos theta_o`.
type Lobe<'a> = Box<dyn Fn(DVec3, usize) -> f64 + 'a>;

/// The light that enters grooves from `wi` and leaves after `k` bounces, integrated over the
/// groove normals, for k = 1..=`orders` (index k - 1): `∫ D(m) <wi·m> g_k(m) / cos theta_i dm`,
/// with `g_k` the cross-section's fraction in the plane of `m` (no outgoing direction, no
/// Jacobian).
fn over_normals<N: Ndf>(ndf: &N, wi: DVec3, orders: usize, n: usize) -> Vec<f64> {
    (0..orders)
        .map(|order| {
            hemisphere_midpoint(n, |m| {
                let e = DVec3::new(m.x, m.y, 0.0).normalize_or_zero();
                if e == DVec3::ZERO || wi.dot(m) <= 0.0 {
                    return 0.0;
                }
                let theta_i = (-wi.dot(e)).atan2(wi.z);
                ndf.d(m) * wi.dot(m) * bounce_fraction(theta_i, m.z.acos(), order + 1) / wi.z
            })
        })
        .collect()
}

#[test]
fn each_order_carries_the_light_its_grooves_send_and_all_orders_sum_to_one() {
    // ∫ order_lobe dwo (over outgoing directions, through the inverse map and the Jacobian)
    // against the same order's light over groove normals (forward), orders 1 to 3: midpoint
    // rules of 200 x 400 nodes (in s, phi, `hemisphere_midpoint`), whose error at the lobes' kinks and at the
    // integrable peak in the mirror direction stays below 3e-3 here (against 400 x 800 nodes
    // the two sides moved by at most 1.1e-3). With F = 1 every ray that enters a groove leaves
    // it, so the orders over normals sum to 1 (orders beyond 30 carry < 4e-4 here).
    let ggx = Ggx(Roughness::isotropic(0.5));
    let beckmann = Beckmann(Roughness::isotropic(0.8));
    for theta in [0.0, 40.0, 75.0] {
        let wi = dir(theta, 30.0);
        let cases: [(&str, Vec<f64>, Lobe); 2] = [
            ("ggx 0.5", over_normals(&ggx, wi, 30, 200), Box::new(|wo, k| order_lobe(&ggx, wi, wo, k, |_| 1.0))),
            (
                "beckmann 0.8",
                over_normals(&beckmann, wi, 30, 200),
                Box::new(|wo, k| order_lobe(&beckmann, wi, wo, k, |_| 1.0)),
            ),
        ];
        for (name, forward, lobe) in &cases {
            for k in 1..=3 {
                let inverse = hemisphere_midpoint(200, |wo| lobe(wo, k));
                println!("{name} {theta} deg order {k}: over wo {inverse:.5}, over m {:.5}", forward[k - 1]);
                assert!(
                    (inverse - forward[k - 1]).abs() < 3e-3,
                    "{name} {theta} deg order {k}: {inverse} vs {forward:?}"
                );
            }
            let total: f64 = forward.iter().sum();
            println!("{name} {theta} deg: orders 1-30 sum to {total:.5}");
            assert!((total - 1.0).abs() < 2e-3, "{name} {theta} deg: {total}");
        }
    }
}

#[test]
fn the_inverse_map_finds_the_direction_the_groove_sends_the_ray_to() {
    // Forward: a ray from wi in the groove of m, k bounces (if its cross-section allows k),
    // leaves along wo; the order-k lobe at that wo is then positive. (Grooves whose k bounces
    // send wi to its mirror direction, where wi + wo is vertical and the groove's axis is
    // undefined, are avoided: 80 deg walls do that in 9 bounces, 72 deg ones in 5.)
    let ggx = Ggx(Roughness::isotropic(1.0));
    let mut found = 0;
    for (tm, pm) in [(20.0, 0.0), (35.0, 60.0), (50.0, 100.0), (65.0, 200.0), (74.0, 150.0), (78.0, 300.0)] {
        let m = dir(tm, pm);
        for ti in [0.0, 30.0, 60.0] {
            let wi = dir(ti, 45.0);
            let e = DVec3::new(m.x, m.y, 0.0).normalize();
            let theta_i = (-wi.dot(e)).atan2(wi.z);
            for k in 1..12 {
                if bounce_fraction(theta_i, tm.to_radians(), k) <= 0.0 {
                    continue;
                }
                let (_, wo) = leave(wi, m, k, |_| 1.0);
                assert!(wo.z > 0.0, "m {tm} {pm} wi {ti} k {k}: the ray leaves downwards");
                assert!(order_lobe(&ggx, wi, wo, k, |_| 1.0) > 0.0, "m {tm} {pm} wi {ti} k {k}");
                found += 1;
            }
        }
    }
    assert!(found >= 19, "{found}");
}
