//! What a `smithwalk lut` table is, as its `lut.json` records it under `config`: the facet, the
//! microsurface and the grid (docs/exports.md). `smithwalk lut` writes it; `compare
//! --albedo-table` reads it back to refuse a table made for another surface than the run's.
//!
//! The record is flat, in the form table configs had before they were read with the run's
//! `[surface]` and `[material]` types, so that the `lut.json` of a table made then reads the
//! same; fields added since are left out when they hold their default.

use serde::{Deserialize, Serialize};

use crate::setup::config::{HeightKind, NdfKind, NormalsKind, SmithKind};

/// Which facet material a table is for.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum TableKind {
    /// Conductor with F = 1: all orders together are 1; the orders >= 2 are the energy a
    /// single-scattering model loses (Kulla-Conty).
    Conductor,
    /// Dielectric interface: reflection and transmission, light from outside and from inside.
    Dielectric,
    /// Hammon 2017's facet (Schlick-Fresnel specular over a Lambertian base).
    Hammon,
}

/// Where a table's nodes lie in each axis' interval `[lo, hi]`.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Nodes {
    /// Cell centres, `lo + (i + 1/2) (hi - lo) / n`: a texture's texel centres.
    #[default]
    Cells,
    /// The end points and between them evenly, `lo + i (hi - lo) / (n - 1)`: a texture read
    /// at `lo` and `hi` returns the nodes there, with no clamp error.
    Edges,
}

crate::setup::config::deserialize_by_name!(Nodes: [Nodes::Cells, Nodes::Edges]);

impl Nodes {
    /// `n` nodes of `[lo, hi]`.
    pub fn of(self, n: usize, [lo, hi]: [f64; 2]) -> Vec<f64> {
        match self {
            Nodes::Cells => (0..n).map(|i| lo + (i as f64 + 0.5) * (hi - lo) / n as f64).collect(),
            // The last node is `hi` itself, not `lo + (n - 1) * step` rounded.
            Nodes::Edges => {
                (0..n).map(|i| if i + 1 == n { hi } else { lo + i as f64 * (hi - lo) / (n - 1) as f64 }).collect()
            }
        }
    }

    fn is_cells(&self) -> bool {
        *self == Nodes::Cells
    }
}

/// The `config` of a table's `lut.json`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct TableRecord {
    pub table: TableKind,
    pub ndf: NdfKind,
    /// Nodes in mu = cos(theta_i) (default 32; 16 for dielectrics).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<usize>,
    /// Nodes in alpha (default 32; 16 for dielectrics).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<usize>,
    pub alpha_range: [f64; 2],
    /// Nodes in eta, dielectrics only (default 16).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<usize>,
    pub eta_range: [f64; 2],
    /// Hammon facet only: specular reflectance at normal incidence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f0: Option<f64>,
    /// Hammon facet only: albedo of the diffuse base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    pub max_order: u32,
    pub avg_nodes: usize,
    pub paths: u64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_stderr: Option<f64>,
    pub seed: u64,
    #[serde(default, skip_serializing_if = "Nodes::is_cells")]
    pub nodes: Nodes,
    #[serde(default = "uniform", skip_serializing_if = "is_uniform")]
    pub height: HeightKind,
    #[serde(default = "exact", skip_serializing_if = "is_exact")]
    pub smith: SmithKind,
    #[serde(default = "vndf", skip_serializing_if = "is_vndf")]
    pub normals: NormalsKind,
}

fn uniform() -> HeightKind {
    HeightKind::Uniform
}
fn is_uniform(h: &HeightKind) -> bool {
    *h == HeightKind::Uniform
}
fn exact() -> SmithKind {
    SmithKind::Exact
}
fn is_exact(s: &SmithKind) -> bool {
    *s == SmithKind::Exact
}
fn vndf() -> NormalsKind {
    NormalsKind::Vndf
}
fn is_vndf(n: &NormalsKind) -> bool {
    *n == NormalsKind::Vndf
}

/// The `lut.json` of a table, of which a reader needs the record only.
#[derive(Deserialize)]
struct TableJson {
    config: TableRecord,
}

impl TableRecord {
    /// Reads the record of the `lut.json` at `path`.
    pub fn read(path: &std::path::Path) -> anyhow::Result<Self> {
        use anyhow::Context;
        let text = crate::input::read_to_string(path, crate::input::MAX_CONFIG_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let json: TableJson = serde_json::from_str(&text)
            .with_context(|| format!("{}: not the `lut.json` of a `smithwalk lut` table", path.display()))?;
        Ok(json.config)
    }
}
