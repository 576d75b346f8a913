//! MERL `.binary` export read back by an independent reader written here from the format
//! description (Matusik et al. 2003: header of three i32 dimensions 90 x 90 x 180; three f64
//! channels; half-angle cell floor(90 sqrt(theta_h / (pi/2))), difference cells
//! floor(90 theta_d / (pi/2)) and floor(180 phi_d / pi) with phi_d folded into [0, pi);
//! scales 1/1500, 1.15/1500, 1.66/1500), from the in/out directions by the half/difference
//! change of variables computed here with vector algebra (no rotations).
//!
//! Checks: the header and size; for three simulated incident angles, the reader's BRDF
//! averaged over each detector bin of the reflection lobe against the simulated bin's BSDF
//! (per channel: the relative L1 distance over the lobe, weighted by projected solid angle, at
//! most 2% above the bins' own noise;
//! the MERL cells are about 1 degree and the export interpolates between bins); and the
//! directional albedo integrated from the reader's BRDF against the run's albedo (within 2%).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use smithwalk::microsurface::DVec3;
use smithwalk::setup::config::Config;

const CELLS: usize = 90 * 90 * 180;

/// A MERL file, read from bytes.
struct Merl {
    values: Vec<f64>,
}

impl Merl {
    fn parse(bytes: &[u8]) -> Merl {
        let dims: Vec<i32> = bytes[..12].chunks(4).map(|b| i32::from_le_bytes(b.try_into().unwrap())).collect();
        assert_eq!(dims, [90, 90, 180]);
        assert_eq!(bytes.len(), 12 + 3 * 8 * CELLS);
        let values = bytes[12..].chunks(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect();
        Merl { values }
    }

    /// The BRDF per channel for light from `wi` to `wo` (both unit, above the horizon).
    fn lookup(&self, wi: DVec3, wo: DVec3) -> [f64; 3] {
        let h = (wi + wo).normalize();
        let theta_h = h.z.clamp(-1.0, 1.0).acos();
        let theta_d = wi.dot(h).clamp(-1.0, 1.0).acos();
        // phi_d: azimuth of wi about h, measured from the plane of h and the normal.
        let (x_axis, y_axis) = if theta_h > 1e-9 {
            // x axis: the tangent of h's azimuth pointing away from the normal's projection.
            let x = (h * h.z - DVec3::Z).normalize();
            (x, h.cross(x))
        } else {
            (DVec3::X, DVec3::Y)
        };
        let d = wi - h * wi.dot(h);
        let mut phi_d = d.dot(y_axis).atan2(d.dot(x_axis));
        if phi_d < 0.0 {
            phi_d += PI;
        }
        let ih = if theta_h <= 0.0 { 0 } else { ((theta_h / FRAC_PI_2).sqrt() * 90.0) as usize }.min(89);
        let id = ((theta_d / FRAC_PI_2 * 90.0) as usize).min(89);
        let ip = ((phi_d / PI * 180.0) as usize).min(179);
        let index = ip + 180 * (id + 90 * ih);
        let scale = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
        std::array::from_fn(|c| self.values[c * CELLS + index] * scale[c])
    }
}

fn direction(cos_theta: f64, phi: f64) -> DVec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

#[test]
fn merl_file_read_back_independently_matches_the_simulated_lobes() {
    // GGX alpha 0.5, Schlick conductor with coloured f0, theta_i 0..88 deg in steps of 4,
    // 1 500 000 photons per angle on a 32 x 64 grid.
    let thetas: Vec<String> = (0..=22).map(|i| (4 * i).to_string()).collect();
    let toml = format!(
        "paths = 1500000\nseed = 5\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.95, 0.6, 0.3]\n[incident]\ntheta_deg = [{}]\n[detector]\ncos_theta_bins = 32\nphi_bins = 64\nmax_order = 1\n",
        thetas.join(", ")
    );
    let config = Config::parse(&toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    let dir = tempfile::tempdir().unwrap();
    smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
    let file = smithwalk::exports::merl::export(dir.path(), &dir.path().join("ggx.binary")).unwrap();
    let merl = Merl::parse(&std::fs::read(file).unwrap());

    let (cos_bins, phi_bins) = (32, 64);
    for case in [5, 10, 15] {
        // theta_i = 20, 40, 60 deg
        let wi = direction((4.0 * case as f64).to_radians().cos(), 0.0);
        let smithwalk::engine::run::CaseResult::Rgb(d) = &sim.results[case] else { panic!("rgb run") };
        let n = d.tallies.photons;
        for c in 0..3 {
            let (mut l1, mut noise, mut norm, mut albedo) = (0.0, 0.0, 0.0, 0.0);
            for ic in 0..cos_bins {
                let solid = TAU / phi_bins as f64 * 0.5 * (((ic + 1) * (ic + 1) - ic * ic) as f64)
                    / (cos_bins * cos_bins) as f64;
                for ip in 0..phi_bins {
                    let tally = &d.tallies.orders[0].bins[ic * phi_bins + ip];
                    let (energy, se) = tally.mean_and_stderr(n, c);
                    let simulated = energy / solid;
                    // The reader's BRDF averaged over a 4 x 4 grid of the bin, cosine-weighted.
                    let (mut sum, mut weight) = (0.0, 0.0);
                    for a in 0..4 {
                        for b in 0..4 {
                            let u = (ic as f64 + (a as f64 + 0.5) / 4.0) / cos_bins as f64;
                            let p = (ip as f64 + (b as f64 + 0.5) / 4.0) / phi_bins as f64 * TAU;
                            sum += u * merl.lookup(wi, direction(u, p))[c];
                            weight += u;
                        }
                    }
                    let read = sum / weight;
                    l1 += (read - simulated).abs() * solid;
                    noise += (2.0 / PI).sqrt() * se;
                    norm += simulated * solid;
                    albedo += read * solid;
                }
            }
            // The bins' own noise contributes about sqrt(2/pi) SE each to the L1 distance.
            let excess = (l1 - noise) / norm;
            println!("case {case} channel {c}: relative L1 {:.4}, noise {:.4}", l1 / norm, noise / norm);
            assert!(excess < 0.02, "case {case} channel {c}: relative L1 {} beyond noise {}", l1 / norm, noise / norm);
            let measured = d.tallies.orders[0].albedo[0].mean_and_stderr(n, c).0;
            assert!((albedo / measured - 1.0).abs() < 0.02, "case {case} channel {c}: {albedo} vs {measured}");
        }
    }
}

#[test]
fn merl_export_refuses_runs_that_are_not_one_isotropic_material() {
    let dir = tempfile::tempdir().unwrap();
    for (toml, expected) in [
        (
            "paths = 100\n[surface]\nalpha = [0.3, 0.5]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [10, 20]\n",
            "sweeps the surface or material",
        ),
        (
            "paths = 100\n[surface]\nalpha = [[0.3, 0.5]]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [10, 20]\n",
            "isotropic",
        ),
    ] {
        let config = Config::parse(toml).unwrap();
        let sim = smithwalk::simulate(&config, Some(1), false).unwrap();
        smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
        let out = dir.path().join("x.binary");
        let err = smithwalk::exports::merl::export(dir.path(), &out).expect_err(toml).to_string();
        assert!(err.contains(expected), "{err}");
        assert!(!out.exists(), "no file on error");
    }
}
