//! `smithwalk lut`: energy-compensation tables. The directional albedo E(mu, alpha) of the
//! Smith microsurface per bounce order and for all orders (docs/theory.md §9.4), and its cosine-
//! weighted hemispherical average E_avg(alpha) = 2 ∫ E(mu) mu dmu, for the conductor with F = 1
//! (the Kulla-Conty tables), the dielectric E(mu, alpha, eta) in reflection and transmission
//! from both sides, and the `hammon` facet. Every value is a walk measurement with its
//! standard error; cells stop at a requested standard error.
//!
//! The table grids are cell centres: mu_i = (i + 1/2) / n_mu, and likewise alpha and eta over
//! their ranges. E_avg is a Gauss–Legendre sum over its own incidence nodes in mu (E is smooth
//! in mu, so the rule's error is far below the statistical one), not a sum over the table grid.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::analysis::quadrature::gauss_legendre;
use crate::atomic::write_atomically;
use crate::engine::detector::Hemisphere;
use crate::engine::run::Estimator;
use crate::engine::{RunOptions, Simulation};
use crate::io::output::name;
use crate::setup::config::{
    Alpha, Channels, Config, ConfigError, DetectorConfig, EnergyConfig, IncidentConfig, IncidentSide, MaterialConfig,
    NdfKind, OneOrMany, PrecisionConfig, RUN_TABLES, SurfaceConfig, invalid, parse_toml,
};

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

/// A `smithwalk lut` configuration (TOML).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LutConfig {
    pub table: TableKind,
    #[serde(default = "default_ndf")]
    pub ndf: NdfKind,
    /// Nodes in mu = cos(theta_i) (default 32; 16 for dielectrics).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<usize>,
    /// Nodes in alpha (default 32; 16 for dielectrics).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<usize>,
    #[serde(default = "default_alpha_range")]
    pub alpha_range: [f64; 2],
    /// Nodes in eta, dielectrics only (default 16).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<usize>,
    #[serde(default = "default_eta_range")]
    pub eta_range: [f64; 2],
    /// Hammon facet only: specular reflectance at normal incidence (default 0.04).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f0: Option<f64>,
    /// Hammon facet only: albedo of the diffuse base (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    /// Orders 1 .. max_order-1 are tabulated one by one, order max_order and above together.
    #[serde(default = "default_max_order")]
    pub max_order: u32,
    /// Gauss–Legendre incidence nodes for E_avg.
    #[serde(default = "default_avg_nodes")]
    pub avg_nodes: usize,
    /// Photons per cell, the most a cell gets.
    pub paths: u64,
    /// Stop a cell once every albedo in it has at most this standard error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_stderr: Option<f64>,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_ndf() -> NdfKind {
    NdfKind::Ggx
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

/// `n` cell centres of `[lo, hi]`.
fn cell_centres(n: usize, [lo, hi]: [f64; 2]) -> Vec<f64> {
    (0..n).map(|i| lo + (i as f64 + 0.5) * (hi - lo) / n as f64).collect()
}

/// Refuses a run config (`smithwalk run`) read as a table config: the message names the run
/// config's tables it has and where the table format is described.
fn not_a_run_config(document: &toml::Table) -> Result<(), String> {
    let tables: Vec<String> =
        RUN_TABLES.iter().filter(|t| document.contains_key(**t)).map(|t| format!("`[{t}]`")).collect();
    if tables.is_empty() {
        return Ok(());
    }
    Err(format!(
        "this looks like a run config for `smithwalk run` (it has {}); `smithwalk lut` reads a table config, \
         with `table` = \"conductor\", \"dielectric\" or \"hammon\" and its grid (configs/lut-*.toml, docs/exports.md)",
        tables.join(", ")
    ))
}

impl LutConfig {
    /// Reads, parses and validates a TOML table configuration.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|cause| ConfigError::Read { path: path.display().to_string(), cause })?;
        let in_file = |e: ConfigError| e.in_source(&path.display().to_string());
        if let Ok(document) = text.parse::<toml::Table>() {
            not_a_run_config(&document)
                .map_err(|message| in_file(ConfigError::Parse { path: String::new(), message }))?;
        }
        let config: LutConfig = parse_toml(&text).map_err(in_file)?;
        config.validate().map_err(in_file)?;
        Ok(config)
    }

    fn is_dielectric(&self) -> bool {
        self.table == TableKind::Dielectric
    }

    fn default_nodes(&self) -> usize {
        if self.is_dielectric() { 16 } else { 32 }
    }

    pub fn mu_nodes(&self) -> Vec<f64> {
        cell_centres(self.mu.unwrap_or(self.default_nodes()), [0.0, 1.0])
    }

    pub fn alpha_nodes(&self) -> Vec<f64> {
        cell_centres(self.alpha.unwrap_or(self.default_nodes()), self.alpha_range)
    }

    /// The eta nodes of a dielectric table; empty for the other tables.
    pub fn eta_nodes(&self) -> Vec<f64> {
        if self.is_dielectric() { cell_centres(self.eta.unwrap_or(16), self.eta_range) } else { Vec::new() }
    }

    /// The incidence nodes and weights of E_avg = ∫_0^1 E(mu) 2 mu dmu (weights include 2 mu).
    pub fn avg_rule(&self) -> Vec<(f64, f64)> {
        gauss_legendre(self.avg_nodes, 0.0, 1.0).into_iter().map(|(mu, w)| (mu, 2.0 * mu * w)).collect()
    }

    /// Checks every field; errors name the field, the value and what is allowed.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let counts = [("mu", self.mu), ("alpha", self.alpha), ("eta", self.eta)];
        for (field, n) in counts {
            if let Some(n) = n
                && !(1..=1024).contains(&n)
            {
                return Err(invalid(field, n, "a node count from 1 to 1024"));
            }
        }
        if self.eta.is_some() && !self.is_dielectric() {
            return Err(invalid("eta", self.eta.unwrap_or(0), "only with table = \"dielectric\""));
        }
        let [lo, hi] = self.alpha_range;
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo && hi <= 3.0) {
            return Err(invalid("alpha_range", format!("[{lo}, {hi}]"), "[lo, hi] with 0 <= lo < hi <= 3"));
        }
        let [lo, hi] = self.eta_range;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo && hi <= 10.0) {
            return Err(invalid("eta_range", format!("[{lo}, {hi}]"), "[lo, hi] with 0 < lo < hi <= 10"));
        }
        if let Some(e) = self.eta_nodes().into_iter().find(|&e| e == 1.0) {
            return Err(invalid("eta_range", format!("[{lo}, {hi}] (a node is {e})"), "ranges whose nodes avoid 1"));
        }
        for (field, v) in [("f0", self.f0), ("albedo", self.albedo)] {
            if let Some(v) = v {
                if self.table != TableKind::Hammon {
                    return Err(invalid(field, v, "only with table = \"hammon\""));
                }
                if !(0.0..=1.0).contains(&v) {
                    return Err(invalid(field, v, "a value in [0, 1]"));
                }
            }
        }
        if !(1..=64).contains(&self.max_order) {
            return Err(invalid("max_order", self.max_order, "an order from 1 to 64"));
        }
        if !(2..=256).contains(&self.avg_nodes) {
            return Err(invalid("avg_nodes", self.avg_nodes, "a node count from 2 to 256"));
        }
        if let Some(t) = self.target_stderr
            && !(t.is_finite() && t > 0.0)
        {
            return Err(invalid("target_stderr", t, "a standard error > 0"));
        }
        self.run_config().validate()
    }

    /// The materials of the table, one per eta node for dielectrics.
    fn materials(&self) -> Vec<MaterialConfig> {
        match self.table {
            TableKind::Conductor => vec![MaterialConfig::Conductor {
                fresnel: crate::setup::config::FresnelKind::None,
                f0: None,
                eta: None,
                k: None,
                name: None,
            }],
            TableKind::Dielectric => {
                self.eta_nodes().into_iter().map(|eta| MaterialConfig::Dielectric { eta, name: None }).collect()
            }
            TableKind::Hammon => vec![MaterialConfig::Hammon {
                f0: Channels::Mono(self.f0.unwrap_or(0.04)),
                albedo: Channels::Mono(self.albedo.unwrap_or(1.0)),
                name: None,
            }],
        }
    }

    fn sides(&self) -> Vec<IncidentSide> {
        if self.is_dielectric() {
            vec![IncidentSide::Outside, IncidentSide::Inside]
        } else {
            vec![IncidentSide::Outside]
        }
    }

    /// The incidence nodes walked: the table's, then E_avg's.
    fn all_mu(&self) -> Vec<f64> {
        let mut mu = self.mu_nodes();
        mu.extend(self.avg_rule().into_iter().map(|(m, _)| m));
        mu
    }

    /// The run that measures the table: one case per (alpha, eta, side, mu) node, a 1 x 1
    /// detector (only albedos are kept), orders folded at `max_order`.
    pub fn run_config(&self) -> Config {
        Config {
            paths: self.paths,
            seed: self.seed,
            surface: SurfaceConfig {
                ndf: OneOrMany::One(self.ndf),
                alpha: OneOrMany::Many(self.alpha_nodes().into_iter().map(Alpha::Isotropic).collect()),
                height: OneOrMany::One(crate::setup::config::HeightKind::Uniform),
                smith: OneOrMany::One(crate::setup::config::SmithKind::Exact),
                normals: OneOrMany::One(crate::setup::config::NormalsKind::Vndf),
            },
            material: OneOrMany::Many(self.materials()),
            incident: IncidentConfig {
                theta_deg: Some(OneOrMany::Many(self.all_mu().into_iter().map(|m| m.acos().to_degrees()).collect())),
                theta_rad: None,
                phi_deg: OneOrMany::One(0.0),
                side: OneOrMany::Many(self.sides()),
            },
            detector: DetectorConfig { cos_theta_bins: 1, phi_bins: 1, max_order: Some(self.max_order) },
            energy: EnergyConfig::default(),
            precision: self.target_stderr.map(|t| PrecisionConfig {
                target_rel_stderr: None,
                target_stderr: Some(t),
                orders: self.max_order as usize,
            }),
            compare: None,
        }
    }

    /// The tabulated quantities: per side and hemisphere, all orders and each order slot.
    fn quantities(&self) -> Vec<Quantity> {
        let hemispheres: &[Hemisphere] =
            if self.is_dielectric() { &[Hemisphere::R, Hemisphere::T] } else { &[Hemisphere::R] };
        let mut out = Vec::new();
        for side in self.sides() {
            for &hemisphere in hemispheres {
                for slot in 0..=self.max_order as usize {
                    let order = match slot {
                        0 => "all".to_string(),
                        k if k == self.max_order as usize => format!("{k}plus"),
                        k => k.to_string(),
                    };
                    let prefix = match (self.is_dielectric(), side) {
                        (false, _) => "",
                        (true, IncidentSide::Outside) => "outside_",
                        (true, IncidentSide::Inside) => "inside_",
                    };
                    out.push(Quantity {
                        name: format!("{prefix}{hemisphere:?}_{order}"),
                        side,
                        hemisphere,
                        slot,
                        order,
                    });
                }
            }
        }
        out
    }
}

/// One tabulated albedo: a side, a hemisphere and an order slot (0 = all orders).
#[derive(Clone, Debug, PartialEq)]
pub struct Quantity {
    /// Identifier-safe name, e.g. `R_all`, `outside_T_2`, `R_4plus`.
    pub name: String,
    pub side: IncidentSide,
    pub hemisphere: Hemisphere,
    pub slot: usize,
    /// `all`, `1`, `2`, ... or `Kplus` (order K and above).
    pub order: String,
}

/// A table of one quantity: E at `[eta][alpha][mu]` and E_avg at `[eta][alpha]`, each with
/// its standard error (one eta slice for conductor and Hammon tables).
#[derive(Clone, Debug, PartialEq)]
pub struct QuantityTable {
    pub quantity: Quantity,
    pub e: Vec<f64>,
    pub e_stderr: Vec<f64>,
    pub avg: Vec<f64>,
    pub avg_stderr: Vec<f64>,
}

/// The measured tables.
#[derive(Clone, Debug)]
pub struct Lut {
    pub config: LutConfig,
    pub mu: Vec<f64>,
    pub alpha: Vec<f64>,
    /// Empty except for dielectric tables.
    pub eta: Vec<f64>,
    pub tables: Vec<QuantityTable>,
    /// Photons walked per table cell `[eta][alpha][mu]` (side outside; precision targets stop
    /// cells at different counts).
    pub photons: Vec<u64>,
    pub wall_seconds: f64,
}

impl Lut {
    fn slices(&self) -> usize {
        self.eta.len().max(1)
    }

    pub fn table(&self, name: &str) -> Option<&QuantityTable> {
        self.tables.iter().find(|t| t.quantity.name == name)
    }
}

/// Walks every cell of the table configuration and assembles the tables.
pub fn build(config: &LutConfig, threads: Option<usize>, show_progress: bool) -> Result<Lut> {
    config.validate()?;
    let run = config.run_config();
    let options = RunOptions {
        estimator: Estimator::Walk,
        shard: crate::engine::run::Shard::WHOLE,
        threads,
        show_progress,
        max_memory: None,
    };
    let sim = crate::engine::simulate_from(&run, &options, None, &mut |_, _, _| Ok(()))?;
    Ok(assemble(config, &sim))
}

/// Splits the simulation's cases (ordered alpha, material = eta, side, mu) into tables.
fn assemble(config: &LutConfig, sim: &Simulation) -> Lut {
    let (mu, alpha, eta, rule) = (config.mu_nodes(), config.alpha_nodes(), config.eta_nodes(), config.avg_rule());
    let sides = config.sides();
    // The rule's weights add up to 1 up to rounding; dividing by their sum makes an albedo of
    // exactly 1 at every node (a conductor's all orders) average to exactly 1.
    let weights: f64 = rule.iter().map(|&(_, w)| w).sum();
    let (n_mu, n_all_mu, slices) = (mu.len(), mu.len() + rule.len(), eta.len().max(1));
    let case_index = |a: usize, e: usize, s: usize, m: usize| ((a * slices + e) * sides.len() + s) * n_all_mu + m;
    let mut tables = Vec::new();
    for quantity in config.quantities() {
        let s = sides.iter().position(|&x| x == quantity.side).expect("a side of the table");
        let (mut e, mut e_stderr, mut avg, mut avg_stderr) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for slice in 0..slices {
            for a in 0..alpha.len() {
                let albedo =
                    |m: usize| sim.results[case_index(a, slice, s, m)].albedo(quantity.slot, quantity.hemisphere);
                for m in 0..n_mu {
                    let (value, se) = albedo(m);
                    e.push(value);
                    e_stderr.push(se);
                }
                let (mut sum, mut var) = (0.0, 0.0);
                for (k, &(_, w)) in rule.iter().enumerate() {
                    let (value, se) = albedo(n_mu + k);
                    sum += w * value;
                    var += (w * se).powi(2);
                }
                avg.push(sum / weights);
                avg_stderr.push(var.sqrt() / weights);
            }
        }
        tables.push(QuantityTable { quantity, e, e_stderr, avg, avg_stderr });
    }
    let mut photons = Vec::new();
    for slice in 0..slices {
        for a in 0..alpha.len() {
            photons.extend((0..n_mu).map(|m| sim.results[case_index(a, slice, 0, m)].photons()));
        }
    }
    Lut { config: config.clone(), mu, alpha, eta, tables, photons, wall_seconds: sim.wall_seconds }
}

/// The leading CSV fields of a quantity at eta slice `slice` (eta empty for tables without
/// eta) and roughness `alpha`.
fn quantity_fields(lut: &Lut, q: &Quantity, slice: usize, alpha: f64) -> Vec<String> {
    vec![
        q.name.clone(),
        name(&q.side),
        format!("{:?}", q.hemisphere),
        q.order.clone(),
        lut.eta.get(slice).map_or(String::new(), |e| e.to_string()),
        alpha.to_string(),
    ]
}

/// `lut.csv`: one row per quantity and cell, with the standard error and photon count.
pub fn csv_table(lut: &Lut) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["quantity", "side", "hemisphere", "order", "eta", "alpha", "mu", "E", "E_stderr", "photons"])?;
    let n_mu = lut.mu.len();
    for t in &lut.tables {
        let q = &t.quantity;
        for slice in 0..lut.slices() {
            for (a, alpha) in lut.alpha.iter().enumerate() {
                for (m, mu) in lut.mu.iter().enumerate() {
                    let i = (slice * lut.alpha.len() + a) * n_mu + m;
                    let mut row = quantity_fields(lut, q, slice, *alpha);
                    row.extend([mu.to_string(), t.e[i].to_string(), t.e_stderr[i].to_string()]);
                    row.push(lut.photons[i].to_string());
                    w.write_record(&row)?;
                }
            }
        }
    }
    Ok(w.into_inner()?)
}

/// `lut_avg.csv`: E_avg per quantity, eta and alpha.
pub fn csv_avg(lut: &Lut) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["quantity", "side", "hemisphere", "order", "eta", "alpha", "E_avg", "E_avg_stderr"])?;
    for t in &lut.tables {
        let q = &t.quantity;
        for slice in 0..lut.slices() {
            for (a, alpha) in lut.alpha.iter().enumerate() {
                let i = slice * lut.alpha.len() + a;
                let mut row = quantity_fields(lut, q, slice, *alpha);
                row.extend([t.avg[i].to_string(), t.avg_stderr[i].to_string()]);
                w.write_record(&row)?;
            }
        }
    }
    Ok(w.into_inner()?)
}

/// `lut.exr`: two layers. `E` is n_mu wide and n_eta * n_alpha high (row = eta * n_alpha +
/// alpha, column = mu), one channel per quantity plus `<quantity>_stderr`; `E_avg` is one pixel
/// wide with the same rows. Samples are 32-bit floats.
pub fn exr_image(lut: &Lut) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let rows = lut.slices() * lut.alpha.len();
    let samples = |v: &[f64]| FlatSamples::F32(v.iter().map(|&x| x as f32).collect());
    let layer = |name: &str, width: usize, columns: Vec<(String, FlatSamples)>| {
        let channels = columns.into_iter().map(|(n, v)| AnyChannel::new(n.as_str(), v)).collect();
        Layer::new((width, rows), LayerAttributes::named(name), Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels))
    };
    let with_stderr = |t: &QuantityTable, values: &[f64], errors: &[f64]| {
        [(t.quantity.name.clone(), samples(values)), (format!("{}_stderr", t.quantity.name), samples(errors))]
    };
    let e = layer("E", lut.mu.len(), lut.tables.iter().flat_map(|t| with_stderr(t, &t.e, &t.e_stderr)).collect());
    let avg = layer("E_avg", 1, lut.tables.iter().flat_map(|t| with_stderr(t, &t.avg, &t.avg_stderr)).collect());
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((lut.mu.len(), rows))),
        SmallVec::from_vec(vec![e, avg]),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes).context("cannot encode the OpenEXR image")?;
    Ok(bytes.into_inner())
}

/// Shortest text that reads back as the same `f32`.
fn f32_literal(x: f64) -> String {
    format!("{:?}", x as f32)
}

/// Writes `values` (row-major over `dims`) as nested braces, one innermost row per line.
fn nested(out: &mut String, values: &[f64], dims: &[usize], suffix: &str, indent: usize) {
    if let [n] = dims {
        let items: Vec<String> = values.iter().take(*n).map(|&v| format!("{}{suffix}", f32_literal(v))).collect();
        let _ = write!(out, "{:indent$}{{{}}}", "", items.join(", "));
        return;
    }
    let inner: usize = dims[1..].iter().product();
    let _ = writeln!(out, "{:indent$}{{", "");
    for i in 0..dims[0] {
        nested(out, &values[i * inner..(i + 1) * inner], &dims[1..], suffix, indent + 4);
        out.push_str(if i + 1 < dims[0] { ",\n" } else { "\n" });
    }
    let _ = write!(out, "{:indent$}}}", "");
}

/// The dimensions of E (`[eta][alpha][mu]`, or `[alpha][mu]`) and of E_avg.
fn dims(lut: &Lut) -> (Vec<usize>, Vec<usize>) {
    let mut avg = vec![lut.alpha.len()];
    if !lut.eta.is_empty() {
        avg.insert(0, lut.eta.len());
    }
    let mut e = avg.clone();
    e.push(lut.mu.len());
    (e, avg)
}

fn provenance(lut: &Lut) -> String {
    let c = &lut.config;
    format!(
        "smithwalk {} lut: table = {}, ndf = {}, paths <= {} per cell, target_stderr = {}, seed = {}.\n\
         E[{}] is the directional albedo at cell centres mu_i = (i + 1/2) / n_mu (cos theta_i), alpha over \
         {:?}{}; E_avg = 2 * integral of E(mu) mu dmu. Every array has a matching _stderr array.",
        env!("CARGO_PKG_VERSION"),
        name(&c.table),
        name(&c.ndf),
        c.paths,
        c.target_stderr.map_or("none".to_string(), |t| t.to_string()),
        c.seed,
        if lut.eta.is_empty() { "alpha][mu" } else { "eta][alpha][mu" },
        c.alpha_range,
        if lut.eta.is_empty() { String::new() } else { format!(", eta over {:?}", c.eta_range) },
    )
}

/// Every array a source file carries, in order: the nodes, then per quantity E, its
/// standard error, E_avg and its standard error; each with its name and dimensions.
fn source_arrays(lut: &Lut) -> Vec<(String, &[f64], Vec<usize>)> {
    let (e_dims, avg_dims) = dims(lut);
    let mut arrays = vec![("mu".to_string(), lut.mu.as_slice(), vec![lut.mu.len()])];
    arrays.push(("alpha".to_string(), &lut.alpha, vec![lut.alpha.len()]));
    if !lut.eta.is_empty() {
        arrays.push(("eta".to_string(), &lut.eta, vec![lut.eta.len()]));
    }
    for t in &lut.tables {
        let q = &t.quantity.name;
        arrays.push((format!("E_{q}"), &t.e, e_dims.clone()));
        arrays.push((format!("E_{q}_stderr"), &t.e_stderr, e_dims.clone()));
        arrays.push((format!("E_avg_{q}"), &t.avg, avg_dims.clone()));
        arrays.push((format!("E_avg_{q}_stderr"), &t.avg_stderr, avg_dims.clone()));
    }
    arrays
}

/// `lut.h`: a C header with the node arrays and, per quantity, `smithwalk_E_<q>`,
/// `smithwalk_E_<q>_stderr`, `smithwalk_E_avg_<q>` and `smithwalk_E_avg_<q>_stderr`.
pub fn c_header(lut: &Lut) -> Vec<u8> {
    let mut out = String::new();
    let _ = writeln!(out, "/* {} */", provenance(lut));
    out.push_str("#ifndef SMITHWALK_LUT_H\n#define SMITHWALK_LUT_H\n\n");
    for (name, values, dims) in source_arrays(lut) {
        let shape: String = dims.iter().map(|d| format!("[{d}]")).collect();
        let _ = writeln!(out, "static const float smithwalk_{name}{shape} =");
        nested(&mut out, values, &dims, "f", 0);
        out.push_str(";\n\n");
    }
    out.push_str("#endif /* SMITHWALK_LUT_H */\n");
    out.into_bytes()
}

/// `lut.rs`: the same arrays as Rust constants (`MU`, `E_R_ALL`, `E_AVG_R_ALL_STDERR`, ...),
/// for `include!`.
pub fn rust_source(lut: &Lut) -> Vec<u8> {
    let mut out = String::new();
    for line in provenance(lut).lines() {
        let _ = writeln!(out, "// {line}");
    }
    for (name, values, dims) in source_arrays(lut) {
        let ty = dims.iter().rev().fold("f32".to_string(), |inner, d| format!("[{inner}; {d}]"));
        let _ = writeln!(out, "#[rustfmt::skip]\npub const {}: {ty} =", name.to_uppercase());
        let mut text = String::new();
        nested(&mut text, values, &dims, "", 0);
        out.push_str(&text.replace('{', "[").replace('}', "]"));
        out.push_str(";\n\n");
    }
    out.into_bytes()
}

#[derive(Serialize)]
struct LutReport<'a> {
    smithwalk_version: &'static str,
    config: &'a LutConfig,
    mu: &'a [f64],
    alpha: &'a [f64],
    eta: &'a [f64],
    avg_rule: Vec<(f64, f64)>,
    quantities: Vec<&'a str>,
    layout: String,
    wall_seconds: f64,
    photons_total: u64,
}

fn lut_json(lut: &Lut) -> Result<Vec<u8>> {
    let report = LutReport {
        smithwalk_version: env!("CARGO_PKG_VERSION"),
        config: &lut.config,
        mu: &lut.mu,
        alpha: &lut.alpha,
        eta: &lut.eta,
        avg_rule: lut.config.avg_rule(),
        quantities: lut.tables.iter().map(|t| t.quantity.name.as_str()).collect(),
        layout: provenance(lut),
        wall_seconds: lut.wall_seconds,
        photons_total: lut.photons.iter().sum(),
    };
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    Ok(text)
}

/// Writes `lut.csv`, `lut_avg.csv`, `lut.exr`, `lut.h`, `lut.rs` and `lut.json`, atomically.
pub fn write(lut: &Lut, dir: &Path) -> Result<Vec<PathBuf>> {
    write_atomically(
        dir,
        &[
            ("lut.csv", csv_table(lut)?),
            ("lut_avg.csv", csv_avg(lut)?),
            ("lut.exr", exr_image(lut)?),
            ("lut.h", c_header(lut)),
            ("lut.rs", rust_source(lut)),
            ("lut.json", lut_json(lut)?),
        ],
    )
}
