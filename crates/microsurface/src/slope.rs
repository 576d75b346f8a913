//! Slope-space integrals of GGX (docs/theory.md §8.1, §8.2; Loubet et al. 2020 supplement).
//!
//! In the stretched roughness-1 configuration the GGX slope density is a cosine lobe on the
//! sphere, `P22 dX dY = (m·z)/pi dm`, and straight lines in slope space are great circles
//! (the gnomonic property, §1.1). The probability of a slope-space polygon is therefore the
//! cosine-weighted solid angle of a spherical polygon: Lambert's formula, in closed form. The
//! same holds for the visible normals of any direction, weighted by `w'·m` instead of `z·m`.

use glam::DVec3;

use crate::ndf::{Ggx, Ndf, Roughness};

/// `Phi(P) = ∫_P m dm` over the spherical polygon whose vertices are the unit normals
/// `normals`, in order (§8.2): `1/2 sum_e theta_e n_e`, with `theta_e` the arc length of edge
/// `e` and `n_e` the unit normal of its great circle, written `(theta / sin theta) (n_i × n_{i+1})`
/// so that a vanishing edge contributes its limit 0. The sign follows the orientation.
fn vector_integral(normals: &[DVec3]) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for (i, a) in normals.iter().enumerate() {
        let b = normals[(i + 1) % normals.len()];
        let cross = a.cross(b);
        let sin = cross.length();
        let angle = sin.atan2(a.dot(b));
        // theta / sin(theta) -> 1 for a vanishing edge.
        let ratio = if sin > 1e-12 { angle / sin } else { 1.0 };
        sum += cross * ratio;
    }
    0.5 * sum
}

/// The unit normals of stretched slope-space points `(X, Y)`: `normalize(-X, -Y, 1)` (§1.1).
fn normals_of(stretched: &[(f64, f64)]) -> Vec<DVec3> {
    stretched.iter().map(|&(x, y)| DVec3::new(-x, -y, 1.0).normalize()).collect()
}

/// The slope-space vertices `(x, y)` stretched to roughness 1: `(x / alpha_x, y / alpha_y)`.
fn stretched(roughness: Roughness, vertices: &[(f64, f64)]) -> Vec<(f64, f64)> {
    vertices.iter().map(|&(x, y)| (x / roughness.x, y / roughness.y)).collect()
}

/// `∫ P22` over the slope-space polygon with `vertices` (`(x, y)` slopes, in order, convex or
/// not but simple) of GGX with `roughness` (§8.1):
/// `1/(2 pi) |sum_i acos(n_i·n_{i+1}) (n_i × n_{i+1})_z / |n_i × n_{i+1}||`, with `n_i` the
/// unit normals of the stretched vertices; that is `|Phi_z| / pi`.
pub fn ggx_polygon_mass(roughness: Roughness, vertices: &[(f64, f64)]) -> f64 {
    vector_integral(&normals_of(&stretched(roughness, vertices))).z.abs() / std::f64::consts::PI
}

/// The probability that a normal drawn from the visible normals of `w`,
/// `D_w(m) = <w·m> D(m) / A(w)`, has its slope in the convex slope-space polygon `vertices`
/// (§8.2): `|w'·Phi(P')| / (pi A(w))`, with `w' = (alpha_x w_x, alpha_y w_y, w_z)` and `P'` the
/// stretched polygon clipped to the facets `w` sees, the half-plane `w'_z - w'_x X - w'_y Y > 0`
/// (the image of `w·m > 0`). Any `w` on the sphere except `-z`, where no facet is visible.
pub fn ggx_visible_polygon_probability(roughness: Roughness, w: DVec3, vertices: &[(f64, f64)]) -> f64 {
    let ws = DVec3::new(roughness.x * w.x, roughness.y * w.y, w.z);
    let facing = |(x, y): (f64, f64)| ws.z - ws.x * x - ws.y * y;
    // Sutherland-Hodgman against the one line.
    let polygon = stretched(roughness, vertices);
    let mut clipped = Vec::with_capacity(polygon.len() + 1);
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (fa, fb) = (facing(a), facing(b));
        if fa > 0.0 {
            clipped.push(a);
        }
        if (fa > 0.0) != (fb > 0.0) {
            let t = fa / (fa - fb);
            clipped.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    let phi = vector_integral(&normals_of(&clipped));
    ws.dot(phi).abs() / (std::f64::consts::PI * Ggx(roughness).projected_area(w))
}
