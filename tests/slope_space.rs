//! Closed-form GGX slope-space polygon masses (THEORY.md §8.1, Loubet et al. 2020) against
//! numerical quadrature, and then used as exact expected counts of a histogram of sampled
//! slopes over a triangulated slope-space grid (chi-square; cells with expected count < 5
//! pooled; 500 000 samples per roughness; Sidak family level 0.01 over both roughnesses).

use microsurface::DVec3;
use microsurface::ndf::{Ggx, Ndf, Roughness};
use microsurface::slope::ggx_polygon_mass;
use rand_pcg::Pcg64Mcg;
use smithwalk::quadrature::integrate_2d;
use smithwalk::stats::{WeightedBin, chi_square, sidak};

/// `P22` of anisotropic GGX (§1.2).
fn p22(r: Roughness, x: f64, y: f64) -> f64 {
    let (sx, sy) = (x / r.x, y / r.y);
    let k = 1.0 + sx * sx + sy * sy;
    1.0 / (std::f64::consts::PI * r.x * r.y * k * k)
}

/// `∫ P22` over a triangle by quadrature in Duffy coordinates:
/// `p = p0 + u (p1 - p0) + u v (p2 - p1)`, Jacobian `u |det(p1 - p0, p2 - p1)|`.
fn triangle_quadrature(r: Roughness, t: [(f64, f64); 3]) -> f64 {
    let (e1, e2) = ((t[1].0 - t[0].0, t[1].1 - t[0].1), (t[2].0 - t[1].0, t[2].1 - t[1].1));
    let det = (e1.0 * e2.1 - e1.1 * e2.0).abs();
    let f = |u: f64, v: f64| {
        let (x, y) = (t[0].0 + u * e1.0 + u * v * e2.0, t[0].1 + u * e1.1 + u * v * e2.1);
        p22(r, x, y) * u * det
    };
    integrate_2d(f, (0.0, 1.0), (0.0, 1.0), 1e-12).0
}

#[test]
fn triangle_masses_match_quadrature() {
    let roughnesses = [Roughness::isotropic(0.5), Roughness { x: 0.8, y: 0.2 }, Roughness { x: 0.1, y: 1.5 }];
    let triangles = [
        [(0.1, 0.2), (0.9, -0.3), (0.4, 0.8)],
        // contains the origin
        [(-0.5, -0.4), (0.6, -0.2), (0.0, 0.7)],
        // far out in the tails, and long and thin
        [(2.0, 1.0), (3.5, 1.2), (2.2, 4.0)],
        [(-1.0, 0.01), (1.0, 0.0), (0.0, 0.02)],
    ];
    for r in roughnesses {
        for t in triangles {
            let closed = ggx_polygon_mass(r, &t);
            let numeric = triangle_quadrature(r, t);
            assert!((closed - numeric).abs() < 1e-9 * (1.0 + numeric), "{r:?} {t:?}: {closed} vs quadrature {numeric}");
        }
        // A square split into its two triangles has the mass of the square.
        let square = [(-0.3, -0.2), (0.5, -0.2), (0.5, 0.6), (-0.3, 0.6)];
        let halves = ggx_polygon_mass(r, &[square[0], square[1], square[2]])
            + ggx_polygon_mass(r, &[square[0], square[2], square[3]]);
        assert!((ggx_polygon_mass(r, &square) - halves).abs() < 1e-13);
    }
}

#[test]
fn sampled_slopes_follow_the_triangle_masses() {
    const N: u64 = 500_000;
    const CELLS: usize = 12;
    let level = sidak(0.01, 2);
    for (seed, r) in [Roughness::isotropic(0.5), Roughness { x: 0.9, y: 0.3 }].into_iter().enumerate() {
        let ndf = Ggx(r);
        // A grid of 12 x 12 squares over [-2.5 alpha, 2.5 alpha], each cut along its diagonal,
        // plus the rest of the plane as one cell.
        let (lx, ly) = (2.5 * r.x, 2.5 * r.y);
        let (hx, hy) = (2.0 * lx / CELLS as f64, 2.0 * ly / CELLS as f64);
        let corner = |i: usize, j: usize| (-lx + i as f64 * hx, -ly + j as f64 * hy);
        let mut expected = Vec::new();
        for i in 0..CELLS {
            for j in 0..CELLS {
                let (a, b, c, d) = (corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1));
                expected.push(ggx_polygon_mass(r, &[a, b, c]));
                expected.push(ggx_polygon_mass(r, &[a, c, d]));
            }
        }
        expected.push(1.0 - expected.iter().sum::<f64>());
        // Normals from D(m) m_z: the visible normals at normal incidence (§3.1).
        let mut rng = Pcg64Mcg::new(900 + seed as u128);
        let mut counts = vec![0u64; expected.len()];
        for _ in 0..N {
            let m = ndf.sample_visible(DVec3::Z, &mut rng);
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
        let observed: Vec<WeightedBin> =
            counts.iter().map(|&c| c as f64 / N as f64).map(|p| WeightedBin { mean: p, second_moment: p }).collect();
        let test = chi_square(&observed, &expected, N, 5.0);
        assert!(test.p_value > level, "{r:?}: sampled slopes rejected\n{}", test.worst_cells(10));
    }
}
