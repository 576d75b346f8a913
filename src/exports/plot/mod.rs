//! `smithwalk plot RUN_DIR`: figures of a finished run, ready for a paper (PNG or SVG), and
//! an `index.html` report that shows them with captions, the cases and the comparison with the
//! models. docs/figures.md describes every figure and the fixed style of models and orders.
//!
//! - `lobes_g<k>_<R|T>`: the plane-of-incidence lobes of one surface and material
//!   (`lobes`);
//! - `heat_case<i>_<R|T>`: the full lobe f per order over the projected hemisphere
//!   (`heatmap`);
//! - `albedo_vs_theta`, `albedo_vs_alpha`: per-order albedos against a swept parameter
//!   (`albedo`);
//! - `index.html` (`report`).

mod albedo;
mod heatmap;
mod lobes;
mod report;
pub mod style;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

pub use self::style::Format;
use crate::atomic::{prepare_dir, write_atomically};
use crate::io::output::{CASE_COLUMNS, case_fields};
use crate::io::rundir::{BinValue, Lobes, RunDir};
use crate::setup::cases::Case;

/// Points of a curve with error bars: (x, y, standard error).
type Points = Vec<(f64, f64, f64)>;

/// What `smithwalk plot` draws and where.
#[derive(Clone, Debug)]
pub struct PlotOptions {
    pub format: Format,
    /// Directory for the figures and `index.html` (default: the run directory).
    pub out: Option<PathBuf>,
    /// Channel of an RGB run: 0, 1, 2 for r, g, b (default r); a mono run has only 0.
    pub channel: usize,
    /// Heat maps on a logarithmic colour scale (three decades below each panel's maximum).
    pub log: bool,
}

impl Default for PlotOptions {
    fn default() -> Self {
        Self { format: Format::Png, out: None, channel: 0, log: false }
    }
}

/// The channel drawn and the heat maps' scale, shared by every figure of a run.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Selection {
    pub channel: usize,
    pub rgb: bool,
    pub log: bool,
}

impl Selection {
    /// The `channel` value of the rows drawn (`None` for mono runs, which have no column).
    fn channel_name(self) -> Option<&'static str> {
        self.rgb.then(|| ["r", "g", "b"][self.channel])
    }

    /// What figure titles add for an RGB run.
    fn suffix(self) -> String {
        self.channel_name().map_or(String::new(), |c| format!(", channel {c}"))
    }

    /// What captions add for an RGB run.
    fn note(self) -> String {
        self.channel_name().map_or(String::new(), |c| format!(" Channel {c} of an RGB run."))
    }
}

/// The order slots a run has, in plotting order: 1, 2, ..., then 0 (all orders).
fn slots(run: &RunDir, lobes: &Lobes) -> Vec<usize> {
    let highest = lobes.lobes.keys().map(|k| k.1).max().unwrap_or(0);
    let mut out: Vec<usize> = (1..=highest.min(4)).collect();
    if highest > 4 {
        // Only one slot beyond 3: the folded "K+" slot, or order 4 when nothing is folded.
        out.pop();
        out.push(run.config.detector.max_order.map_or(4, |k| k as usize).min(highest));
    }
    out.push(0);
    out
}

fn slot_label(run: &RunDir, slot: usize) -> String {
    match slot {
        0 => "all orders".into(),
        k if run.config.detector.max_order == Some(k as u32) => format!("orders {k}+"),
        k => format!("order {k}"),
    }
}

/// The lobe f |cos theta_o| in the plane of incidence: (signed theta_o in degrees, value,
/// standard error), light's side negative, mirror side positive.
fn plane_of_incidence(run: &RunDir, bins: &[BinValue]) -> Points {
    let g = run.grid;
    let dphi = std::f64::consts::TAU / g.phi_bins as f64;
    let dcos = 1.0 / g.cos_bins as f64;
    let mut points = Vec::new();
    for (ip, sign) in [(0, -1.0), (g.phi_bins / 2, 1.0)] {
        for ic in 0..g.cos_bins {
            let b = bins[ic * g.phi_bins + ip];
            let theta = ((ic as f64 + 0.5) * dcos).acos().to_degrees();
            points.push((sign * theta, b.energy / (dcos * dphi), b.energy_stderr / (dcos * dphi)));
        }
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points
}

/// The case fields without the case index and the columns `swept`, which identify a group of
/// cases that differ only in those columns.
fn group_key(case: &Case, swept: &[usize]) -> Vec<String> {
    case_fields(case).into_iter().enumerate().filter(|(i, _)| *i != 0 && !swept.contains(i)).map(|(_, f)| f).collect()
}

/// Cases that differ only in the columns `swept` (indices into `CASE_COLUMNS`), in order of
/// their first case, each sorted by the incident angle.
fn groups<'a>(cases: impl IntoIterator<Item = &'a Case>, swept: &[usize]) -> Vec<Vec<&'a Case>> {
    let mut map: BTreeMap<Vec<String>, Vec<&Case>> = BTreeMap::new();
    for case in cases {
        map.entry(group_key(case, swept)).or_default().push(case);
    }
    let mut out: Vec<Vec<&Case>> = map.into_values().collect();
    out.sort_by_key(|cases| cases[0].index);
    for cases in &mut out {
        cases.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg).then(a.alpha_x.total_cmp(&b.alpha_x)));
    }
    out
}

/// The indices of the case columns (after `case`) whose value differs between cases.
fn varying(cases: &[Case]) -> Vec<usize> {
    let fields: Vec<Vec<String>> = cases.iter().map(case_fields).collect();
    (1..CASE_COLUMNS.len()).filter(|&c| fields.iter().any(|f| f[c] != fields[0][c])).collect()
}

/// How a case column reads in captions: a name and the value (`α_x = 0.5`, `θ_i = 30°`).
fn pretty_field(column: usize, value: &str) -> String {
    match CASE_COLUMNS[column] {
        "alpha_x" => format!("α_x = {value}"),
        "alpha_y" => format!("α_y = {value}"),
        "theta_i_deg" => format!("θ_i = {:.1}°", value.parse::<f64>().unwrap_or(f64::NAN)),
        "phi_i_deg" => format!("φ_i = {value}°"),
        "material" => value.to_string(),
        name => format!("{name} {value}"),
    }
}

/// The fields of `case` that vary over the run, except those of `skip`, for captions.
fn pretty_fields(run: &RunDir, case: &Case, skip: &[usize]) -> String {
    let columns: Vec<usize> = varying(&run.cases).into_iter().filter(|c| !skip.contains(c)).collect();
    describe(&case_fields(case), &columns).join(", ")
}

/// How the case columns `columns` of a case (its `fields`) read in captions, an isotropic
/// roughness as one value.
fn describe(fields: &[String], columns: &[usize]) -> Vec<String> {
    let isotropic = columns.contains(&2) && columns.contains(&3) && fields[2] == fields[3];
    columns
        .iter()
        .filter(|&&c| !(isotropic && c == 3))
        .map(|&c| if isotropic && c == 2 { format!("α = {}", fields[2]) } else { pretty_field(c, &fields[c]) })
        .collect()
}

/// A self-contained name of a case's surface and material (NDF, roughness, material, and the
/// Smith, normals and side settings when they are not the defaults).
fn surface_label(case: &Case) -> String {
    let alpha = if case.alpha_x == case.alpha_y {
        format!("α = {}", case.alpha_x)
    } else {
        format!("α = ({}, {})", case.alpha_x, case.alpha_y)
    };
    let fields = case_fields(case);
    let mut label = format!("{}, {alpha}, {}", fields[1].to_uppercase(), fields[7]);
    for (column, default) in [(5, "exact"), (6, "vndf"), (10, "outside")] {
        if fields[column] != default {
            label.push_str(&format!(", {} {}", CASE_COLUMNS[column], fields[column]));
        }
    }
    label
}

/// A figure drawn and the caption the report shows under it.
struct Drawn {
    name: String,
    bytes: Vec<u8>,
    caption: String,
}

/// Draws every figure of the run in `run_dir` and writes them with `index.html` into
/// `options.out` (default: the run directory), atomically. Returns the files written.
pub fn plot(run_dir: &Path, options: &PlotOptions) -> Result<Vec<PathBuf>> {
    let run = RunDir::open(run_dir)?;
    let rgb = run.config.is_rgb();
    if options.channel > 0 && !rgb {
        bail!(
            "--channel {}: the run in {} has one channel (only RGB runs have g and b)",
            ["r", "g", "b"][options.channel.min(2)],
            run_dir.display()
        );
    }
    if options.channel > 2 {
        bail!("channel {}: allowed are 0, 1, 2 (r, g, b)", options.channel);
    }
    let selection = Selection { channel: options.channel, rgb, log: options.log };
    let measured = run.measured()?;
    let models: BTreeMap<String, Lobes> = run.models()?.into_iter().collect();
    let summary = run.summary()?;
    let order_slots = slots(&run, &measured);
    let ext = options.format.extension();

    let mut albedos = Vec::new();
    for sweep in [albedo::Sweep::Theta, albedo::Sweep::Alpha] {
        if let Some(figure) = albedo::AlbedoFigure::new(&run, &summary, sweep, selection) {
            albedos.push(Drawn {
                name: format!("{}.{ext}", sweep.file_stem()),
                bytes: style::render(&figure, options.format)?,
                caption: figure.caption(),
            });
        }
    }
    let mut sections = Vec::new();
    for (g, cases) in groups(&run.cases, &[8]).into_iter().enumerate() {
        let mut lobes = Vec::new();
        let mut heats = Vec::new();
        for hemisphere in crate::io::output::hemispheres(cases[0]).iter().map(|h| format!("{h:?}")) {
            let figure = lobes::LobeFigure {
                run: &run,
                cases: &cases,
                hemisphere: &hemisphere,
                selection,
                measured: &measured,
                models: &models,
                slots: &order_slots,
            };
            lobes.push(Drawn {
                name: format!("lobes_g{g}_{hemisphere}.{ext}"),
                bytes: style::render(&figure, options.format)?,
                caption: figure.caption(),
            });
            for case in &cases {
                let figure = heatmap::HeatFigure {
                    run: &run,
                    case,
                    hemisphere: &hemisphere,
                    selection,
                    measured: &measured,
                    slots: &order_slots,
                };
                heats.push((
                    case.index,
                    Drawn {
                        name: format!("heat_case{}_{hemisphere}.{ext}", case.index),
                        bytes: style::render(&figure, options.format)?,
                        caption: figure.caption(),
                    },
                ));
            }
        }
        heats.sort_by_key(|(case, _)| *case);
        sections.push(report::Section { cases, lobes, heats: heats.into_iter().map(|(_, d)| d).collect() });
    }
    let html = report::page(&run, run_dir, &models, selection, &albedos, &sections)?;

    let out = options.out.clone().unwrap_or_else(|| run_dir.to_path_buf());
    prepare_dir(&out)?;
    let mut files: Vec<(String, Vec<u8>)> = albedos
        .into_iter()
        .chain(sections.into_iter().flat_map(|s| s.lobes.into_iter().chain(s.heats)))
        .map(|d| (d.name, d.bytes))
        .collect();
    files.push(("index.html".into(), html.into_bytes()));
    let files: Vec<(&str, Vec<u8>)> = files.iter_mut().map(|(n, b)| (n.as_str(), std::mem::take(b))).collect();
    write_atomically(&out, &files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_of_incidence_puts_the_mirror_side_at_positive_angles() {
        let dir = tempfile::tempdir().unwrap();
        let config = crate::setup::config::Config::parse(
            "paths = 10\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\n",
        )
        .unwrap();
        let sim = crate::engine::simulate(&config, Some(1), false).unwrap();
        crate::io::output::write_outputs(&sim, &config, dir.path()).unwrap();
        let run = RunDir::open(dir.path()).unwrap();
        // Energy 0.1 only in cos bin 2 (|cos| in [0.5, 0.75)), phi bin 4 (phi in [180, 225) deg).
        let mut bins = vec![BinValue::default(); 32];
        bins[2 * 8 + 4].energy = 0.1;
        let points = plane_of_incidence(&run, &bins);
        assert_eq!(points.len(), 8);
        let lit: Vec<_> = points.iter().filter(|p| p.1 > 0.0).collect();
        assert_eq!(lit.len(), 1);
        let expected_theta = 0.625_f64.acos().to_degrees();
        assert!((lit[0].0 - expected_theta).abs() < 1e-12, "{:?}", lit[0]);
        // f |cos| = energy / (d|cos| dphi) = 0.1 / (0.25 * pi / 4).
        assert!((lit[0].1 - 0.1 / (0.25 * std::f64::consts::FRAC_PI_4)).abs() < 1e-12);
    }
}
