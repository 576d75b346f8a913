//! Adaptive Gauss–Kronrod quadrature (7-point Gauss, 15-point Kronrod), in one dimension and
//! nested in two: the independent integrator behind every analytic bin expectation.

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

/// `∫_a^b f` by adaptive bisection until each panel's error estimate is below its share of
/// `abs_tol` (or a depth of 50 halvings). The interval starts as four panels, so that a
/// narrow feature is not missed by a single panel's 15 nodes. Returns the integral and the
/// summed error estimate.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, abs_tol: f64) -> (f64, f64) {
    fn recurse(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, whole: (f64, f64), depth: u32) -> (f64, f64) {
        let (value, err) = whole;
        if err <= tol || depth >= 50 {
            return (value, err);
        }
        let mid = 0.5 * (a + b);
        let left = recurse(f, a, mid, 0.5 * tol, panel(f, a, mid), depth + 1);
        let right = recurse(f, mid, b, 0.5 * tol, panel(f, mid, b), depth + 1);
        (left.0 + right.0, left.1 + right.1)
    }
    if a == b {
        return (0.0, 0.0);
    }
    const START: usize = 4;
    let width = (b - a) / START as f64;
    (0..START).fold((0.0, 0.0), |(value, err), i| {
        let (lo, hi) = (a + i as f64 * width, if i + 1 == START { b } else { a + (i + 1) as f64 * width });
        let part = recurse(&f, lo, hi, abs_tol / START as f64, panel(&f, lo, hi), 0);
        (value + part.0, err + part.1)
    })
}

/// `∫_{x0}^{x1} ∫_{y0}^{y1} f(x, y) dy dx` by nested adaptive quadrature; the inner integrals
/// get a tolerance scaled to the outer interval.
pub fn integrate_2d(f: impl Fn(f64, f64) -> f64, x: (f64, f64), y: (f64, f64), abs_tol: f64) -> (f64, f64) {
    let inner_tol = abs_tol / (x.1 - x.0).abs().max(1e-300) * 0.1;
    integrate(|xv| integrate(|yv| f(xv, yv), y.0, y.1, inner_tol).0, x.0, x.1, abs_tol)
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
    fn two_dimensional_gaussian() {
        // ∫∫_{[-5,5]^2} e^{-x^2-y^2} = pi erf(5)^2.
        let (v, _) = integrate_2d(|x, y| (-x * x - y * y).exp(), (-5.0, 5.0), (-5.0, 5.0), 1e-12);
        let e5 = statrs::function::erf::erf(5.0);
        assert!((v - std::f64::consts::PI * e5 * e5).abs() < 1e-9, "{v}");
    }
}
