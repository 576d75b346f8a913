//! `smithwalk merl`: a measured-BRDF file in the MERL format (Matusik et al. 2003) from an
//! isotropic reflective sweep over the incident angle.
//!
//! The format: three little-endian `i32` dimensions (90, 90, 180), then three channels (red,
//! green, blue) of 90 x 90 x 180 little-endian `f64`, each channel indexed
//! `phi_d + 180 * (theta_d + 90 * theta_h)` over Rusinkiewicz's half/difference angles:
//! theta_h cell `floor(90 sqrt(theta_h / (pi/2)))`, theta_d cell `floor(90 theta_d / (pi/2))`,
//! phi_d cell `floor(180 phi_d / pi)` with phi_d folded into [0, pi) (reciprocity). A reader
//! multiplies the stored numbers by 1/1500, 1.15/1500 and 1.66/1500 for red, green and blue.
//!
//! Each cell holds the BRDF at its centre: the in/out pair of the centre's half/difference
//! angles (phi_h = 0), from the sweep's interpolated lobes ([`Sweep::brdf`]). Cells whose pair
//! lies below the horizon hold 0.

use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};

use anyhow::Result;
use glam::DVec3;

use crate::atomic::write_file_atomically;
use crate::exports::sweep::Sweep;
use crate::io::rundir::RunDir;

pub const THETA_H_CELLS: usize = 90;
pub const THETA_D_CELLS: usize = 90;
pub const PHI_D_CELLS: usize = 180;
/// The factors a MERL reader multiplies the stored numbers by, per channel.
pub const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// The in and out directions of half/difference angles with phi_h = 0 (Rusinkiewicz 1998):
/// the difference vector rotated by theta_h about y gives `wi`; `wo` is its mirror about the
/// half vector.
pub fn from_half_diff(theta_h: f64, theta_d: f64, phi_d: f64) -> (DVec3, DVec3) {
    let (sd, cd) = theta_d.sin_cos();
    let d = DVec3::new(sd * phi_d.cos(), sd * phi_d.sin(), cd);
    let (sh, ch) = theta_h.sin_cos();
    let wi = DVec3::new(d.x * ch + d.z * sh, d.y, -d.x * sh + d.z * ch);
    let h = DVec3::new(sh, 0.0, ch);
    (wi, 2.0 * wi.dot(h) * h - wi)
}

/// The bytes of the MERL file of a sweep.
pub fn merl_bytes(sweep: &Sweep) -> Vec<u8> {
    let cells = THETA_H_CELLS * THETA_D_CELLS * PHI_D_CELLS;
    let mut values = vec![0.0_f64; 3 * cells];
    for ih in 0..THETA_H_CELLS {
        let theta_h = ((ih as f64 + 0.5) / THETA_H_CELLS as f64).powi(2) * FRAC_PI_2;
        for id in 0..THETA_D_CELLS {
            let theta_d = (id as f64 + 0.5) / THETA_D_CELLS as f64 * FRAC_PI_2;
            for ip in 0..PHI_D_CELLS {
                let phi_d = (ip as f64 + 0.5) / PHI_D_CELLS as f64 * PI;
                let (wi, wo) = from_half_diff(theta_h, theta_d, phi_d);
                if wi.z <= 0.0 || wo.z <= 0.0 {
                    continue;
                }
                let f = sweep.brdf(wi, wo);
                let index = ip + PHI_D_CELLS * (id + THETA_D_CELLS * ih);
                for c in 0..3 {
                    values[c * cells + index] = f[c] / SCALE[c];
                }
            }
        }
    }
    let mut bytes = Vec::with_capacity(12 + 8 * values.len());
    for dim in [THETA_H_CELLS, THETA_D_CELLS, PHI_D_CELLS] {
        bytes.extend((dim as i32).to_le_bytes());
    }
    for v in values {
        bytes.extend(v.to_le_bytes());
    }
    bytes
}

/// Writes the MERL file of the sweep in `run_dir` to `out` (atomically).
pub fn export(run_dir: &Path, out: &Path) -> Result<PathBuf> {
    let run = RunDir::open(run_dir)?;
    let sweep = Sweep::read(&run)?;
    if let Some(note) = run.dropped_transmission()? {
        eprintln!("{note}");
    }
    write_file_atomically(out, merl_bytes(&sweep))
}
