//! The detector's geometry: the angular grid of bins, the hemispheres, and the binning of an
//! escaping direction without trigonometry.

use glam::DVec3;

/// The angular grid: bins uniform in |cos theta| and in phi measured from the incident azimuth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    pub cos_bins: usize,
    pub phi_bins: usize,
}

impl Grid {
    pub fn bins(&self) -> usize {
        self.cos_bins * self.phi_bins
    }

    /// `[|cos| lo, |cos| hi]` of a cos index.
    pub fn cos_edges(&self, ic: usize) -> (f64, f64) {
        (ic as f64 / self.cos_bins as f64, (ic + 1) as f64 / self.cos_bins as f64)
    }

    /// `[phi lo, phi hi]` in degrees of a phi index.
    pub fn phi_edges_deg(&self, ip: usize) -> (f64, f64) {
        let w = 360.0 / self.phi_bins as f64;
        (ip as f64 * w, (ip + 1) as f64 * w)
    }

    /// Projected solid angle `∫ |cos theta| dω` of a bin with cos index `ic` (§4.7).
    pub fn projected_solid_angle(&self, ic: usize) -> f64 {
        let (lo, hi) = self.cos_edges(ic);
        std::f64::consts::TAU / self.phi_bins as f64 * 0.5 * (hi * hi - lo * lo)
    }
}

/// Which hemisphere light leaves into, relative to where it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hemisphere {
    /// Reflection: back to the side of the light.
    R = 0,
    /// Transmission: to the other side.
    T = 1,
}

/// The "diamond angle" of a planar direction `(x, y)`: a monotone function of its azimuth
/// `atan2(y, x)` taken in `[0, 2 pi)`, onto `[0, 4)`, without trigonometry (one division).
#[inline]
fn diamond_angle(x: f64, y: f64) -> f64 {
    let l1 = x.abs() + y.abs();
    if l1 == 0.0 {
        return 0.0;
    }
    let t = x / l1;
    // `1 - t` for y >= 0, else `3 + t`, without a branch: the sign of y is as likely as not,
    // so a branch would be mispredicted for half the escapes. Both forms are exact.
    let lower = f64::from(u8::from(y < 0.0));
    (1.0 + 2.0 * lower) + (2.0 * lower - 1.0) * t
}

/// Bins escaping directions: |cos theta| directly, and the azimuth relative to the incident
/// azimuth without trigonometry. The diamond angle of the rotated direction is looked up in a
/// table of `4 phi_bins` equal cells, each holding the number of bin edges
/// (`2 pi k / phi_bins`, as diamond angles) at or below its start and the edge inside it, if
/// any (edges are at least `pi / (2 phi_bins)` apart in diamond angle, so a cell holds at
/// most one).
#[derive(Clone, Debug)]
pub(super) struct Binner {
    grid: Grid,
    /// `(cos phi_i, sin phi_i)` of the incident azimuth.
    rotation: (f64, f64),
    /// Per cell: edges at or below its start, and the edge inside it (`inf` if none).
    cells: Vec<(usize, f64)>,
    /// `cos_bins` and `cells.len() / 4` as floats, the scales from |cos| and diamond angle to
    /// an index.
    cos_scale: f64,
    cell_scale: f64,
}

impl Binner {
    pub(super) fn new(grid: Grid, rotation: (f64, f64)) -> Self {
        let n = grid.phi_bins;
        let edges: Vec<f64> = (1..n)
            .map(|k| {
                let (s, c) = (std::f64::consts::TAU * k as f64 / n as f64).sin_cos();
                diamond_angle(c, s)
            })
            .collect();
        let count = 4 * n;
        let cells = (0..count)
            .map(|i| {
                let (start, end) = (4.0 * i as f64 / count as f64, 4.0 * (i + 1) as f64 / count as f64);
                let below = edges.partition_point(|&e| e <= start);
                let inside = edges.get(below).copied().filter(|&e| e < end).unwrap_or(f64::INFINITY);
                (below, inside)
            })
            .collect();
        Self { grid, rotation, cells, cos_scale: grid.cos_bins as f64, cell_scale: 0.25 * count as f64 }
    }

    /// Bin index `cos_index * phi_bins + phi_index` of an escaping direction.
    #[inline]
    pub(super) fn bin(&self, dir: DVec3) -> usize {
        let g = self.grid;
        // Both products are at least 0, where truncation through i64 (one instruction, unlike
        // u64) gives the same index.
        let ic = ((dir.z.abs() * self.cos_scale) as i64 as usize).min(g.cos_bins - 1);
        let (c, s) = self.rotation;
        let p = diamond_angle(c * dir.x + s * dir.y, c * dir.y - s * dir.x);
        let cell = ((p * self.cell_scale) as i64 as usize).min(self.cells.len() - 1);
        let (below, edge) = self.cells[cell];
        let ip = (below + usize::from(p >= edge)).min(g.phi_bins - 1);
        ic * g.phi_bins + ip
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    /// The trigonometric reference: `floor(phi n / 2 pi)` of `phi = atan2` in `[0, 2 pi)`.
    fn reference_phi_bin(n: usize, x: f64, y: f64) -> (usize, f64) {
        let phi = y.atan2(x).rem_euclid(std::f64::consts::TAU);
        let u = phi * n as f64 / std::f64::consts::TAU;
        ((u as usize).min(n - 1), (u - u.round()).abs())
    }

    #[test]
    fn azimuth_bins_agree_with_atan2() {
        // 10^5 random directions per grid and rotation; directions within 1e-9 of a bin edge
        // (in units of bins) are skipped, where rounding may legitimately go either way. The
        // axes and the diagonals, where the diamond angle changes branch, are checked exactly.
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        for n in [1, 2, 3, 7, 64, 360, 1000] {
            for phi_i in [0.0_f64, 0.3, 2.0, -2.5] {
                let rotation = (phi_i.cos(), phi_i.sin());
                let binner = Binner::new(Grid { cos_bins: 4, phi_bins: n }, rotation);
                let check = |d: DVec3| {
                    let (c, s) = rotation;
                    let (x, y) = (c * d.x + s * d.y, c * d.y - s * d.x);
                    let (want, distance) = reference_phi_bin(n, x, y);
                    if n == 1 || distance > 1e-9 {
                        assert_eq!(binner.bin(d) % n, want, "n {n}, phi_i {phi_i}, d {d:?}");
                    }
                };
                for _ in 0..100_000 {
                    let phi = std::f64::consts::TAU * microsurface::random::open01(&mut rng);
                    let z = 2.0 * microsurface::random::open01(&mut rng) - 1.0;
                    let r = (1.0 - z * z).sqrt();
                    check(DVec3::new(r * phi.cos(), r * phi.sin(), z));
                }
                for k in 0..8 {
                    let a = phi_i + std::f64::consts::FRAC_PI_4 * k as f64 + 1e-6;
                    check(DVec3::new(a.cos(), a.sin(), 0.0));
                }
            }
        }
    }
}
