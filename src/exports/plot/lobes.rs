//! The plane-of-incidence figure of one surface and material: f |cos theta_o| (a bin's energy
//! over its solid angle, theory.md §4.7) against the signed outgoing angle, one row per bounce
//! order and one column per incident angle, as in the Wang et al. 2022 supplement; sweeps of
//! more than five angles wrap into blocks of at most five columns.

use std::collections::BTreeMap;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{self, CAPTION, FONT, Figure, Key, MEASURED, TICK, draw_err};
use super::{
    Points, Row, Selection, all_orders_only, bar_top, folded_note, highest_slot, plane_of_incidence, row_bins,
    row_label, surface_label,
};
use crate::io::rundir::{BinValue, Lobes, RunDir};
use crate::setup::cases::Case;
use crate::setup::config::IncidentSide;

const PANEL: (u32, u32) = (330, 250);
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
        let Some(bins) = self.bins(self.measured, case, row) else { return Ok(()) };
        let points = plane_of_incidence(self.run, &bins);
        let lines: Vec<(style::LineStyle, Points)> = self
            .models
            .iter()
            .filter_map(|(name, lobes)| {
                self.bins(lobes, case, row)
                    .map(|b| (style::model_style_by_name(name), plane_of_incidence(self.run, &b)))
            })
            .collect();
        let top = points
            .iter()
            .map(bar_top)
            .chain(lines.iter().flat_map(|(_, l)| l.iter().map(|p| p.1)))
            .fold(0.0_f64, f64::max);
        let top = if top > 0.0 && top.is_finite() { 1.08 * top } else { 1.0 };
        let decimals = style::tick_decimals(0.0, top, 5);
        let caption = format!("{}, θ_i = {:.1}°", row_label(self.run, row), case.theta_i_deg);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, CAPTION))
            .margin(6)
            .margin_right(14)
            .x_label_area_size(26)
            .y_label_area_size(56)
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
        for (line, curve) in &lines {
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
        let models = if self.models_drawn().is_empty() {
            "No models (run `smithwalk compare` to draw them).".to_string()
        } else {
            "Lines: the models of models.csv, each in its fixed colour and dash (docs/figures.md).".to_string()
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
            surface_label(self.run, self.cases[0]),
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
            title: format!("{}: {hemisphere}{}", surface_label(self.run, self.cases[0]), self.selection.suffix()),
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

#[cfg(test)]
mod tests {
    #[test]
    fn wide_sweeps_wrap_into_balanced_blocks() {
        assert_eq!(super::wrap(4), (4, 1));
        assert_eq!(super::wrap(5), (5, 1));
        assert_eq!(super::wrap(6), (3, 2));
        assert_eq!(super::wrap(10), (5, 2));
        assert_eq!(super::wrap(11), (4, 3));
    }
}
