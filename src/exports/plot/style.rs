//! The figures' fixed style, the same in every figure (docs/figures.md lists it): one colour
//! and line style per model and per bounce order, the fonts, plain tick labels, legends drawn
//! outside the data, and the canvas written as PNG or SVG.

use anyhow::{Context, Result, anyhow};
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::{FontTransform, text_anchor};

use crate::setup::config::Model;

pub const FONT: &str = "sans-serif";
/// Text sizes as plotters takes them. plotters draws a font of size `s` with an em of `s / 1.24`
/// pixels (its SVG output writes `font-size="s/1.24"`), so these give 22, 17, 18 and 15 pixel
/// fonts: tick labels of 15 pixels are 9 at 1000 pixels of a 1680-pixel figure of five columns.
pub const TITLE: u32 = 27;
pub const CAPTION: u32 = 21;
pub const LABEL: u32 = 22;
pub const TICK: u32 = 19;

/// The measurement: black points with one-standard-error bars.
pub const MEASURED: RGBColor = BLACK;

/// How a line is stroked (dashes as (dash, gap) in pixels).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dash {
    Solid,
    Dashed,
    Dotted,
    LongDash,
}

impl Dash {
    fn pattern(self) -> Option<(u32, u32)> {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((7, 4)),
            Dash::Dotted => Some((2, 3)),
            Dash::LongDash => Some((14, 4)),
        }
    }
}

/// A series' colour, dash and marker, fixed per model and per order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineStyle {
    pub colour: RGBColor,
    pub dash: Dash,
    pub width: u32,
    pub marker: Marker,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    None,
    Circle,
    Square,
    Triangle,
    Diamond,
    Cross,
}

/// Okabe and Ito's colour-blind-safe palette and Tol's muted one, chosen so that every two
/// models' colours stay apart in normal vision, protanopia and deuteranopia (test below) and
/// each stands out on white.
const BLUE: RGBColor = RGBColor(0x00, 0x72, 0xb2);
const ORANGE: RGBColor = RGBColor(0xe6, 0x9f, 0x00);
const GREEN: RGBColor = RGBColor(0x00, 0x9e, 0x73);
const VERMILLION: RGBColor = RGBColor(0xd5, 0x5e, 0x00);
const PURPLE: RGBColor = RGBColor(0xcc, 0x79, 0xa7);
const WINE: RGBColor = RGBColor(0x88, 0x22, 0x55);
const INDIGO: RGBColor = RGBColor(0x33, 0x22, 0x88);
const FOREST: RGBColor = RGBColor(0x11, 0x77, 0x33);
const OLIVE: RGBColor = RGBColor(0x99, 0x99, 0x33);
const ROSE: RGBColor = RGBColor(0xee, 0x66, 0x77);
const BROWN: RGBColor = RGBColor(0x8c, 0x51, 0x0a);
const SKY: RGBColor = RGBColor(0x56, 0xb4, 0xe9);
const GREY: RGBColor = RGBColor(0x77, 0x77, 0x77);
/// Saturated blue-violet: the colour farthest from all the others in the three visions.
const ULTRAMARINE: RGBColor = RGBColor(0x33, 0x00, 0xff);
/// Light blue-violet: the colour farthest from all the others in the three visions once
/// ultramarine is taken (CIE76 difference 32 or more, searched on a grid of 16 levels a channel).
const LAVENDER: RGBColor = RGBColor(0x77, 0x66, 0xff);

const fn line(colour: RGBColor, dash: Dash) -> LineStyle {
    LineStyle { colour, dash, width: 2, marker: Marker::None }
}

/// The style of a model's lines in every figure.
pub fn model_style(model: Model) -> LineStyle {
    match model {
        Model::Single => line(FOREST, Dash::Solid),
        Model::HammonFit => line(WINE, Dash::Solid),
        Model::HeitzNee => line(BLUE, Dash::Dashed),
        Model::ExactPositionFree => line(VERMILLION, Dash::LongDash),
        Model::WangCorrelated => line(PURPLE, Dash::Solid),
        Model::WangUncorrelated => line(INDIGO, Dash::Dotted),
        Model::CuiReleased => line(ULTRAMARINE, Dash::Dashed),
        Model::KullaConty => line(GREEN, Dash::Dashed),
        Model::Turquin => line(OLIVE, Dash::Dotted),
        Model::FdezAguera => line(ROSE, Dash::Dotted),
        Model::MaterialX => line(SKY, Dash::Dashed),
        Model::Lee2018 => line(LAVENDER, Dash::Dotted),
        Model::External => line(BROWN, Dash::LongDash),
    }
}

/// The style of a model named in `models.csv` (grey for a name this version does not know).
pub fn model_style_by_name(name: &str) -> LineStyle {
    Model::parse(name).map_or(line(GREY, Dash::Solid), model_style)
}

/// The style of an order slot (0 = all orders; `4` is also the fourth row, "4+" or "K+") in the albedo
/// figures: a colour, a dash and a marker each, so that the orders stay apart in grey print.
pub fn order_style(slot: usize) -> LineStyle {
    let (colour, dash, marker) = match slot {
        0 => (BLACK, Dash::Solid, Marker::Circle),
        1 => (BLUE, Dash::Solid, Marker::Square),
        2 => (ORANGE, Dash::Dashed, Marker::Triangle),
        3 => (GREEN, Dash::Dotted, Marker::Diamond),
        _ => (PURPLE, Dash::LongDash, Marker::Cross),
    };
    LineStyle { colour, dash, width: 2, marker }
}

/// A drawing error as an error of this crate.
pub fn draw_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("cannot draw: {e}")
}

/// Draws a polyline (in the area's coordinates) with the style's dash.
pub fn draw_line<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    points: &[CT::From],
    style: LineStyle,
) -> Result<()>
where
    CT::From: Clone,
{
    let stroke = style.colour.stroke_width(style.width);
    match style.dash.pattern() {
        None => area.draw(&PathElement::new(points.to_vec(), stroke)).map_err(draw_err),
        Some((dash, gap)) => {
            area.draw(&DashedPathElement::new(points.iter().cloned(), dash, gap, stroke)).map_err(draw_err)
        }
    }
}

/// Draws the style's marker centred on a point (in the area's coordinates).
pub fn draw_marker<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    at: CT::From,
    style: LineStyle,
) -> Result<()> {
    let fill = style.colour.filled();
    let stroke = style.colour.stroke_width(2);
    let r = 4;
    let here = EmptyElement::at(at);
    match style.marker {
        Marker::None => Ok(()),
        Marker::Circle => area.draw(&(here + Circle::new((0, 0), r, fill))),
        Marker::Square => area.draw(&(here + Rectangle::new([(-r, -r), (r, r)], fill))),
        Marker::Triangle => area.draw(&(here + Polygon::new(vec![(0, -r - 1), (-r - 1, r), (r + 1, r)], fill))),
        Marker::Diamond => area.draw(&(here + Polygon::new(vec![(0, -r - 1), (r, 0), (0, r + 1), (-r, 0)], fill))),
        Marker::Cross => area.draw(
            &(here
                + PathElement::new(vec![(-r, -r), (r, r)], stroke)
                + PathElement::new(vec![(-r, r), (r, -r)], stroke)),
        ),
    }
    .map_err(draw_err)
}

/// A legend entry: a line sample (and marker), or the measurement's point with an error bar.
pub enum Key {
    Line(LineStyle),
    Measured,
}

/// The distance between the lines of a legend that wraps.
const LEGEND_LINE: u32 = 28;

/// The width in pixels each legend entry takes: line sample, gap, text and the space to the
/// next entry.
fn legend_widths(entries: &[(Key, String)]) -> Vec<i32> {
    let font = (FONT, CAPTION).into_font();
    entries
        .iter()
        .map(|(_, name)| {
            let (w, _) = font.box_size(name).unwrap_or((8 * name.len() as u32, 0));
            LEGEND_SAMPLE + 6 + w as i32 + 24
        })
        .collect()
}

/// The length of a legend entry's line sample.
const LEGEND_SAMPLE: i32 = 34;

/// The legend's entries in lines that fit `width` pixels (at least one entry per line), each
/// line as the range of its entries.
fn legend_lines(entries: &[(Key, String)], width: u32) -> Vec<std::ops::Range<usize>> {
    let mut lines = Vec::new();
    let (mut start, mut used) = (0, 0);
    for (i, w) in legend_widths(entries).into_iter().enumerate() {
        if i > start && used + w > width as i32 - 8 {
            lines.push(start..i);
            (start, used) = (i, 0);
        }
        used += w;
    }
    lines.push(start..entries.len());
    lines
}

/// Draws a legend centred in `area` (a band outside the panels), entries left to right, in as
/// many lines as its width needs, `LEGEND_LINE` apart.
pub fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, entries: &[(Key, String)]) -> Result<()> {
    let font = (FONT, CAPTION).into_font();
    let widths = legend_widths(entries);
    let (width, height) = area.dim_in_pixel();
    let lines = legend_lines(entries, width);
    let first = height as i32 / 2 - (lines.len() as i32 - 1) * LEGEND_LINE as i32 / 2;
    for (n, line) in lines.into_iter().enumerate() {
        let mut x = ((width as i32 - widths[line.clone()].iter().sum::<i32>()) / 2).max(4);
        let y = first + n as i32 * LEGEND_LINE as i32;
        for ((key, name), w) in entries[line.clone()].iter().zip(&widths[line]) {
            match key {
                Key::Line(style) => {
                    draw_line(area, &[(x, y), (x + LEGEND_SAMPLE, y)], *style)?;
                    draw_marker(area, (x + LEGEND_SAMPLE / 2, y), *style)?;
                }
                Key::Measured => {
                    let c = (x + LEGEND_SAMPLE / 2, y);
                    area.draw(&PathElement::new(vec![(c.0, y - 8), (c.0, y + 8)], MEASURED.stroke_width(1)))
                        .map_err(draw_err)?;
                    area.draw(&Circle::new(c, 3, MEASURED.filled())).map_err(draw_err)?;
                }
            }
            let style = font
                .clone()
                .color(&BLACK)
                .pos(text_anchor::Pos::new(text_anchor::HPos::Left, text_anchor::VPos::Center));
            area.draw(&Text::new(name.clone(), (x + LEGEND_SAMPLE + 6, y), style)).map_err(draw_err)?;
            x += w;
        }
    }
    Ok(())
}

/// Bands around a grid of panels: the title and a one-line legend above (each further legend
/// line adds [`LEGEND_LINE`]), the y label shared by the grid on the left and the x label below.
const GRID_TOP: u32 = 90;
const GRID_LEFT: u32 = 34;
const GRID_BOTTOM: u32 = 40;

/// What a grid of panels says around them.
pub struct GridLabels {
    pub title: String,
    pub legend: Vec<(Key, String)>,
    pub y: String,
    pub x: String,
}

/// The height of the band above a grid `width` pixels wide: title and legend.
fn grid_top(legend: &[(Key, String)], width: u32) -> u32 {
    GRID_TOP + LEGEND_LINE * (legend_lines(legend, width).len() as u32 - 1)
}

/// The width in pixels of `text` at font size `size`.
pub fn text_width(text: &str, size: u32) -> u32 {
    (FONT, size).into_font().box_size(text).map_or(8 * text.chars().count() as u32, |(w, _)| w)
}

/// The canvas size of a grid of `cols` x `rows` panels of `panel` pixels with its bands: wider
/// panels where the title or the x label would not fit above or below narrow ones (a single
/// column).
pub fn grid_size(panel: (u32, u32), (cols, rows): (usize, usize), labels: &GridLabels) -> (u32, u32) {
    let texts = (text_width(&labels.title, TITLE) + 24).max(GRID_LEFT + text_width(&labels.x, LABEL) + 24);
    let width = (GRID_LEFT + panel.0 * cols as u32).max(texts);
    (width, grid_top(&labels.legend, width) + panel.1 * rows as u32 + GRID_BOTTOM)
}

/// Draws the title, the legend and the shared axis labels of a grid of panels, and returns
/// the panels' areas row by row.
pub fn draw_grid<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    labels: &GridLabels,
    (cols, rows): (usize, usize),
) -> Result<Vec<DrawingArea<DB, Shift>>> {
    let (width, height) = root.dim_in_pixel();
    let top = grid_top(&labels.legend, width);
    draw_centred(root, &labels.title, (width as i32 / 2, 20), TITLE, false)?;
    draw_legend(&root.margin(42, 0, 0, 0).shrink((0, 0), (width, top - 46)), &labels.legend)?;
    let middle = (top + (height - top - GRID_BOTTOM) / 2) as i32;
    draw_centred(root, &labels.y, (GRID_LEFT as i32 / 2, middle), LABEL, true)?;
    let below = ((GRID_LEFT + (width - GRID_LEFT) / 2) as i32, (height - GRID_BOTTOM / 2) as i32);
    draw_centred(root, &labels.x, below, LABEL, false)?;
    Ok(root.margin(top, GRID_BOTTOM, GRID_LEFT, 0).split_evenly((rows, cols)))
}

/// Draws a text centred at a pixel, turned by `rotate` (axis labels shared by a row or column
/// of panels).
pub fn draw_centred<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    at: (i32, i32),
    size: u32,
    rotate: bool,
) -> Result<()> {
    let font = (FONT, size).into_font();
    let font = if rotate { font.transform(FontTransform::Rotate270) } else { font };
    let style = font.color(&BLACK).pos(text_anchor::Pos::new(text_anchor::HPos::Center, text_anchor::VPos::Center));
    area.draw(&Text::new(text.to_string(), at, style)).map_err(draw_err)
}

/// The number of decimals that writes every tick of the axis `lo..hi` (about `n` ticks, as
/// plotters places them) exactly, so that all ticks of an axis share one plain format.
pub fn tick_decimals(lo: f64, hi: f64, n: usize) -> usize {
    let keys = RangedCoordf64::from(lo..hi).key_points(n);
    keys.iter()
        .map(|&v| {
            (0..=8)
                .find(|&d| (format!("{v:.d$}").parse::<f64>().unwrap_or(f64::NAN) - v).abs() <= 1e-9 * (hi - lo).abs())
                .unwrap_or(8)
        })
        .max()
        .unwrap_or(0)
}

/// A positive number with two significant digits, in plain notation (0.0032, 0.1, 25) down to
/// 10^-4 and in scientific notation below (3.2e-5, 1e-8).
pub fn significant(x: f64) -> String {
    if x < 1e-4 {
        let text = format!("{x:.1e}");
        return text.replacen(".0e", "e", 1);
    }
    let decimals = (1 - x.log10().floor() as i32).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

/// A tick label: the value in plain decimal notation with `decimals` places (and `0` for zero).
pub fn tick(v: f64, decimals: usize) -> String {
    if v.abs() < 1e-12 { "0".into() } else { format!("{v:.decimals$}") }
}

/// What a figure needs to be drawn on any plotters backend.
pub trait Figure {
    /// Canvas size in pixels.
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// Output format of the figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Svg,
}

impl Format {
    pub fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Svg => "svg",
        }
    }
}

/// Draws a figure on a white canvas and encodes it.
pub fn render(figure: &impl Figure, format: Format) -> Result<Vec<u8>> {
    let (width, height) = figure.size();
    match format {
        Format::Png => {
            let mut pixels = vec![0u8; (width * height * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                figure.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            let image = image::RgbImage::from_raw(width, height, pixels).context("canvas size")?;
            let mut png = std::io::Cursor::new(Vec::new());
            image.write_to(&mut png, image::ImageOutputFormat::Png).context("cannot encode PNG")?;
            Ok(png.into_inner())
        }
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                figure.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            // plotters-svg 0.3.7 labels embedded PNGs `data:png`; the MIME type is image/png
            // (browsers guess it, stricter SVG readers do not).
            Ok(svg.replace("href=\"data:png;base64,", "href=\"data:image/png;base64,").into_bytes())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CIE L*a*b* (D65) of an sRGB colour whose linear components `rgb` are first mixed by
    /// `vision` (Machado, Oliveira and Fernandes 2009's matrices for full protanopia and
    /// deuteranopia, in linear RGB; the identity for normal vision).
    fn lab(colour: RGBColor, vision: &[[f64; 3]; 3]) -> [f64; 3] {
        let linear = |c: u8| {
            let c = c as f64 / 255.0;
            if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
        };
        let l = [linear(colour.0), linear(colour.1), linear(colour.2)];
        let [r, g, b] = vision.map(|row| (row[0] * l[0] + row[1] * l[1] + row[2] * l[2]).clamp(0.0, 1.0));
        let xyz = [
            (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047,
            0.2126 * r + 0.7152 * g + 0.0722 * b,
            (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883,
        ];
        let f = |t: f64| {
            if t > (6.0f64 / 29.0).powi(3) { t.cbrt() } else { t / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0 }
        };
        let [fx, fy, fz] = xyz.map(f);
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }

    /// Every two models' colours differ by a CIE76 colour difference of at least 11 in normal
    /// vision, protanopia and deuteranopia (the palette before, with orange beside vermillion
    /// and ochre, came to 3.3), and every colour is dark enough to read on white (L* below 70).
    #[test]
    fn model_colours_stay_apart_for_colour_blind_readers() {
        let normal = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let protanopia =
            [[0.152286, 1.052583, -0.204868], [0.114503, 0.786281, 0.099216], [-0.003882, -0.048116, 1.051998]];
        let deuteranopia =
            [[0.367322, 0.860646, -0.227968], [0.280085, 0.672501, 0.047413], [-0.011820, 0.042940, 0.968881]];
        let models: Vec<Model> = Model::ALL.into_iter().chain([Model::External]).collect();
        for (i, &a) in models.iter().enumerate() {
            let luminance = lab(model_style(a).colour, &normal)[0];
            assert!(luminance < 70.0, "{} is too light on white (L* {luminance:.0})", a.name());
            for &b in &models[i + 1..] {
                for vision in [&normal, &protanopia, &deuteranopia] {
                    let (la, lb) = (lab(model_style(a).colour, vision), lab(model_style(b).colour, vision));
                    let difference = la.iter().zip(lb).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
                    assert!(difference >= 11.0, "{} and {}: colour difference {difference:.1}", a.name(), b.name());
                }
            }
        }
    }

    #[test]
    fn every_model_and_order_has_its_own_style() {
        let models: Vec<LineStyle> = Model::ALL.iter().map(|&m| model_style(m)).collect();
        for (i, a) in models.iter().enumerate() {
            for b in &models[i + 1..] {
                assert_ne!(a.colour, b.colour);
            }
        }
        let orders: Vec<LineStyle> = [0, 1, 2, 3, 4].map(order_style).to_vec();
        for (i, a) in orders.iter().enumerate() {
            for b in &orders[i + 1..] {
                assert!(a.colour != b.colour && a.marker != b.marker);
            }
        }
        assert_eq!(model_style_by_name("heitz-nee"), model_style(Model::HeitzNee));
    }

    #[test]
    fn ticks_are_plain_decimals_with_one_format_per_axis() {
        assert_eq!(tick_decimals(0.0, 0.33, 5), 1);
        assert_eq!(tick(0.3, 1), "0.3");
        assert_eq!(tick(0.0, 3), "0");
        assert_eq!(tick_decimals(-90.0, 90.0, 7), 0);
        assert!(tick_decimals(0.0, 0.0033, 5) >= 3);
    }

    #[test]
    fn legends_wrap_into_lines_that_fit_the_figure() {
        let entries: Vec<(Key, String)> = ["order 1", "order 2", "order 3", "orders 4+", "all orders"]
            .iter()
            .enumerate()
            .map(|(i, name)| (Key::Line(order_style(i)), name.to_string()))
            .collect();
        assert_eq!(legend_lines(&entries, 1400), vec![std::ops::Range { start: 0, end: 5 }]);
        let widths = legend_widths(&entries);
        let lines = legend_lines(&entries, 390);
        assert!(lines.len() > 1, "{lines:?}");
        for line in &lines {
            assert!(widths[line.clone()].iter().sum::<i32>() <= 390, "{line:?} of {widths:?}");
        }
        assert_eq!(lines.iter().map(|l| l.len()).sum::<usize>(), 5);
        let labels = |title: &str, x: &str| GridLabels {
            title: title.to_string(),
            legend: entries.iter().map(|(_, name)| (Key::Measured, name.clone())).collect(),
            y: String::new(),
            x: x.to_string(),
        };
        let short = labels("t", "x");
        assert!(grid_size((360, 260), (1, 1), &short).1 > grid_size((360, 260), (4, 1), &short).1);
    }

    /// A single column of panels is widened to its title and x label (they were cut off), and
    /// a grid wide enough for them keeps its panels' width.
    #[test]
    fn a_narrow_grid_is_as_wide_as_its_title_and_x_label() {
        let long = "GGX, α = 0.5, conductor F=1: reflection (R), a title much wider than one panel";
        let x = "θ_o from +z (deg): + mirror side, − light's side, a label wider than one panel";
        let labels = |title: &str, x: &str| GridLabels {
            title: title.into(),
            legend: Vec::new(),
            y: String::new(),
            x: x.into(),
        };
        let (width, _) = grid_size((330, 250), (1, 5), &labels(long, "x"));
        assert!(width >= text_width(long, TITLE) + 24 && width > 360, "{width}");
        let (width, _) = grid_size((330, 250), (1, 5), &labels("t", x));
        assert!(width >= GRID_LEFT + text_width(x, LABEL) + 24, "{width}");
        assert_eq!(grid_size((330, 250), (4, 1), &labels(long, x)).0, GRID_LEFT + 4 * 330);
    }
}
