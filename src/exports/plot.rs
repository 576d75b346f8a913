//! `smithwalk plot RUN_DIR`: PNG figures of a finished run, and an `index.html` that shows
//! them with their case parameters.
//!
//! - `lobes_<group>_<R|T>.png`: for one surface and material, the lobe in the plane of
//!   incidence, f |cos theta_o| (a bin's energy over its solid angle, §4.7), against the signed
//!   outgoing angle (positive on the mirror side, phi = 180 deg), one row per bounce order
//!   (1, 2, 3, the last or "K+", all) and one column per incident angle, as in the Wang et al.
//!   2022 supplement figures. The measurement is drawn with one-standard-error bars, every model
//!   of `models.csv` as a line.
//! - `heat_case<i>_<R|T>.png`: polar maps of the full lobe f per order, over the projected
//!   hemisphere (x = sin theta_o cos phi_o, y = sin theta_o sin phi_o, phi from the incident
//!   azimuth: the light comes from +x).
//! - `albedo_vs_theta.png`, `albedo_vs_alpha.png`: per-order albedos with error bars.
//!
//! RGB runs are drawn in their first channel.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;

use crate::atomic::write_atomically;
use crate::io::output::case_fields;
use crate::io::rundir::{BinValue, Lobes, RunDir, SummaryRow};
use crate::setup::cases::Case;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
/// Points of a curve with error bars: (x, y, standard error).
type Points = Vec<(f64, f64, f64)>;

const FONT: &str = "sans-serif";
/// Line colours of the models, in `models.csv` order (the measurement is black).
const MODEL_COLOURS: [RGBColor; 6] = [
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
];

/// Draws into a `width` x `height` RGB canvas and encodes it as PNG.
fn render(width: u32, height: u32, draw: impl FnOnce(&Area) -> Result<()>) -> Result<Vec<u8>> {
    let mut pixels = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    let image = image::RgbImage::from_raw(width, height, pixels).context("canvas size")?;
    let mut png = std::io::Cursor::new(Vec::new());
    image.write_to(&mut png, image::ImageOutputFormat::Png).context("cannot encode PNG")?;
    Ok(png.into_inner())
}

fn draw_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("cannot draw: {e}")
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

/// Cases that differ only in the incident polar angle, in order of their first case, each
/// sorted by the incident angle.
fn groups(cases: &[Case]) -> Vec<Vec<&Case>> {
    let mut map: BTreeMap<Vec<String>, Vec<&Case>> = BTreeMap::new();
    for case in cases {
        let mut key = case_fields(case);
        key.remove(8); // theta_i_deg
        key.remove(0); // case index
        map.entry(key).or_default().push(case);
    }
    let mut out: Vec<Vec<&Case>> = map.into_values().collect();
    out.sort_by_key(|cases| cases[0].index);
    for cases in &mut out {
        cases.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg));
    }
    out
}

fn surface_label(case: &Case) -> String {
    format!("{:?} alpha=({}, {}) {}", case.ndf, case.alpha_x, case.alpha_y, case.material.label()).to_lowercase()
}

/// One surface and material: orders x incident angles of plane-of-incidence lobes.
fn lobe_figure(
    run: &RunDir,
    cases: &[&Case],
    hemisphere: &str,
    measured: &Lobes,
    models: &BTreeMap<String, Lobes>,
) -> Result<Vec<u8>> {
    let orders = slots(run, measured);
    let (cols, rows) = (cases.len() as u32, orders.len() as u32);
    render(280 * cols, 40 + 210 * rows, |root| {
        let (top, body) = root.split_vertically(40);
        let title = format!("{} - {} - f|cos theta_o| in the plane of incidence", surface_label(cases[0]), hemisphere);
        top.titled(&title, (FONT, 20)).map_err(draw_err)?;
        let panels = body.split_evenly((rows as usize, cols as usize));
        for (r, &slot) in orders.iter().enumerate() {
            for (c, case) in cases.iter().enumerate() {
                let area = &panels[r * cols as usize + c];
                let Some(bins) = measured.get(case.index, slot, hemisphere, 0) else { continue };
                let points = plane_of_incidence(run, bins);
                // Colours follow the model, not its position among the models of this panel.
                let lines: Vec<(RGBColor, &String, Points)> = models
                    .iter()
                    .enumerate()
                    .filter_map(|(k, (name, lobes))| {
                        let colour = MODEL_COLOURS[k % MODEL_COLOURS.len()];
                        lobes.get(case.index, slot, hemisphere, 0).map(|b| (colour, name, plane_of_incidence(run, b)))
                    })
                    .collect();
                let top = points
                    .iter()
                    .map(|p| p.1 + p.2)
                    .chain(lines.iter().flat_map(|(_, _, l)| l.iter().map(|p| p.1)))
                    .fold(0.0_f64, f64::max);
                let top = if top > 0.0 && top.is_finite() { 1.1 * top } else { 1.0 };
                let caption = format!("{}, theta_i = {:.1} deg", slot_label(run, slot), case.theta_i_deg);
                let mut chart = ChartBuilder::on(area)
                    .caption(caption, (FONT, 13))
                    .margin(6)
                    .x_label_area_size(20)
                    .y_label_area_size(42)
                    .build_cartesian_2d(-90.0..90.0, 0.0..top)
                    .map_err(draw_err)?;
                chart
                    .configure_mesh()
                    .x_labels(7)
                    .y_labels(5)
                    .label_style((FONT, 10))
                    .y_label_formatter(&|v| format!("{v:.2e}"))
                    .draw()
                    .map_err(draw_err)?;
                for &(colour, name, ref line) in &lines {
                    let series = chart
                        .draw_series(LineSeries::new(line.iter().map(|p| (p.0, p.1)), colour.stroke_width(2)))
                        .map_err(draw_err)?;
                    series
                        .label(name.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
                }
                chart
                    .draw_series(
                        points.iter().map(|&(x, y, e)| ErrorBar::new_vertical(x, y - e, y, y + e, BLACK.filled(), 3)),
                    )
                    .map_err(draw_err)?
                    .label("walk (1 SE)")
                    .legend(|(x, y)| Circle::new((x + 8, y), 2, BLACK.filled()));
                if r == 0 && c == 0 {
                    chart
                        .configure_series_labels()
                        .label_font((FONT, 10))
                        .background_style(WHITE.mix(0.8))
                        .border_style(BLACK)
                        .position(SeriesLabelPosition::UpperLeft)
                        .draw()
                        .map_err(draw_err)?;
                }
            }
        }
        Ok(())
    })
}

/// One case and hemisphere: polar maps of f per order.
fn heat_figure(run: &RunDir, case: &Case, hemisphere: &str, measured: &Lobes) -> Result<Vec<u8>> {
    let orders = slots(run, measured);
    let g = run.grid;
    render(260 * orders.len() as u32, 330, |root| {
        let (top, body) = root.split_vertically(40);
        let title = format!(
            "case {}: {}, theta_i = {:.1} deg, {} - f over the projected hemisphere (light from +x)",
            case.index,
            surface_label(case),
            case.theta_i_deg,
            hemisphere
        );
        top.titled(&title, (FONT, 15)).map_err(draw_err)?;
        for (area, &slot) in body.split_evenly((1, orders.len())).iter().zip(&orders) {
            let Some(bins) = measured.get(case.index, slot, hemisphere, 0) else { continue };
            let max = bins.iter().map(|b| b.bsdf).fold(0.0_f64, f64::max);
            let caption = format!("{}: max f = {max:.3e}", slot_label(run, slot));
            let mut chart = ChartBuilder::on(area)
                .caption(caption, (FONT, 12))
                .margin(8)
                .build_cartesian_2d(-1.0..1.0, -1.0..1.0)
                .map_err(draw_err)?;
            let polygons = (0..g.bins()).map(|i| {
                let (lo, hi) = g.cos_edges(i / g.phi_bins);
                let (r_in, r_out) = ((1.0 - hi * hi).max(0.0).sqrt(), (1.0 - lo * lo).max(0.0).sqrt());
                let (p0, p1) = g.phi_edges_deg(i % g.phi_bins);
                let arc = |r: f64, from: f64, to: f64| {
                    (0..=4).map(move |k| {
                        let p = (from + (to - from) * k as f64 / 4.0).to_radians();
                        (r * p.cos(), r * p.sin())
                    })
                };
                let outline: Vec<(f64, f64)> = arc(r_out, p0, p1).chain(arc(r_in, p1, p0)).collect();
                let level = if max > 0.0 { bins[i].bsdf / max } else { 0.0 };
                Polygon::new(outline, ViridisRGB::get_color(level.clamp(0.0, 1.0) as f32).filled())
            });
            chart.draw_series(polygons).map_err(draw_err)?;
        }
        Ok(())
    })
}

/// Per-order albedos against a case parameter: one panel per combination of the other
/// parameters and hemisphere, one line per order slot.
fn albedo_figure(
    run: &RunDir,
    summary: &[SummaryRow],
    x_name: &str,
    x_of: impl Fn(&Case) -> f64,
    key_of: impl Fn(&Case) -> String,
) -> Result<Option<Vec<u8>>> {
    let mut panels: BTreeMap<(String, String), BTreeMap<usize, Points>> = BTreeMap::new();
    for row in summary.iter().filter(|r| matches!(r.hemisphere.as_str(), "R" | "T")) {
        if row.channel.as_deref().is_some_and(|c| c != "r") {
            continue;
        }
        let case = &run.cases[row.case];
        let panel = panels.entry((key_of(case), row.hemisphere.clone())).or_default();
        panel.entry(row.order).or_default().push((x_of(case), row.albedo, row.albedo_stderr));
    }
    let longest = panels.values().flat_map(|p| p.values()).map(Vec::len).max().unwrap_or(0);
    if longest < 2 {
        return Ok(None);
    }
    let cols = panels.len().min(4);
    let rows = panels.len().div_ceil(cols);
    let png = render(360 * cols as u32, 270 * rows as u32, |root| {
        for (area, ((key, hemisphere), orders)) in root.split_evenly((rows, cols)).iter().zip(&panels) {
            let xs = orders.values().flatten().map(|p| p.0);
            let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            let pad = 0.05 * (hi - lo).max(1e-9);
            let top = orders.values().flatten().map(|p| p.1 + p.2).fold(0.0_f64, f64::max).max(1e-9) * 1.1;
            let mut chart = ChartBuilder::on(area)
                .caption(format!("{key} {hemisphere}"), (FONT, 12))
                .margin(6)
                .x_label_area_size(30)
                .y_label_area_size(40)
                .build_cartesian_2d(lo - pad..hi + pad, 0.0..top)
                .map_err(draw_err)?;
            chart
                .configure_mesh()
                .x_desc(x_name)
                .y_desc("albedo")
                .label_style((FONT, 10))
                .axis_desc_style((FONT, 11))
                .draw()
                .map_err(draw_err)?;
            let ordered = orders.iter().filter(|(s, _)| **s != 0).chain(orders.iter().filter(|(s, _)| **s == 0));
            for (k, (&slot, points)) in ordered.enumerate() {
                let colour = if slot == 0 { BLACK } else { MODEL_COLOURS[k % MODEL_COLOURS.len()] };
                let mut points = points.clone();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart
                    .draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), colour.stroke_width(2)))
                    .map_err(draw_err)?
                    .label(slot_label(run, slot))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
                chart
                    .draw_series(
                        points.iter().map(|&(x, y, e)| ErrorBar::new_vertical(x, y - e, y, y + e, colour.filled(), 3)),
                    )
                    .map_err(draw_err)?;
            }
            chart
                .configure_series_labels()
                .label_font((FONT, 9))
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(draw_err)?;
        }
        Ok(())
    })?;
    Ok(Some(png))
}

fn html_escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Draws every figure of the run in `run_dir` and writes them with `index.html` into it.
pub fn plot(run_dir: &Path) -> Result<Vec<PathBuf>> {
    let run = RunDir::open(run_dir)?;
    let measured = run.measured()?;
    let models: BTreeMap<String, Lobes> = run.models()?.into_iter().collect();
    let summary = run.summary()?;
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>smithwalk run {}</title>\n\
         <style>body{{font-family:sans-serif;margin:2em}} img{{max-width:100%}} td,th{{padding:2px 8px;text-align:left}} table{{border-collapse:collapse}} tr:nth-child(even){{background:#f3f3f3}}</style></head><body>\n\
         <h1>smithwalk run {}</h1>\n<p>{} cases, {} photons each, seed {}; a {} x {} (cos theta x phi) detector. Models: {}.</p>\n",
        html_escape(&run_dir.display().to_string()),
        html_escape(&run_dir.display().to_string()),
        run.cases.len(),
        run.config.paths,
        run.config.seed,
        run.grid.cos_bins,
        run.grid.phi_bins,
        if models.is_empty() {
            "none (run `smithwalk compare` first to draw them)".to_string()
        } else {
            models.keys().cloned().collect::<Vec<_>>().join(", ")
        },
    );
    if run.config.is_rgb() {
        html.push_str("<p>An RGB run: figures show the first (red) channel.</p>\n");
    }
    html.push_str("<h2>Albedo per order</h2>\n");
    let by_theta = albedo_figure(
        &run,
        &summary,
        "theta_i (deg)",
        |c| c.theta_i_deg,
        |c| format!("{} a={}", c.material.label(), c.alpha_x),
    )?;
    let by_alpha = albedo_figure(
        &run,
        &summary,
        "alpha_x",
        |c| c.alpha_x,
        |c| format!("{} th={:.1}", c.material.label(), c.theta_i_deg),
    )?;
    for (name, png) in [("albedo_vs_theta.png", by_theta), ("albedo_vs_alpha.png", by_alpha)] {
        if let Some(png) = png {
            let _ = writeln!(html, "<p><img src=\"{name}\" alt=\"{name}\"></p>");
            files.push((name.to_string(), png));
        }
    }
    for (group, cases) in groups(&run.cases).into_iter().enumerate() {
        let _ = writeln!(html, "<h2>{}</h2>", html_escape(&surface_label(cases[0])));
        html.push_str("<table><tr>");
        for column in crate::io::output::CASE_COLUMNS {
            let _ = write!(html, "<th>{column}</th>");
        }
        html.push_str("<th>heat maps</th></tr>\n");
        let hemispheres: Vec<String> =
            crate::io::output::hemispheres(cases[0]).iter().map(|h| format!("{h:?}")).collect();
        for case in &cases {
            html.push_str("<tr>");
            for field in case_fields(case) {
                let _ = write!(html, "<td>{}</td>", html_escape(&field));
            }
            html.push_str("<td>");
            for h in &hemispheres {
                let name = format!("heat_case{}_{h}.png", case.index);
                files.push((name.clone(), heat_figure(&run, case, h, &measured)?));
                let _ = write!(html, "<a href=\"{name}\">{h}</a> ");
            }
            html.push_str("</td></tr>\n");
        }
        html.push_str("</table>\n");
        for h in &hemispheres {
            let name = format!("lobes_g{group}_{h}.png");
            files.push((name.clone(), lobe_figure(&run, &cases, h, &measured, &models)?));
            let _ = writeln!(html, "<p><img src=\"{name}\" alt=\"{name}\"></p>");
        }
    }
    html.push_str("</body></html>\n");
    files.push(("index.html".to_string(), html.into_bytes()));
    let refs: Vec<(&str, Vec<u8>)> = files.iter_mut().map(|(n, b)| (n.as_str(), std::mem::take(b))).collect();
    write_atomically(run_dir, &refs)
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
