//! The plane-of-incidence figure of one surface and material: f |cos theta_o| (a bin's energy
//! over its solid angle, theory.md §4.7) against the signed outgoing angle, one row per bounce
//! order and one column per incident angle, as in the Wang et al. 2022 supplement; sweeps of
//! more than five angles wrap into blocks of at most five columns.

use std::collections::BTreeMap;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::cases::{group_label, incidence};
use super::points::{Points, bar_top};
use super::rows::{Row, all_orders_only, folded_note, highest_slot, row_bins, row_label};
use super::selection::Selection;
use super::style::{self, CAPTION, FONT, Figure, Key, MEASURED, TICK, draw_err};
use crate::analysis::compare::is_monte_carlo;
use crate::io::rundir::{BinValue, Lobes, RunDir};
use crate::setup::cases::Case;
use crate::setup::config::{IncidentSide, Model};

const PANEL: (u32, u32) = (330, 250);
/// The opacity of a Monte Carlo model's ±1 standard-error band, in the model's colour.
const BAND_OPACITY: f64 = 0.2;
/// The most incident angles side by side before a sweep wraps into another block of rows.
const MAX_COLUMNS: usize = 5;

pub struct LobeFigure<'a> {
    pub run: &'a RunDir,
    pub cases: &'a [&'a Case],
    pub hemisphere: &'a str,
    pub selection: Selection,
    pub measured: &'a Lobes,
    pub models: &'a BTreeMap<String, Lobes>,
    pub rows: &'a [Row],
}

/// Columns per block and blocks for `n` incident angles: as few blocks as possible of at
/// most [`MAX_COLUMNS`], balanced (10 angles: 2 blocks of 5; 6 angles: 2 of 3).
pub fn wrap(n: usize) -> (usize, usize) {
    let blocks = n.div_ceil(MAX_COLUMNS).max(1);
    (n.div_ceil(blocks).max(1), blocks)
}

/// Whether the model named `name` in models.csv is a Monte Carlo estimate (drawn with its
/// standard-error band) rather than computed in closed form.
fn is_monte_carlo_name(name: &str) -> bool {
    Model::parse(name).is_ok_and(is_monte_carlo)
}

/// The ±1 standard-error band around a curve (x, y, standard error) as polygons, one per run of
/// consecutive points with a finite standard error (a summed row has none), clamped to the
/// axis' range `0..top`.
fn bands(curve: &Points, top: f64) -> Vec<Vec<(f64, f64)>> {
    curve
        .chunk_by(|a, b| a.2.is_finite() == b.2.is_finite())
        .filter(|run| run[0].2.is_finite())
        .map(|run| {
            let upper = run.iter().map(|&(x, y, e)| (x, (y + e).clamp(0.0, top)));
            let lower = run.iter().rev().map(|&(x, y, e)| (x, (y - e).clamp(0.0, top)));
            upper.chain(lower).collect()
        })
        .collect()
}

impl LobeFigure<'_> {
    fn models_drawn(&self) -> Vec<&String> {
        self.models
            .iter()
            .filter(|(_, lobes)| {
                self.cases.iter().any(|c| self.rows.iter().any(|&row| self.bins(lobes, c, row).is_some()))
            })
            .map(|(name, _)| name)
            .collect()
    }

    /// The bins of a row of one case in `lobes` (the measurement or a model).
    fn bins<'b>(&self, lobes: &'b Lobes, case: &Case, row: Row) -> Option<std::borrow::Cow<'b, [BinValue]>> {
        let ch = self.selection.channel;
        let highest = highest_slot(self.measured, case.index, self.hemisphere, ch);
        row_bins(lobes, row, (case.index, self.hemisphere, ch), highest)
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, case: &Case, row: Row) -> Result<()> {
        // lobes.csv has no rows for an order no photon left in: its panel keeps its axes and
        // says so, rather than leaving a hole in the grid.
        let points = self.bins(self.measured, case, row).map(|b| plane_of_incidence(self.run, &b)).unwrap_or_default();
        // Per model drawn: its style, its curve and whether it is a Monte Carlo estimate.
        let lines: Vec<(style::LineStyle, Points, bool)> = self
            .models
            .iter()
            .filter_map(|(name, lobes)| {
                self.bins(lobes, case, row).map(|b| {
                    (style::model_style_by_name(name), plane_of_incidence(self.run, &b), is_monte_carlo_name(name))
                })
            })
            .collect();
        let top = points
            .iter()
            .map(bar_top)
            .chain(lines.iter().flat_map(|(_, l, _)| l.iter().map(|p| p.1)))
            .fold(0.0_f64, f64::max);
        let top = if top > 0.0 && top.is_finite() { 1.08 * top } else { 1.0 };
        let decimals = style::tick_decimals(0.0, top, 5);
        let caption = format!("{}, {}", row_label(self.run, row), incidence(case));
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, CAPTION))
            .margin(6)
            .margin_right(14)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d((-90.0..90.001).step(30.0), 0.0..top)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(0xe4, 0xe4, 0xe4))
            .x_labels(7)
            .y_labels(5)
            .label_style((FONT, TICK))
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| style::tick(*v, decimals))
            .draw()
            .map_err(draw_err)?;
        // The Monte Carlo models' bands under every line, the lines under the walk's points.
        for (line, curve, _) in lines.iter().filter(|l| l.2) {
            let fill = line.colour.mix(BAND_OPACITY).filled();
            chart.draw_series(bands(curve, top).into_iter().map(|b| Polygon::new(b, fill))).map_err(draw_err)?;
        }
        // The Monte Carlo models' noisy lines first, so that the closed-form ones (`single`, the
        // exact oracle of order 1) stay visible on top of them.
        let (noisy, exact): (Vec<_>, Vec<_>) = lines.iter().partition(|l| l.2);
        for (line, curve, _) in noisy.into_iter().chain(exact) {
            let curve: Vec<(f64, f64)> = curve.iter().map(|p| (p.0, p.1)).collect();
            style::draw_line(chart.plotting_area(), &curve, *line)?;
        }
        chart
            .draw_series(
                points
                    .iter()
                    .filter(|p| p.2.is_finite())
                    .map(|&(x, y, e)| PathElement::new(vec![(x, y - e), (x, y + e)], MEASURED.stroke_width(1))),
            )
            .map_err(draw_err)?;
        chart
            .draw_series(points.iter().map(|&(x, y, _)| Circle::new((x, y), 2, MEASURED.filled())))
            .map_err(draw_err)?;
        if points.is_empty() && lines.is_empty() {
            let (x, y) = chart.plotting_area().get_pixel_range();
            let (ax, ay) = area.get_base_pixel();
            let centre = ((x.start + x.end) / 2 - ax, (y.start + y.end) / 2 - ay);
            let text = if row_label(self.run, row).starts_with("orders") {
                "no light in these orders"
            } else {
                "no light in this order"
            };
            style::draw_centred(area, text, centre, CAPTION, false)?;
        }
        Ok(())
    }

    /// The axis the hemisphere's θ_o is measured from: +z on the side of the light for R, the
    /// other side for T (lobes.csv's `theta_o_deg` is from +z: θ_o is it or 180° minus it).
    fn axis(&self) -> &'static str {
        let below = (self.hemisphere == "T") == (self.cases[0].side == IncidentSide::Outside);
        if below { "−z" } else { "+z" }
    }

    /// What the positive angles of the figure are: the mirror side in R, the refraction side in T.
    fn positive_side(&self) -> &'static str {
        if self.hemisphere == "T" { "refraction" } else { "mirror" }
    }

    /// What the report says under the figure.
    pub fn caption(&self) -> String {
        let g = self.run.grid;
        let hemisphere = if self.hemisphere == "T" { "transmitted" } else { "reflected" };
        let drawn = self.models_drawn();
        let monte_carlo: Vec<&str> = drawn.iter().map(|m| m.as_str()).filter(|m| is_monte_carlo_name(m)).collect();
        let bands = if monte_carlo.is_empty() {
            String::new()
        } else {
            let summed = if self.rows.iter().any(|r| matches!(r, Row::From(_))) {
                "; the summed row has none, for the reason its points have no error bars"
            } else {
                ""
            };
            let closed = if drawn.len() > monte_carlo.len() {
                " The other models are computed in closed form: lines alone."
            } else {
                ""
            };
            format!(
                " The Monte Carlo models ({}) are estimates with noise of their own, which makes their lines jump \
                 from bin to bin in sparse lobes: the light band in a model's colour around its line is ±1 standard \
                 error of its estimate (models.csv){summed}.{closed}",
                monte_carlo.join(", ")
            )
        };
        let models = if drawn.is_empty() {
            "No models (run `smithwalk compare` to draw them).".to_string()
        } else {
            format!("Lines: the models of models.csv, each in its fixed colour and dash (docs/figures.md).{bands}")
        };
        let rows = if all_orders_only(self.rows) {
            "all bounce orders together in one row"
        } else {
            "one row per bounce order"
        };
        format!(
            "{}: the {hemisphere} lobe f·|cos θ_o| (1/sr) in the plane of incidence against the outgoing angle θ_o, \
             measured from {} (positive on the {} side, φ_o = 180°; negative on the light's side, φ_o = 0°), {rows} \
             and one column per incident angle θ_i. Black points: the random walk, each the average over a detector \
             bin ({} bins in |cos θ_o|, {:.1}° of azimuth), with ±1 standard-error bars.{} {models}{}",
            group_label(self.run, self.cases[0]),
            self.axis(),
            self.positive_side(),
            g.cos_bins,
            360.0 / g.phi_bins as f64,
            folded_note(self.run, self.rows, true),
            self.selection.note(),
        )
    }

    /// The legend: the walk's points and every model drawn.
    fn legend(&self) -> Vec<(Key, String)> {
        let mut legend = vec![(Key::Measured, "random walk (±1 SE)".to_string())];
        legend.extend(self.models_drawn().into_iter().map(|m| (Key::Line(style::model_style_by_name(m)), m.clone())));
        legend
    }

    fn grid(&self) -> (usize, usize) {
        let (cols, blocks) = wrap(self.cases.len());
        (cols, blocks * self.rows.len())
    }

    fn labels(&self) -> style::GridLabels {
        let hemisphere = if self.hemisphere == "T" { "transmission (T)" } else { "reflection (R)" };
        style::GridLabels {
            title: format!("{}: {hemisphere}{}", group_label(self.run, self.cases[0]), self.selection.suffix()),
            legend: self.legend(),
            y: "f·|cos θ_o| (1/sr)".to_string(),
            x: format!("θ_o from {} (deg): + {} side, − light's side", self.axis(), self.positive_side()),
        }
    }
}

impl Figure for LobeFigure<'_> {
    fn size(&self) -> (u32, u32) {
        style::grid_size(PANEL, self.grid(), &self.labels())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let labels = self.labels();
        let (cols, rows) = self.grid();
        let panels = style::draw_grid(root, &labels, (cols, rows))?;
        for (i, case) in self.cases.iter().enumerate() {
            let (block, col) = (i / cols, i % cols);
            for (r, &row) in self.rows.iter().enumerate() {
                let at = (block * self.rows.len() + r) * cols + col;
                self.panel(&panels[at], case, row)?;
            }
        }
        Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exports::plot::rows::tests::written_run;

    #[test]
    fn wide_sweeps_wrap_into_balanced_blocks() {
        assert_eq!(super::wrap(4), (4, 1));
        assert_eq!(super::wrap(5), (5, 1));
        assert_eq!(super::wrap(6), (3, 2));
        assert_eq!(super::wrap(10), (5, 2));
        assert_eq!(super::wrap(11), (4, 3));
    }

    /// A band runs over consecutive points with a finite standard error: up along y + e, back
    /// along y - e, clamped to the axis.
    #[test]
    fn bands_cover_runs_of_finite_errors_within_the_axis() {
        let curve = vec![(-1.0, 0.5, 0.1), (0.0, 0.2, 0.3), (1.0, 0.9, f64::NAN), (2.0, 0.9, 0.2)];
        let bands = bands(&curve, 1.0);
        assert_eq!(bands.len(), 2);
        assert_eq!(bands[0], [(-1.0, 0.6), (0.0, 0.5), (0.0, 0.0), (-1.0, 0.4)]);
        assert_eq!(bands[1], [(2.0, 1.0), (2.0, 0.7)]);
    }

    /// Pixels of `png` within 2 of `colour` in every channel.
    fn pixels_of(png: &[u8], colour: (f64, f64, f64)) -> usize {
        let image = image::load_from_memory(png).unwrap().to_rgb8();
        let near = |p: &image::Rgb<u8>| {
            [colour.0, colour.1, colour.2].iter().zip(p.0).all(|(c, v)| (c - f64::from(v)).abs() <= 2.0)
        };
        image.pixels().filter(|p| near(p)).count()
    }

    /// A Monte Carlo model's line gets a light band of ±1 its standard error in its colour; a
    /// closed-form model's line is drawn alone, whatever its standard errors; the caption says
    /// which models have a band.
    #[test]
    fn monte_carlo_models_are_drawn_with_a_standard_error_band() {
        let (_dir, run) = written_run(
            "paths = 4000\nseed = 3\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n",
        );
        let measured = run.measured().unwrap();
        // A model: the measured lobes times `scale`, with a standard error of `error` of each bin.
        let model = |scale: f64, error: f64| Lobes {
            lobes: measured
                .lobes
                .iter()
                .map(|(id, bins)| {
                    let bins = bins
                        .iter()
                        .map(|b| BinValue { energy: scale * b.energy, energy_stderr: error * scale * b.energy, ..*b })
                        .collect();
                    (id.clone(), bins)
                })
                .collect(),
        };
        let cases: Vec<&Case> = run.cases.iter().collect();
        let rows = super::super::rows::rows(2);
        let drawn = |single_error: f64| {
            let models: BTreeMap<String, Lobes> =
                [("heitz-nee".to_string(), model(1.0, 0.3)), ("single".to_string(), model(0.6, single_error))].into();
            let figure = LobeFigure {
                run: &run,
                cases: &cases,
                hemisphere: "R",
                selection: Selection { channel: 0, rgb: false, log: false },
                measured: &measured,
                models: &models,
                rows: &rows,
            };
            (style::render(&figure, style::Format::Png).unwrap(), figure.caption())
        };
        let (png, caption) = drawn(0.3);
        // A band over white: 0.2 of the model's colour, 0.8 of white.
        let mix = |v: u8| BAND_OPACITY * f64::from(v) + (1.0 - BAND_OPACITY) * 255.0;
        let blue = style::model_style(Model::HeitzNee).colour;
        let band = pixels_of(&png, (mix(blue.0), mix(blue.1), mix(blue.2)));
        assert!(band > 5000, "heitz-nee's band: {band} pixels");
        assert!(png == drawn(0.0).0, "single's standard errors change the figure");
        assert!(
            caption.contains("Monte Carlo models (heitz-nee)") && caption.contains("±1 standard error"),
            "{caption}"
        );
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
}
