//! A `smithwalk lut` configuration: the microsurface in `[surface]` and the facet in
//! `[material]`, read by the run config's own types and checked by its validation, and the grid
//! in `[table]`.
//!
//! A table sweeps the roughness, and a dielectric table the relative index, along its axes: the
//! config leaves `surface.alpha` (and a dielectric's `material.eta`) out, and the axis replaces
//! it. `surface.alpha` holds the alpha nodes once read; a dielectric's `material.eta` holds the
//! first eta node, and the table's materials are that one at every eta node.

use std::path::Path;

use serde::Deserialize;

use crate::analysis::quadrature::gauss_legendre;
use crate::io::table_record::{Nodes, TableKind, TableRecord};
use crate::setup::config::{
    Alpha, Channels, Config, ConfigError, DetectorConfig, EnergyConfig, FresnelKind, IncidentConfig, IncidentSide,
    MaterialConfig, OneOrMany, PrecisionConfig, RUN_TABLES, Supplied, SurfaceConfig, invalid, locate,
    parse_toml_supplied,
};

/// The cosine of incidence at which a node at `mu = 0` is walked: light at exactly grazing
/// incidence never descends onto the surface (`Lambda = inf`, docs/theory.md §1.4), so the node
/// holds `E` at `theta_i` = 89.99994 deg. `E` approaches its limit about linearly in `mu`
/// (order 1 of the F = 1 GGX conductor, alpha 0.03: `1 - E_1` = 0.061 at `mu` = 1e-2 and
/// 7.2e-4 at 1e-4 by quadrature), so at 1e-6 the node is within ~1e-5 of it (docs/exports.md).
pub const MU_GRAZING: f64 = 1e-6;

/// The grid of a table config: `[table]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TableConfig {
    /// Nodes in mu = cos(theta_i) (default 32; 16 for dielectrics).
    pub mu: Option<usize>,
    /// Nodes in alpha (default 32; 16 for dielectrics).
    pub alpha: Option<usize>,
    #[serde(default = "default_alpha_range")]
    pub alpha_range: [f64; 2],
    /// Nodes in eta, dielectrics only (default 16).
    pub eta: Option<usize>,
    #[serde(default = "default_eta_range")]
    pub eta_range: [f64; 2],
    /// Cell centres (the default) or the intervals' end points.
    #[serde(default)]
    pub nodes: Nodes,
    /// Orders 1 .. max_order-1 are tabulated one by one, order max_order and above together.
    #[serde(default = "default_max_order")]
    pub max_order: u32,
    /// Gauss–Legendre incidence nodes for E_avg.
    #[serde(default = "default_avg_nodes")]
    pub avg_nodes: usize,
    /// Photons per cell, the most a cell gets.
    pub paths: u64,
    /// Stop a cell once every albedo in it has at most this standard error.
    pub target_stderr: Option<f64>,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

/// A `smithwalk lut` configuration (TOML).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LutConfig {
    pub surface: SurfaceConfig,
    pub material: MaterialConfig,
    pub table: TableConfig,
}

fn default_alpha_range() -> [f64; 2] {
    [0.0, 1.0]
}
fn default_eta_range() -> [f64; 2] {
    [1.0, 3.0]
}
fn default_max_order() -> u32 {
    4
}
fn default_avg_nodes() -> usize {
    16
}
fn default_seed() -> u64 {
    1
}

/// The top-level keys of a table config before it was read with the run's types.
const FLAT_KEYS: [&str; 14] = [
    "table",
    "ndf",
    "mu",
    "alpha",
    "alpha_range",
    "eta",
    "eta_range",
    "f0",
    "albedo",
    "max_order",
    "avg_nodes",
    "paths",
    "target_stderr",
    "seed",
];

/// Refuses a table config in the flat form of before (`table = "conductor"`, `mu = 32`, ...):
/// the message names the keys it has and where they go now.
fn not_flat(document: &toml::Table) -> Result<(), String> {
    let flat: Vec<String> = FLAT_KEYS
        .iter()
        .filter(|k| document.get(**k).is_some_and(|v| !v.is_table()))
        .map(|k| format!("`{k}`"))
        .collect();
    if flat.is_empty() {
        return Ok(());
    }
    Err(format!(
        "a table config in the form before `smithwalk lut` read the run's types (it has {} at the top); write the \
         NDF as [surface] ndf, the facet as [material] kind (a hammon's f0 and albedo there too), and move `mu`, \
         `alpha`, `alpha_range`, `eta`, `eta_range`, `max_order`, `avg_nodes`, `paths`, `target_stderr` and `seed` \
         into [table] (configs/lut-*.toml, docs/exports.md)",
        flat.join(", ")
    ))
}

/// Refuses a run config (`smithwalk run`) read as a table config: the message names the run
/// config's tables it has that a table config has not, and where the table format is described.
fn not_a_run_config(document: &toml::Table) -> Result<(), String> {
    let tables: Vec<String> = RUN_TABLES
        .iter()
        .filter(|t| !["surface", "material"].contains(*t) && document.contains_key(**t))
        .map(|t| format!("`[{t}]`"))
        .collect();
    if tables.is_empty() {
        return Ok(());
    }
    Err(format!(
        "this looks like a run config for `smithwalk run` (it has {}); `smithwalk lut` reads a table config, \
         with [surface], [material] (kind = \"conductor\", \"dielectric\" or \"hammon\") and the grid in [table] \
         (configs/lut-*.toml, docs/exports.md)",
        tables.join(", ")
    ))
}

/// One value of a `[surface]` list, or an error: a table is made for one microsurface.
fn one<T: Copy>(field: &str, values: &OneOrMany<T>) -> Result<T, ConfigError> {
    match values {
        OneOrMany::One(v) => Ok(*v),
        OneOrMany::Many(v) => Err(invalid(
            field,
            format!("a list of {}", v.len()),
            "one value: a table is made for one microsurface (one table per value)",
        )),
    }
}

/// The value of a one-channel material parameter, or an error: a table has one channel.
fn mono(field: &str, c: Channels) -> Result<f64, ConfigError> {
    match c {
        Channels::Mono(v) => Ok(v),
        Channels::Rgb(rgb) => Err(invalid(field, format!("{rgb:?}"), "one number: a table has one channel")),
    }
}

/// A field of the run config that a table config names otherwise.
fn in_table_terms(e: ConfigError) -> ConfigError {
    match e {
        ConfigError::Invalid { field, value, allowed } if field == "paths" || field == "seed" => {
            ConfigError::Invalid { field: format!("table.{field}"), value, allowed }
        }
        e => e,
    }
}

impl LutConfig {
    /// Reads, parses and validates a TOML table configuration.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = crate::input::read_to_string(path, crate::input::MAX_CONFIG_BYTES)
            .map_err(|cause| ConfigError::Read { path: path.display().to_string(), cause })?;
        Self::parse(&text).map_err(|e| e.in_source(&path.display().to_string()))
    }

    /// Parses and validates TOML text; errors name it `<text>`.
    pub fn parse(text: &str) -> Result<Self, ConfigError> {
        let in_text = |message: String| ConfigError::Parse { path: "<text>".into(), message };
        let document = text.parse::<toml::Table>().ok();
        if let Some(document) = &document {
            not_a_run_config(document).map_err(in_text)?;
            not_flat(document).map_err(in_text)?;
        }
        // Placeholders that satisfy the run's types; the axes replace them below.
        let alpha = Supplied {
            table: "surface",
            key: "alpha",
            value: "1.0".into(),
            by: "a table sweeps alpha: its axis, `alpha` nodes over `alpha_range` in [table], replaces it".into(),
        };
        let eta = Supplied {
            table: "material",
            key: "eta",
            value: "1.5".into(),
            by: "a dielectric table sweeps eta: its axis, `eta` nodes over `eta_range` in [table], replaces it".into(),
        };
        let kind = document.as_ref().and_then(|d| d.get("material")?.get("kind")?.as_str().map(String::from));
        let supplied = if kind.as_deref() == Some("dielectric") { vec![alpha, eta] } else { vec![alpha] };
        if document.as_ref().and_then(|d| d.get("material")).is_some_and(toml::Value::is_array) {
            let allowed = "one [material] table: a table is made for one facet (one config per material)";
            return Err(locate(invalid("material", "[[material]]", allowed), text, true).in_source("<text>"));
        }
        let mut config: LutConfig = parse_toml_supplied(text, &supplied)?;
        config.validate().map_err(|e| locate(e, text, true).in_source("<text>"))?;
        config.surface.alpha = OneOrMany::Many(config.alpha_nodes().into_iter().map(Alpha::Isotropic).collect());
        let first_eta = config.eta_nodes().first().copied();
        if let (MaterialConfig::Dielectric { eta, .. }, Some(first)) = (&mut config.material, first_eta) {
            *eta = first;
        }
        Ok(config)
    }

    /// The facet of the table, or an error naming the `[material]` field that no table has.
    pub fn kind(&self) -> Result<TableKind, ConfigError> {
        match &self.material {
            MaterialConfig::Conductor { fresnel: FresnelKind::None, .. } => Ok(TableKind::Conductor),
            MaterialConfig::Conductor { fresnel, .. } => Err(invalid(
                "material.fresnel",
                format!("\"{}\"", crate::setup::config::values::name(fresnel)),
                "\"none\": a conductor table is the F = 1 (Kulla-Conty) table",
            )),
            MaterialConfig::Dielectric { .. } => Ok(TableKind::Dielectric),
            MaterialConfig::Hammon { f0, albedo, .. } => {
                mono("material.f0", *f0)?;
                mono("material.albedo", *albedo)?;
                Ok(TableKind::Hammon)
            }
            MaterialConfig::Diffuse { .. } => Err(invalid(
                "material.kind",
                "\"diffuse\"",
                "\"conductor\", \"dielectric\" or \"hammon\", the facets `smithwalk lut` tabulates",
            )),
        }
    }

    pub(super) fn is_dielectric(&self) -> bool {
        matches!(self.material, MaterialConfig::Dielectric { .. })
    }

    fn default_nodes(&self) -> usize {
        if self.is_dielectric() { 16 } else { 32 }
    }

    pub fn mu_nodes(&self) -> Vec<f64> {
        self.table.nodes.of(self.table.mu.unwrap_or(self.default_nodes()), [0.0, 1.0])
    }

    pub fn alpha_nodes(&self) -> Vec<f64> {
        self.table.nodes.of(self.table.alpha.unwrap_or(self.default_nodes()), self.table.alpha_range)
    }

    /// The eta nodes of a dielectric table; empty for the other tables.
    pub fn eta_nodes(&self) -> Vec<f64> {
        if self.is_dielectric() {
            self.table.nodes.of(self.table.eta.unwrap_or(16), self.table.eta_range)
        } else {
            Vec::new()
        }
    }

    /// The incidence nodes and weights of E_avg = ∫_0^1 E(mu) 2 mu dmu (weights include 2 mu).
    pub fn avg_rule(&self) -> Vec<(f64, f64)> {
        gauss_legendre(self.table.avg_nodes, 0.0, 1.0).into_iter().map(|(mu, w)| (mu, 2.0 * mu * w)).collect()
    }

    /// Checks every field; errors name the field, the value and what is allowed. `[surface]`
    /// and `[material]` are checked by the run config's validation of the run that measures
    /// the table.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let t = &self.table;
        let kind = self.record()?.table;
        let least = match t.nodes {
            Nodes::Cells => 1,
            Nodes::Edges => 2,
        };
        for (field, n) in [("table.mu", t.mu), ("table.alpha", t.alpha), ("table.eta", t.eta)] {
            if let Some(n) = n
                && !(least..=1024).contains(&n)
            {
                return Err(invalid(
                    field,
                    n,
                    format!("a node count from {least} to 1024 (with nodes = {t:?})", t = t.nodes),
                ));
            }
        }
        if t.eta.is_some() && kind != TableKind::Dielectric {
            return Err(invalid("table.eta", t.eta.unwrap_or(0), "only with [material] kind = \"dielectric\""));
        }
        let [lo, hi] = t.alpha_range;
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo && hi <= 3.0) {
            return Err(invalid("table.alpha_range", format!("[{lo}, {hi}]"), "[lo, hi] with 0 <= lo < hi <= 3"));
        }
        let [lo, hi] = t.eta_range;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo && hi <= 10.0) {
            return Err(invalid("table.eta_range", format!("[{lo}, {hi}]"), "[lo, hi] with 0 < lo < hi <= 10"));
        }
        if let Some(e) = self.eta_nodes().into_iter().find(|&e| e == 1.0) {
            return Err(invalid(
                "table.eta_range",
                format!("[{lo}, {hi}] (a node is {e})"),
                "ranges whose nodes avoid 1",
            ));
        }
        if !(1..=64).contains(&t.max_order) {
            return Err(invalid("table.max_order", t.max_order, "an order from 1 to 64"));
        }
        if !(2..=256).contains(&t.avg_nodes) {
            return Err(invalid("table.avg_nodes", t.avg_nodes, "a node count from 2 to 256"));
        }
        if let Some(e) = t.target_stderr
            && !(e.is_finite() && e > 0.0)
        {
            return Err(invalid("table.target_stderr", e, "a standard error > 0"));
        }
        self.run_config().validate().map_err(in_table_terms)
    }

    /// The materials of the table, one per eta node for dielectrics.
    pub(super) fn materials(&self) -> Vec<MaterialConfig> {
        match &self.material {
            MaterialConfig::Dielectric { name, .. } => {
                self.eta_nodes().into_iter().map(|eta| MaterialConfig::Dielectric { eta, name: name.clone() }).collect()
            }
            material => vec![material.clone()],
        }
    }

    pub(super) fn sides(&self) -> Vec<IncidentSide> {
        if self.is_dielectric() {
            vec![IncidentSide::Outside, IncidentSide::Inside]
        } else {
            vec![IncidentSide::Outside]
        }
    }

    /// The alpha nodes that are walked: all but a node at alpha = 0, the flat surface, whose
    /// albedos are exact (`super::flat`).
    pub(super) fn walked_alpha(&self) -> Vec<f64> {
        self.alpha_nodes().into_iter().filter(|&a| a > 0.0).collect()
    }

    /// The incidence cosines walked: the table's (a node at 0 at [`MU_GRAZING`]), then E_avg's.
    fn walked_mu(&self) -> Vec<f64> {
        let mut mu: Vec<f64> = self.mu_nodes().into_iter().map(|m| m.max(MU_GRAZING)).collect();
        mu.extend(self.avg_rule().into_iter().map(|(m, _)| m));
        mu
    }

    /// The run that measures the table: one case per walked (alpha, eta, side, mu) node, a
    /// 1 x 1 detector (only albedos are kept), orders folded at `max_order`.
    pub fn run_config(&self) -> Config {
        let t = &self.table;
        Config {
            paths: t.paths,
            seed: t.seed,
            surface: SurfaceConfig {
                alpha: OneOrMany::Many(self.walked_alpha().into_iter().map(Alpha::Isotropic).collect()),
                ..self.surface.clone()
            },
            // One `[material]` names its errors `material`, as the config does.
            material: if self.is_dielectric() {
                OneOrMany::Many(self.materials())
            } else {
                OneOrMany::One(self.material.clone())
            },
            incident: IncidentConfig {
                theta_deg: Some(OneOrMany::Many(self.walked_mu().into_iter().map(|m| m.acos().to_degrees()).collect())),
                theta_rad: None,
                phi_deg: OneOrMany::One(0.0),
                side: OneOrMany::Many(self.sides()),
            },
            detector: DetectorConfig { cos_theta_bins: 1, phi_bins: 1, max_order: Some(t.max_order) },
            energy: EnergyConfig::default(),
            precision: t.target_stderr.map(|e| PrecisionConfig {
                target_rel_stderr: None,
                target_stderr: Some(e),
                orders: t.max_order as usize,
            }),
            compare: None,
        }
    }

    /// What the table is, as its `lut.json` records it.
    pub fn record(&self) -> Result<TableRecord, ConfigError> {
        let t = &self.table;
        let s = &self.surface;
        let (f0, albedo) = match self.material {
            MaterialConfig::Hammon { f0, albedo, .. } => (Some(f0.channel(0)), Some(albedo.channel(0))),
            _ => (None, None),
        };
        Ok(TableRecord {
            table: self.kind()?,
            ndf: one("surface.ndf", &s.ndf)?,
            mu: t.mu,
            alpha: t.alpha,
            alpha_range: t.alpha_range,
            eta: t.eta,
            eta_range: t.eta_range,
            f0,
            albedo,
            max_order: t.max_order,
            avg_nodes: t.avg_nodes,
            paths: t.paths,
            target_stderr: t.target_stderr,
            seed: t.seed,
            nodes: t.nodes,
            height: one("surface.height", &s.height)?,
            smith: one("surface.smith", &s.smith)?,
            normals: one("surface.normals", &s.normals)?,
        })
    }
}
