//! Energy-compensation models (`analysis::compensation`, docs/compensation.md) against exact
//! oracles, all deterministic (quadrature, no random numbers):
//! - the directional albedo E(mu) of the models agrees with the independent bin-by-bin
//!   quadrature of single scattering (`single_scattering_bins`, in the detector's bins) and its
//!   polynomial interpolant with direct quadrature;
//! - F_avg of Schlick's Fresnel is the closed form F0 + (1 - F0)/21;
//! - with F = 1 the Kulla-Conty lobe integrates to 1 over the outgoing directions for every
//!   incidence, GGX and Beckmann, alpha 0.3 to 2.5, theta 0 to 89 deg, and is reciprocal;
//! - Turquin's and Fdez-Agüera's lobes integrate to 1 over the light directions (their papers'
//!   integral, the view fixed), and are not reciprocal;
//! - each model minus its multiple-scattering part is exactly single scattering;
//! - deliberately wrong formulas (E_avg in place of E(mu_i); the light's E in Turquin's scale)
//!   miss 1 by far more than the tolerance and are rejected.
//!
//! Tolerances: quadrature to 1e-9 per integral; energy sums are held to 1e-6.

use smithwalk::analysis::compensation::*;
use smithwalk::analysis::models::single_scattering_bins;
use smithwalk::analysis::quadrature::{gauss_legendre, integrate_2d};
use smithwalk::engine::detector::{Grid, Hemisphere};
use smithwalk::microsurface::DVec3;
use smithwalk::microsurface::ndf::{Beckmann, Ggx};
use smithwalk::setup::cases::Case;
use smithwalk::setup::config::*;

const TOL: f64 = 1e-9;
const GRID: Grid = Grid { cos_bins: 4, phi_bins: 8 };

fn conductor(fresnel: FresnelKind, f0: Option<f64>) -> MaterialConfig {
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

fn case(ndf: NdfKind, alpha: f64, theta: f64, material: MaterialConfig) -> Case {
    Case {
        index: 0,
        ndf,
        alpha_x: alpha,
        alpha_y: alpha,
        height: HeightKind::Uniform,
        smith: SmithKind::Exact,
        normals: NormalsKind::Vndf,
        material,
        theta_i_deg: theta,
        phi_i_deg: 0.0,
        side: IncidentSide::Outside,
    }
}

fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// `∫ g(w) cos theta dw` over the upper hemisphere (adaptive, split at `mu_peak`).
fn hemisphere_integral(g: impl Fn(DVec3) -> f64, mu_peak: f64) -> f64 {
    let f = |u: f64, phi: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        g(DVec3::new(s * phi.cos(), s * phi.sin(), u)) * u
    };
    let tau = std::f64::consts::TAU;
    integrate_2d(f, (0.0, mu_peak), (0.0, tau), TOL).0 + integrate_2d(f, (mu_peak, 1.0), (0.0, tau), TOL).0
}

#[test]
#[ignore = "did not finish in 4 minutes on the loaded 2-core host (docs/compensation.md, Not done)"]
fn directional_albedo_matches_the_binned_single_scattering_and_its_interpolant() {
    for (ndf, alpha) in [(NdfKind::Ggx, 0.05), (NdfKind::Ggx, 1.0), (NdfKind::Beckmann, 0.3), (NdfKind::Beckmann, 2.0)]
    {
        for (material, f) in [
            (conductor(FresnelKind::None, None), Fresnel::One),
            (conductor(FresnelKind::Schlick, Some(0.04)), Fresnel::Schlick(0.04)),
        ] {
            for theta in [0.0f64, 50.0, 85.0] {
                let mu = theta.to_radians().cos();
                let bins: f64 =
                    single_scattering_bins(&case(ndf, alpha, theta, material.clone()), &GRID, Hemisphere::R, 1e-11)
                        .unwrap()
                        .iter()
                        .sum();
                let e = match ndf {
                    NdfKind::Ggx => directional_albedo(&Ggx::with_alpha(alpha), mu, f, TOL),
                    NdfKind::Beckmann => directional_albedo(&Beckmann::with_alpha(alpha), mu, f, TOL),
                };
                assert!((e - bins).abs() < 1e-7, "{ndf:?} alpha {alpha} theta {theta} {f:?}: E {e} vs bins {bins}");
            }
        }
        // The interpolant between quadrature nodes, at points that are no nodes.
        let table = match ndf {
            NdfKind::Ggx => Albedo::exact(&Ggx::with_alpha(alpha), Fresnel::One),
            NdfKind::Beckmann => Albedo::exact(&Beckmann::with_alpha(alpha), Fresnel::One),
        };
        for mu in [0.0007, 0.09, 0.5521, 0.999] {
            let direct = match ndf {
                NdfKind::Ggx => directional_albedo(&Ggx::with_alpha(alpha), mu, Fresnel::One, TOL),
                NdfKind::Beckmann => directional_albedo(&Beckmann::with_alpha(alpha), mu, Fresnel::One, TOL),
            };
            assert!(
                (table.at(mu) - direct).abs() < 1e-8,
                "{ndf:?} alpha {alpha} mu {mu}: {} vs {direct}",
                table.at(mu)
            );
        }
        // E_avg = 2 ∫ E mu dmu against an independent 100-node Gauss–Legendre sum of direct quadrature.
        if ndf == NdfKind::Ggx && alpha == 1.0 {
            let avg: f64 = gauss_legendre(100, 0.0, 1.0)
                .iter()
                .map(|&(mu, w)| 2.0 * w * mu * directional_albedo(&Ggx::with_alpha(alpha), mu, Fresnel::One, TOL))
                .sum();
            assert!((table.average() - avg).abs() < 1e-8, "E_avg {} vs {avg}", table.average());
        }
    }
    // GGX alpha 1 at normal incidence in closed form: D = 1/pi, Lambda(wi) = 0, and the mirror
    // direction of a normal at theta_m has 1 + Lambda = (1 + cos 2theta_m) / (2 cos 2theta_m), so
    // E = 2 ∫_0^{pi/4} (2 cos^2 - 1) tan theta_m dtheta_m = 2 [sin^2 + ln cos]_0^{pi/4} = 1 - ln 2.
    let e = directional_albedo(&Ggx::with_alpha(1.0), 1.0, Fresnel::One, TOL);
    assert!((e - (1.0 - std::f64::consts::LN_2)).abs() < 1e-9, "{e}");
}

#[test]
fn fresnel_averages() {
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

/// The all-orders bins of a model for a mono case, summed.
fn total(model: Compensation, c: &Case, cache: &mut AlbedoCache) -> f64 {
    let [bins] = compensated_bins::<1>(model, c, &GRID, TOL, cache).unwrap();
    assert!(bins.iter().all(|b| b.is_finite() && *b >= 0.0));
    bins.iter().sum()
}

#[test]
fn kulla_conty_conserves_energy_at_every_incidence_and_is_reciprocal() {
    let mut cache = AlbedoCache::default();
    for (ndf, alpha) in [(NdfKind::Ggx, 0.3), (NdfKind::Ggx, 1.0), (NdfKind::Beckmann, 0.5), (NdfKind::Ggx, 2.5)] {
        {
            for theta in [0.0, 60.0, 89.0] {
                let c = case(ndf, alpha, theta, conductor(FresnelKind::None, None));
                let sum = total(Compensation::KullaConty, &c, &mut cache);
                assert!((sum - 1.0).abs() < 1e-6, "{ndf:?} alpha {alpha} theta {theta}: {sum}");
            }
        }
    }
    let e = Albedo::exact(&Ggx::with_alpha(0.7), Fresnel::One);
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
    for (ndf_alpha, view) in [(0.3, 70.0), (1.0, 45.0)] {
        let ndf = Ggx::with_alpha(ndf_alpha);
        let e = Albedo::exact(&ndf, Fresnel::One);
        let wo = dir(view, 0.0);
        for model in [Compensation::Turquin, Compensation::FdezAguera] {
            let lobe = Compensated::new(model, ndf, Fresnel::One, &e, &e);
            let over_lights = hemisphere_integral(|wi| lobe.bsdf(wi, wo), wo.z);
            assert!((over_lights - 1.0).abs() < 1e-6, "{model:?} alpha {ndf_alpha} view {view}: {over_lights}");
        }
    }
    // Not reciprocal: integrated over the outgoing (view) directions, as the walk measures for
    // a fixed light, they miss 1 at alpha 1 and 60 deg.
    for model in [Compensation::Turquin, Compensation::FdezAguera] {
        let sum = total(
            model,
            &case(NdfKind::Ggx, 1.0, 60.0, conductor(FresnelKind::None, None)),
            &mut AlbedoCache::default(),
        );
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
            let single = single_scattering_bins(&c, &GRID, Hemisphere::R, 1e-10).unwrap();
            let f = Fresnel::channels::<1>(&material).unwrap()[0];
            let e = match ndf {
                NdfKind::Ggx => Albedo::exact(&Ggx::with_alpha(alpha), Fresnel::One),
                NdfKind::Beckmann => Albedo::exact(&Beckmann::with_alpha(alpha), Fresnel::One),
            };
            let ef = match ndf {
                NdfKind::Ggx => Albedo::exact(&Ggx::with_alpha(alpha), f),
                NdfKind::Beckmann => Albedo::exact(&Beckmann::with_alpha(alpha), f),
            };
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
                let mut cache = AlbedoCache::default();
                let [bins] = compensated_bins::<1>(model, &c, &GRID, 1e-10, &mut cache).unwrap();
                for (i, b) in bins.iter().enumerate() {
                    let (lo, hi) = GRID.cos_edges(i / GRID.phi_bins);
                    let dphi = std::f64::consts::TAU / GRID.phi_bins as f64;
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
        let single = single_scattering_bins(&c, &GRID, Hemisphere::R, 1e-10).unwrap();
        let [bins] =
            compensated_bins::<1>(Compensation::Turquin, &c, &GRID, 1e-10, &mut AlbedoCache::default()).unwrap();
        for (b, s) in bins.iter().zip(&single) {
            assert!((b - s).abs() < 1e-9, "{b} vs {s}");
        }
    }
}

#[test]
fn wrong_formulas_are_rejected() {
    // Kulla-Conty with E_avg in place of E(mu_i): the same bins and the same 1e-6 check.
    let (alpha, theta) = (1.0, 80.0);
    let c = case(NdfKind::Ggx, alpha, theta, conductor(FresnelKind::None, None));
    let single: f64 = single_scattering_bins(&c, &GRID, Hemisphere::R, TOL).unwrap().iter().sum();
    let e = Albedo::exact(&Ggx::with_alpha(alpha), Fresnel::One);
    let ms = |e_i: f64| -> f64 {
        gauss_legendre(64, 0.0, 1.0)
            .iter()
            .map(|&(mu, w)| w * kulla_conty_lobe(e_i, e.at(mu), e.average()) * mu * std::f64::consts::TAU)
            .sum()
    };
    let right = single + ms(e.at(theta.to_radians().cos()));
    let wrong = single + ms(e.average());
    assert!((right - 1.0).abs() < 1e-6, "{right}");
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
#[ignore = "minutes: the exact E(mu) table at alpha 0.02 is slow near grazing (docs/compensation.md, Not done)"]
fn low_roughness_gives_finite_bounded_lobes() {
    let mut cache = AlbedoCache::default();
    for (alpha, theta) in [(0.02, 0.0), (0.02, 89.0)] {
        for model in [Compensation::KullaConty, Compensation::Turquin, Compensation::FdezAguera] {
            let c = case(NdfKind::Ggx, alpha, theta, conductor(FresnelKind::Schlick, Some(0.04)));
            let sum = total(model, &c, &mut cache);
            assert!(sum.is_finite() && sum > 0.0 && sum < 1.5, "{model:?} alpha {alpha} theta {theta}: {sum}");
        }
    }
}

#[test]
#[ignore = "did not finish in 4 minutes on the loaded 2-core host (docs/compensation.md, Not done)"]
fn high_roughness_grazing_light_and_colour_give_finite_bounded_lobes() {
    let mut cache = AlbedoCache::default();
    for (alpha, theta) in [(3.0, 0.0), (3.0, 89.0)] {
        for model in [Compensation::KullaConty, Compensation::Turquin, Compensation::FdezAguera] {
            let c = case(NdfKind::Ggx, alpha, theta, conductor(FresnelKind::Schlick, Some(0.04)));
            let sum = total(model, &c, &mut cache);
            assert!(sum.is_finite() && sum > 0.0 && sum < 1.5, "{model:?} alpha {alpha} theta {theta}: {sum}");
        }
    }
    // An RGB conductor gives three channels, each its own Fresnel.
    let c = case(NdfKind::Ggx, 0.5, 30.0, gold());
    let [r, _, b] =
        compensated_bins::<3>(Compensation::KullaConty, &c, &GRID, TOL, &mut AlbedoCache::default()).unwrap();
    let (r, b): (f64, f64) = (r.iter().sum(), b.iter().sum());
    assert!(r > b + 0.2 && r < 1.0, "gold is red: {r} {b}");
}

/// A user's model file (`--external`): read into the run's bins, and refused with the file,
/// line and column when it is not one.
#[test]
fn external_models_are_read_into_the_runs_bins_and_bad_files_are_refused() {
    use smithwalk::analysis::external;
    let config = Config::parse(
        "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [0, 60]\n\
         [detector]\ncos_theta_bins = 2\nphi_bins = 2\n",
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut rows = String::from("case,order,hemisphere,cos_lo,cos_hi,phi_lo_deg,phi_hi_deg,energy\n");
    for (ic, ip) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let (lo, hi) = (ic as f64 / 2.0, (ic + 1) as f64 / 2.0);
        rows += &format!("1,0,R,{lo},{hi},{},{},{}\n", 180 * ip, 180 * (ip + 1), 0.1 * (2 * ic + ip) as f64);
    }
    let path = dir.path().join("model.csv");
    std::fs::write(&path, &rows).unwrap();
    let model = external::read(&path, &config).unwrap();
    assert_eq!(model.lobes.len(), 1);
    assert_eq!((model.lobes[0].case, model.lobes[0].order), (1, 0));
    assert_eq!(model.lobes[0].energy, vec![0.0, 0.1, 0.2, 0.30000000000000004]);
    assert_eq!(model.photons(), 0);
    let refused = |text: &str, expected: &[&str]| {
        std::fs::write(&path, text).unwrap();
        let message = format!("{:#}", external::read(&path, &config).unwrap_err());
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
    refused(&rows.lines().take(4).collect::<Vec<_>>().join("\n"), &["1 of its 4 bins are missing"]);
    refused(&rows.replace(",energy", ",power"), &["no column `energy`"]);
}
