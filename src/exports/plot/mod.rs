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
mod cases;
mod heatmap;
mod lobes;
mod points;
mod report;
mod rows;
mod selection;
pub mod style;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use self::cases::{case_column, groups};
use self::report::Drawn;
use self::rows::rows;
use self::selection::Selection;
pub use self::style::Format;
use crate::atomic::{prepare_dir, write_atomically};
use crate::io::rundir::{Lobes, RunDir};

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
    for sweep in albedo::Sweep::ALL {
        if let Some(figure) = albedo::AlbedoFigure::new(&run, &summary, sweep, selection, &order_rows) {
            albedos.push(Drawn {
                name: format!("{}.{ext}", sweep.file_stem()),
                bytes: style::render(&figure, options.format)?,
                caption: figure.caption(),
            });
        }
    }
    let mut sections = Vec::new();
    for (g, cases) in groups(&run.cases, &[case_column("theta_i_deg")]).into_iter().enumerate() {
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
    use super::rows::tests::written_run;
    use super::rows::{Row, folded_note, highest_slot};
    use super::*;
    use crate::setup::cases::Case;

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
}
