//! Per-order albedos against one swept case parameter (the incident angle, the roughness, or the
//! Student-T shape):
//! one panel per combination of the other parameters and hemisphere, one line with markers and
//! one-standard-error bars per order slot, and one legend for the whole figure.

use std::collections::{BTreeMap, BTreeSet};

use anyhow::Result;
use microsurface::ndf::AnyNdf;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::cases::{case_column, groups, pretty_fields};
use super::points::{Points, bar_top};
use super::rows::{Row, all_orders_only, folded_note, open_row, row_label};
use super::selection::Selection;
use super::style::{self, CAPTION, FONT, Figure, Key, TICK, draw_err};
use crate::io::rundir::{RunDir, SummaryRow};
use crate::setup::cases::Case;

const PANEL: (u32, u32) = (360, 260);
const MAX_COLUMNS: usize = 4;

/// The parameter on the x axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    Theta,
    Alpha,
    /// The Student-T shape, drawn as `1/gamma`: the family is GGX at `gamma = 2` and tends to
    /// Beckmann as `1/gamma` (theory §1.6), so GGX cases stand at 0.5 and Beckmann cases at 0.
    Gamma,
}

impl Sweep {
    pub const ALL: [Sweep; 3] = [Sweep::Theta, Sweep::Alpha, Sweep::Gamma];

    fn x(self, case: &Case) -> f64 {
        match self {
            Sweep::Theta => case.theta_i_deg,
            Sweep::Alpha => case.roughness().x,
            Sweep::Gamma => match case.surface.ndf {
                AnyNdf::StudentT(ndf) => 1.0 / ndf.gamma(),
                AnyNdf::Ggx(_) => 0.5,
                AnyNdf::Beckmann(_) => 0.0,
            },
        }
    }

    /// Which case columns (of `CASE_COLUMNS`) the sweep varies, besides the case index.
    fn columns(self) -> Vec<usize> {
        match self {
            Sweep::Theta => vec![case_column("theta_i_deg")],
            Sweep::Alpha => vec![case_column("alpha_x"), case_column("alpha_y")],
            Sweep::Gamma => vec![case_column("ndf"), case_column("gamma")],
        }
    }

    /// Whether the case belongs on this figure: the roughness sweep takes isotropic surfaces;
    /// the shape sweep every case, GGX and Beckmann as members of the Student-T family.
    fn takes(self, case: &Case) -> bool {
        self != Sweep::Alpha || case.roughness().x == case.roughness().y
    }

    /// Whether the run has the figure at all: the shape sweep needs a Student-T case (a run
    /// of GGX and Beckmann alone is not a study of the family).
    fn applies(self, cases: &[Case]) -> bool {
        self != Sweep::Gamma || cases.iter().any(|c| matches!(c.surface.ndf, AnyNdf::StudentT(_)))
    }

    fn axis(self) -> &'static str {
        match self {
            Sweep::Theta => "incident angle θ_i (deg)",
            Sweep::Alpha => "roughness α (isotropic surfaces)",
            Sweep::Gamma => "1/γ (Student-T shape; Beckmann 0, GGX 0.5)",
        }
    }

    pub fn file_stem(self) -> &'static str {
        match self {
            Sweep::Theta => "albedo_vs_theta",
            Sweep::Alpha => "albedo_vs_alpha",
            Sweep::Gamma => "albedo_vs_gamma",
        }
    }
}

/// One panel: its caption and per row (an index into the figure's rows) the points (x, albedo,
/// standard error).
type Panel = (String, BTreeMap<usize, Points>);

/// The style of a row: its slot's, the "K+" row's for a row the figure sums.
fn order_style(row: Row) -> style::LineStyle {
    match row {
        Row::Slot(slot) | Row::From(slot) => style::order_style(slot),
    }
}

/// The albedo and its standard error of a row of one case, from the case's albedos per order
/// slot: a slot's own, or for `From(k)` the sum over the slots from k up, exact, with a NaN
/// standard error when it sums more than one slot (summary.csv has no covariances between
/// orders); `None` where the case has none of them.
fn row_albedo(orders: &BTreeMap<usize, (f64, f64)>, row: Row) -> Option<(f64, f64)> {
    match row {
        Row::Slot(slot) => orders.get(&slot).copied(),
        Row::From(k) => {
            let terms: Vec<(f64, f64)> = orders.range(k..).map(|(_, &v)| v).collect();
            match terms[..] {
                [] => None,
                [one] => Some(one),
                _ => Some((terms.iter().map(|t| t.0).sum(), f64::NAN)),
            }
        }
    }
}

pub struct AlbedoFigure<'a> {
    run: &'a RunDir,
    sweep: Sweep,
    selection: Selection,
    rows: &'a [Row],
    panels: Vec<Panel>,
}

impl<'a> AlbedoFigure<'a> {
    /// The figure of `sweep` with the order rows `rows`, or `None` when no panel has two values
    /// of the swept parameter.
    pub fn new(
        run: &'a RunDir,
        summary: &[SummaryRow],
        sweep: Sweep,
        selection: Selection,
        rows: &'a [Row],
    ) -> Option<Self> {
        if !sweep.applies(&run.cases) {
            return None;
        }
        let channel = selection.channel_name();
        let groups = groups(run.cases.iter().filter(|c| sweep.takes(c)), &sweep.columns());
        let mut group_of = vec![usize::MAX; run.cases.len()];
        for (g, cases) in groups.iter().enumerate() {
            for case in cases {
                group_of[case.index] = g;
            }
        }
        let mut skip = sweep.columns();
        skip.push(0);
        let mut panels = Vec::new();
        for (g, cases) in groups.iter().enumerate() {
            for hemisphere in ["R", "T"] {
                // Per case, its albedos per order slot.
                let mut albedos: BTreeMap<usize, BTreeMap<usize, (f64, f64)>> = BTreeMap::new();
                let found = summary.iter().filter(|r| {
                    group_of.get(r.case) == Some(&g) && r.hemisphere == hemisphere && r.channel.as_deref() == channel
                });
                for r in found {
                    albedos.entry(r.case).or_default().insert(r.order, (r.albedo, r.albedo_stderr));
                }
                let mut orders: BTreeMap<usize, Points> = BTreeMap::new();
                for (case, slots) in &albedos {
                    for (i, &row) in rows.iter().enumerate() {
                        if let Some((albedo, stderr)) = row_albedo(slots, row) {
                            orders.entry(i).or_default().push((sweep.x(&run.cases[*case]), albedo, stderr));
                        }
                    }
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
        (longest >= 2).then_some(Self { run, sweep, selection, rows, panels })
    }

    /// The legend: the rows drawn in some panel, in plotting order.
    fn legend(&self) -> Vec<(Key, String)> {
        let drawn: BTreeSet<usize> = self.panels.iter().flat_map(|p| p.1.keys().copied()).collect();
        drawn.into_iter().map(|i| (Key::Line(order_style(self.rows[i])), row_label(self.run, self.rows[i]))).collect()
    }

    fn grid(&self) -> (usize, usize) {
        let cols = self.panels.len().clamp(1, MAX_COLUMNS);
        (cols, self.panels.len().div_ceil(cols))
    }

    /// What the report says under the figure.
    pub fn caption(&self) -> String {
        let x = match self.sweep {
            Sweep::Theta => "the incident angle θ_i",
            Sweep::Alpha => "the roughness α (isotropic surfaces only)",
            Sweep::Gamma => "the Student-T shape as 1/γ (Beckmann at 0, GGX at 0.5: the family's limit and member)",
        };
        let what = if all_orders_only(self.rows) {
            "Albedo of all bounce orders together (the fraction of the incident energy that leaves in the hemisphere)"
                .to_string()
        } else {
            let more = open_row(self.run, self.rows)
                .map_or(String::new(), |(k, _)| format!(", or for \"orders {k}+\" after {k} or more"));
            format!(
                "Albedo per bounce order (the fraction of the incident energy that leaves in the hemisphere after \
                 exactly that many bounces{more}; \"all orders\" is their sum)"
            )
        };
        format!(
            "{what} against {x}, one panel per combination of the other case parameters (surface, material, side \
             the light comes from) and hemisphere. Bars: ±1 standard error (most are smaller than the markers).{}{}",
            folded_note(self.run, self.rows, true),
            self.selection.note()
        )
    }

    /// Whether the x axis is logarithmic: a roughness sweep over a decade or more, where a
    /// linear axis would crowd the smooth surfaces into its first tick.
    fn log_x(&self) -> bool {
        let xs = || self.panels.iter().flat_map(|(_, orders)| orders.values().flatten().map(|p| p.0));
        let (lo, hi) = xs().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        self.sweep == Sweep::Alpha && lo > 0.0 && hi >= 10.0 * lo
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, (caption, orders): &Panel) -> Result<()> {
        // On a logarithmic axis the points are drawn at log10 x and the ticks name 10^v.
        let log_x = self.log_x();
        let at = |x: f64| if log_x { x.log10() } else { x };
        let orders: BTreeMap<usize, Points> =
            orders.iter().map(|(&i, points)| (i, points.iter().map(|&(x, y, e)| (at(x), y, e)).collect())).collect();
        let xs = orders.values().flatten().map(|p| p.0);
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        let pad = 0.05 * (hi - lo).max(1e-9);
        let top = orders.values().flatten().map(bar_top).fold(0.0_f64, f64::max).max(1e-9) * 1.08;
        let (x_decimals, y_decimals) = (style::tick_decimals(lo - pad, hi + pad, 6), style::tick_decimals(0.0, top, 5));
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, CAPTION))
            .margin(6)
            .margin_right(14)
            .x_label_area_size(30)
            .y_label_area_size(64)
            .build_cartesian_2d(lo - pad..hi + pad, 0.0..top)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(0xe4, 0xe4, 0xe4))
            .x_labels(6)
            .y_labels(5)
            .label_style((FONT, TICK))
            .x_label_formatter(&|v| {
                if log_x { style::significant(10f64.powf(*v)) } else { style::tick(*v, x_decimals) }
            })
            .y_label_formatter(&|v| style::tick(*v, y_decimals))
            .draw()
            .map_err(draw_err)?;
        for (i, points) in &orders {
            let line = order_style(self.rows[*i]);
            let curve: Vec<(f64, f64)> = points.iter().map(|p| (p.0, p.1)).collect();
            style::draw_line(chart.plotting_area(), &curve, line)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .filter(|p| p.2.is_finite())
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

impl AlbedoFigure<'_> {
    fn labels(&self) -> style::GridLabels {
        let orders = if all_orders_only(self.rows) { "of all orders" } else { "per bounce order" };
        let x = match self.sweep {
            Sweep::Theta => "the incident angle",
            Sweep::Alpha => "the roughness",
            Sweep::Gamma => "the Student-T shape",
        };
        style::GridLabels {
            title: format!("Albedo {orders} against {x}{}", self.selection.suffix()),
            legend: self.legend(),
            y: "albedo".to_string(),
            x: if self.log_x() { format!("{} (log scale)", self.sweep.axis()) } else { self.sweep.axis().to_string() },
        }
    }
}

impl Figure for AlbedoFigure<'_> {
    fn size(&self) -> (u32, u32) {
        style::grid_size(PANEL, self.grid(), &self.labels())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let labels = self.labels();
        for (area, panel) in style::draw_grid(root, &labels, self.grid())?.iter().zip(&self.panels) {
            self.panel(area, panel)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A summed row adds the albedos of its orders; its standard error is NaN unless it holds
    /// one order only.
    #[test]
    fn a_summed_row_adds_the_albedos_of_its_orders() {
        let orders: BTreeMap<usize, (f64, f64)> =
            [(0, (0.9, 0.01)), (3, (0.1, 0.01)), (4, (0.05, 0.002)), (6, (0.01, 0.001))].into();
        let (albedo, stderr) = row_albedo(&orders, Row::From(4)).unwrap();
        assert!((albedo - 0.06).abs() < 1e-15 && stderr.is_nan());
        assert_eq!(row_albedo(&orders, Row::From(6)), Some((0.01, 0.001)));
        assert_eq!(row_albedo(&orders, Row::From(7)), None);
        assert_eq!(row_albedo(&orders, Row::Slot(3)), Some((0.1, 0.01)));
    }
}
