//! An isotropic reflective sweep: the all-orders reflection lobes of one surface and material
//! lit from outside at many incident angles, read from a run directory and interpolated to any
//! pair of directions. The measured-BRDF exports ([`crate::exports::merl`], [`crate::exports::rgl`]) sample it.

use std::f64::consts::TAU;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::engine::detector::Grid;
use crate::io::rundir::{BinValue, RunDir};
use microsurface::ndf::AnyNdf;

use crate::setup::config::IncidentSide;

/// The all-orders reflection lobes of an isotropic sweep over the incident angle.
pub struct Sweep {
    /// The surface's normal distribution with its (isotropic) roughness.
    pub ndf: AnyNdf,
    /// One line naming the surface, the material and the incident angles.
    pub description: String,
    /// Incident polar angles (radians), ascending.
    pub theta_i: Vec<f64>,
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
            let differs = case.surface != first.surface || case.material != first.material;
            if differs {
                bail!(
                    "{}: a measured-BRDF file holds one material, but the run sweeps the surface or \
                     material (cases 0 and {}); run one surface and material over many theta_deg",
                    run.path.display(),
                    case.index
                );
            }
            if case.roughness().x != case.roughness().y {
                bail!(
                    "surface.alpha = [{}, {}] is not allowed: measured-BRDF exports are isotropic",
                    case.roughness().x,
                    case.roughness().y
                );
            }
            if case.side != IncidentSide::Outside {
                bail!("incident.side = \"inside\" is not allowed: measured-BRDF exports are reflection BRDFs");
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
        let description = format!(
            "smithwalk: {} alpha {}, {}, all orders of reflection, theta_i {}..{} deg in {} steps",
            first.surface.ndf.name(),
            first.roughness().x,
            first.material_label(),
            thetas[0].0.to_degrees(),
            thetas[thetas.len() - 1].0.to_degrees(),
            thetas.len()
        );
        Ok(Self {
            ndf: first.surface.ndf,
            description,
            theta_i: thetas.iter().map(|t| t.0).collect(),
            lobes,
            grid: run.grid,
        })
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

    /// The BRDF per channel for light from `wi` leaving towards `wo` (both above the horizon):
    /// linear in the incident angle between the swept cases (clamped outside them), bilinear
    /// between bin centres in (|cos theta_o|, phi_o - phi_i).
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
