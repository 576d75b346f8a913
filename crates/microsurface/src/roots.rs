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

    #[test]
    fn the_last_step_is_taken() {
        // x - 1/2 with a derivative twice too large: each step halves the error, exactly in
        // binary, so the search ends on a step of 2^-50 (the first below 1.5e-15) with the error
        // 2^-49 before it. Taking that step leaves 2^-50 = 8.9e-16, within the tolerance;
        // undoing it would leave 3 x 2^-50.
        let (x, _) = solve(|x| x - 0.5, |_| 2.0, 0.0, 1.0, 1.0);
        assert!((x - 0.5).abs() <= 1.5e-15, "{x}");
    }

    #[test]
    fn a_root_at_a_jump_is_bracketed_to_tolerance() {
        // A CDF with an atom: f jumps from -0.1 to 0.1 at 0.3, so no Newton step is ever small
        // and only the bracket can end the search: about 50 halvings of [0, 1], not the 200
        // evaluations of the iteration limit.
        let (x, calls) = solve(|x| if x < 0.3 { x - 0.4 } else { x - 0.2 }, |_| 1.0, 0.0, 1.0, 0.9);
        assert!((x - 0.3).abs() <= 2e-15 && calls <= 60, "{x} after {calls} calls");
    }
}
