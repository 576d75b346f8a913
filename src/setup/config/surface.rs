//! The `[surface]` table: NDF, roughness, height distribution, Smith variant and law of hit
//! normals.

use serde::{Deserialize, Serialize};

use super::values::{Alpha, OneOrMany, deserialize_by_name};

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum NdfKind {
    Ggx,
    Beckmann,
    #[serde(rename = "student-t")]
    StudentT,
}

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum HeightKind {
    Uniform,
    Gaussian,
}

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SmithKind {
    Exact,
    Symmetric,
}

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum NormalsKind {
    Vndf,
    HammonRejection,
}

deserialize_by_name!(NdfKind: [NdfKind::Ggx, NdfKind::Beckmann, NdfKind::StudentT]);
deserialize_by_name!(HeightKind: [HeightKind::Uniform, HeightKind::Gaussian]);
deserialize_by_name!(SmithKind: [SmithKind::Exact, SmithKind::Symmetric]);
deserialize_by_name!(NormalsKind: [NormalsKind::Vndf, NormalsKind::HammonRejection]);

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceConfig {
    #[serde(default = "default_ndf")]
    pub ndf: OneOrMany<NdfKind>,
    pub alpha: OneOrMany<Alpha>,
    /// The Student-T shapes (theory §1.6), a sweep axis of the `student-t` NDF only.
    #[serde(default)]
    pub gamma: Option<OneOrMany<f64>>,
    #[serde(default = "default_height")]
    pub height: OneOrMany<HeightKind>,
    #[serde(default = "default_smith")]
    pub smith: OneOrMany<SmithKind>,
    #[serde(default = "default_normals")]
    pub normals: OneOrMany<NormalsKind>,
}

fn default_ndf() -> OneOrMany<NdfKind> {
    OneOrMany::One(NdfKind::Ggx)
}
fn default_height() -> OneOrMany<HeightKind> {
    OneOrMany::One(HeightKind::Uniform)
}
fn default_smith() -> OneOrMany<SmithKind> {
    OneOrMany::One(SmithKind::Exact)
}
fn default_normals() -> OneOrMany<NormalsKind> {
    OneOrMany::One(NormalsKind::Vndf)
}

impl SurfaceConfig {
    /// The NDF axis of the sweep: each NDF once, `student-t` once per `gamma` (the shape is
    /// `None` for the others).
    pub fn ndf_shapes(&self) -> Vec<(NdfKind, Option<f64>)> {
        let gammas = self.gamma.as_ref().map(|g| g.values()).unwrap_or_default();
        self.ndf
            .values()
            .into_iter()
            .flat_map(|kind| match kind {
                NdfKind::StudentT => gammas.iter().map(|&g| (kind, Some(g))).collect::<Vec<_>>(),
                _ => vec![(kind, None)],
            })
            .collect()
    }
}
