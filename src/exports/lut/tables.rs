//! The tables of a configuration: its quantities, the walk of its cells and their assembly.

use anyhow::Result;

use super::config::LutConfig;
use super::flat;
use crate::engine::detector::Hemisphere;
use crate::engine::run::Estimator;
use crate::engine::{RunOptions, Simulation};
use crate::io::table_record::TableRecord;
use crate::setup::config::IncidentSide;

impl LutConfig {
    /// The tabulated quantities: per side and hemisphere, all orders and each order slot.
    fn quantities(&self) -> Vec<Quantity> {
        let hemispheres: &[Hemisphere] =
            if self.is_dielectric() { &[Hemisphere::R, Hemisphere::T] } else { &[Hemisphere::R] };
        let mut out = Vec::new();
        for side in self.sides() {
            for &hemisphere in hemispheres {
                for slot in 0..=self.table.max_order as usize {
                    let order = match slot {
                        0 => "all".to_string(),
                        k if k == self.table.max_order as usize => format!("{k}plus"),
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
    /// What the table is, as `lut.json` records it.
    pub record: TableRecord,
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
    pub(super) fn slices(&self) -> usize {
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
    let record = config.record()?;
    let sim = crate::engine::simulate_from(&run, &options, None, &mut |_, _, _| Ok(()))?;
    Ok(assemble(config, record, &sim))
}

/// Splits the simulation's cases (ordered walked alpha, material = eta, side, mu) into tables;
/// a node at alpha = 0 takes the flat surface's exact albedos.
fn assemble(config: &LutConfig, record: TableRecord, sim: &Simulation) -> Lut {
    let (mu, alpha, eta, rule) = (config.mu_nodes(), config.alpha_nodes(), config.eta_nodes(), config.avg_rule());
    let (sides, materials) = (config.sides(), config.materials());
    // The rule's weights add up to 1 up to rounding; dividing by their sum makes an albedo of
    // exactly 1 at every node (a conductor's all orders) average to exactly 1.
    let weights: f64 = rule.iter().map(|&(_, w)| w).sum();
    let (n_mu, n_all_mu, slices) = (mu.len(), mu.len() + rule.len(), eta.len().max(1));
    // Each alpha node's index among the walked ones; `None` for the flat surface.
    let walked: Vec<Option<usize>> =
        alpha.iter().scan(0, |next, &a| Some((a > 0.0).then(|| std::mem::replace(next, *next + 1)))).collect();
    let case_index = |a: usize, e: usize, s: usize, m: usize| ((a * slices + e) * sides.len() + s) * n_all_mu + m;
    let incidence = |m: usize| if m < n_mu { mu[m] } else { rule[m - n_mu].0 };
    let mut tables = Vec::new();
    for quantity in config.quantities() {
        let s = sides.iter().position(|&x| x == quantity.side).unwrap_or(0);
        let (mut e, mut e_stderr, mut avg, mut avg_stderr) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // One material per eta slice (one slice without eta).
        for (slice, material) in materials.iter().enumerate() {
            for walked_a in &walked {
                // Order 1 holds all of a flat surface's albedo (slot 1 is "1plus" when max_order = 1).
                let flat = |m: usize| {
                    let value = flat::albedo(material, quantity.side, quantity.hemisphere, incidence(m));
                    (if quantity.slot <= 1 { value } else { 0.0 }, 0.0)
                };
                let albedo = |m: usize| match walked_a {
                    Some(a) => sim.results[case_index(*a, slice, s, m)].albedo(quantity.slot, quantity.hemisphere),
                    None => flat(m),
                };
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
        for walked_a in &walked {
            photons
                .extend((0..n_mu).map(|m| walked_a.map_or(0, |a| sim.results[case_index(a, slice, 0, m)].photons())));
        }
    }
    Lut { config: config.clone(), record, mu, alpha, eta, tables, photons, wall_seconds: sim.wall_seconds }
}
