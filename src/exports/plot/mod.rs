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

use std::borrow::Cow;
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

/// The top of a point's error bar, or the point where it has none (a NaN standard error).
fn bar_top(p: &(f64, f64, f64)) -> f64 {
    p.1 + if p.2.is_finite() { p.2 } else { 0.0 }
}

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

/// The most bounce-order rows a figure shows besides "all orders": orders 1 to 3 and a fourth
/// row that holds the rest.
const ORDER_ROWS: usize = 4;

/// A row of the per-order figures (lobes, heat maps, albedos).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Row {
    /// One order slot of the run as written: order k, the run's folded "K+" slot
    /// (`max_order = K`), or 0 (all orders).
    Slot(usize),
    /// Orders k and higher, summed by the figure over the run's slots from k up (the run has
    /// more orders than the figure has rows).
    From(usize),
}

/// The rows of a run whose highest order slot is `highest`, in plotting order: 1, 2, ... up to
/// [`ORDER_ROWS`], the last of them "K+" (the sum of every order from K up) when the run has
/// more, then all orders. A run with one order slot gets the all-orders row only: its slot 1
/// holds the same lobe as slot 0 (the "1+" slot of `max_order = 1`, which `smithwalk compare`
/// also tests once, as slot 0; or order 1 where no light bounced twice).
fn rows(highest: usize) -> Vec<Row> {
    let mut out: Vec<Row> = if highest > ORDER_ROWS {
        (1..ORDER_ROWS).map(Row::Slot).chain([Row::From(ORDER_ROWS)]).collect()
    } else if highest > 1 {
        (1..=highest).map(Row::Slot).collect()
    } else {
        Vec::new()
    };
    out.push(Row::Slot(0));
    out
}

/// Whether `rows` is the all-orders row alone (a run with one order slot, see [`rows`]).
fn all_orders_only(rows: &[Row]) -> bool {
    rows == [Row::Slot(0)]
}

/// The highest order slot of the lobes of one case, hemisphere and channel (0 if none).
fn highest_slot(lobes: &Lobes, case: usize, hemisphere: &str, channel: usize) -> usize {
    lobes.lobes.keys().filter(|k| k.0 == case && k.2 == hemisphere && k.3 == channel).map(|k| k.1).max().unwrap_or(0)
}

/// The bins of `row` for one case, hemisphere and channel of `lobes` (the measurement or a
/// model), or `None` where `lobes` lacks the lobe. A row `From(k)` sums the slots k to `highest`
/// (the measurement's highest slot of the case), all of which `lobes` must have: energies and
/// BSDF values exactly; its standard errors are NaN (no error bar) when it sums more than one
/// slot, since one photon's energy in one bin can come from several orders (Fresnel splitting)
/// and lobes.csv has no covariances between orders.
fn row_bins<'a>(
    lobes: &'a Lobes,
    row: Row,
    (case, hemisphere, channel): (usize, &str, usize),
    highest: usize,
) -> Option<Cow<'a, [BinValue]>> {
    match row {
        Row::Slot(slot) => lobes.get(case, slot, hemisphere, channel).map(Cow::Borrowed),
        Row::From(k) if highest == k => lobes.get(case, k, hemisphere, channel).map(Cow::Borrowed),
        Row::From(k) => {
            let slots = (k..=highest).map(|s| lobes.get(case, s, hemisphere, channel)).collect::<Option<Vec<_>>>()?;
            let mut sum = vec![
                BinValue { energy_stderr: f64::NAN, bsdf_stderr: f64::NAN, ..BinValue::default() };
                slots.first()?.len()
            ];
            for bins in slots {
                for (total, b) in sum.iter_mut().zip(bins) {
                    total.energy += b.energy;
                    total.bsdf += b.bsdf;
                }
            }
            Some(Cow::Owned(sum))
        }
    }
}

/// The K of the row "orders K+" among `rows`, if there is one, and whether it is the run's
/// folded slot (`max_order = K`) rather than a sum the figure makes.
fn open_row(run: &RunDir, rows: &[Row]) -> Option<(usize, bool)> {
    let folded = run.config.detector.max_order.map(|k| k as usize).filter(|&k| k > 0 && rows.contains(&Row::Slot(k)));
    folded
        .map(|k| (k, true))
        .or_else(|| rows.iter().find_map(|r| if let Row::From(k) = r { Some((*k, false)) } else { None }))
}

/// What a caption says about the row "orders K+", if the figure has one (empty otherwise):
/// whether it is the run's folded slot (`max_order = K`, tallied by the walk, with error bars)
/// or a sum the figure makes of the run's orders K and higher, and with `bars`, why that sum has
/// none; with `max_order = 1`, that the run's "1+" slot is drawn once, as all orders.
fn folded_note(run: &RunDir, rows: &[Row], bars: bool) -> String {
    if all_orders_only(rows) && run.config.detector.max_order == Some(1) {
        return " The run tallies every order in one slot (max_order = 1), \"orders 1+\", which is the all-orders \
                lobe: it is drawn once, as \"all orders\"."
            .to_string();
    }
    let Some((k, folded)) = open_row(run, rows) else {
        return String::new();
    };
    if folded {
        let with = if bars { ", with its standard errors" } else { "" };
        return format!(
            " \"orders {k}+\" is the run's own folded slot (max_order = {k}): the energy the walk tallied after {k} \
             or more bounces{with}."
        );
    }
    let why = if bars {
        ", without error bars: lobes.csv and summary.csv have no covariances between orders (docs/figures.md)"
    } else {
        ""
    };
    format!(
        " \"orders {k}+\" is not a slot of the run but the sum, made by the plot, of its orders {k} and higher{why}."
    )
}

/// How an order slot reads in figures and tables: "order k", "orders K+" for the run's folded
/// slot, "all orders" for slot 0.
fn slot_label(run: &RunDir, slot: usize) -> String {
    match slot {
        0 => "all orders".into(),
        k if run.config.detector.max_order == Some(k as u32) => format!("orders {k}+"),
        k => format!("order {k}"),
    }
}

/// How a row reads in figures: as its slot, or "orders K+" for a row the figure sums.
fn row_label(run: &RunDir, row: Row) -> String {
    match row {
        Row::Slot(slot) => slot_label(run, slot),
        Row::From(k) => format!("orders {k}+"),
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
        cases.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg).then(a.roughness().x.total_cmp(&b.roughness().x)));
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
        "side" => format!("light from {value}"),
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
/// Smith and normals settings when they are not the defaults) and the side the light comes
/// from, named when it is not outside or when the run has both sides.
fn surface_label(run: &RunDir, case: &Case) -> String {
    let alpha = if case.roughness().x == case.roughness().y {
        format!("α = {}", case.roughness().x)
    } else {
        format!("α = ({}, {})", case.roughness().x, case.roughness().y)
    };
    let fields = case_fields(case);
    let mut label = format!("{}, {alpha}, {}", fields[1].to_uppercase(), fields[7]);
    for (column, default) in [(5, "exact"), (6, "vndf")] {
        if fields[column] != default {
            label.push_str(&format!(", {} {}", CASE_COLUMNS[column], fields[column]));
        }
    }
    if fields[10] != "outside" || varying(&run.cases).contains(&10) {
        label.push_str(&format!(", {}", pretty_field(10, &fields[10])));
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
    let order_rows = rows(measured.lobes.keys().map(|k| k.1).max().unwrap_or(0));
    let ext = options.format.extension();

    let mut albedos = Vec::new();
    for sweep in [albedo::Sweep::Theta, albedo::Sweep::Alpha] {
        if let Some(figure) = albedo::AlbedoFigure::new(&run, &summary, sweep, selection, &order_rows) {
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
                rows: &order_rows,
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
                    rows: &order_rows,
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

    /// The run directory of the config `toml`, walked on 1 thread and written to a temporary
    /// directory (kept alive by the first element).
    pub(super) fn written_run(toml: &str) -> (tempfile::TempDir, RunDir) {
        let dir = tempfile::tempdir().unwrap();
        let config = crate::setup::config::Config::parse(toml).unwrap();
        let sim = crate::engine::simulate(&config, Some(1), false).unwrap();
        crate::io::output::write_outputs(&sim, &config, dir.path()).unwrap();
        let run = RunDir::open(dir.path()).unwrap();
        (dir, run)
    }

    #[test]
    fn plane_of_incidence_puts_the_mirror_side_at_positive_angles() {
        let (_dir, run) = written_run(
            "paths = 10\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\n",
        );
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

    #[test]
    fn runs_with_more_than_four_orders_get_a_fourth_row_of_every_order_above_three() {
        assert_eq!(rows(13), [Row::Slot(1), Row::Slot(2), Row::Slot(3), Row::From(4), Row::Slot(0)]);
        assert_eq!(rows(5), rows(13));
        assert_eq!(rows(4), [Row::Slot(1), Row::Slot(2), Row::Slot(3), Row::Slot(4), Row::Slot(0)]);
        assert_eq!(rows(2), [Row::Slot(1), Row::Slot(2), Row::Slot(0)]);
    }

    /// With `max_order = 1` the run's "1+" slot is the all-orders lobe: every figure draws it once,
    /// as "all orders", and no caption speaks of other orders or of a sum.
    #[test]
    fn a_run_with_one_order_slot_draws_the_all_orders_lobe_once() {
        let (_dir, run) = written_run(
            "paths = 200\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [0, 30]\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 1\n",
        );
        let measured = run.measured().unwrap();
        assert_eq!(highest_slot(&measured, 0, "R", 0), 1);
        let rows = rows(1);
        assert_eq!(rows, [Row::Slot(0)]);
        let selection = Selection { channel: 0, rgb: false, log: false };
        let summary = run.summary().unwrap();
        let albedo = albedo::AlbedoFigure::new(&run, &summary, albedo::Sweep::Theta, selection, &rows).unwrap();
        let cases: Vec<&Case> = run.cases.iter().collect();
        let models = BTreeMap::new();
        let lobe = lobes::LobeFigure {
            run: &run,
            cases: &cases,
            hemisphere: "R",
            selection,
            measured: &measured,
            models: &models,
            rows: &rows,
        };
        for caption in [albedo.caption(), lobe.caption(), folded_note(&run, &rows, false)] {
            assert!(caption.contains("drawn once, as \"all orders\""), "{caption}");
            assert!(!caption.contains("their sum") && !caption.contains("per bounce order"), "{caption}");
        }
    }

    /// The summed "4+" row of a run without `max_order` holds, bin by bin, the all-orders lobe
    /// minus orders 1 to 3, in both hemispheres; its standard errors are NaN (not drawn).
    #[test]
    fn the_summed_row_is_all_orders_minus_the_orders_above_it() {
        let (_dir, run) = written_run(
            "paths = 20000\nseed = 5\n[surface]\nalpha = 0.8\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = 60\nside = \"inside\"\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\n",
        );
        let measured = run.measured().unwrap();
        for hemisphere in ["R", "T"] {
            let highest = highest_slot(&measured, 0, hemisphere, 0);
            assert!(highest > 5, "{hemisphere}: orders up to {highest} only");
            assert_eq!(rows(highest)[3], Row::From(4));
            let folded = row_bins(&measured, Row::From(4), (0, hemisphere, 0), highest).unwrap();
            let slot = |s| measured.get(0, s, hemisphere, 0).unwrap();
            for (i, b) in folded.iter().enumerate() {
                let rest = slot(0)[i].energy - slot(1)[i].energy - slot(2)[i].energy - slot(3)[i].energy;
                assert!((b.energy - rest).abs() <= 1e-12, "{hemisphere} bin {i}: {} against {rest}", b.energy);
                assert!(b.energy_stderr.is_nan() && b.bsdf_stderr.is_nan());
            }
            assert!(folded.iter().map(|b| b.energy).sum::<f64>() > 0.0);
        }
    }
}
