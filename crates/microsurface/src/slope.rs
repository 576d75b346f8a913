//! Slope-space integrals of GGX (THEORY.md §8.1; Loubet et al. 2020 supplement).
//!
//! In the stretched roughness-1 configuration the GGX slope density is a cosine lobe on the
//! sphere, `P22 dX dY = (m·z)/pi dm`, and straight lines in slope space are great circles
//! (the gnomonic property, §1.1). The probability of a slope-space polygon is therefore the
//! cosine-weighted solid angle of a spherical polygon: Lambert's formula, in closed form.

use glam::DVec3;

use crate::ndf::Roughness;

/// `∫ P22` over the slope-space polygon with `vertices` (`(x, y)` slopes, in order, convex or
/// not but simple) of GGX with `roughness` (§8.1):
/// `1/(2 pi) |sum_i acos(n_i·n_{i+1}) (n_i × n_{i+1})_z / |n_i × n_{i+1}||`, with `n_i` the
/// unit normals of the stretched vertices.
pub fn ggx_polygon_mass(roughness: Roughness, vertices: &[(f64, f64)]) -> f64 {
    let normals: Vec<DVec3> =
        vertices.iter().map(|&(x, y)| DVec3::new(-x / roughness.x, -y / roughness.y, 1.0).normalize()).collect();
    let mut sum = 0.0;
    for (i, a) in normals.iter().enumerate() {
        let b = normals[(i + 1) % normals.len()];
        let cross = a.cross(b);
        let sin = cross.length();
        let angle = sin.atan2(a.dot(b));
        // theta / sin(theta) -> 1 for a vanishing edge.
        let ratio = if sin > 1e-12 { angle / sin } else { 1.0 };
        sum += cross.z * ratio;
    }
    (sum / (2.0 * std::f64::consts::PI)).abs()
}
