//! Heat maps of one case: the full lobe f per bounce order over the projected hemisphere
//! (x = sin theta_o cos phi_o, y = sin theta_o sin phi_o, phi from the incident azimuth, so the
//! light comes from +x), each panel with its colour bar, on a linear scale or (`--log`) over
//! the three decades below its maximum.
//!
//! The detector's bins are uniform in |cos theta_o| and phi_o (equal solid angle, theory.md
//! §4.7), so its innermost ring is a cap (theta_o up to 14.4 deg with 32 bins) cut
//! into thin wedges that meet at the pole. Painted flat, bin by bin, those wedges showed as a
//! star of streaks around the centre, with a step at the cap's edge, that is not in the lobe.
//! So every pixel is interpolated between bin centres instead: linearly in |cos theta_o| and
//! (periodically) in phi_o, and inside the innermost ring's centres towards the pole's value,
//! the mean of that ring (phi means nothing at the pole). Colour bars are in the bins' own
//! values.
//!
//! A colour scale runs to the largest value the bins support ([`scale_top`]: a bin's f where
//! it is measured to a relative standard error of at most [`RELIABLE`], else f less one
//! standard error), not to the largest bin: near the horizon a bin's projected solid angle is tiny
//! (63 times less at the rim than at the pole with 32 bins), so a single photon there has a
//! huge f and, as the top of a linear scale, left the rest of a sparse order's panel blank.
//! Bins above the scale, all noisy, are drawn in its top colour, and the panel says how many.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;

use super::cases::{incidence, surface_label};
use super::rows::{Row, folded_note, highest_slot, row_bins, row_label};
use super::selection::Selection;
use super::style::{self, CAPTION, FONT, Figure, LABEL, TICK, TITLE, draw_err};
use crate::engine::detector::Grid;
use crate::io::rundir::{BinValue, Lobes, RunDir};
use crate::setup::cases::Case;

const PANEL: (u32, u32) = (440, 360);
const BAR: u32 = 110;
const MARGIN: u32 = 8;
const X_AREA: u32 = 54;
const Y_AREA: u32 = 68;
const CAPTION_HEIGHT: u32 = 30;
const TOP: u32 = 50;
const MAX_COLUMNS: usize = 3;
/// Decades shown by a logarithmic colour scale.
const DECADES: f64 = 3.0;
/// The largest relative standard error of a bin that may set the top of a colour scale (a
/// Poisson count of about 11 photons).
const RELIABLE: f64 = 0.3;

pub struct HeatFigure<'a> {
    pub run: &'a RunDir,
    pub case: &'a Case,
    pub hemisphere: &'a str,
    pub selection: Selection,
    pub measured: &'a Lobes,
    pub rows: &'a [Row],
}

/// A panel's colour scale: values in `range` (of f, or of log10 f) map to 0..1.
struct Scale {
    log: bool,
    range: (f64, f64),
}

/// The top of a colour scale for `bins` with standard errors `stderr` (of f): the largest value
/// the bins support, a bin measured to a relative standard error of at most [`RELIABLE`]
/// counting with its f and a noisier one with f less one standard error (nothing for a bin of
/// one photon); where no bin supports any value, the largest f.
fn scale_top(bins: &[BinValue], stderr: &[f64]) -> f64 {
    let finite = || bins.iter().zip(stderr).filter(|(b, _)| b.bsdf.is_finite());
    let supported = |(b, se): (&BinValue, &f64)| if *se <= RELIABLE * b.bsdf { b.bsdf } else { b.bsdf - se };
    let top = finite().map(supported).filter(|v| v.is_finite()).fold(0.0_f64, f64::max);
    if top > 0.0 { top } else { finite().map(|(b, _)| b.bsdf).fold(0.0_f64, f64::max) }
}

impl Scale {
    /// The scale of a panel whose colours run up to `max` (a linear scale from 0, or `DECADES`
    /// decades below it).
    fn up_to(max: f64, log: bool) -> Self {
        match (log, max > 0.0) {
            (true, true) => {
                let top = max.log10();
                Self { log, range: ((top - DECADES).floor(), top) }
            }
            (true, false) => Self { log, range: (-DECADES, 0.0) },
            (false, _) => Self { log, range: (0.0, if max > 0.0 { max } else { 1.0 }) },
        }
    }

    /// Where `f` lies on the scale, clamped to 0..1 (zero and tiny values at the bottom).
    fn level(&self, f: f64) -> f64 {
        let v = if self.log { if f > 0.0 { f.log10() } else { f64::NEG_INFINITY } } else { f };
        ((v - self.range.0) / (self.range.1 - self.range.0)).clamp(0.0, 1.0)
    }
}

/// The lobe at the direction with projected coordinates (x, y), interpolated between the bin
/// centres of `bins` (see the module's doc), or `None` outside the unit disc.
pub fn value_at(grid: Grid, bins: &[BinValue], x: f64, y: f64) -> Option<f64> {
    let r2 = x * x + y * y;
    if r2 > 1.0 {
        return None;
    }
    let (nc, np) = (grid.cos_bins, grid.phi_bins);
    let cos = (1.0 - r2).sqrt();
    // Continuous bin indices whose integers are the bin centres.
    let u = (cos * nc as f64 - 0.5).max(0.0);
    let v = y.atan2(x).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * np as f64 - 0.5;
    let (j0, s) = (v.floor(), v - v.floor());
    let j0 = (j0 as i64).rem_euclid(np as i64) as usize;
    let ring = |i: usize| (1.0 - s) * bins[i * np + j0].bsdf + s * bins[i * np + (j0 + 1) % np].bsdf;
    let i0 = u.floor() as usize;
    let t = u - i0 as f64;
    Some(if i0 + 1 < nc {
        (1.0 - t) * ring(i0) + t * ring(i0 + 1)
    } else {
        // Between the innermost ring's centres (u = nc - 1) and the pole (u = nc - 1/2).
        let pole = bins[(nc - 1) * np..].iter().map(|b| b.bsdf).sum::<f64>() / np as f64;
        let t = ((u - (nc - 1) as f64) / 0.5).min(1.0);
        (1.0 - t) * ring(nc - 1) + t * pole
    })
}

fn colour(level: f64) -> RGBColor {
    ViridisRGB::get_color(level as f32)
}

impl HeatFigure<'_> {
    /// The standard errors of f in the bins of `row`: the bins' own, or for a row that sums
    /// several slots (whose bins carry none, see `row_bins`) the sum of its slots' standard
    /// errors, an upper bound whatever their correlation.
    fn stderrs(&self, row: Row, bins: &[BinValue], highest: usize) -> Vec<f64> {
        let (case, ch) = (self.case.index, self.selection.channel);
        match row {
            Row::From(k) if k < highest => (k..=highest)
                .filter_map(|slot| self.measured.get(case, slot, self.hemisphere, ch))
                .fold(vec![0.0; bins.len()], |mut sum, slot| {
                    sum.iter_mut().zip(slot).for_each(|(s, b)| *s += b.bsdf_stderr);
                    sum
                }),
            _ => bins.iter().map(|b| b.bsdf_stderr).collect(),
        }
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, row: Row, log: bool) -> Result<()> {
        let ch = self.selection.channel;
        let highest = highest_slot(self.measured, self.case.index, self.hemisphere, ch);
        let Some(bins) = row_bins(self.measured, row, (self.case.index, self.hemisphere, ch), highest) else {
            return Ok(());
        };
        let bins = &bins[..];
        let top = scale_top(bins, &self.stderrs(row, bins, highest));
        let scale = Scale::up_to(top, log);
        // An order no light left through gets no colours and no colour bar: a bar from 0 to an
        // arbitrary 1 would read as a measured scale.
        let empty = top <= 0.0;
        let above = bins.iter().filter(|b| b.bsdf > top).count();
        let (caption, area) = area.split_vertically(CAPTION_HEIGHT);
        let (w, _) = caption.dim_in_pixel();
        let mut label = row_label(self.run, row);
        match above {
            0 => {}
            1 => label += " (1 bin above scale)",
            n => label += &format!(" ({n} bins above scale)"),
        }
        style::draw_centred(&caption, &label, ((w - BAR) as i32 / 2, 16), CAPTION, false)?;
        let (map_area, bar_area) = area.split_horizontally(PANEL.0 - BAR);
        // A square plotting area, so that the disc is round.
        let (mw, mh) = map_area.dim_in_pixel();
        let side = (mw - 2 * MARGIN - Y_AREA).min(mh - 2 * MARGIN - X_AREA);
        let reach = 1.04;
        let mut chart = ChartBuilder::on(&map_area)
            .margin(MARGIN)
            .x_label_area_size(X_AREA)
            .y_label_area_size(Y_AREA)
            .build_cartesian_2d(
                -reach * (mw - 2 * MARGIN - Y_AREA) as f64 / side as f64
                    ..reach * (mw - 2 * MARGIN - Y_AREA) as f64 / side as f64,
                -reach * (mh - 2 * MARGIN - X_AREA) as f64 / side as f64
                    ..reach * (mh - 2 * MARGIN - X_AREA) as f64 / side as f64,
            )
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(5)
            .y_labels(5)
            .label_style((FONT, TICK))
            .axis_desc_style((FONT, LABEL))
            .x_desc("sin θ_o cos φ_o")
            .y_desc("sin θ_o sin φ_o")
            .x_label_formatter(&|v| style::tick(*v, 1))
            .y_label_formatter(&|v| style::tick(*v, 1))
            .draw()
            .map_err(draw_err)?;
        // Each pixel interpolated between the bin centres around its centre's direction.
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let (xr, yr) = (chart.x_range(), chart.y_range());
        let mut pixels = vec![255u8; (pw * ph * 3) as usize];
        for py in (0..ph).filter(|_| !empty) {
            for px in 0..pw {
                let x = xr.start + (px as f64 + 0.5) / pw as f64 * (xr.end - xr.start);
                let y = yr.end - (py as f64 + 0.5) / ph as f64 * (yr.end - yr.start);
                if let Some(f) = value_at(self.run.grid, bins, x, y) {
                    let c = colour(scale.level(f));
                    let at = 3 * (py * pw + px) as usize;
                    pixels[at..at + 3].copy_from_slice(&[c.0, c.1, c.2]);
                }
            }
        }
        let image = BitMapElement::with_owned_buffer((xr.start, yr.end), (pw, ph), pixels).expect("pixel buffer size");
        chart.draw_series(std::iter::once(image)).map_err(draw_err)?;
        let circle: Vec<(f64, f64)> =
            (0..=180).map(|k| (k as f64 * 2.0).to_radians()).map(|p| (p.cos(), p.sin())).collect();
        chart.draw_series(std::iter::once(PathElement::new(circle, BLACK.stroke_width(1)))).map_err(draw_err)?;
        if self.hemisphere == "R" {
            // The mirror direction, theta_o = theta_i at phi_o = 180 deg, as a ring: a marker that
            // covered it would hide the peak it marks (at grazing incidence, at the rim).
            let mirror = (-self.case.theta_i_deg.to_radians().sin(), 0.0);
            let ring = |c: RGBColor, w: u32| EmptyElement::at(mirror) + Circle::new((0, 0), 8, c.stroke_width(w));
            chart.plotting_area().draw(&ring(WHITE, 4)).map_err(draw_err)?;
            chart.plotting_area().draw(&ring(BLACK, 2)).map_err(draw_err)?;
        }
        if empty {
            let (x, y) = chart.plotting_area().get_pixel_range();
            let (ax, ay) = area.get_base_pixel();
            let centre = ((x.start + x.end) / 2 - ax, (y.start + y.end) / 2 - ay);
            return style::draw_centred(&area, "no light in this order", centre, CAPTION, false);
        }
        // The colour bar, as tall as the map.
        let bar_top = MARGIN + (mh - 2 * MARGIN - X_AREA - ph) / 2;
        let bar = bar_area.margin(MARGIN + bar_top - MARGIN, MARGIN + X_AREA, 0, 0);
        let mut bar_chart = ChartBuilder::on(&bar)
            .margin_right(4)
            .right_y_label_area_size(BAR - 24)
            .build_cartesian_2d(0.0..1.0, scale.range.0..scale.range.1)
            .map_err(draw_err)?;
        let decimals = style::tick_decimals(scale.range.0, scale.range.1, 5);
        let label = |v: &f64| if log { style::significant(10f64.powf(*v)) } else { style::tick(*v, decimals) };
        bar_chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(5)
            .label_style((FONT, TICK))
            .y_label_formatter(&label)
            .draw()
            .map_err(draw_err)?;
        let (bw, bh) = bar_chart.plotting_area().dim_in_pixel();
        let (bx, by) =
            (bar_chart.plotting_area().get_pixel_range().0.start, bar_chart.plotting_area().get_pixel_range().1.start);
        let (ax, ay) = (area.get_base_pixel().0, area.get_base_pixel().1);
        style::draw_centred(&area, "f (1/sr)", (bx - ax + bw as i32 / 2 + 6, by - ay - 14), TICK, false)?;
        let mut gradient = vec![0u8; (bw * bh * 3) as usize];
        for py in 0..bh {
            let c = colour(1.0 - (py as f64 + 0.5) / bh as f64);
            for px in 0..bw {
                let at = 3 * (py * bw + px) as usize;
                gradient[at..at + 3].copy_from_slice(&[c.0, c.1, c.2]);
            }
        }
        let gradient = BitMapElement::with_owned_buffer((0.0, scale.range.1), (bw, bh), gradient).expect("bar buffer");
        bar_chart.draw_series(std::iter::once(gradient)).map_err(draw_err)?;
        Ok(())
    }
}

impl Figure for HeatFigure<'_> {
    /// The panels' grid, widened where the title would not fit above it (a single panel); the
    /// panels keep their width, centred.
    fn size(&self) -> (u32, u32) {
        let (cols, rows) = self.grid();
        let width = (PANEL.0 * cols as u32).max(style::text_width(&self.title(), TITLE - 2) + 24);
        (width, TOP + PANEL.1 * rows as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let (width, _) = self.size();
        style::draw_centred(root, &self.title(), (width as i32 / 2, TOP as i32 / 2), TITLE - 2, false)?;
        let (cols, rows) = self.grid();
        let side = (width - PANEL.0 * cols as u32) / 2;
        let panels = root.margin(TOP, 0, side, side).split_evenly((rows, cols));
        for (area, &row) in panels.iter().zip(self.rows) {
            self.panel(area, row, self.selection.log)?;
        }
        Ok(())
    }
}

impl HeatFigure<'_> {
    fn title(&self) -> String {
        let hemisphere = if self.hemisphere == "T" { "transmission" } else { "reflection" };
        format!(
            "{}, {}: f over the {hemisphere} hemisphere (light from +x){}{}",
            surface_label(self.run, self.case),
            incidence(self.case),
            if self.selection.log { ", log colour scale" } else { "" },
            self.selection.suffix()
        )
    }

    /// What the report says under the figure.
    pub fn caption(&self) -> String {
        let scale = if self.selection.log {
            "a logarithmic colour scale over the three decades below its top (lower values are dark blue)"
        } else {
            "a linear colour scale from 0 to its top"
        };
        let top = "Each panel's scale tops at the largest value its bins support: a bin measured to a relative \
                   standard error of at most 30% counts with its value, a noisier one with its value less one \
                   standard error. Bins above the top, all noisy (near the horizon, where a bin's projected solid \
                   angle is small, one photon makes a large f), are drawn in the top colour, and the panel's title \
                   counts them (\"bins above scale\"). Blobs in sparse orders and a star around the pole, where \
                   the innermost ring's wedges are a few pixels wide, are the bins' noise, not lobe structure \
                   (docs/figures.md).";
        let grazing = if self.selection.log || self.case.theta_i_deg < 75.0 {
            ""
        } else {
            " At grazing incidence the lobe peaks at the rim and a linear scale leaves the rest of the disc \
             dark: `smithwalk plot --log` shows both."
        };
        let (hemisphere, mirror) = if self.hemisphere == "T" {
            ("transmission", "")
        } else {
            ("reflection", "; a ring marks the mirror direction")
        };
        format!(
            "Case {} ({}, {}), {hemisphere}: the BSDF f (1/sr) per bounce order over the projected hemisphere, \
             x = sin θ_o cos φ_o, y = sin θ_o sin φ_o with φ_o from the incident azimuth (the light comes from +x{mirror}). \
             Each pixel is interpolated between the centres of the detector bins around its direction (linearly in |cos θ_o| and φ_o; at the pole, the mean of the innermost ring), on {scale}. {top}{grazing}{}{}",
            self.case.index,
            surface_label(self.run, self.case),
            incidence(self.case),
            folded_note(self.run, self.rows, false),
            self.selection.note(),
        )
    }

    fn grid(&self) -> (usize, usize) {
        let cols = self.rows.len().clamp(1, MAX_COLUMNS);
        (cols, self.rows.len().div_ceil(cols).max(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_passes_through_bin_centres_and_the_pole() {
        let grid = Grid { cos_bins: 4, phi_bins: 8 };
        let bins: Vec<BinValue> = (0..32).map(|i| BinValue { bsdf: i as f64, ..BinValue::default() }).collect();
        let at = |cos: f64, phi_deg: f64| {
            let (r, p) = ((1.0 - cos * cos).sqrt(), phi_deg.to_radians());
            value_at(grid, &bins, r * p.cos(), r * p.sin()).unwrap()
        };
        // The centre of bin (cos 1, phi 2) is cos 0.375, phi 112.5 deg: its own value, 8 + 2.
        assert!((at(0.375, 112.5) - 10.0).abs() < 1e-9);
        // Half-way between phi centres 7 (337.5 deg) and 0 (22.5 deg), across phi = 0.
        assert!((at(0.375, 0.0) - 0.5 * (15.0 + 8.0)).abs() < 1e-9);
        // The pole: the mean of the innermost ring, 24..31.
        assert!((value_at(grid, &bins, 0.0, 0.0).unwrap() - 27.5).abs() < 1e-9);
        // Below the lowest centre (cos < 1/8) the lowest ring's value; outside the disc, none.
        assert!((at(0.05, 112.5) - 2.0).abs() < 1e-9);
        assert_eq!(value_at(grid, &bins, 0.8, 0.7), None);
    }

    #[test]
    fn colour_scales_put_the_maximum_on_top() {
        let linear = Scale::up_to(2.0, false);
        assert_eq!((linear.level(2.0), linear.level(0.0), linear.level(1.0)), (1.0, 0.0, 0.5));
        // log10 2 = 0.301: the scale runs from 10^-3 to 2, a value of 0.02 sits 2 decades up.
        let log = Scale::up_to(2.0, true);
        assert_eq!(log.range.0, -3.0);
        assert!((log.level(0.02) - (0.02f64.log10() + 3.0) / (2f64.log10() + 3.0)).abs() < 1e-12);
        assert_eq!(log.level(0.0), 0.0);
        assert_eq!(style::significant(0.001), "0.001");
        assert_eq!(style::significant(0.000316), "0.00032");
        assert_eq!(style::significant(25.0), "25");
        assert_eq!(style::significant(1e-8), "1e-8");
        assert_eq!(style::significant(3.16e-5), "3.2e-5");
    }

    /// A one-photon bin at the rim (relative standard error 1) does not set the scale; a
    /// well-measured peak does, however narrow; a noisy bin counts with its value less one
    /// standard error; with no support at all, the largest value does.
    #[test]
    fn a_noisy_bin_does_not_set_the_colour_scale() {
        let bin = |bsdf: f64, relative: f64| (BinValue { bsdf, ..BinValue::default() }, relative * bsdf);
        let top = |bins: &[(BinValue, f64)]| {
            let (values, stderr): (Vec<BinValue>, Vec<f64>) = bins.iter().copied().unzip();
            scale_top(&values, &stderr)
        };
        assert_eq!(top(&[bin(0.01, 0.1), bin(0.02, 0.2), bin(0.9, 1.0), bin(0.0, 0.0)]), 0.02);
        assert_eq!(top(&[bin(0.01, 0.1), bin(5.0, 0.3), bin(0.9, 1.0)]), 5.0);
        assert_eq!(top(&[bin(0.01, 0.5), bin(0.9, 1.0)]), 0.005);
        assert_eq!(top(&[bin(0.9, 1.0), bin(0.4, 1.0)]), 0.9);
        assert_eq!(top(&[bin(f64::NAN, 0.0), bin(0.2, 0.1)]), 0.2);
    }
}
