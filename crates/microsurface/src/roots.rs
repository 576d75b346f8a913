//! Root finding for the inverse CDFs of the samplers.

/// Solves `f(x) = 0` for an increasing `f` with derivative `df` on the bracket `[lo, hi]`
/// (`f(lo) <= 0 <= f(hi)`), by Newton steps from `x0` that fall back to bisection whenever a
/// step leaves the shrinking bracket, until the step or the bracket is below `1e-15` relative.
pub fn newton_bisect(f: impl Fn(f64) -> f64, df: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, x0: f64) -> f64 {
    let mut x = x0.clamp(lo, hi);
    for _ in 0..200 {
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if fx > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let step = fx / df(x);
        let tol = 1e-15 * (1.0 + x.abs());
        // Converged: tested before the bracket, because a step this small may round onto the
        // bracket's end, and bisecting the whole bracket from there would start over.
        if step.abs() <= tol {
            return x - step;
        }
        let newton = x - step;
        let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= tol {
            return next;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// Solves with `newton_bisect`, counting the evaluations of `f`.
    fn solve(f: impl Fn(f64) -> f64, df: impl Fn(f64) -> f64, lo: f64, hi: f64, x0: f64) -> (f64, u32) {
        let calls = Cell::new(0);
        let x = newton_bisect(
            |x| {
                calls.set(calls.get() + 1);
                f(x)
            },
            df,
            lo,
            hi,
            x0,
        );
        (x, calls.get())
    }

    #[test]
    fn an_exact_root_ends_the_search() {
        // Newton lands exactly on the root of a line: f = 0 there, and the search must stop
        // rather than bisect the bracket [0.5, 1] it has just shrunk to.
        let (x, calls) = solve(|x| x - 0.5, |_| 1.0, 0.0, 1.0, 0.25);
        assert_eq!((x, calls), (0.5, 2));
    }

    #[test]
    fn converges_quadratically_from_either_side() {
        // x^3 = 2 on [0, 2]: Newton's iterates approach from above, with the bracket's low end
        // never moving; the cube root of 2 to 1e-15, in a handful of evaluations.
        let root = 2f64.cbrt();
        for x0 in [0.1, 1.0, 1.9] {
            let (x, calls) = solve(|x| x * x * x - 2.0, |x| 3.0 * x * x, 0.0, 2.0, x0);
            assert!((x - root).abs() <= 4e-15 && calls <= 12, "x0 {x0}: {x} after {calls} calls");
        }
    }
}
