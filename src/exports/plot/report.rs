//! `index.html`: the run report. It opens from `file://` without network (no scripts, no
//! external resources): a header line with what every case shares, the comparison with the
//! models when `compare.csv` exists, and every figure with a caption, the case table of each
//! surface and material showing only the columns that vary.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use super::cases::{describe, group_label, pretty_fields, varying};
use super::rows::slot_label;
use super::selection::Selection;
use crate::analysis::stats::sidak;
use crate::io::output::case_fields;
use crate::io::rundir::{Lobes, RunDir, Table};
use crate::io::schema::{self, CASE_COLUMNS};
use crate::setup::cases::Case;

/// A figure drawn and the caption the report shows under it.
pub(super) struct Drawn {
    pub(super) name: String,
    pub(super) bytes: Vec<u8>,
    pub(super) caption: String,
}

/// The family-wise significance level of the comparison verdicts (Sidak over a model's lobes),
/// as in `smithwalk compare`.
const FAMILY_LEVEL: f64 = 0.01;
/// Worst lobes listed per model.
const WORST: usize = 5;

/// The figures of one surface and material.
pub(super) struct Section<'a> {
    pub cases: Vec<&'a Case>,
    pub lobes: Vec<Drawn>,
    pub heats: Vec<Drawn>,
}

/// A p-value as the console prints it (`<1e-300` below what a double holds), for HTML.
fn p_text(p: f64) -> String {
    escape(&crate::analysis::compare::p_value_text(p))
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A figure with its caption, numbered.
fn figure(html: &mut String, number: &mut usize, drawn: &Drawn) {
    *number += 1;
    let _ = writeln!(
        html,
        "<figure><img src=\"{0}\" alt=\"{0}\"><figcaption><b>Figure {1}.</b> {2} <a href=\"{0}\">{0}</a></figcaption></figure>",
        escape(&drawn.name),
        number,
        escape(&drawn.caption)
    );
}

/// One row of `compare.csv`, read by column name.
struct Comparison {
    case: usize,
    model: String,
    order: usize,
    hemisphere: String,
    channel: Option<String>,
    chi2: f64,
    dof: String,
    p: f64,
    rel_l1: f64,
    albedo_diff_se: f64,
    folded: Option<bool>,
    family_level: Option<f64>,
    lobe_level: Option<f64>,
    rejected: Option<bool>,
}

/// The rows of `compare.csv`, once the comparison is checked to be sealed and this run's
/// ([`RunDir::comparison`]); `None` if `compare` has not run.
fn read_comparisons(run: &RunDir) -> Result<Option<Vec<Comparison>>> {
    if run.comparison()?.is_none() {
        return Ok(None);
    }
    let path = run.path.join(schema::COMPARE.file);
    let table = Table::read(&path, run.table_limit)?;
    let column = |c| table.column(c);
    let optional = |c| table.optional(c);
    let (case, model, order, hemisphere) =
        (column(schema::CASE)?, column(schema::MODEL)?, column(schema::ORDER)?, column(schema::HEMISPHERE)?);
    let (chi2, dof, p, rel_l1, diff) = (
        column(schema::CHI2)?,
        column(schema::DOF)?,
        column(schema::P_VALUE)?,
        column(schema::REL_L1)?,
        column(schema::ALBEDO_DIFF_SE)?,
    );
    let (channel, folded, level, lobe_level, rejected) = (
        optional(schema::CHANNEL),
        optional(schema::FOLDED),
        optional(schema::FAMILY_LEVEL),
        optional(schema::LOBE_LEVEL),
        optional(schema::REJECTED),
    );
    let number = |r: &csv::StringRecord, c: usize| -> Result<f64> {
        r[c].parse().map_err(|_| {
            anyhow::anyhow!("{}: `{}` in column {} is not a number", path.display(), &r[c], &table.headers[c])
        })
    };
    let flag = |r: &csv::StringRecord, c: Option<usize>| c.map(|c| matches!(&r[c], "true" | "1"));
    table
        .records
        .iter()
        .map(|r| {
            Ok(Comparison {
                case: number(r, case)? as usize,
                model: r[model].to_string(),
                order: number(r, order)? as usize,
                hemisphere: r[hemisphere].to_string(),
                channel: channel.map(|c| r[c].to_string()),
                chi2: number(r, chi2)?,
                dof: r[dof].to_string(),
                p: number(r, p)?,
                rel_l1: number(r, rel_l1)?,
                albedo_diff_se: number(r, diff)?,
                folded: flag(r, folded),
                family_level: level.map(|c| number(r, c)).transpose()?,
                lobe_level: lobe_level.map(|c| number(r, c)).transpose()?,
                rejected: flag(r, rejected),
            })
        })
        .collect::<Result<Vec<_>>>()
        .map(Some)
}

/// Per model: the number of lobes, the family level, the per-lobe level, how many lobes it
/// rejects, and the worst lobes. `family_level`, `lobe_level` and `rejected` come from
/// `compare.csv` when it has them; otherwise they are computed here: Sidak at family level 0.01
/// over the model's lobes.
fn comparison_tables(html: &mut String, run: &RunDir, rows: &[Comparison]) {
    let mut by_model: BTreeMap<&str, Vec<&Comparison>> = BTreeMap::new();
    for row in rows {
        by_model.entry(row.model.as_str()).or_default().push(row);
    }
    html.push_str(
        "<h2>Measurement against the models</h2>\n<p>Per lobe (case, order, hemisphere), a chi-square test of the walk's bins \
         against the model's; a model is rejected in a lobe where p is below the family level, Sidak-corrected over the \
         model's lobes so that a right model is rejected anywhere with probability 0.01. <code>rel L1</code>: the lobe \
         difference relative to the model's L1 norm; <code>albedo diff</code>: measured minus model albedo in combined \
         standard errors.</p>\n<table class=\"compare\"><tr><th>model</th><th>lobes</th><th>family level</th>\
         <th>per-lobe level</th><th>rejected</th><th>worst p</th><th>verdict</th></tr>\n",
    );
    for (model, lobes) in &by_model {
        let family = lobes.iter().find_map(|c| c.family_level).unwrap_or(FAMILY_LEVEL);
        let level = lobes.iter().find_map(|c| c.lobe_level).unwrap_or_else(|| sidak(family, lobes.len()));
        let rejected = lobes.iter().filter(|c| c.rejected.unwrap_or(c.p < level)).count();
        let worst = lobes.iter().map(|c| c.p).fold(f64::INFINITY, f64::min);
        let verdict =
            if rejected == 0 { "agrees with the walk".to_string() } else { format!("rejected in {rejected} lobes") };
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{family}</td><td>{level:.2e}</td><td>{rejected}</td><td>{}</td><td class=\"{}\">{verdict}</td></tr>",
            escape(model),
            lobes.len(),
            p_text(worst),
            if rejected == 0 { "pass" } else { "fail" }
        );
    }
    html.push_str("</table>\n");
    for (model, lobes) in &by_model {
        let mut worst: Vec<&&Comparison> = lobes.iter().collect();
        worst.sort_by(|a, b| a.p.total_cmp(&b.p));
        let _ = writeln!(html, "<h3>{}: the {} lobes with the lowest p</h3>", escape(model), WORST.min(worst.len()));
        html.push_str("<table class=\"compare\"><tr><th>case</th><th>parameters</th><th>order</th><th>hemisphere</th><th>χ²</th><th>dof</th><th>p</th><th>rel L1</th><th>albedo diff (SE)</th></tr>\n");
        for c in worst.into_iter().take(WORST) {
            let case = &run.cases[c.case.min(run.cases.len() - 1)];
            let parameters = pretty_fields(run, case, &[]);
            let order = if c.folded == Some(true) { format!("{}+", c.order) } else { slot_label(run, c.order) };
            let hemisphere = match &c.channel {
                Some(ch) => format!("{} ({ch})", c.hemisphere),
                None => c.hemisphere.clone(),
            };
            let _ = writeln!(
                html,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.1}</td></tr>",
                c.case,
                escape(&parameters),
                escape(&order),
                escape(&hemisphere),
                c.chi2,
                escape(&c.dof),
                p_text(c.p),
                c.rel_l1,
                c.albedo_diff_se
            );
        }
        html.push_str("</table>\n");
    }
}

/// The whole page.
pub(super) fn page(
    run: &RunDir,
    run_dir: &Path,
    models: &BTreeMap<String, Lobes>,
    selection: Selection,
    albedos: &[Drawn],
    sections: &[Section],
) -> Result<String> {
    let name = run_dir.file_name().map_or_else(|| run_dir.display().to_string(), |n| n.to_string_lossy().into_owned());
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>smithwalk run {0}</title>\n<style>\
         body{{font-family:sans-serif;margin:2em;max-width:1400px;color:#222}} img{{max-width:100%;height:auto}} \
         figure{{margin:1.5em 0}} figcaption{{max-width:60em;font-size:0.95em;margin-top:0.3em}} \
         td,th{{padding:2px 8px;text-align:left}} table{{border-collapse:collapse;margin:0.5em 0}} \
         tr:nth-child(even){{background:#f3f3f3}} th{{border-bottom:1px solid #999}} \
         td.pass{{color:#006400}} td.fail{{color:#b00000;font-weight:bold}} p.header{{background:#f6f6f6;padding:0.5em}}\
         </style></head><body>\n<h1>smithwalk run {0}</h1>\n",
        escape(&name)
    );
    // The header line: what every case shares.
    let shown = varying(&run.cases);
    let first = case_fields(&run.cases[0]);
    let fixed: Vec<usize> = (1..CASE_COLUMNS.len()).filter(|c| !shown.contains(c)).collect();
    let constant = describe(&first, &fixed);
    let _ = writeln!(
        html,
        "<p class=\"header\">{} cases, {} photons each, seed {}; detector {} × {} bins (|cos θ_o| × φ_o){}. \
         Every case: {}. Models: {}.{}</p>",
        run.cases.len(),
        run.config.paths,
        run.config.seed,
        run.grid.cos_bins,
        run.grid.phi_bins,
        run.config.detector.max_order.map_or(String::new(), |k| format!(", orders {k} and above folded into \"{k}+\"")),
        escape(&constant.join(", ")),
        if models.is_empty() {
            "none (run <code>smithwalk compare</code> first to draw them)".to_string()
        } else {
            escape(&models.keys().cloned().collect::<Vec<_>>().join(", "))
        },
        if selection.rgb {
            format!(" An RGB run: the figures show channel {}.", selection.channel_name().unwrap_or("r"))
        } else {
            String::new()
        }
    );
    if let Some(rows) = read_comparisons(run)? {
        comparison_tables(&mut html, run, &rows);
    }
    let mut number = 0;
    if !albedos.is_empty() {
        html.push_str("<h2>Albedo per order</h2>\n");
        for drawn in albedos {
            figure(&mut html, &mut number, drawn);
        }
    }
    for section in sections {
        let _ = writeln!(html, "<h2>{}</h2>", escape(&group_label(run, section.cases[0])));
        html.push_str("<table><tr><th>case</th>");
        for &c in &shown {
            let _ = write!(html, "<th>{}</th>", CASE_COLUMNS[c].name);
        }
        html.push_str("</tr>\n");
        for case in &section.cases {
            let fields = case_fields(case);
            let _ = write!(html, "<tr><td>{}</td>", case.index);
            for &c in &shown {
                let _ = write!(html, "<td>{}</td>", escape(&fields[c]));
            }
            html.push_str("</tr>\n");
        }
        html.push_str("</table>\n");
        for drawn in &section.lobes {
            figure(&mut html, &mut number, drawn);
        }
        let _ = writeln!(html, "<details><summary>Heat maps of the {} cases above</summary>", section.cases.len());
        for drawn in &section.heats {
            figure(&mut html, &mut number, drawn);
        }
        html.push_str("</details>\n");
    }
    html.push_str("</body></html>\n");
    Ok(html)
}

#[cfg(test)]
mod tests {
    /// An underflowed p-value reads as the console's bound (it read `0`, a false value), escaped.
    #[test]
    fn an_underflowed_p_value_is_a_bound_in_html() {
        assert_eq!(super::p_text(0.0), "&lt;1e-300");
        assert_eq!(super::p_text(9.28e-4), "9.28e-4");
    }
}
