//! Closed-form GGX slope-space polygon masses (docs/theory.md §8.1, Loubet et al. 2020) and their
//! generalization to the visible normals of any direction (§8.2) against numerical
//! quadrature, and then used as exact expected counts of histograms of sampled slopes over a
//! triangulated slope-space grid (chi-square; cells with expected count < 5 pooled; 500 000
//! samples per case; Sidak family level 0.01 over the cases of each test).

use microsurface::DVec3;
use microsurface::ndf::{Ggx, Ndf, Roughness};
use microsurface::slope::{ggx_polygon_mass, ggx_visible_polygon_probability};
use numerics::quadrature::integrate_2d;
use numerics::stats::{ChiSquare, WeightedBin, chi_square, sidak};
use rand_pcg::Pcg64Mcg;

/// `P22` of anisotropic GGX (§1.2).
fn p22(r: Roughness, x: f64, y: f64) -> f64 {
    let (sx, sy) = (x / r.x, y / r.y);
    let k = 1.0 + sx * sx + sy * sy;
    1.0 / (std::f64::consts::PI * r.x * r.y * k * k)
}

/// `∫ density(x, y)` over a slope-space triangle by quadrature in Duffy coordinates:
/// `p = p0 + u (p1 - p0) + u v (p2 - p1)`, Jacobian `u |det(p1 - p0, p2 - p1)|`.
fn triangle_quadrature(density: impl Fn(f64, f64) -> f64, t: [(f64, f64); 3], tolerance: f64) -> f64 {
    let (e1, e2) = ((t[1].0 - t[0].0, t[1].1 - t[0].1), (t[2].0 - t[1].0, t[2].1 - t[1].1));
    let det = (e1.0 * e2.1 - e1.1 * e2.0).abs();
    let f = |u: f64, v: f64| {
        let (x, y) = (t[0].0 + u * e1.0 + u * v * e2.0, t[0].1 + u * e1.1 + u * v * e2.1);
        density(x, y) * u * det
    };
    integrate_2d(f, (0.0, 1.0), (0.0, 1.0), tolerance).0
}

/// The visible-normal density of `w` in slope space (§8.2):
/// `D_w dm = P22(x, y) <w_z - w_x x - w_y y> / A(w) dx dy`.
fn visible_density(r: Roughness, w: DVec3, x: f64, y: f64) -> f64 {
    p22(r, x, y) * (w.z - w.x * x - w.y * y).max(0.0) / Ggx(r).projected_area(w)
}

/// Unit direction at polar angle `theta` and azimuth `phi` (degrees).
fn direction(theta: f64, phi: f64) -> DVec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

const TRIANGLES: [[(f64, f64); 3]; 4] = [
    [(0.1, 0.2), (0.9, -0.3), (0.4, 0.8)],
    // contains the origin
    [(-0.5, -0.4), (0.6, -0.2), (0.0, 0.7)],
    // far out in the tails, and long and thin
    [(2.0, 1.0), (3.5, 1.2), (2.2, 4.0)],
    [(-1.0, 0.01), (1.0, 0.0), (0.0, 0.02)],
];

#[test]
fn triangle_masses_match_quadrature() {
    let roughnesses = [Roughness::isotropic(0.5), Roughness { x: 0.8, y: 0.2 }, Roughness { x: 0.1, y: 1.5 }];
    for r in roughnesses {
        for t in TRIANGLES {
            let closed = ggx_polygon_mass(r, &t);
            let numeric = triangle_quadrature(|x, y| p22(r, x, y), t, 1e-12);
            assert!((closed - numeric).abs() < 1e-9 * (1.0 + numeric), "{r:?} {t:?}: {closed} vs quadrature {numeric}");
        }
        // A square split into its two triangles has the mass of the square.
        let square = [(-0.3, -0.2), (0.5, -0.2), (0.5, 0.6), (-0.3, 0.6)];
        let halves = ggx_polygon_mass(r, &[square[0], square[1], square[2]])
            + ggx_polygon_mass(r, &[square[0], square[2], square[3]]);
        assert!((ggx_polygon_mass(r, &square) - halves).abs() < 1e-13);
    }
}

/// §8.2 against quadrature of the visible-normal density (whose kink along the visibility
/// line the triangles cross), for directions above, at and below the horizon; at normal
/// incidence it is §8.1's mass; and over a square of half-side `R = 10^10` around the origin
/// it sums to 1 up to the mass outside (the visible density falls as `r^-3`, so that mass
/// falls as `1 / R`: at 170 deg, where few facets are visible, `R = 10^8` still leaves 1.3e-7).
#[test]
fn visible_triangle_probabilities_match_quadrature() {
    let roughnesses = [Roughness::isotropic(0.5), Roughness { x: 0.8, y: 0.2 }, Roughness { x: 0.1, y: 1.5 }];
    let directions = [direction(60.0, 30.0), direction(89.0, 200.0), direction(120.0, 250.0), direction(170.0, 10.0)];
    for r in roughnesses {
        for w in directions {
            for t in TRIANGLES {
                let closed = ggx_visible_polygon_probability(r, w, &t);
                let numeric = triangle_quadrature(|x, y| visible_density(r, w, x, y), t, 1e-11);
                assert!(
                    (closed - numeric).abs() < 1e-8 * (1.0 + numeric),
                    "{r:?} {w:?} {t:?}: {closed} vs quadrature {numeric}"
                );
            }
            let far = [(-1e10, -1e10), (1e10, -1e10), (1e10, 1e10), (-1e10, 1e10)];
            let total = ggx_visible_polygon_probability(r, w, &far);
            assert!((total - 1.0).abs() < 1e-7, "{r:?} {w:?}: total probability {total}");
        }
        for t in TRIANGLES {
            let (visible, mass) = (ggx_visible_polygon_probability(r, DVec3::Z, &t), ggx_polygon_mass(r, &t));
            assert!((visible - mass).abs() < 1e-15, "{r:?} {t:?}: {visible} vs {mass}");
        }
    }
}

/// The chi-square test of a histogram of the slopes of 500 000 visible normals of `w` on a
/// grid of 12 x 12 squares over `[-4 alpha, 4 alpha]`, each cut along its diagonal, plus the
/// rest of the plane as one cell, against `expected_of(triangle)`.
fn triangulated_grid_test(r: Roughness, w: DVec3, seed: u128, expected_of: impl Fn(&[(f64, f64)]) -> f64) -> ChiSquare {
    const N: u64 = 500_000;
    const CELLS: usize = 12;
    let ndf = Ggx(r);
    let (lx, ly) = (4.0 * r.x, 4.0 * r.y);
    let (hx, hy) = (2.0 * lx / CELLS as f64, 2.0 * ly / CELLS as f64);
    let corner = |i: usize, j: usize| (-lx + i as f64 * hx, -ly + j as f64 * hy);
    let mut expected = Vec::new();
    for i in 0..CELLS {
        for j in 0..CELLS {
            let (a, b, c, d) = (corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1));
            expected.push(expected_of(&[a, b, c]));
            expected.push(expected_of(&[a, c, d]));
        }
    }
    expected.push((1.0 - expected.iter().sum::<f64>()).max(0.0));
    let mut rng = Pcg64Mcg::new(seed);
    let mut counts = vec![0u64; expected.len()];
    for _ in 0..N {
        let m = ndf.sample_visible(w, &mut rng);
        let (x, y) = (-m.x / m.z, -m.y / m.z);
        let (u, v) = ((x + lx) / hx, (y + ly) / hy);
        let cell = if (0.0..CELLS as f64).contains(&u) && (0.0..CELLS as f64).contains(&v) {
            let (i, j) = (u as usize, v as usize);
            // The diagonal from (i, j) to (i+1, j+1): below it is the first triangle.
            let below = (u - i as f64) >= (v - j as f64);
            2 * (i * CELLS + j) + usize::from(!below)
        } else {
            expected.len() - 1
        };
        counts[cell] += 1;
    }
    let observed: Vec<WeightedBin> = counts.iter().map(|&c| WeightedBin::of_count(c, N)).collect();
    chi_square(&observed, &expected, N, 5.0)
}

/// The visible-normal sampler (Dupuy & Benyoub's caps, §3.2) against the exact §8.2
/// probabilities of the grid's triangles: directions above the horizon (anisotropic, and
/// grazing) and below it (seen from inside).
#[test]
fn sampled_visible_slopes_follow_the_visible_triangle_probabilities() {
    let cases = [
        (Roughness { x: 0.9, y: 0.3 }, direction(60.0, 30.0)),
        (Roughness::isotropic(0.5), direction(85.0, 100.0)),
        (Roughness::isotropic(0.5), direction(120.0, 200.0)),
    ];
    let level = sidak(0.01, cases.len());
    for (seed, (r, w)) in cases.into_iter().enumerate() {
        let test = triangulated_grid_test(r, w, 1200 + seed as u128, |t| ggx_visible_polygon_probability(r, w, t));
        assert!(test.p_value > level, "{r:?} {w:?}: sampled visible slopes rejected\n{}", test.worst_cells(10));
    }
}

/// The visible normals at normal incidence are drawn from `D(m) m_z` (§3.1): against §8.1's
/// masses of the grid's triangles.
#[test]
fn sampled_slopes_follow_the_triangle_masses() {
    let level = sidak(0.01, 2);
    for (seed, r) in [Roughness::isotropic(0.5), Roughness { x: 0.9, y: 0.3 }].into_iter().enumerate() {
        let test = triangulated_grid_test(r, DVec3::Z, 900 + seed as u128, |t| ggx_polygon_mass(r, t));
        assert!(test.p_value > level, "{r:?}: sampled slopes rejected\n{}", test.worst_cells(10));
    }
}
