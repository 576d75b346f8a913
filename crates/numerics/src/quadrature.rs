//! Adaptive Gauss–Kronrod quadrature: in one dimension (7-point Gauss, 15-point Kronrod) and
//! nested in two, and a globally adaptive cubature on rectangles (product 3-point Gauss,
//! 7-point Kronrod) with a bound on evaluations, graded towards a known peak: the independent
//! integrators behind every analytic bin expectation. Every one of them terminates: tolerances
//! have a floor at rounding level and the evaluations a bound.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Kronrod abscissae on [-1, 1] (non-negative half; the last is the centre).
const XK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights matching [`XK`].
const WK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss weights of the 7-point rule, on the odd Kronrod abscissae `XK[1], XK[3], XK[5], XK[7]`.
const WG: [f64; 4] =
    [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// One Gauss–Kronrod panel: the Kronrod estimate and |Kronrod - Gauss|.
fn panel(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let centre = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let fc = f(centre);
    let mut kronrod = WK[7] * fc;
    let mut gauss = WG[3] * fc;
    for i in 0..7 {
        let dx = half * XK[i];
        let pair = f(centre - dx) + f(centre + dx);
        kronrod += WK[i] * pair;
        if i % 2 == 1 {
            gauss += WG[i / 2] * pair;
        }
    }
    (kronrod * half, ((kronrod - gauss) * half).abs())
}

/// Panels one call of [`integrate`] may evaluate (15 nodes each): a bound on its work whatever
/// the integrand and the tolerance.
const MAX_PANELS: usize = 20_000;

/// `∫_a^b f` by adaptive bisection until each panel's error estimate is below its share of
/// `abs_tol`, or below the rounding floor `1e-15 |panel|` (a halved tolerance cannot go below
/// what doubles resolve), or a depth of 50 halvings, or `MAX_PANELS` panels in all. The
/// interval starts as four panels, so that a narrow feature is not missed by a single panel's 15
/// nodes. Returns the integral and the summed error estimate.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, abs_tol: f64) -> (f64, f64) {
    fn recurse(
        f: &impl Fn(f64) -> f64,
        (a, b): (f64, f64),
        tol: f64,
        whole: (f64, f64),
        depth: u32,
        panels: &mut usize,
    ) -> (f64, f64) {
        let (value, err) = whole;
        if err <= tol.max(1e-15 * value.abs()) || depth >= 50 || *panels + 2 > MAX_PANELS {
            return (value, err);
        }
        *panels += 2;
        let mid = 0.5 * (a + b);
        let left = recurse(f, (a, mid), 0.5 * tol, panel(f, a, mid), depth + 1, panels);
        let right = recurse(f, (mid, b), 0.5 * tol, panel(f, mid, b), depth + 1, panels);
        (left.0 + right.0, left.1 + right.1)
    }
    if a == b {
        return (0.0, 0.0);
    }
    const START: usize = 4;
    let width = (b - a) / START as f64;
    let mut panels = START;
    (0..START).fold((0.0, 0.0), |(value, err), i| {
        let (lo, hi) = (a + i as f64 * width, if i + 1 == START { b } else { a + (i + 1) as f64 * width });
        let part = recurse(&f, (lo, hi), abs_tol / START as f64, panel(&f, lo, hi), 0, &mut panels);
        (value + part.0, err + part.1)
    })
}

/// `∫_{x0}^{x1} ∫_{y0}^{y1} f(x, y) dy dx` by nested adaptive quadrature; the inner integrals
/// get a tolerance scaled to the outer interval.
pub fn integrate_2d(f: impl Fn(f64, f64) -> f64, x: (f64, f64), y: (f64, f64), abs_tol: f64) -> (f64, f64) {
    let f = &f;
    integrate_2d_nested(|xv| move |yv| f(xv, yv), x, y, abs_tol)
}

/// [`integrate_2d`] with the integrand given per outer abscissa: `inner_at(x)` is `y -> f(x, y)`,
/// so what depends on `x` alone is computed once for its whole inner integral.
pub fn integrate_2d_nested<G: Fn(f64) -> f64>(
    inner_at: impl Fn(f64) -> G,
    x: (f64, f64),
    y: (f64, f64),
    abs_tol: f64,
) -> (f64, f64) {
    let inner_tol = abs_tol / (x.1 - x.0).abs().max(1e-300) * 0.1;
    integrate(|xv| integrate(inner_at(xv), y.0, y.1, inner_tol).0, x.0, x.1, abs_tol)
}

/// Kronrod abscissae of the 7-point rule that extends the 3-point Gauss rule, on [-1, 1].
const XK7: [f64; 7] = [
    -0.960_491_268_708_020_2,
    -0.774_596_669_241_483_4,
    -0.434_243_749_346_802_6,
    0.0,
    0.434_243_749_346_802_6,
    0.774_596_669_241_483_4,
    0.960_491_268_708_020_2,
];
/// Weights of [`XK7`] (exact for polynomials of degree 11).
const WK7: [f64; 7] = [
    0.104_656_226_026_467_2,
    0.268_488_089_868_333_4,
    0.401_397_414_775_962_2,
    0.450_916_538_658_474_1,
    0.401_397_414_775_962_2,
    0.268_488_089_868_333_4,
    0.104_656_226_026_467_2,
];
/// Weights of the 3-point Gauss rule on the Kronrod abscissae (0 where it has no node).
const WG3: [f64; 7] = [0.0, 5.0 / 9.0, 0.0, 8.0 / 9.0, 0.0, 5.0 / 9.0, 0.0];

/// The outcome of a bounded integration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integral {
    pub value: f64,
    /// The error estimate: |Kronrod - Gauss| summed over the final rectangles (pessimistic for
    /// smooth integrands, where the Kronrod value is far more accurate than the Gauss one).
    pub error: f64,
    pub evaluations: usize,
    /// Whether the evaluation bound stopped the refinement before the tolerance was met.
    pub capped: bool,
}

/// A known narrow feature of an integrand: where it is and its size along each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    pub at: (f64, f64),
    pub scale: (f64, f64),
}

/// One rectangle of [`cubature`] with its product-rule estimate.
#[derive(Clone, Copy, Debug)]
struct Cell {
    x: (f64, f64),
    y: (f64, f64),
    value: f64,
    error: f64,
    /// Whether more of the error comes from the x direction (split across x) than from y.
    split_x: bool,
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.error.total_cmp(&other.error) == Ordering::Equal
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Cell {
    fn cmp(&self, other: &Self) -> Ordering {
        self.error.total_cmp(&other.error)
    }
}

/// Evaluations of one [`Cell`]: the 7 x 7 product Kronrod nodes.
const CELL_EVALUATIONS: usize = 49;

/// The product K7 x K7 estimate of `∫∫ f` over a rectangle; its error along x is |K7 x K7 -
/// G3 x K7| (the Gauss rule in x on the same nodes), along y likewise. The cell's error
/// estimate is their sum, scaled as QUADPACK does (Piessens et al. 1983, `qk21`): with `asc`
/// the integral of `|f - mean|` on the nodes, `asc min(1, (200 e / asc)^1.5)`. A bare
/// |Kronrod - Gauss| can be tiny where both rules miss a peak narrower than the cell; the
/// scaling makes a small estimate believable only when it is small against the cell's own
/// variation.
fn cell(f: &impl Fn(f64, f64) -> f64, x: (f64, f64), y: (f64, f64)) -> Cell {
    let (cx, hx) = (0.5 * (x.0 + x.1), 0.5 * (x.1 - x.0));
    let (cy, hy) = (0.5 * (y.0 + y.1), 0.5 * (y.1 - y.0));
    let (mut kk, mut gk, mut kg) = (0.0, 0.0, 0.0);
    let mut values = [[0.0; 7]; 7];
    for i in 0..7 {
        let xv = cx + hx * XK7[i];
        let (mut k_row, mut g_row) = (0.0, 0.0);
        for j in 0..7 {
            let v = f(xv, cy + hy * XK7[j]);
            values[i][j] = v;
            k_row += WK7[j] * v;
            g_row += WG3[j] * v;
        }
        kk += WK7[i] * k_row;
        gk += WG3[i] * k_row;
        kg += WK7[i] * g_row;
    }
    let area = hx * hy;
    let mean = 0.25 * kk;
    let asc: f64 =
        (0..7).map(|i| (0..7).map(|j| WK7[i] * WK7[j] * (values[i][j] - mean).abs()).sum::<f64>()).sum::<f64>() * area;
    let (ex, ey) = (((kk - gk) * area).abs(), ((kk - kg) * area).abs());
    let scaled = |e: f64| if asc > 0.0 && e > 0.0 { asc * (200.0 * e / asc).powf(1.5).min(1.0) } else { e };
    Cell { x, y, value: kk * area, error: scaled(ex + ey), split_x: ex >= ey }
}

/// How far outside an interval, in units of the peak's scale, a peak still grades it: so that
/// a peak on an edge, computed a rounding error beyond it, grades the bins on both sides, and
/// a steep tail reaching into a bin is seen by its nodes (for `smithwalk`'s specular lobes 16
/// scales are 8 alpha of facet slope, where a Beckmann lobe has fallen to e^-64).
const GRADING_REACH: f64 = 16.0;

/// The pieces of `[lo, hi]`: graded geometrically towards the point nearest to `at` when `at`
/// lies within [`GRADING_REACH`] scales of the interval (pieces halving towards it on either
/// side until they are no wider than `scale`), else the interval itself.
fn graded_axis((lo, hi): (f64, f64), at: f64, scale: f64) -> Vec<(f64, f64)> {
    let nearest = at.clamp(lo, hi);
    let near = scale > 0.0 && (at - nearest).abs() <= GRADING_REACH * scale;
    if !near {
        return vec![(lo, hi)];
    }
    let at = nearest;
    let mut edges = vec![lo, at, hi];
    for (direction, side) in [(-1.0, at - lo), (1.0, hi - at)] {
        let mut width = side;
        for _ in 0..40 {
            if width <= scale {
                break;
            }
            width *= 0.5;
            edges.push(at + direction * width);
        }
    }
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    edges.windows(2).map(|w| (w[0], w[1])).collect()
}

/// The rectangles that cover `x` x `y`: the product of the axes' pieces, each axis graded
/// towards the peak's coordinate when it lies within reach (see [`graded_axis`]), so that the
/// rule's nodes see a feature much narrower than the rectangle, and its tails along the lines
/// through the peak (a feature between nodes gives a wrong value with a small error estimate).
fn graded(x: (f64, f64), y: (f64, f64), peak: Option<Peak>) -> Vec<((f64, f64), (f64, f64))> {
    let Some(peak) = peak else { return vec![(x, y)] };
    let xs = graded_axis(x, peak.at.0, peak.scale.0);
    let ys = graded_axis(y, peak.at.1, peak.scale.1);
    xs.iter().flat_map(|&x| ys.iter().map(move |&y| (x, y))).collect()
}

/// `∫_{x0}^{x1} ∫_{y0}^{y1} f(x, y) dy dx` by globally adaptive cubature: the rectangle (graded
/// towards `peak`, see `graded`) is covered by cells of the product 7-point Kronrod rule, and
/// the cell with the largest error estimate is halved across its worse direction until the
/// summed estimate is at most `max(abs_tol, 1e-14 |value|)` or `max_evaluations` are spent
/// (then [`Integral::capped`]).
pub fn cubature(
    f: impl Fn(f64, f64) -> f64,
    x: (f64, f64),
    y: (f64, f64),
    peak: Option<Peak>,
    abs_tol: f64,
    max_evaluations: usize,
) -> Integral {
    if x.0 == x.1 || y.0 == y.1 {
        return Integral::default();
    }
    let mut heap: BinaryHeap<Cell> = graded(x, y, peak).into_iter().map(|(x, y)| cell(&f, x, y)).collect();
    let mut evaluations = heap.len() * CELL_EVALUATIONS;
    let total = |heap: &BinaryHeap<Cell>| heap.iter().fold((0.0, 0.0), |(v, e), c| (v + c.value, e + c.error));
    let (mut value, mut error) = total(&heap);
    let mut capped = false;
    while error > abs_tol.max(1e-14 * value.abs()) {
        if evaluations + 2 * CELL_EVALUATIONS > max_evaluations {
            capped = true;
            break;
        }
        let worst = heap.pop().expect("a cell has the error");
        let halves = if worst.split_x {
            let mid = 0.5 * (worst.x.0 + worst.x.1);
            [cell(&f, (worst.x.0, mid), worst.y), cell(&f, (mid, worst.x.1), worst.y)]
        } else {
            let mid = 0.5 * (worst.y.0 + worst.y.1);
            [cell(&f, worst.x, (worst.y.0, mid)), cell(&f, worst.x, (mid, worst.y.1))]
        };
        evaluations += 2 * CELL_EVALUATIONS;
        value += halves[0].value + halves[1].value - worst.value;
        error += halves[0].error + halves[1].error - worst.error;
        heap.extend(halves);
        // Running sums drift; resum now and then so that the stopping test stays honest.
        if evaluations % (64 * CELL_EVALUATIONS) < 2 * CELL_EVALUATIONS {
            (value, error) = total(&heap);
        }
    }
    let (value, error) = total(&heap);
    Integral { value, error, evaluations, capped }
}

/// Gauss–Legendre nodes and weights on [a, b] (Newton iteration on the Legendre polynomial).
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (0.5 * (a + b) + 0.5 * (b - a) * x, 0.5 * (b - a) * w)
        })
        .collect()
}

/// Tanh–sinh (double exponential) nodes and weights on [a, b] with step `h` (Takahasi & Mori
/// 1974): `x = tanh(pi/2 sinh(k h))` for every integer `k` whose weight
/// `h pi/2 cosh(k h) / cosh^2(pi/2 sinh(k h))` is at least `1e-20` of the central one. The
/// nodes crowd double-exponentially towards the ends, so that integrable algebraic endpoint
/// singularities of bounded or mildly singular integrands (`x^p`, `(b - x)^p`, `p >= -1/2`)
/// cost no accuracy: the error falls like `e^{-c/h}`. The distance of a node to its nearer end is computed as `1 / (1 + e^{2u})`, not
/// as a difference, so that nodes a rounding error from an end stay distinct from it.
pub fn tanh_sinh(h: f64, a: f64, b: f64) -> Vec<(f64, f64)> {
    let half = std::f64::consts::FRAC_PI_2;
    let weight = |t: f64| h * half * t.cosh() / (half * t.sinh()).cosh().powi(2);
    let floor = 1e-20 * weight(0.0);
    let mut rule = vec![(0.5 * (a + b), (b - a) * 0.5 * weight(0.0))];
    for k in 1.. {
        let t = k as f64 * h;
        let w = weight(t);
        if w < floor {
            break;
        }
        // 1 - tanh(u) = 2 / (1 + e^{2u}).
        let gap = (b - a) / (1.0 + (2.0 * half * t.sinh()).exp());
        rule.push((a + gap, 0.5 * (b - a) * w));
        rule.push((b - gap, 0.5 * (b - a) * w));
    }
    rule
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_are_exact() {
        // The 15-point Kronrod rule integrates degree-22 polynomials exactly: ∫_0^2 x^22 = 2^23/23.
        let (v, _) = integrate(|x| x.powi(22), 0.0, 2.0, 1e-12);
        assert!((v - 2f64.powi(23) / 23.0).abs() < 1e-9 * v);
    }

    #[test]
    fn peaked_and_singular_integrands() {
        // ∫_0^1 1/sqrt(x) = 2 (endpoint singularity), ∫_{-1}^{1} 1/(1e-4 + x^2) = 2 atan(100)/0.01.
        let (v, _) = integrate(|x| 1.0 / x.sqrt(), 0.0, 1.0, 1e-10);
        assert!((v - 2.0).abs() < 1e-6, "{v}");
        let (v, _) = integrate(|x| 1.0 / (1e-4 + x * x), -1.0, 1.0, 1e-10);
        let exact = 2.0 * 100f64.atan() / 0.01;
        assert!((v - exact).abs() < 1e-8 * exact, "{v} vs {exact}");
    }

    #[test]
    fn the_product_kronrod_cell_is_exact_for_degree_eleven() {
        // ∫_0^2 ∫_1^3 x^11 y^10 = (2^12 / 12) (3^11 - 1) / 11, in one cell (tolerance met at once).
        let r = cubature(|x, y| x.powi(11) * y.powi(10), (0.0, 2.0), (1.0, 3.0), None, 1e-3, 49);
        let exact = 2f64.powi(12) / 12.0 * (3f64.powi(11) - 1.0) / 11.0;
        assert!((r.value - exact).abs() < 1e-12 * exact, "{} vs {exact}", r.value);
    }

    #[test]
    fn a_peak_narrower_than_the_nodes_is_found_by_grading() {
        // A Gaussian of width 1e-5 at (0.3, 0.7) in the unit square: pi s^2 (its tails beyond the
        // square are e^{-10^8}). Without grading every node sees zero and the estimate is zero.
        let s = 1e-5;
        let f = |x: f64, y: f64| (-((x - 0.3).powi(2) + (y - 0.7).powi(2)) / (s * s)).exp();
        let exact = std::f64::consts::PI * s * s;
        let peak = Peak { at: (0.3, 0.7), scale: (s, s) };
        let r = cubature(f, (0.0, 1.0), (0.0, 1.0), Some(peak), 1e-6 * exact, 200_000);
        assert!((r.value - exact).abs() < 1e-5 * exact && !r.capped, "{r:?} vs {exact}");
        assert_eq!(cubature(f, (0.0, 1.0), (0.0, 1.0), None, 1e-6 * exact, 200_000).value, 0.0);
    }

    #[test]
    fn a_peak_on_an_edge_or_in_the_middle_grades_both_sides() {
        // The same Gaussian centred a rounding error outside the square, at x = 1 + 2^-52 (a
        // peak on a bin edge, computed on the wrong side): half of it lies inside, pi s^2 / 2.
        // Ten widths away its tail inside is e^-100 of it and grading must not invent mass.
        let s = 1e-5;
        let gaussian = |x0: f64| move |x: f64, y: f64| (-((x - x0).powi(2) + (y - 0.7).powi(2)) / (s * s)).exp();
        let half = 0.5 * std::f64::consts::PI * s * s;
        // Centred in the square, the peak grades both sides of it (each side was once graded
        // by its distance to the peak, which the two share there): the whole Gaussian.
        for (x0, expected) in [(1.0 + f64::EPSILON, half), (1.0 + 10.0 * s, 0.0), (0.5, 2.0 * half)] {
            let peak = Peak { at: (x0, 0.7), scale: (s, s) };
            let r = cubature(gaussian(x0), (0.0, 1.0), (0.0, 1.0), Some(peak), 1e-6 * half, 200_000);
            assert!((r.value - expected).abs() < 1e-5 * half && !r.capped, "{x0}: {r:?} vs {expected}");
        }
    }

    #[test]
    fn the_evaluation_bound_stops_an_unreachable_tolerance_and_says_so() {
        // A jump along a slanted line cannot be integrated to 1e-30: the bound stops it.
        let r = cubature(|x, y| f64::from(u8::from(x > y)), (0.0, 1.0), (0.0, 1.0), None, 1e-30, 10_000);
        assert!(r.capped && r.evaluations <= 10_000, "{r:?}");
        assert!((r.value - 0.5).abs() < 1e-2, "{r:?}");
        // The one-dimensional rule with a zero tolerance on a singular integrand terminates too.
        let (v, _) = integrate(|x| (x - 0.3).abs().powf(-0.5), 0.0, 1.0, 0.0);
        assert!((v - 2.0 * (0.3f64.sqrt() + 0.7f64.sqrt())).abs() < 1e-3, "{v}");
    }

    #[test]
    fn two_dimensional_gaussian() {
        // ∫∫_{[-5,5]^2} e^{-x^2-y^2} = pi erf(5)^2.
        let (v, _) = integrate_2d(|x, y| (-x * x - y * y).exp(), (-5.0, 5.0), (-5.0, 5.0), 1e-12);
        let e5 = statrs::function::erf::erf(5.0);
        assert!((v - std::f64::consts::PI * e5 * e5).abs() < 1e-9, "{v}");
    }

    #[test]
    fn tanh_sinh_takes_endpoint_singularities() {
        // ∫_0^1 x^-0.5 = 2, ∫_0^1 x^(1/17) (1 - x)^1.5 = B(18/17, 5/2), ∫_0^2 x^2 = 8/3: the
        // algebraic singularities at either end cost nothing at h = 1/8 (55 nodes). (Stronger
        // ones, x^-0.8, lose 3e-4 to the truncation of the weights at 1e-20.)
        let rule = |f: &dyn Fn(f64) -> f64, a, b| tanh_sinh(0.125, a, b).iter().map(|&(x, w)| w * f(x)).sum::<f64>();
        assert!((rule(&|x| x.powf(-0.5), 0.0, 1.0) - 2.0).abs() < 1e-9);
        let beta = statrs::function::beta::beta(18.0 / 17.0, 2.5);
        assert!((rule(&|x| x.powf(1.0 / 17.0) * (1.0 - x).powf(1.5), 0.0, 1.0) - beta).abs() < 1e-12 * beta);
        assert!((rule(&|x| x * x, 0.0, 2.0) - 8.0 / 3.0).abs() < 1e-13);
        assert_eq!(tanh_sinh(0.125, 0.0, 1.0).len(), 55);
    }
}
