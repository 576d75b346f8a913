//! Root finding for the inverse CDFs of the samplers.

/// Solves `f(x) = 0` for an increasing `f` with derivative `df` on the bracket `[lo, hi]`
/// (`f(lo) <= 0 <= f(hi)`), by Newton steps from `x0` that fall back to bisection whenever a
/// step leaves the shrinking bracket, until the step or the bracket is below `1e-15` relative.
pub fn newton_bisect(f: impl Fn(f64) -> f64, df: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, x0: f64) -> f64 {
    let mut x = x0.clamp(lo, hi);
    for _ in 0..200 {
        let fx = f(x);
        if fx > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let newton = x - fx / df(x);
        let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        let tol = 1e-15 * (1.0 + next.abs());
        if (next - x).abs() <= tol || hi - lo <= tol {
            return next;
        }
        x = next;
    }
    x
}
