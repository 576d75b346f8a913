//! Energy-compensation models (`analysis::compensation`, docs/compensation.md) against exact
//! oracles. All but the last two tests are deterministic quadrature (no random numbers):
//! - the directional albedo E(mu) against independent values: docs/theory.md §9.4's table (six
//!   digits), the closed form 1 - ln 2 (GGX alpha 1, normal incidence, §5), and the sum over the
//!   detector's bins of the `single` model (a different integrator over outgoing directions);
//! - the tabulated E(mu) and E_avg against direct quadrature at points that are not nodes;
//! - F_avg of Schlick's Fresnel is the closed form F0 + (1 - F0)/21;
//! - with F = 1 the Kulla-Conty lobe integrates to 1 over the outgoing directions for every
//!   incidence, and is reciprocal;
//! - Turquin's and Fdez-Agüera's lobes integrate to 1 over the light directions (their papers'
//!   integral, the view fixed), and are not reciprocal;
//! - each model minus its multiple-scattering part is exactly single scattering;
//! - deliberately wrong formulas (E_avg in place of E(mu_i); the light's E in Turquin's scale)
//!   miss 1 by far more than the tolerance, and `smithwalk compare` rejects the first on a real
//!   walk while it accepts the right formula there (seeded, see the test).

use crate::common;

use std::f64::consts::{LN_2, PI, TAU};

use smithwalk::analysis::compare::{CompareOptions, compare_with};
use smithwalk::analysis::compensation::*;
use smithwalk::analysis::models::single_scattering_bins;
use smithwalk::analysis::quadrature::{gauss_legendre, integrate, integrate_2d};
use smithwalk::engine::detector::{Grid, Hemisphere};
use smithwalk::microsurface::DVec3;
use smithwalk::microsurface::ndf::{Beckmann, Ggx};
use smithwalk::setup::cases::{Case, expand};
use smithwalk::setup::config::*;

/// The tolerance of every direct E(mu) evaluation here.
const TOL: f64 = 1e-10;
const GRID: Grid = Grid { cos_bins: 4, phi_bins: 8 };

pub(crate) fn conductor(fresnel: FresnelKind, f0: Option<f64>) -> MaterialConfig {
    MaterialConfig::Conductor { fresnel, f0: f0.map(Channels::Mono), eta: None, k: None, name: None }
}

fn gold() -> MaterialConfig {
    MaterialConfig::Conductor {
        fresnel: FresnelKind::Exact,
        f0: None,
        eta: Some(Channels::Rgb([0.143, 0.424, 1.367])),
        k: Some(Channels::Rgb([3.983, 2.469, 1.864])),
        name: None,
    }
}

/// A case of `material` on an isotropic `ndf` of roughness `alpha`, lit from `theta` degrees.
pub(crate) fn case(ndf: NdfKind, alpha: f64, theta: f64, material: MaterialConfig) -> Case {
    let mut config = Config::parse(
        "paths = 2\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n",
    )
    .unwrap();
    config.surface.ndf = OneOrMany::One(ndf);
    config.surface.alpha = OneOrMany::One(Alpha::Isotropic(alpha));
    config.material = OneOrMany::One(material);
    config.incident.theta_deg = Some(OneOrMany::One(theta));
    expand(&config).unwrap().remove(0)
}

fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

fn e_direct(ndf: NdfKind, alpha: f64, mu: f64, f: Fresnel) -> f64 {
    match ndf {
        NdfKind::Ggx => directional_albedo(&Ggx::with_alpha(alpha), mu, f, TOL),
        NdfKind::Beckmann => directional_albedo(&Beckmann::with_alpha(alpha), mu, f, TOL),
        NdfKind::StudentT => panic!("the compensation models cover GGX and Beckmann only"),
    }
}

fn e_table(ndf: NdfKind, alpha: f64, f: Fresnel) -> Albedo {
    match ndf {
        NdfKind::Ggx => Albedo::exact(&Ggx::with_alpha(alpha), f),
        NdfKind::Beckmann => Albedo::exact(&Beckmann::with_alpha(alpha), f),
        NdfKind::StudentT => panic!("the compensation models cover GGX and Beckmann only"),
    }
}

/// `∫ g(w) cos theta dw` over the upper hemisphere (adaptive, split at `mu_peak`).
fn hemisphere_integral(g: impl Fn(DVec3) -> f64, mu_peak: f64) -> f64 {
    let f = |u: f64, phi: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        g(DVec3::new(s * phi.cos(), s * phi.sin(), u)) * u
    };
    integrate_2d(f, (0.0, mu_peak), (0.0, TAU), 1e-9).0 + integrate_2d(f, (mu_peak, 1.0), (0.0, TAU), 1e-9).0
}

#[test]
fn directional_albedo_matches_independent_values() {
    // docs/theory.md §9.4: GGX, F = 1, six digits (rounding 5e-7).
    let table = [
        (0.10, [0.988304, 0.986087, 0.969205, 0.895519]),
        (0.25, [0.915812, 0.904147, 0.857263, 0.855554]),
        (0.50, [0.687849, 0.683052, 0.698251, 0.805323]),
        (0.75, [0.463917, 0.481650, 0.564623, 0.736844]),
        (1.00, [0.306853, 0.335194, 0.450694, 0.668186]),
    ];
    for (alpha, row) in table {
        for (theta, expected) in [0.0f64, 30.0, 60.0, 80.0].into_iter().zip(row) {
            let e = e_direct(NdfKind::Ggx, alpha, theta.to_radians().cos(), Fresnel::One);
            assert!((e - expected).abs() < 1e-6, "alpha {alpha} theta {theta}: {e} vs {expected}");
        }
    }
    // §5: GGX alpha 1 at normal incidence, E = 1 - ln 2 in closed form.
    let e = e_direct(NdfKind::Ggx, 1.0, 1.0, Fresnel::One);
    assert!((e - (1.0 - LN_2)).abs() < 1e-12, "{e}");
    // The `single` model's bins (adaptive cubature over outgoing directions, 1e-10 per bin,
    // 32 bins) summed: Beckmann and GGX, F = 1 and Schlick.
    for (ndf, alpha) in [(NdfKind::Beckmann, 0.3), (NdfKind::Beckmann, 2.0), (NdfKind::Ggx, 0.2)] {
        for (material, f) in [
            (conductor(FresnelKind::None, None), Fresnel::One),
            (conductor(FresnelKind::Schlick, Some(0.04)), Fresnel::Schlick(0.04)),
        ] {
            for theta in [0.0f64, 50.0, 85.0] {
                let c = case(ndf, alpha, theta, material.clone());
                let bins: f64 = single_scattering_bins(&c, &GRID, Hemisphere::R, 0, 1e-10).unwrap().iter().sum();
                let e = e_direct(ndf, alpha, theta.to_radians().cos(), f);
                assert!((e - bins).abs() < 1e-8, "{ndf:?} alpha {alpha} theta {theta} {f:?}: E {e} vs bins {bins}");
            }
        }
    }
    // Grazing and the extremes stay in [0, 1] and tend to 1 with F = 1 (§5: G2/G1 -> 1).
    for ndf in [NdfKind::Ggx, NdfKind::Beckmann] {
        for alpha in [0.01, 3.0] {
            let e = e_direct(ndf, alpha, MU_MIN, Fresnel::One);
            assert!(e > 0.99 && e <= 1.0, "{ndf:?} alpha {alpha}: {e}");
        }
    }
}

/// The interpolation bound the docs state for [`Albedo`]: 1e-6 against direct quadrature.
const TABLE_BOUND: f64 = 1e-6;

#[test]
fn the_albedo_table_is_within_its_bound_of_direct_quadrature() {
    // Points that are no nodes: log-spaced from MU_MIN to 1, and each panel's middle region.
    let points: Vec<f64> = (0..=16).map(|i| MU_MIN * (1.0 / MU_MIN).powf(f64::from(i) / 16.0)).collect();
    let mut worst = (0.0f64, NdfKind::Ggx, 0.0, 0.0);
    for (ndf, alpha) in [
        (NdfKind::Ggx, 0.01),
        (NdfKind::Ggx, 0.3),
        (NdfKind::Ggx, 3.0),
        (NdfKind::Beckmann, 0.05),
        (NdfKind::Beckmann, 3.0),
    ] {
        let table = e_table(ndf, alpha, Fresnel::One);
        for &mu in points.iter().chain(&[0.0, 0.5 * MU_MIN, 0.3137, 0.9411]) {
            let (t, d) = (table.at(mu), e_direct(ndf, alpha, mu, Fresnel::One));
            if (t - d).abs() > worst.0 {
                worst = ((t - d).abs(), ndf, alpha, mu);
            }
            assert!((t - d).abs() < TABLE_BOUND, "{ndf:?} alpha {alpha} mu {mu}: table {t} vs direct {d}");
        }
    }
    eprintln!("largest |table - direct| of E(mu), with its NDF, alpha and mu: {worst:?}");
    // E_avg = 2 ∫ E mu dmu against adaptive Gauss–Kronrod over mu of direct quadrature (which
    // shares no node with the table), with F = 1 and with gold's red channel.
    for (ndf, alpha, f) in
        [(NdfKind::Ggx, 0.05, Fresnel::One), (NdfKind::Ggx, 1.0, Fresnel::Conductor { eta: 0.143, k: 3.983 })]
    {
        let table = e_table(ndf, alpha, f);
        let direct = 2.0 * integrate(|mu| mu * e_direct(ndf, alpha, mu, f), 0.0, 1.0, 1e-8).0;
        assert!((table.average() - direct).abs() < 1e-7, "{ndf:?} {alpha}: E_avg {} vs {direct}", table.average());
    }
}

#[test]
fn fresnel_averages_match_closed_forms_and_quadrature() {
    for f0 in [0.0, 0.04, 0.5, 0.95] {
        let exact = fresnel_average(Fresnel::Schlick(f0));
        assert!((exact - (f0 + (1.0 - f0) / 21.0)).abs() < 1e-12, "{f0}: {exact}");
        assert_eq!(fdez_aguera_fresnel_average(f0), f0 + (1.0 - f0) / 21.0);
    }
    assert!((fresnel_average(Fresnel::One) - 1.0).abs() < 1e-12);
    // Gold's red and blue channels: 2 ∫ F mu dmu by a 200-node Gauss–Legendre sum in numpy
    // (an independent quadrature of the same conductor formula): 0.9645871607, 0.4323234458.
    // Fdez-Agüera's closed form (made for Schlick) misses them: 0.9682738, 0.4262958.
    for (eta, k, expected, closed) in
        [(0.143, 3.983, 0.9645871607, 0.9682738211), (1.367, 1.864, 0.4323234458, 0.4262958122)]
    {
        let gold = Fresnel::Conductor { eta, k };
        assert!((fresnel_average(gold) - expected).abs() < 1e-9, "{}", fresnel_average(gold));
        assert!((fdez_aguera_fresnel_average(gold.f0()) - closed).abs() < 1e-9);
    }
}

/// The all-orders bins of a model for a mono case, each to `tol` (or to where the
/// evaluation bound stops it: the sums below are checked, not the bins' estimates).
fn bins(model: Compensation, c: &Case, tol: f64, cache: &mut AlbedoCache) -> Vec<f64> {
    let [lobe] = compensated_bins::<1>(model, c, &GRID, &|_| tol, cache).unwrap();
    assert!(lobe.energy.iter().all(|b| b.is_finite() && *b >= 0.0));
    lobe.energy
}

#[test]
fn kulla_conty_conserves_energy_at_every_incidence_and_is_reciprocal() {
    // F = 1: the sum over the 32 bins is E_ss(mu_i) + (1 - E(mu_i)) = 1, up to the bins'
    // quadrature (1e-9 each) and the table's bound.
    let mut cache = AlbedoCache::default();
    for (ndf, alpha) in [(NdfKind::Ggx, 0.05), (NdfKind::Ggx, 0.3), (NdfKind::Ggx, 1.0), (NdfKind::Beckmann, 0.5)] {
        for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
            let c = case(ndf, alpha, theta, conductor(FresnelKind::None, None));
            let sum: f64 = bins(Compensation::KullaConty, &c, 1e-9, &mut cache).iter().sum();
            assert!((sum - 1.0).abs() < 2e-6, "{ndf:?} alpha {alpha} theta {theta}: {sum}");
        }
    }
    let e = e_table(NdfKind::Ggx, 0.7, Fresnel::One);
    for f in [Fresnel::One, Fresnel::Schlick(0.04), Fresnel::Conductor { eta: 0.143, k: 3.983 }] {
        let lobe = Compensated::new(Compensation::KullaConty, Ggx::with_alpha(0.7), f, &e, &e);
        for (a, b) in [((10.0, 0.0), (70.0, 140.0)), ((45.0, 30.0), (85.0, 200.0)), ((0.0, 0.0), (60.0, 90.0))] {
            let (wi, wo) = (dir(a.0, a.1), dir(b.0, b.1));
            let (x, y) = (lobe.bsdf(wi, wo), lobe.bsdf(wo, wi));
            assert!((x - y).abs() <= 1e-12 * x, "{f:?}: {x} vs {y}");
        }
    }
}

#[test]
fn turquin_and_fdez_aguera_conserve_energy_over_the_light_directions_only() {
    for (alpha, view) in [(0.3, 70.0), (1.0, 45.0)] {
        let ndf = Ggx::with_alpha(alpha);
        let e = Albedo::exact(&ndf, Fresnel::One);
        let wo = dir(view, 0.0);
        for model in [Compensation::Turquin, Compensation::FdezAguera] {
            let lobe = Compensated::new(model, ndf, Fresnel::One, &e, &e);
            let over_lights = hemisphere_integral(|wi| lobe.bsdf(wi, wo), wo.z);
            assert!((over_lights - 1.0).abs() < 2e-6, "{model:?} alpha {alpha} view {view}: {over_lights}");
        }
    }
    // Not reciprocal: integrated over the outgoing (view) directions, as the walk measures for
    // a fixed light, they miss 1 at alpha 1 and 60 deg.
    for model in [Compensation::Turquin, Compensation::FdezAguera] {
        let c = case(NdfKind::Ggx, 1.0, 60.0, conductor(FresnelKind::None, None));
        let sum: f64 = bins(model, &c, 1e-9, &mut AlbedoCache::default()).iter().sum();
        assert!((sum - 1.0).abs() > 1e-2, "{model:?}: {sum}");
        let e = Albedo::exact(&Ggx::with_alpha(1.0), Fresnel::One);
        let lobe = Compensated::new(model, Ggx::with_alpha(1.0), Fresnel::One, &e, &e);
        let (wi, wo) = (dir(20.0, 0.0), dir(75.0, 180.0));
        assert!((lobe.bsdf(wi, wo) / lobe.bsdf(wo, wi) - 1.0).abs() > 1e-2);
    }
}

#[test]
fn the_order_one_part_of_every_model_is_single_scattering() {
    for (ndf, alpha, theta) in [(NdfKind::Ggx, 0.5, 40.0), (NdfKind::Beckmann, 0.8, 70.0)] {
        for material in [conductor(FresnelKind::None, None), conductor(FresnelKind::Schlick, Some(0.3))] {
            let c = case(ndf, alpha, theta, material.clone());
            let single = single_scattering_bins(&c, &GRID, Hemisphere::R, 0, 1e-10).unwrap();
            let f = Fresnel::channels::<1>(&c.material).unwrap()[0];
            let (e, ef) = (e_table(ndf, alpha, Fresnel::One), e_table(ndf, alpha, f));
            let mu_i = theta.to_radians().cos();
            // Kulla-Conty and Fdez-Agüera add lobes that depend on theta_o only: integrate them
            // over each bin's cosine range by Gauss–Legendre, independently of the model's bins.
            let kc = |mu: f64| {
                kulla_conty_lobe(e.at(mu_i), e.at(mu), e.average())
                    * kulla_conty_fresnel(fresnel_average(f), e.average())
            };
            let fa = |mu: f64| fdez_aguera_lobe(e.at(mu), ef.at(mu), fdez_aguera_fresnel_average(f.f0()));
            for (model, ms) in [(Compensation::KullaConty, &kc as &dyn Fn(f64) -> f64), (Compensation::FdezAguera, &fa)]
            {
                let model_bins = bins(model, &c, 1e-10, &mut AlbedoCache::default());
                for (i, b) in model_bins.iter().enumerate() {
                    let (lo, hi) = GRID.cos_edges(i / GRID.phi_bins);
                    let dphi = TAU / GRID.phi_bins as f64;
                    let added: f64 = gauss_legendre(20, lo, hi).iter().map(|&(mu, w)| w * ms(mu) * mu * dphi).sum();
                    assert!(
                        (b - added - single[i]).abs() < 1e-9,
                        "{model:?} {ndf:?} bin {i}: {b} - {added} vs {}",
                        single[i]
                    );
                }
            }
        }
        // Turquin scales single scattering by 1 + F0 (...): with F0 = 0 nothing is added.
        let c = case(ndf, alpha, theta, conductor(FresnelKind::Schlick, Some(0.0)));
        let single = single_scattering_bins(&c, &GRID, Hemisphere::R, 0, 1e-10).unwrap();
        let model_bins = bins(Compensation::Turquin, &c, 1e-10, &mut AlbedoCache::default());
        for (b, s) in model_bins.iter().zip(&single) {
            assert!((b - s).abs() < 1e-9, "{b} vs {s}");
        }
    }
}

#[test]
fn wrong_formulas_miss_the_exact_integrals() {
    // Kulla-Conty with E_avg in place of E(mu_i): the same bins and the same 2e-6 check.
    let (alpha, theta) = (1.0, 80.0);
    let c = case(NdfKind::Ggx, alpha, theta, conductor(FresnelKind::None, None));
    let single: f64 = single_scattering_bins(&c, &GRID, Hemisphere::R, 0, 1e-10).unwrap().iter().sum();
    let e = e_table(NdfKind::Ggx, alpha, Fresnel::One);
    let ms = |e_i: f64| -> f64 {
        gauss_legendre(64, 0.0, 1.0)
            .iter()
            .map(|&(mu, w)| w * kulla_conty_lobe(e_i, e.at(mu), e.average()) * mu * TAU)
            .sum()
    };
    let right = single + ms(e.at(theta.to_radians().cos()));
    let wrong = single + ms(e.average());
    assert!((right - 1.0).abs() < 2e-6, "{right}");
    assert!((wrong - 1.0).abs() > 1e-2, "the mutant passes: {wrong}");
    // Turquin's scale with the light's albedo in place of the view's: over the light directions
    // it no longer integrates to 1.
    let ndf = Ggx::with_alpha(alpha);
    let wo = dir(30.0, 0.0);
    let mutant = |wi: DVec3| {
        let f1 = smithwalk::microsurface::single::reflection(&ndf, wi, wo, |_| 1.0) / wo.z;
        f1 * turquin_scale(1.0, e.at(wi.z))
    };
    let over_lights = hemisphere_integral(mutant, wo.z);
    assert!((over_lights - 1.0).abs() > 1e-2, "the mutant passes: {over_lights}");
}

#[test]
fn low_and_high_roughness_grazing_light_and_colour_give_finite_bounded_lobes() {
    let mut cache = AlbedoCache::default();
    for (alpha, theta) in [(0.02, 0.0), (0.02, 89.0), (3.0, 0.0), (3.0, 89.0)] {
        for model in [Compensation::KullaConty, Compensation::Turquin, Compensation::FdezAguera] {
            let c = case(NdfKind::Ggx, alpha, theta, conductor(FresnelKind::Schlick, Some(0.04)));
            let [lobe] = compensated_bins::<1>(model, &c, &GRID, &|_| 1e-7, &mut cache).unwrap();
            let sum: f64 = lobe.energy.iter().sum();
            assert!(lobe.energy.iter().all(|b| b.is_finite() && *b >= 0.0));
            assert!(sum > 0.0 && sum < 1.5, "{model:?} alpha {alpha} theta {theta}: {sum}");
        }
    }
    // An RGB conductor gives three channels, each its own Fresnel.
    let c = case(NdfKind::Ggx, 0.5, 30.0, gold());
    let [r, _, b] = compensated_bins::<3>(Compensation::KullaConty, &c, &GRID, &|_| 1e-8, &mut cache).unwrap();
    let (r, b): (f64, f64) = (r.energy.iter().sum(), b.energy.iter().sum());
    assert!(r > b + 0.2 && r < 1.0, "gold is red: {r} {b}");
}

/// A small real walk: GGX alpha 0.35, F = 1, normal incidence, 4 x 8 bins, max_order 2, seed 18,
/// 2 x 10^5 photons. At normal incidence Kulla-Conty is closest to the walk (the study,
/// docs/compensation.md, accepts it there at 10^6 photons in 16 x 32 bins).
const WALK: &str = "paths = 200000\nseed = 18\n[surface]\nalpha = 0.35\n[material]\nkind = \"conductor\"\n\
                    [incident]\ntheta_deg = 0\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 2\n";

/// The all-orders lobe of a Kulla-Conty variant as an external model file.
fn external_file(path: &std::path::Path, energy: &[f64]) {
    let mut rows = String::from("case,order,hemisphere,cos_lo,cos_hi,phi_lo_deg,phi_hi_deg,energy\n");
    for (i, e) in energy.iter().enumerate() {
        let ((lo, hi), (plo, phi)) = (GRID.cos_edges(i / GRID.phi_bins), GRID.phi_edges_deg(i % GRID.phi_bins));
        rows += &format!("0,0,R,{lo},{hi},{plo},{phi},{e}\n");
    }
    std::fs::write(path, rows).unwrap();
}

/// `smithwalk compare --external` on a real walk: Kulla-Conty with E_avg in place of E(mu_i)
/// is rejected at family level 0.01 (p far below it), while the published formula, in the
/// same file format, is not, and neither is treated as an exact oracle.
#[test]
fn compare_rejects_a_wrong_compensation_formula_on_a_real_walk() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(dir.path(), "walk", WALK);
    let c = case(NdfKind::Ggx, 0.35, 0.0, conductor(FresnelKind::None, None));
    let right = bins(Compensation::KullaConty, &c, 1e-9, &mut AlbedoCache::default());
    // The mutant adds (1 - E(mu_o)) (E(mu_i) - E_avg) / (pi (1 - E_avg)) to every direction.
    let e = e_table(NdfKind::Ggx, 0.35, Fresnel::One);
    let shift = (e.at(1.0) - e.average()) / (PI * (1.0 - e.average()));
    let wrong: Vec<f64> = right
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (lo, hi) = GRID.cos_edges(i / GRID.phi_bins);
            let dphi = TAU / GRID.phi_bins as f64;
            b + gauss_legendre(20, lo, hi).iter().map(|&(mu, w)| w * (1.0 - e.at(mu)) * shift * mu * dphi).sum::<f64>()
        })
        .collect();
    let mut p_values = Vec::new();
    for (name, energy) in [("right", &right), ("wrong", &wrong)] {
        let file = dir.path().join(format!("{name}.csv"));
        external_file(&file, energy);
        let options = CompareOptions { external: Some(file), ..CompareOptions::new(vec![], None, Some(2)) };
        let outcome = compare_with(&run, &options).unwrap();
        assert!(!outcome.exact_oracle_rejected(), "an external model is no exact oracle");
        assert!(outcome.report.contains("external (approximation)"), "{}", outcome.report);
        let table = std::fs::read_to_string(run.join("compare.csv")).unwrap();
        let mut reader = csv::Reader::from_reader(table.as_bytes());
        let header = reader.headers().unwrap().clone();
        let col = |n: &str| header.iter().position(|h| h == n).unwrap();
        let row = reader.records().next().unwrap().unwrap();
        p_values.push((name, row[col("p_value")].parse::<f64>().unwrap(), outcome.verdicts[0].rejected));
    }
    eprintln!("p-values: {p_values:?}");
    assert_eq!(p_values[0].2, 0, "the published formula is rejected: {p_values:?}");
    assert_eq!(p_values[1].2, 1, "the mutant is not rejected: {p_values:?}");
    assert!(p_values[1].1 < 1e-6, "{p_values:?}");
}

/// A user's model file (`--external`): read into the run's bins, and refused with the file,
/// line and column when it is not one.
#[test]
fn external_models_are_read_into_the_runs_bins_and_bad_files_are_refused() {
    use smithwalk::analysis::external;
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(
        dir.path(),
        "tiny",
        "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [0, 60]\n\
         [detector]\ncos_theta_bins = 2\nphi_bins = 2\nmax_order = 2\n",
    );
    let run = smithwalk::io::rundir::RunDir::open(&run).unwrap();
    let mut rows = String::from("case,order,hemisphere,cos_lo,cos_hi,phi_lo_deg,phi_hi_deg,energy\n");
    for (ic, ip) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let (lo, hi) = (ic as f64 / 2.0, (ic + 1) as f64 / 2.0);
        rows += &format!("1,0,R,{lo},{hi},{},{},{}\n", 180 * ip, 180 * (ip + 1), 0.1 * (2 * ic + ip) as f64);
    }
    let path = dir.path().join("model.csv");
    std::fs::write(&path, &rows).unwrap();
    let model = external::read(&path, &run).unwrap();
    assert_eq!(model.lobes.len(), 1);
    assert_eq!((model.lobes[0].case, model.lobes[0].order), (1, 0));
    assert_eq!(model.lobes[0].energy, vec![0.0, 0.1, 0.2, 0.30000000000000004]);
    assert_eq!(model.photons(), 0);
    let refused = |text: &str, expected: &[&str]| {
        std::fs::write(&path, text).unwrap();
        let message = format!("{:#}", external::read(&path, &run).unwrap_err());
        for e in expected {
            assert!(message.contains(e), "{message:?} lacks {e:?}");
        }
    };
    refused(
        &rows.replace("1,0,R,0.5,1,180,360,0.30000000000000004", "1,0,R,0.5,1,180,360,NaN"),
        &["line 5", "`energy`", "finite"],
    );
    refused(&rows.replace("1,0,R,0.5,1,180,360", "1,0,R,0.5,0.9,180,360"), &["line 5", "not a bin of the run"]);
    refused(&rows.replace("1,0,R,0,0.5,0,180", "7,0,R,0,0.5,0,180"), &["line 2", "`case`", "case 7 is not in the run"]);
    refused(&rows.replace("1,0,R,0,0.5,0,180", "1,0,T,0,0.5,0,180"), &["line 2", "`hemisphere`", "does not transmit"]);
    // max_order = 2: slot 2 is "2+", never compared with a per-order model.
    refused(&rows.replace("1,0,R,0,0.5,0,180", "1,2,R,0,0.5,0,180"), &["line 2", "`order`", "\"2+\""]);
    refused(&rows.lines().take(4).collect::<Vec<_>>().join("\n"), &["1 of its 4 bins are missing"]);
    refused(&rows.replace(",energy", ",power"), &["no column `energy`"]);
}

/// Issue 36 item 15: another smithwalk run as `--external` (its `lobes.csv`, `run.json` beside
/// it). Two runs of the same config with different seeds fold at the same `max_order` (2), so
/// their "2+" slots are compared too: the comparison runs (it refused "order 2 is not allowed"
/// before) and, the two being the same physics, rejects no lobe at family level 0.01. A run that
/// folds at 3 is refused in the slot where the two differ; a file that says it folds with a
/// `folded` column is read like another run's.
#[test]
fn another_run_that_folds_at_the_same_order_is_compared_slot_for_slot() {
    use smithwalk::analysis::external;
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(dir.path(), "a", WALK);
    let (other, _) = common::run_config(dir.path(), "b", &WALK.replace("seed = 18", "seed = 19"));
    let options =
        CompareOptions { external: Some(other.join("lobes.csv")), ..CompareOptions::new(vec![], None, Some(2)) };
    let outcome = compare_with(&run, &options).unwrap();
    let table = std::fs::read_to_string(run.join("compare.csv")).unwrap();
    // Slots 0 (all orders), 1 and the folded 2 ("2+"), each tested once.
    let mut reader = csv::Reader::from_reader(table.as_bytes());
    let header = reader.headers().unwrap().clone();
    let col = |n: &str| header.iter().position(|h| h == n).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let tested: Vec<(&str, &str)> = rows.iter().map(|r| (&r[col("order")], &r[col("folded")])).collect();
    assert_eq!(tested, [("0", "false"), ("1", "false"), ("2", "true")], "{table}");
    // Two independent walks of one config: the p-values are uniform; at family level 0.01 over
    // 3 lobes no rejection is expected (a false rejection has probability 0.01; seeds fixed).
    assert_eq!(outcome.verdicts.iter().map(|v| v.rejected).sum::<usize>(), 0, "{}", outcome.report);
    // A run folded at 3: its slot 2 is order 2 alone, the run's is "2+".
    let (folds_at_3, _) = common::run_config(dir.path(), "c", &WALK.replace("max_order = 2", "max_order = 3"));
    let opened = smithwalk::io::rundir::RunDir::open(&run).unwrap();
    let e = format!("{:#}", external::read(&folds_at_3.join("lobes.csv"), &opened).unwrap_err());
    assert!(e.contains("order 2 is not allowed: the run's slot 2 is \"2+\"") && e.contains("`order`"), "{e}");
    // The other way round: a run folded at 2 against one folded at 3.
    let opened_3 = smithwalk::io::rundir::RunDir::open(&folds_at_3).unwrap();
    let e = format!("{:#}", external::read(&other.join("lobes.csv"), &opened_3).unwrap_err());
    assert!(e.contains("the model's slot 2 is \"2+\"") && e.contains("the run's slot 2 is order 2 alone"), "{e}");
    // The same rows copied elsewhere (no run.json beside them) are a per-order model: refused
    // in slot 2; with a `folded` column saying so, accepted.
    let text = std::fs::read_to_string(other.join("lobes.csv")).unwrap();
    let copy = dir.path().join("copy.csv");
    std::fs::write(&copy, &text).unwrap();
    assert!(format!("{:#}", external::read(&copy, &opened).unwrap_err()).contains("never compared"));
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let order = header.split(',').position(|h| h == "order").unwrap();
    let mut marked = format!("{header},folded\n");
    for line in lines {
        marked += &format!("{line},{}\n", line.split(',').nth(order) == Some("2"));
    }
    std::fs::write(&copy, marked).unwrap();
    let model = external::read(&copy, &opened).unwrap();
    assert!(model.lobes.iter().any(|l| l.order == 2));
}
