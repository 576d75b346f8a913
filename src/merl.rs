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
//! angles (phi_h = 0), looked up in the measured all-orders reflection lobes: linear in the
//! incident angle between the swept cases (clamped outside them) and bilinear between bin
//! centres in (|cos theta_o|, phi_o - phi_i). Cells whose pair lies below the horizon hold 0.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::detector::Grid;
use crate::output::write_atomically;
use crate::rundir::{BinValue, RunDir};

pub const THETA_H_CELLS: usize = 90;
pub const THETA_D_CELLS: usize = 90;
pub const PHI_D_CELLS: usize = 180;
/// The factors a MERL reader multiplies the stored numbers by, per channel.
pub const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// The all-orders reflection lobes of an isotropic sweep over the incident angle.
pub struct Sweep {
    /// Incident polar angles (radians), ascending.
    theta_i: Vec<f64>,
    /// Per incident angle and channel: BSDF per bin in detector order.
    lobes: Vec<[Vec<f64>; 3]>,
    grid: Grid,
}

impl Sweep {
    /// Reads the sweep from a run directory: every case must be the same isotropic surface and
    /// material lit from outside, differing only in the incident angle.
    pub fn read(run: &RunDir) -> Result<Self> {
        let first = run.cases.first().context("the run has no cases")?;
        for case in &run.cases {
            let differs = case.ndf != first.ndf
                || case.alpha_x != first.alpha_x
                || case.smith != first.smith
                || case.normals != first.normals
                || case.material != first.material;
            if differs {
                bail!(
                    "{}: a MERL file holds one material, but the run sweeps the surface or material \
                     (cases 0 and {}); run one surface and material over many theta_deg",
                    run.path.display(),
                    case.index
                );
            }
            if case.alpha_x != case.alpha_y {
                bail!("surface.alpha = [{}, {}] is not allowed: MERL files are isotropic", case.alpha_x, case.alpha_y);
            }
            if case.side != crate::config::IncidentSide::Outside {
                bail!("incident.side = \"inside\" is not allowed: a MERL file is a reflection BRDF");
            }
        }
        let mut thetas: Vec<(f64, usize)> = run.cases.iter().map(|c| (c.theta_i_deg.to_radians(), c.index)).collect();
        thetas.sort_by(|a, b| a.0.total_cmp(&b.0));
        if thetas.windows(2).any(|w| w[0].0 == w[1].0) {
            bail!("incident: the sweep repeats an incident angle (several phi_deg?); give one phi and many theta_deg");
        }
        let measured = run.measured()?;
        let rgb = run.config.is_rgb();
        let lobes = thetas
            .iter()
            .map(|&(_, case)| {
                let channel = |c: usize| -> Result<Vec<f64>> {
                    let bins = measured
                        .get(case, 0, "R", if rgb { c } else { 0 })
                        .with_context(|| format!("lobes.csv has no all-orders reflection lobe for case {case}"))?;
                    Ok(bins.iter().map(|b: &BinValue| b.bsdf).collect())
                };
                Ok([channel(0)?, channel(1)?, channel(2)?])
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { theta_i: thetas.iter().map(|t| t.0).collect(), lobes, grid: run.grid })
    }

    /// The measured BRDF of one lobe at `wo`, bilinear between bin centres in (|cos theta|, phi)
    /// with phi periodic and |cos theta| clamped to the outer centres.
    fn lobe_at(&self, bins: &[f64], cos_o: f64, phi: f64) -> f64 {
        let g = self.grid;
        let u = (cos_o * g.cos_bins as f64 - 0.5).clamp(0.0, (g.cos_bins - 1) as f64);
        let v = phi.rem_euclid(TAU) / TAU * g.phi_bins as f64 - 0.5;
        let (i0, fu) = (u.floor() as usize, u.fract());
        let i1 = (i0 + 1).min(g.cos_bins - 1);
        let vf = v.floor();
        let fv = v - vf;
        let j0 = (vf as i64).rem_euclid(g.phi_bins as i64) as usize;
        let j1 = (j0 + 1) % g.phi_bins;
        let at = |i: usize, j: usize| bins[i * g.phi_bins + j];
        (1.0 - fu) * ((1.0 - fv) * at(i0, j0) + fv * at(i0, j1)) + fu * ((1.0 - fv) * at(i1, j0) + fv * at(i1, j1))
    }

    /// The BRDF per channel for light from `wi` leaving towards `wo` (both above the horizon).
    pub fn brdf(&self, wi: DVec3, wo: DVec3) -> [f64; 3] {
        let theta = wi.z.clamp(-1.0, 1.0).acos();
        let phi = wo.y.atan2(wo.x) - wi.y.atan2(wi.x);
        let k = self.theta_i.partition_point(|&t| t <= theta);
        let (lo, hi, t) = if k == 0 {
            (0, 0, 0.0)
        } else if k == self.theta_i.len() {
            (k - 1, k - 1, 0.0)
        } else {
            (k - 1, k, (theta - self.theta_i[k - 1]) / (self.theta_i[k] - self.theta_i[k - 1]))
        };
        std::array::from_fn(|c| {
            let a = self.lobe_at(&self.lobes[lo][c], wo.z, phi);
            let b = self.lobe_at(&self.lobes[hi][c], wo.z, phi);
            (1.0 - t) * a + t * b
        })
    }
}

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
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = out.file_name().and_then(|n| n.to_str()).context("--out needs a file name")?;
    crate::output::prepare_dir(dir)?;
    let written = write_atomically(dir, &[(name, merl_bytes(&sweep))])?;
    Ok(written.into_iter().next().expect("one file"))
}
