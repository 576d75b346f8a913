//! Per-order albedos against one swept case parameter (the incident angle or the roughness):
//! one panel per combination of the other parameters and hemisphere, one line with markers and
//! one-standard-error bars per order slot, and one legend for the whole figure.

use std::collections::BTreeMap;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{self, CAPTION, FONT, Figure, Key, TICK, draw_err};
use super::{Points, Selection, groups, pretty_fields, slot_label};
use crate::io::rundir::{RunDir, SummaryRow};
use crate::setup::cases::Case;

const PANEL: (u32, u32) = (360, 260);
const MAX_COLUMNS: usize = 4;

/// The parameter on the x axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    Theta,
    Alpha,
}

impl Sweep {
    fn x(self, case: &Case) -> f64 {
        match self {
            Sweep::Theta => case.theta_i_deg,
            Sweep::Alpha => case.alpha_x,
        }
    }

    /// Which case columns (of `CASE_COLUMNS`) the sweep varies, besides the case index.
    fn columns(self) -> &'static [usize] {
        match self {
            Sweep::Theta => &[8],
            Sweep::Alpha => &[2, 3],
        }
    }

    /// Whether the case belongs on this figure: the roughness sweep takes isotropic surfaces.
    fn takes(self, case: &Case) -> bool {
        self == Sweep::Theta || case.alpha_x == case.alpha_y
    }

    fn axis(self) -> &'static str {
        match self {
            Sweep::Theta => "incident angle θ_i (deg)",
            Sweep::Alpha => "roughness α (isotropic surfaces)",
        }
    }

    pub fn file_stem(self) -> &'static str {
        match self {
            Sweep::Theta => "albedo_vs_theta",
            Sweep::Alpha => "albedo_vs_alpha",
        }
    }
}

/// One panel: its caption and per order slot the points (x, albedo, standard error).
type Panel = (String, BTreeMap<usize, Points>);

pub struct AlbedoFigure<'a> {
    run: &'a RunDir,
    sweep: Sweep,
    selection: Selection,
    panels: Vec<Panel>,
}

impl<'a> AlbedoFigure<'a> {
    /// The figure of `sweep`, or `None` when no panel has two values of the swept parameter.
    pub fn new(run: &'a RunDir, summary: &[SummaryRow], sweep: Sweep, selection: Selection) -> Option<Self> {
        let channel = selection.channel_name();
        let groups = groups(run.cases.iter().filter(|c| sweep.takes(c)), sweep.columns());
        let mut group_of = vec![usize::MAX; run.cases.len()];
        for (g, cases) in groups.iter().enumerate() {
            for case in cases {
                group_of[case.index] = g;
            }
        }
        let mut skip = sweep.columns().to_vec();
        skip.push(0);
        let mut panels = Vec::new();
        for (g, cases) in groups.iter().enumerate() {
            for hemisphere in ["R", "T"] {
                let mut orders: BTreeMap<usize, Points> = BTreeMap::new();
                let rows = summary.iter().filter(|r| {
                    group_of.get(r.case) == Some(&g) && r.hemisphere == hemisphere && r.channel.as_deref() == channel
                });
                for row in rows {
                    orders.entry(row.order).or_default().push((
                        sweep.x(&run.cases[row.case]),
                        row.albedo,
                        row.albedo_stderr,
                    ));
                }
                if orders.is_empty() {
                    continue;
                }
                for points in orders.values_mut() {
                    points.sort_by(|a, b| a.0.total_cmp(&b.0));
                }
                // The hemisphere is named where the run has transmission.
                let side = if hemisphere == "T" { "T" } else { "R" };
                let mut caption = pretty_fields(run, cases[0], &skip);
                if run.cases.iter().any(|c| c.material.transmits()) || caption.is_empty() {
                    caption = if caption.is_empty() { side.to_string() } else { format!("{caption}, {side}") };
                }
                panels.push((caption, orders));
            }
        }
        let longest = panels.iter().flat_map(|p| p.1.values()).map(Vec::len).max().unwrap_or(0);
        (longest >= 2).then_some(Self { run, sweep, selection, panels })
    }

    fn grid(&self) -> (usize, usize) {
        let cols = self.panels.len().clamp(1, MAX_COLUMNS);
        (cols, self.panels.len().div_ceil(cols))
    }

    fn slots(&self) -> Vec<usize> {
        let mut slots: Vec<usize> = self.panels.iter().flat_map(|p| p.1.keys().copied()).collect();
        slots.sort_by_key(|&s| if s == 0 { usize::MAX } else { s });
        slots.dedup();
        slots
    }

    /// What the report says under the figure.
    pub fn caption(&self) -> String {
        let x = match self.sweep {
            Sweep::Theta => "the incident angle θ_i",
            Sweep::Alpha => "the roughness α (isotropic surfaces only)",
        };
        format!(
            "Albedo per bounce order (the fraction of the incident energy that leaves in the hemisphere after exactly \
             that many bounces; \"all orders\" is their sum) against {x}, one panel per surface, material and \
             hemisphere. Bars: ±1 standard error (most are smaller than the markers).{}",
            self.selection.note()
        )
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, (caption, orders): &Panel) -> Result<()> {
        let xs = orders.values().flatten().map(|p| p.0);
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        let pad = 0.05 * (hi - lo).max(1e-9);
        let top = orders.values().flatten().map(|p| p.1 + p.2).fold(0.0_f64, f64::max).max(1e-9) * 1.08;
        let (x_decimals, y_decimals) = (style::tick_decimals(lo - pad, hi + pad, 6), style::tick_decimals(0.0, top, 5));
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, CAPTION))
            .margin(6)
            .margin_right(14)
            .x_label_area_size(26)
            .y_label_area_size(52)
            .build_cartesian_2d(lo - pad..hi + pad, 0.0..top)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(0xe4, 0xe4, 0xe4))
            .x_labels(6)
            .y_labels(5)
            .label_style((FONT, TICK))
            .x_label_formatter(&|v| style::tick(*v, x_decimals))
            .y_label_formatter(&|v| style::tick(*v, y_decimals))
            .draw()
            .map_err(draw_err)?;
        for slot in self.slots() {
            let Some(points) = orders.get(&slot) else { continue };
            let line = style::order_style(slot);
            let curve: Vec<(f64, f64)> = points.iter().map(|p| (p.0, p.1)).collect();
            style::draw_line(chart.plotting_area(), &curve, line)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|&(x, y, e)| PathElement::new(vec![(x, y - e), (x, y + e)], line.colour.stroke_width(1))),
                )
                .map_err(draw_err)?;
            for &point in &curve {
                style::draw_marker(chart.plotting_area(), point, line)?;
            }
        }
        Ok(())
    }
}

impl Figure for AlbedoFigure<'_> {
    fn size(&self) -> (u32, u32) {
        style::grid_size(PANEL, self.grid())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let title = match self.sweep {
            Sweep::Theta => "Albedo per bounce order against the incident angle",
            Sweep::Alpha => "Albedo per bounce order against the roughness",
        };
        let title = format!("{title}{}", self.selection.suffix());
        let legend: Vec<(Key, String)> =
            self.slots().into_iter().map(|s| (Key::Line(style::order_style(s)), slot_label(self.run, s))).collect();
        let labels = style::GridLabels { title: &title, legend: &legend, y: "albedo", x: self.sweep.axis() };
        for (area, panel) in style::draw_grid(root, &labels, self.grid())?.iter().zip(&self.panels) {
            self.panel(area, panel)?;
        }
        Ok(())
    }
}
