//! Report: the console summary of a comparison (per model its family, rejections and worst
//! lobes, then the verdict) and the text of `models.csv` and `compare.csv` (docs/compare.md).

use std::fmt::Write as _;

use anyhow::Result;

use super::lobe::{channel_name, hemisphere_name};
use super::predict::ModelLobe;
use super::verdict::{LobeComparison, Verdict, is_exact_oracle, is_monte_carlo, kind};
use crate::analysis::stats;
use crate::engine::detector::Hemisphere;
use crate::io::output::{bin_edges, case_fields, hemisphere_sign, hemispheres};
use crate::io::rundir::RunDir;
use crate::io::schema;
use crate::setup::config::Model;

/// A p-value for the console, to three digits; one too small for f64 (which a lobe far from its
/// model gives) as the bound it is, not as `0.00e0`.
pub fn p_value_text(p: f64) -> String {
    if p > 0.0 { format!("{p:.2e}") } else { "<1e-300".to_string() }
}

/// A difference in standard errors for the console, to one decimal; one that rounds to zero is
/// `0.0`, without the sign of a small negative difference.
fn standard_errors_text(se: f64) -> String {
    let text = format!("{se:.1}");
    if text == "-0.0" { "0.0".to_string() } else { text }
}

/// A number of `models.csv` to `digits` significant digits, and a zero as `0`: six for an
/// energy (a closed-form model's bins are accurate to 0.05 of the measured standard error, a
/// Monte Carlo model's to its own), three for a standard error (an error bar).
fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 { "0".to_string() } else { format!("{v:.*e}", digits - 1) }
}

/// The text of `models.csv`, row for row aligned with `lobes.csv`: its rows (every case,
/// order slot, hemisphere, bin and channel of the run, in its order) with their key columns and
/// `folded`, then per model compared, in that order, its energy (six significant digits) and
/// standard error (three: an error bar), both empty where the model gives no lobe
/// ([`model_lobe`]). A model's lobe for a slot the run does not have (no light reached that
/// order) is not written.
pub(super) fn models_table(
    run: &RunDir,
    predicted: &[(Model, Vec<ModelLobe>)],
    rgb: bool,
    folded: Option<usize>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let names: Vec<&str> = predicted.iter().map(|(model, _)| model.name()).collect();
    let header = schema::MODELS.header(rgb, &names);
    w.write_record(&header)?;
    let channels = if rgb { 3 } else { 1 };
    let zeros = vec![0.0; run.grid.bins()];
    let mut row: Vec<String> = Vec::with_capacity(header.len());
    for case in &run.cases {
        for order in 0..run.slots[case.index] {
            for &h in hemispheres(case) {
                // Per channel, each model's energies and standard errors, if it gives the lobe.
                let lobes: Vec<Vec<LobeCells>> = (0..channels)
                    .map(|c| predicted.iter().map(|p| model_lobe(p, (case.index, order, h, c), &zeros)).collect())
                    .collect();
                for (_, bin, edges) in bin_edges(run.grid, hemisphere_sign(case.side, h)) {
                    for (c, models) in lobes.iter().enumerate() {
                        row.clear();
                        row.extend([case.index.to_string(), order.to_string(), hemisphere_name(h)]);
                        if rgb {
                            row.push(channel_name(rgb, c).to_string());
                        }
                        row.extend(edges.map(|e| e.to_string()));
                        row.push((folded == Some(order)).to_string());
                        for lobe in models {
                            match lobe {
                                Some((e, se)) => row.extend([significant(e[bin], 6), significant(se[bin], 3)]),
                                None => row.extend([String::new(), String::new()]),
                            }
                        }
                        w.write_record(&row)?;
                    }
                }
            }
        }
    }
    Ok(w.into_inner()?)
}

/// A model's energies and standard errors of one lobe, bin by bin, if it gives the lobe.
type LobeCells<'a> = Option<(&'a [f64], &'a [f64])>;

/// A model's energies and standard errors of a lobe (case, order slot, hemisphere, channel),
/// or `None` if it does not give it; zero for a Monte Carlo model whose walk reached no light at
/// that order of a case it applies to.
fn model_lobe<'a>(
    (model, lobes): &'a (Model, Vec<ModelLobe>),
    lobe: (usize, usize, Hemisphere, usize),
    zeros: &'a [f64],
) -> LobeCells<'a> {
    let (case, _, _, channel) = lobe;
    match lobes.iter().find(|l| (l.case, l.order, l.hemisphere, l.channel) == lobe) {
        Some(l) => Some((&l.energy, &l.stderr)),
        None if is_monte_carlo(*model) && lobes.iter().any(|l| (l.case, l.channel) == (case, channel)) => {
            Some((zeros, zeros))
        }
        None => None,
    }
}

/// The text of `compare.csv`: one row per tested lobe and model.
pub(super) fn compare_table(
    comparisons: &[LobeComparison],
    run: &RunDir,
    verdicts: &[Verdict],
    family_level: f64,
    rgb: bool,
    folded: Option<usize>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = schema::COMPARE.header(rgb, &[]);
    w.write_record(&header)?;
    for c in comparisons {
        let lobes = verdicts.iter().find(|v| v.model == c.model).map_or(1, |v| v.lobes);
        let lobe_level = stats::sidak(family_level, lobes.max(1));
        let mut row = case_fields(&run.cases[c.lobe.0]);
        row.extend([c.model.name().to_string(), c.lobe.1.to_string(), c.lobe.2.clone()]);
        if rgb {
            row.push(channel_name(rgb, c.lobe.3).to_string());
        }
        row.extend([c.test.statistic.to_string(), c.test.dof.to_string(), c.test.p_value.to_string()]);
        row.extend(
            [
                c.rel_l1,
                c.rel_l2,
                c.albedo_measured.energy,
                c.albedo_measured.stderr,
                c.albedo_model.energy,
                c.albedo_model.stderr,
                c.albedo_diff_se(),
            ]
            .map(|v| v.to_string()),
        );
        row.extend([
            (folded == Some(c.lobe.1)).to_string(),
            family_level.to_string(),
            lobe_level.to_string(),
            (c.test.p_value < lobe_level).to_string(),
        ]);
        w.write_record(&row)?;
    }
    Ok(w.into_inner()?)
}

/// What the columns of the worst-lobes table mean (docs/compare.md), printed after the first.
const WORST_LOBES_LEGEND: [&str; 3] = [
    "order 0: all orders; ch: channel (- in a one-channel run); rel L1, rel L2: the lobe's difference",
    "from the model in the L1 and L2 norms, over the model's norm; albedo diff: measured minus model",
    "albedo in units of sqrt(SE_measured^2 + SE_model^2) (positive: the walk measured more light)",
];

/// The report: per model its family, level, rejections and worst lobes (the first table with
/// [`WORST_LOBES_LEGEND`] under it), then the verdict. A model that applies to no case of the
/// run says so in its section when the user named it; models of the default list
/// (`default_models`) that apply to no case share one line instead.
pub(super) fn report(
    comparisons: &[LobeComparison],
    verdicts: &[Verdict],
    notes: &[(Model, String)],
    family_level: f64,
    rgb: bool,
    folded: Option<usize>,
    default_models: bool,
) -> String {
    let mut out = String::new();
    let mut legend = Some(WORST_LOBES_LEGEND);
    let mut not_applicable: Vec<&str> = Vec::new();
    for v in verdicts {
        let kind = kind(v.model);
        if let Some(reason) = &v.skipped {
            let _ = writeln!(out, "{} ({kind}): {reason}", v.model.name());
            continue;
        }
        if v.lobes == 0 && default_models {
            not_applicable.push(v.model.name());
            continue;
        }
        if v.lobes == 0 {
            let _ = writeln!(out, "{} ({kind}): applies to no case of this run", v.model.name());
            continue;
        }
        let level = stats::sidak(family_level, v.lobes);
        let _ = writeln!(
            out,
            "{} ({kind}): {} lobes at family level {family_level} (Sidak: each lobe at {level:.2e}): {} rejected",
            v.model.name(),
            v.lobes,
            v.rejected
        );
        for (model, note) in notes.iter().filter(|n| n.0 == v.model) {
            let _ = writeln!(out, "  {}: {note}", model.name());
        }
        let mut mine: Vec<&LobeComparison> = comparisons.iter().filter(|c| c.model == v.model).collect();
        mine.sort_by(|a, b| a.test.p_value.total_cmp(&b.test.p_value));
        let _ = writeln!(out, "  its {} lobes with the lowest p, worst first:", mine.len().min(5));
        let _ = writeln!(
            out,
            "  {:>5} {:>5} {:>4} {:>3} {:>10} {:>6} {:>10} {:>8} {:>8} {:>11}  verdict",
            "case", "order", "hemi", "ch", "chi2", "dof", "p", "rel L1", "rel L2", "albedo diff"
        );
        for c in mine.iter().take(5) {
            let order = if folded == Some(c.lobe.1) { format!("{}+", c.lobe.1) } else { c.lobe.1.to_string() };
            let channel = if rgb { channel_name(rgb, c.lobe.3) } else { "-" };
            let _ = writeln!(
                out,
                "  {:>5} {order:>5} {:>4} {channel:>3} {:>10.1} {:>6} {:>10} {:>8.4} {:>8.4} {:>8} SE{}",
                c.lobe.0,
                c.lobe.2,
                c.test.statistic,
                c.test.dof,
                p_value_text(c.test.p_value),
                c.rel_l1,
                c.rel_l2,
                standard_errors_text(c.albedo_diff_se()),
                if c.test.p_value < level { "  rejected" } else { "" }
            );
        }
        for line in legend.take().into_iter().flatten() {
            let _ = writeln!(out, "  {line}");
        }
    }
    if !not_applicable.is_empty() {
        let _ = writeln!(out, "not applicable to any case of this run: {}", not_applicable.join(", "));
    }
    if folded == Some(1) {
        let _ = writeln!(out, "(max_order = 1: the \"1+\" slot is the all-orders lobe, tested once as order 0)");
    }
    let failed: Vec<String> = verdicts
        .iter()
        .filter(|v| is_exact_oracle(v.model) && v.rejected > 0)
        .map(|v| format!("{} ({} of {} lobes)", v.model.name(), v.rejected, v.lobes))
        .collect();
    let approximations: Vec<&str> =
        verdicts.iter().filter(|v| !is_exact_oracle(v.model) && v.rejected > 0).map(|v| v.model.name()).collect();
    if failed.is_empty() {
        let _ = writeln!(out, "verdict: no exact oracle rejects the run at family level {family_level}");
    } else {
        let _ = writeln!(
            out,
            "verdict: REJECTED by exact oracles: {}: the measurement or the oracle is wrong",
            failed.join(", ")
        );
    }
    if !approximations.is_empty() {
        let _ = writeln!(
            out,
            "({} {} the walk: rejections measure the approximation, not a fault)",
            approximations.join(", "),
            if approximations.len() == 1 { "approximates" } else { "approximate" }
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::verdict::Value;
    use super::*;
    use crate::analysis::stats::ChiSquare;

    #[test]
    fn a_p_value_below_f64s_range_is_printed_as_a_bound() {
        assert_eq!(p_value_text(0.0), "<1e-300");
        assert_eq!(p_value_text(5.25e-110), "5.25e-110");
        assert_eq!(p_value_text(0.5), "5.00e-1");
    }

    /// A comparison of lobe (case 0, order 1, R, channel 0) with `model`: p-value `p`, the
    /// measured albedo `measured` and the model's 0.5, both with standard error 0.1.
    fn comparison(model: Model, p: f64, measured: f64) -> LobeComparison {
        LobeComparison {
            lobe: (0, 1, "R".to_string(), 0),
            model,
            test: ChiSquare { statistic: 1.0, dof: 1, p_value: p, cells: Vec::new() },
            rel_l1: 0.0,
            rel_l2: 0.0,
            albedo_measured: Value { energy: measured, stderr: 0.1 },
            albedo_model: Value { energy: 0.5, stderr: 0.1 },
        }
    }

    #[test]
    fn an_albedo_difference_that_rounds_to_zero_is_printed_without_a_sign() {
        // Measured minus model is -0.004 in units of sqrt(0.1^2 + 0.1^2): -0.0 to one decimal.
        let comparisons = [comparison(Model::Single, 0.5, 0.5 - 0.004 * 0.02_f64.sqrt())];
        let verdicts = [Verdict { model: Model::Single, lobes: 1, rejected: 0, skipped: None }];
        let text = report(&comparisons, &verdicts, &[], 0.01, false, None, false);
        let row = text.lines().find(|l| l.trim_start().starts_with("0 ")).expect(&text);
        assert!(row.ends_with(" 0.0 SE") && !text.contains("-0.0"), "{text}");
        assert_eq!((standard_errors_text(-0.06), standard_errors_text(-0.0)), ("-0.1".into(), "0.0".into()));
    }

    #[test]
    fn the_worst_lobes_columns_are_explained_once_after_the_first_table() {
        let comparisons = [comparison(Model::Single, 0.5, 0.6), comparison(Model::HeitzNee, 0.5, 0.6)];
        let verdicts =
            [Model::Single, Model::HeitzNee].map(|model| Verdict { model, lobes: 1, rejected: 0, skipped: None });
        let text = report(&comparisons, &verdicts, &[], 0.01, false, None, false);
        let lines: Vec<&str> = text.lines().collect();
        // The line after the first table's row starts the legend; the second table has none.
        let row = lines.iter().position(|l| l.trim_start().starts_with("0 ")).expect(&text);
        assert!(
            lines[row + 1].starts_with("  order 0: all orders") && lines[row + 3].starts_with("  albedo in"),
            "{text}"
        );
        for term in [
            "order 0: all orders",
            "ch: channel (- in a one-channel run)",
            "rel L1, rel L2:",
            "albedo diff: measured minus model",
        ] {
            assert_eq!(text.matches(term).count(), 1, "{term}: {text}");
        }
    }
}
