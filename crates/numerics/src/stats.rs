//! Statistical tests of weighted histograms (docs/theory.md §9.5): chi-square against expected bin
//! integrals, two-sample chi-square of two Monte Carlo estimates, Sidak correction. Used by
//! the test suite and by `smithwalk compare`.
//!
//! Bins are described by per-photon means: `mean = S/N` (the energy through the bin) and the
//! per-photon second moment `Q/N`. Under the null hypothesis the variance of a bin's mean is
//! `(mu r - mu^2) / N`, where `mu` is the expected energy and `r = Q/S` the bin's mean weight
//! (1 for unit weights, making the test the usual multinomial Pearson test).

use std::fmt::Write as _;

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// One bin of a weighted histogram, as per-photon moments over `photons` photons.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedBin {
    /// `S / N`: observed energy per photon.
    pub mean: f64,
    /// `Q / N`: per-photon second moment.
    pub second_moment: f64,
}

impl WeightedBin {
    /// The bin that `count` of `samples` unit-weight samples fell in: mean and second moment
    /// are both `count / samples` (the multinomial case).
    pub fn of_count(count: u64, samples: u64) -> Self {
        let p = count as f64 / samples as f64;
        Self { mean: p, second_moment: p }
    }
}

/// One cell of a test after pooling, kept for the diagnostic table.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// The bins it holds (one, or all the pooled ones).
    pub bins: Vec<usize>,
    pub observed: f64,
    pub expected: f64,
    pub z: f64,
}

/// The outcome of a chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct ChiSquare {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    pub cells: Vec<Cell>,
}

impl ChiSquare {
    pub(crate) fn from_cells(cells: Vec<Cell>) -> Self {
        let statistic: f64 = cells.iter().map(|c| c.z * c.z).sum();
        let dof = cells.len();
        let p_value = if dof == 0 { 1.0 } else { ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.sf(statistic)) };
        Self { statistic, dof, p_value, cells }
    }

    /// The observed and expected table of the `n` cells with the largest |z|, for failure reports.
    pub fn worst_cells(&self, n: usize) -> String {
        let mut cells: Vec<&Cell> = self.cells.iter().collect();
        cells.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
        let mut out = format!(
            "chi2 = {:.2}, dof = {}, p = {:.3e}\n   bins        observed        expected       z\n",
            self.statistic, self.dof, self.p_value
        );
        for c in cells.into_iter().take(n) {
            let bins = if c.bins.len() == 1 { c.bins[0].to_string() } else { format!("pool({})", c.bins.len()) };
            let _ = writeln!(out, "{bins:>7} {:>15.6e} {:>15.6e} {:>7.2}", c.observed, c.expected, c.z);
        }
        out
    }
}

/// Per-test level that keeps the family-wise level `family` over `tests` independent tests.
pub fn sidak(family: f64, tests: usize) -> f64 {
    1.0 - (1.0 - family).powf(1.0 / tests as f64)
}

/// Chi-square of observed weighted bins against expected per-photon energies `expected`.
///
/// Bins whose expected photon count `N mu / r` is below `min_count` are pooled into one cell;
/// the pooled cell is tested too if its own expected count reaches `min_count`.
/// Degrees of freedom: the number of cells (the bins need not hold all the light).
pub fn chi_square(observed: &[WeightedBin], expected: &[f64], photons: u64, min_count: f64) -> ChiSquare {
    let n = photons as f64;
    let (s_all, q_all) = observed.iter().fold((0.0, 0.0), |(s, q), b| (s + b.mean, q + b.second_moment));
    let global_ratio = if s_all > 0.0 { q_all / s_all } else { 1.0 };
    let ratio = |b: &WeightedBin| {
        if b.mean > 0.0 { b.second_moment / b.mean } else { global_ratio }
    };
    let mut cells = Vec::new();
    let mut pool = (Vec::new(), 0.0, 0.0, 0.0);
    for (i, (b, &mu)) in observed.iter().zip(expected).enumerate() {
        let r = ratio(b);
        let var_n = mu * r - mu * mu;
        if n * mu / r >= min_count {
            cells.push(Cell { bins: vec![i], observed: b.mean, expected: mu, z: (b.mean - mu) / (var_n / n).sqrt() });
        } else {
            pool.0.push(i);
            pool.1 += b.mean;
            pool.2 += mu;
            pool.3 += mu * r;
        }
    }
    let (bins, obs, mu, mu_r) = pool;
    if !bins.is_empty() && n * mu / (mu_r / mu.max(1e-300)) >= min_count {
        let var_n = mu_r - mu * mu;
        cells.push(Cell { bins, observed: obs, expected: mu, z: (obs - mu) / (var_n / n).sqrt() });
    }
    ChiSquare::from_cells(cells)
}

impl WeightedBin {
    /// The bin's mean weight `r = Q / S` (1 assumed for an empty bin).
    fn mean_weight(&self) -> f64 {
        if self.mean > 0.0 { self.second_moment / self.mean } else { 1.0 }
    }

    /// Variance of the mean over `n` photons if the true mean were `mu`: `(mu r - mu^2) / n`.
    fn variance_at(&self, mu: f64, n: f64) -> f64 {
        ((mu * self.mean_weight() - mu * mu) / n).max(0.0)
    }

    fn add(&mut self, other: &WeightedBin) {
        self.mean += other.mean;
        self.second_moment += other.second_moment;
    }
}

/// The comparison of `smithwalk compare`: a two-sample chi-square of two independent weighted
/// histograms of the same quantity, with `n1` and `n2` photons; `n2 = 0` makes `b` an exact
/// expectation (no variance).
///
/// Per bin, `z = (m1 - m2) / sqrt(v1(mu) + v2(mu))` with the variances evaluated at the common
/// mean `mu` of the null hypothesis, not at the observed means (which inflates the statistic
/// in sparse bins). For two Monte Carlo samples `mu` weights their means by their inverse
/// variances at a common mean, `N / r` each: that makes it uncorrelated with their
/// difference, so choosing bins by it does not bias the test. Bins in which less than
/// `min_count` photons' worth of energy is expected in `a` (`n1 mu`) are pooled into one
/// cell, tested too if it reaches `min_count`. (Pooling by either sample's own counts, or by
/// the plain average, keeps the bins where the noisier sample fluctuated up.)
pub fn two_sample_at_null(a: &[WeightedBin], n1: u64, b: &[WeightedBin], n2: u64, min_count: f64) -> ChiSquare {
    let exact = n2 == 0;
    let (n1, n2) = (n1 as f64, n2 as f64);
    let common_mean = |x: &WeightedBin, y: &WeightedBin| {
        if exact {
            return y.mean;
        }
        let (wx, wy) = (n1 / x.mean_weight(), n2 / y.mean_weight());
        (x.mean * wx + y.mean * wy) / (wx + wy)
    };
    let expected_count = |mu: f64| n1 * mu;
    let z = |x: &WeightedBin, y: &WeightedBin, mu: f64| {
        let v = x.variance_at(mu, n1) + if exact { 0.0 } else { y.variance_at(mu, n2) };
        (v > 0.0).then(|| (x.mean - y.mean) / v.sqrt())
    };
    let mut cells = Vec::new();
    let zero = WeightedBin { mean: 0.0, second_moment: 0.0 };
    let (mut pool_bins, mut pool_a, mut pool_b) = (Vec::new(), zero, zero);
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let mu = common_mean(x, y);
        match z(x, y, mu) {
            Some(z) if expected_count(mu) >= min_count => {
                cells.push(Cell { bins: vec![i], observed: x.mean, expected: y.mean, z });
            }
            _ => {
                pool_bins.push(i);
                pool_a.add(x);
                pool_b.add(y);
            }
        }
    }
    let mu = common_mean(&pool_a, &pool_b);
    if !pool_bins.is_empty()
        && expected_count(mu) >= min_count
        && let Some(z) = z(&pool_a, &pool_b, mu)
    {
        cells.push(Cell { bins: pool_bins, observed: pool_a.mean, expected: pool_b.mean, z });
    }
    ChiSquare::from_cells(cells)
}

/// The test suite's two-sample chi-square of two independent weighted histograms of the same
/// quantity, with `n1` and `n2` photons: `z = (m1 - m2) / sqrt(v1 + v2)` per cell with per-photon variances;
/// bins with fewer than `min_count` photons in the two samples together are pooled.
pub fn two_sample(a: &[WeightedBin], n1: u64, b: &[WeightedBin], n2: u64, counts: &[u64], min_count: u64) -> ChiSquare {
    let var = |bin: &WeightedBin, n: f64| ((bin.second_moment - bin.mean * bin.mean) / (n - 1.0)).max(0.0);
    let (n1, n2) = (n1 as f64, n2 as f64);
    let mut cells = Vec::new();
    let mut pooled =
        (Vec::new(), WeightedBin { mean: 0.0, second_moment: 0.0 }, WeightedBin { mean: 0.0, second_moment: 0.0 }, 0);
    let cell = |bins: Vec<usize>, x: &WeightedBin, y: &WeightedBin| {
        let v = var(x, n1) + var(y, n2);
        Cell { bins, observed: x.mean, expected: y.mean, z: (x.mean - y.mean) / v.sqrt() }
    };
    for (i, ((x, y), &count)) in a.iter().zip(b).zip(counts).enumerate() {
        if count >= min_count {
            cells.push(cell(vec![i], x, y));
        } else {
            pooled.0.push(i);
            pooled.1.mean += x.mean;
            pooled.1.second_moment += x.second_moment;
            pooled.2.mean += y.mean;
            pooled.2.second_moment += y.second_moment;
            pooled.3 += count;
        }
    }
    if pooled.3 >= min_count {
        cells.push(cell(pooled.0, &pooled.1, &pooled.2));
    }
    ChiSquare::from_cells(cells)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidak_level() {
        // (1 - a)^m = 1 - family.
        let a = sidak(0.01, 10);
        assert!(((1.0 - a).powi(10) - 0.99).abs() < 1e-12);
    }

    #[test]
    fn rejects_a_wrong_model_and_accepts_the_right_one() {
        // Multinomial counts 1000 photons over 4 bins with exact probabilities: the statistic of
        // exact expectations equals Pearson's sum; a 10% shifted model must be rejected.
        let counts = [400.0, 300.0, 200.0, 100.0];
        let obs: Vec<WeightedBin> =
            counts.iter().map(|c| WeightedBin { mean: c / 1000.0, second_moment: c / 1000.0 }).collect();
        let right = chi_square(&obs, &[0.4, 0.3, 0.2, 0.1], 1000, 5.0);
        assert_eq!(right.statistic, 0.0);
        let wrong = chi_square(&obs, &[0.3, 0.3, 0.3, 0.1], 1000, 5.0);
        // Pearson by hand: 1000 * (0.01/0.21 + 0.01/0.21) = 95.238...
        assert!((wrong.statistic - 1000.0 * 2.0 * 0.01 / 0.21).abs() < 1e-9, "{}", wrong.statistic);
        assert!(wrong.p_value < 1e-15);
    }

    #[test]
    fn the_compare_statistic_is_pearson_for_an_exact_model_and_zero_for_equal_samples() {
        // Unit weights (second moment = mean), exact model (n2 = 0): the same Pearson sums as
        // above, and 95.238... for the shifted model.
        let counts = [400.0, 300.0, 200.0, 100.0];
        let obs: Vec<WeightedBin> =
            counts.iter().map(|c| WeightedBin { mean: c / 1000.0, second_moment: c / 1000.0 }).collect();
        let exact = |p: [f64; 4]| p.map(|mean| WeightedBin { mean, second_moment: 0.0 });
        assert_eq!(two_sample_at_null(&obs, 1000, &exact([0.4, 0.3, 0.2, 0.1]), 0, 5.0).statistic, 0.0);
        let wrong = two_sample_at_null(&obs, 1000, &exact([0.3, 0.3, 0.3, 0.1]), 0, 5.0);
        assert!((wrong.statistic - 1000.0 * 2.0 * 0.01 / 0.21).abs() < 1e-9, "{}", wrong.statistic);
        // Two samples with equal means agree exactly; halving one sample's means is rejected.
        assert_eq!(two_sample_at_null(&obs, 1000, &obs, 1000, 5.0).statistic, 0.0);
        let half: Vec<WeightedBin> =
            obs.iter().map(|b| WeightedBin { mean: b.mean / 2.0, second_moment: b.second_moment / 2.0 }).collect();
        assert!(two_sample_at_null(&obs, 1000, &half, 1000, 5.0).p_value < 1e-10);
    }
}
