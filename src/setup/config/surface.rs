//! The `[surface]` table: NDF, roughness, height distribution, Smith variant and law of hit
//! normals.

use serde::{Deserialize, Serialize};

use super::values::{Alpha, OneOrMany};

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum NdfKind {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum HeightKind {
    Uniform,
    Gaussian,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SmithKind {
    Exact,
    Symmetric,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum NormalsKind {
    Vndf,
    HammonRejection,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceConfig {
    #[serde(default = "default_ndf")]
    pub ndf: OneOrMany<NdfKind>,
    pub alpha: OneOrMany<Alpha>,
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
