//! Curves as points with error bars.

/// Points of a curve with error bars: (x, y, standard error).
pub(super) type Points = Vec<(f64, f64, f64)>;

/// The top of a point's error bar, or the point where it has none (a NaN standard error).
pub(super) fn bar_top(p: &(f64, f64, f64)) -> f64 {
    p.1 + if p.2.is_finite() { p.2 } else { 0.0 }
}
