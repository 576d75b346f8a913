//! Error bars that tell the truth: many independent seeds of small runs, and the z-scores of
//! every per-order albedo and every (coarse) lobe bin against the all-seed mean must follow a
//! standard normal. Splitting, roulette and total internal reflection mix rare large weights
//! with many small ones; a standard error that ignores how they correlate within a photon, or
//! a walk that reuses random numbers across photons, shows up here as z-scores that are too
//! wide or too narrow.
//!
//! Setup: 40 seeds x 400 000 photons of four cases (a conductor with F = 1, a dielectric lit
//! from outside and from inside, a grey Lambertian facet), orders 1 to 5, "6+" and all, R and
//! T, albedos and the bins of a 3 x 4 grid (each bin pools a twelfth of a hemisphere, so it
//! holds enough photons for a normal z). A quantity is used when each seed saw at least 30
//! photons in it.
//!
//! With `K` seeds, estimates `x_s` with standard errors `e_s` and mean `m`, the z-score is
//! `(x_s - m) / sqrt(e_s^2 (1 - 2/K) + sum_j e_j^2 / K^2)` (the variance of `x_s - m`), and
//! `sum_s z_s^2` is chi-square with `K - 1` degrees of freedom when the errors are right.
//! Checks, each stated with its level:
//!
//! * per quantity, `sum z^2` inside the two-sided chi-square(K - 1) interval at the Sidak level
//!   that keeps the family of all quantities at 0.01;
//! * over all z-scores, the mean of `z^2` in [0.8, 1.25] (1 when the errors are right; the z's
//!   of one seed are correlated, so the bound is wide: about 4 standard deviations of the mean
//!   for a few thousand z's even with their correlation);
//! * the fraction beyond 2 in [0.02, 0.08] (normal: 0.0455) and beyond 3 at most 0.012 (normal:
//!   0.0027).
//!
//! The same checks on the same data with every standard error scaled by 0.8 (errors 20% too
//! small) must fail, so the test can fail.

use smithwalk::engine::detector::Detector;
use smithwalk::engine::run::CaseResult;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::common;

const SEEDS: u64 = 40;
const PHOTONS: u64 = 400_000;
const MIN_COUNT: u64 = 30;
const FAMILY_LEVEL: f64 = 0.01;

/// One case per config: `(name, TOML body after paths and seed)`.
const CASES: [(&str, &str); 4] = [
    ("conductor", "[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_rad = 0.5\n"),
    (
        "dielectric outside",
        "[surface]\nalpha = 0.25\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_rad = 0.5\n",
    ),
    (
        "dielectric inside",
        "[surface]\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_rad = 0.5\nside = \"inside\"\n",
    ),
    (
        "lambertian",
        "[surface]\nalpha = 0.5\n[material]\nkind = \"diffuse\"\nalbedo = 0.8\n[incident]\ntheta_rad = 1.0\n",
    ),
];

/// `(mean, standard error, photons that reached it)` of every albedo and bin of a case,
/// keyed by a readable name.
fn estimates<const C: usize>(d: &Detector<C>) -> Vec<(String, (f64, f64, u64))> {
    let n = d.tallies.photons;
    let bins = d.grid.bins();
    let mut out = Vec::new();
    for (slot, order) in d.tallies.orders.iter().enumerate() {
        for h in 0..2 {
            let t = &order.albedo[h].tally;
            let (m, e) = t.mean_and_stderr(n, 0);
            out.push((format!("slot {slot} {} albedo", ["R", "T"][h]), (m, e, t.count)));
            for b in 0..bins {
                let t = &order.bins[h * bins + b];
                let (m, e) = t.mean_and_stderr(n, 0);
                out.push((format!("slot {slot} {} bin {b}", ["R", "T"][h]), (m, e, t.count)));
            }
        }
    }
    out
}

/// Per quantity name, the `(mean, stderr)` of every seed, for the quantities every seed saw at
/// least [`MIN_COUNT`] photons in and that vary (a conductor with F = 1 reflects everything in
/// every seed: its all-orders albedo is 1 with no error).
fn seeds_of(name: &str, body: &str) -> Vec<(String, Vec<(f64, f64)>)> {
    let mut per_seed = Vec::new();
    for seed in 0..SEEDS {
        let toml = format!(
            "paths = {PHOTONS}\nseed = {}\n{body}[detector]\ncos_theta_bins = 3\nphi_bins = 4\nmax_order = 6\n",
            1000 + seed
        );
        let sim = common::simulate(&toml, 2);
        let CaseResult::Mono(d) = &sim.results[0] else { panic!("{name}: one channel") };
        per_seed.push(estimates(d));
    }
    let names: Vec<String> =
        per_seed.iter().map(|s| s.iter().map(|(k, _)| k.clone()).collect::<Vec<_>>()).min_by_key(Vec::len).unwrap();
    names
        .into_iter()
        .filter_map(|key| {
            let values: Vec<(f64, f64, u64)> =
                per_seed.iter().map(|s| s.iter().find(|(k, _)| *k == key).map_or((0.0, 0.0, 0), |(_, v)| *v)).collect();
            values
                .iter()
                .all(|&(_, e, count)| count >= MIN_COUNT && e > 0.0)
                .then(|| (format!("{name}: {key}"), values.iter().map(|&(m, e, _)| (m, e)).collect()))
        })
        .collect()
}

/// The z-scores of the seeds' estimates against their mean, with standard errors scaled by
/// `scale`.
fn z_scores(values: &[(f64, f64)], scale: f64) -> Vec<f64> {
    let k = values.len() as f64;
    let mean = values.iter().map(|v| v.0).sum::<f64>() / k;
    let spread = values.iter().map(|v| (scale * v.1).powi(2)).sum::<f64>() / (k * k);
    values.iter().map(|&(x, e)| (x - mean) / ((scale * e).powi(2) * (1.0 - 2.0 / k) + spread).sqrt()).collect()
}

/// The checks of the module doc on `quantities` with standard errors scaled by `scale`: the
/// failures, one line each.
fn failures(quantities: &[(String, Vec<(f64, f64)>)], scale: f64) -> Vec<String> {
    let dof = (SEEDS - 1) as f64;
    let chi2 = ChiSquared::new(dof).unwrap();
    let level = smithwalk::analysis::stats::sidak(FAMILY_LEVEL, quantities.len());
    let (lo, hi) = (chi2.inverse_cdf(level / 2.0), chi2.inverse_cdf(1.0 - level / 2.0));
    let mut out = Vec::new();
    let mut all = Vec::new();
    for (name, values) in quantities {
        let z = z_scores(values, scale);
        let sum: f64 = z.iter().map(|z| z * z).sum();
        if !(lo..=hi).contains(&sum) {
            out.push(format!("{name}: sum z^2 = {sum:.1} outside [{lo:.1}, {hi:.1}] (chi-square {dof} dof, two-sided level {level:.2e})"));
        }
        all.extend(z);
    }
    let n = all.len() as f64;
    let mean_sq = all.iter().map(|z| z * z).sum::<f64>() / n;
    let beyond = |t: f64| all.iter().filter(|z| z.abs() > t).count() as f64 / n;
    eprintln!(
        "errors x {scale}: {n} z-scores, mean z^2 {mean_sq:.3}, beyond 2: {:.4}, beyond 3: {:.4}; per-quantity \
         interval [{lo:.1}, {hi:.1}], {} outside",
        beyond(2.0),
        beyond(3.0),
        out.len()
    );
    if !(0.8..=1.25).contains(&mean_sq) {
        out.push(format!("mean z^2 over {n} z-scores = {mean_sq:.3}, outside [0.8, 1.25]"));
    }
    if !(0.02..=0.08).contains(&beyond(2.0)) {
        out.push(format!("fraction beyond 2 = {:.4}, outside [0.02, 0.08]", beyond(2.0)));
    }
    if beyond(3.0) > 0.012 {
        out.push(format!("fraction beyond 3 = {:.4}, above 0.012", beyond(3.0)));
    }
    out
}

#[test]
fn z_scores_over_independent_seeds_are_standard_normal() {
    let quantities: Vec<(String, Vec<(f64, f64)>)> =
        CASES.iter().flat_map(|(name, body)| seeds_of(name, body)).collect();
    // Every case contributes its albedos of orders 1 to 3 in R, and orders 4 and 5 where they
    // are not rare (the low-roughness dielectric lit from outside sends a few photons in 10^5
    // back at order 5).
    for (name, _) in CASES {
        for slot in 1..=3 {
            let key = format!("{name}: slot {slot} R albedo");
            assert!(quantities.iter().any(|(k, _)| *k == key), "{key} has fewer than {MIN_COUNT} photons in some seed");
        }
    }
    for key in [
        "conductor: slot 5 R albedo",
        "lambertian: slot 5 R albedo",
        "dielectric inside: slot 5 T albedo",
        "dielectric inside: slot 3 T albedo",
        "dielectric outside: slot 0 T albedo",
        "dielectric outside: slot 3 T albedo",
        "lambertian: slot 0 R albedo",
    ] {
        assert!(quantities.iter().any(|(k, _)| k == key), "{key} is not tested");
    }
    eprintln!("{} quantities of {} seeds", quantities.len(), SEEDS);
    let bad = failures(&quantities, 1.0);
    assert!(bad.is_empty(), "{} quantities; failed:\n{}", quantities.len(), bad.join("\n"));
    let narrow = failures(&quantities, 0.8);
    assert!(!narrow.is_empty(), "standard errors 20% too small were not noticed");
}
