//! The chain models walked on one chain of directions (`Estimator::JointChains`, what
//! `smithwalk compare` does with two or more of them) estimate each model exactly as the model
//! walked alone: channel `c` of the joint run against the model's own run, lobe by lobe.
//!
//! Cases: a conductor (F = 1, alpha 0.5, 30 deg), a grey Lambertian facet (alpha 1, 60 deg)
//! and a dielectric (eta 1.5, alpha 0.5, 30 deg, R and T; the position-free chain does not
//! describe it, so its channel is left out). 3 x 10^5 photons each, independent seeds.
//! Per lobe (orders 1 to 3, "4+" and all), a two-sample chi-square with per-photon variances,
//! pooling bins with fewer than 10 photons, at the Sidak level that keeps the family of all
//! lobes at 0.01; per model and case, the all-orders albedo's standard error of the joint run
//! at most 1.1 times that of the model alone (the joint run plays Russian roulette on the
//! largest weight, so it is never noisier; 1.1 leaves room for the noise of the estimated
//! errors, a few percent at this photon count).

use smithwalk::analysis::stats::{WeightedBin, sidak, two_sample};
use smithwalk::engine::detector::{Detector, Hemisphere};
use smithwalk::engine::run::{CaseResult, ChainModel, Estimator};
use smithwalk::microsurface::wang::Shadowing;

use crate::common;

const PHOTONS: u64 = 300_000;

const CASES: [(&str, &str); 3] = [
    ("conductor", "[material]\nkind = \"conductor\"\n[surface]\nalpha = 0.5\n[incident]\ntheta_deg = 30\n"),
    (
        "lambertian",
        "[material]\nkind = \"diffuse\"\nalbedo = 0.8\n[surface]\nalpha = 1.0\n[incident]\ntheta_deg = 60\n",
    ),
    (
        "dielectric",
        "[material]\nkind = \"dielectric\"\neta = 1.5\n[surface]\nalpha = 0.5\n[incident]\ntheta_deg = 30\n",
    ),
];

const MODELS: [ChainModel; 3] =
    [ChainModel::Wang(Shadowing::Correlated), ChainModel::Wang(Shadowing::Uncorrelated), ChainModel::PositionFree];

fn toml(body: &str, seed: u64) -> String {
    format!("paths = {PHOTONS}\nseed = {seed}\n{body}[detector]\ncos_theta_bins = 16\nphi_bins = 32\nmax_order = 4\n")
}

/// Per-photon moments, photon counts and the albedo `(mean, stderr)` of one lobe, channel `c`.
fn lobe<const C: usize>(
    d: &Detector<C>,
    slot: usize,
    h: Hemisphere,
    c: usize,
) -> (Vec<WeightedBin>, Vec<u64>, (f64, f64)) {
    let (n, bins) = (d.tallies.photons, d.grid.bins());
    let Some(order) = d.tallies.orders.get(slot) else {
        return (vec![WeightedBin { mean: 0.0, second_moment: 0.0 }; bins], vec![0; bins], (0.0, 0.0));
    };
    let tallies = &order.bins[h as usize * bins..(h as usize + 1) * bins];
    let moments = tallies
        .iter()
        .map(|t| WeightedBin { mean: t.sum[c].to_f64() / n as f64, second_moment: t.sum_sq[c].to_f64() / n as f64 })
        .collect();
    (moments, tallies.iter().map(|t| t.count).collect(), order.albedo[h as usize].mean_and_stderr(n, c))
}

#[test]
fn each_channel_of_the_joint_chain_is_its_model_alone() {
    let mut tests = Vec::new();
    for (i, (name, body)) in CASES.iter().enumerate() {
        let joint = common::simulate_with(&toml(body, 10 + i as u64), Estimator::JointChains(MODELS));
        let CaseResult::Rgb(joint) = &joint.results[0] else { panic!("joint chains fill an RGB detector") };
        let transmits = *name == "dielectric";
        for (c, model) in MODELS.iter().enumerate() {
            if transmits && *model == ChainModel::PositionFree {
                continue;
            }
            let alone = common::simulate_with(&toml(body, 20 + 3 * i as u64 + c as u64), model.estimator());
            let alone = common::mono(&alone, 0);
            let hemispheres: &[Hemisphere] = if transmits { &[Hemisphere::R, Hemisphere::T] } else { &[Hemisphere::R] };
            for &h in hemispheres {
                for slot in 0..=4 {
                    let (a, counts, albedo_joint) = lobe(joint, slot, h, c);
                    let (b, _, albedo_alone) = lobe(alone, slot, h, 0);
                    let test = two_sample(&a, PHOTONS, &b, PHOTONS, &counts, 10);
                    tests.push((format!("{name} {model:?} slot {slot} {h:?}"), test.p_value, test.dof));
                    if slot == 0 {
                        let ratio = albedo_joint.1 / albedo_alone.1;
                        println!("{name} {model:?} {h:?}: all-orders albedo stderr joint / alone = {ratio:.3}");
                        assert!(ratio <= 1.1, "{name} {model:?} {h:?}: joint stderr {ratio:.3} x the model's alone");
                    }
                }
            }
        }
    }
    let level = sidak(0.01, tests.len());
    for (label, p, dof) in &tests {
        println!("{label}: p {p:.3e} ({dof} cells)");
        assert!(*p > level, "{label}: p = {p:.3e} below the Sidak level {level:.2e}");
    }
    assert!(tests.iter().filter(|t| t.2 >= 8).count() >= tests.len() / 2, "too few lobes with 8 cells or more");
}
