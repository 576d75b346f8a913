//! Order 1 of the walk against exact single scattering (docs/theory.md §5): this is the test that
//! proves the walk.
//!
//! * Histograms: for each case below, 10^6 photons on a 16 x 32 grid; the expected energy of
//!   every bin is the single-scattering lobe integrated over the bin by adaptive quadrature
//!   (`models::single_scattering_bins`). Per-bin variances come from the per-photon second
//!   moments (weighted histograms); cells with an expected count below 5 are pooled, and at
//!   least 16 cells must remain (a lobe wrongly expected to be zero would otherwise pool into
//!   one untested cell). Beside each chi-square, the order-1 albedo against the bins' sum by a z
//!   test. Each test runs at the Sidak level keeping the family at 0.01.
//! * Albedo: at 10^7 photons the order-1 albedo of the GGX conductor with F = 1 is compared
//!   with the quadrature values of docs/theory.md §9.4 (independent scripts; 1 - ln 2 in closed
//!   form at alpha 1, normal incidence), within 4 standard errors (SE about 1.5e-4).
//! * RGB runs (a Schlick conductor, gold, Lambertian facets, each channel its own parameters):
//!   every channel's order-1 histogram against the model of that channel, and the conductors'
//!   order-1 albedos against the integral over the visible normals; channel r's model is
//!   rejected on g and b.
//! * Student-T (§1.6): conductor, dielectric R and T, Lambertian and Hammon facets, gamma 1.6
//!   and 3, one anisotropic, by the same chi-square and z tests.
//! * The model itself: on nearly smooth surfaces its bins' sum against the order-1 albedo
//!   integrated over the visible normals instead of the outgoing directions, and it is offered
//!   only for the walk it describes (true Smith Lambda, visible normals, light from outside).

use crate::common;

use common::{albedo, channel_albedo, channel_bins, mono, rgb, simulate, two_sided_z, weighted_bins};
use numerics::quadrature::integrate_2d;
use smithwalk::analysis::models::{single_scattering_bins, single_scattering_lobe};
use smithwalk::analysis::stats::{ChiSquare, chi_square, sidak};
use smithwalk::engine::detector::{Grid, Hemisphere};
use smithwalk::microsurface::ndf::{AnyNdf, Beckmann, Ggx, Ndf, Roughness};
use smithwalk::microsurface::{DVec3, fresnel, single};
use smithwalk::setup::cases::{Case, expand};
use smithwalk::setup::config::{Config, MaterialConfig};
use std::f64::consts::TAU;

/// The one case of a one-case TOML config.
fn case_of(toml: &str) -> Case {
    expand(&Config::parse(toml).unwrap()).unwrap().remove(0)
}

struct HistogramCase {
    surface: &'static str,
    material: &'static str,
    theta: f64,
    phi: f64,
    hemispheres: &'static [Hemisphere],
}

const CASES: [HistogramCase; 6] = [
    HistogramCase {
        surface: "ndf = \"ggx\"\nalpha = 0.5",
        material: "kind = \"conductor\"",
        theta: 30.0,
        phi: 0.0,
        hemispheres: &[Hemisphere::R],
    },
    HistogramCase {
        surface: "ndf = \"beckmann\"\nalpha = 0.3",
        material: "kind = \"conductor\"\nfresnel = \"exact\"\neta = 0.2\nk = 3.0",
        theta: 60.0,
        phi: 0.0,
        hemispheres: &[Hemisphere::R],
    },
    HistogramCase {
        surface: "ndf = \"ggx\"\nalpha = [[0.5, 0.2]]",
        material: "kind = \"conductor\"\nfresnel = \"exact\"\neta = 2.8\nk = 3.7",
        theta: 45.0,
        phi: 30.0,
        hemispheres: &[Hemisphere::R],
    },
    HistogramCase {
        surface: "ndf = \"ggx\"\nalpha = 1.0",
        material: "kind = \"conductor\"",
        theta: 80.0,
        phi: 0.0,
        hemispheres: &[Hemisphere::R],
    },
    HistogramCase {
        surface: "ndf = \"ggx\"\nalpha = 0.5",
        material: "kind = \"dielectric\"\neta = 1.5",
        theta: 30.0,
        phi: 0.0,
        hemispheres: &[Hemisphere::R, Hemisphere::T],
    },
    HistogramCase {
        surface: "ndf = \"beckmann\"\nalpha = 0.4",
        material: "kind = \"dielectric\"\neta = 1.5",
        theta: 70.0,
        phi: 120.0,
        hemispheres: &[Hemisphere::R, Hemisphere::T],
    },
];

/// Beside a chi-square `test` of an order-1 histogram against `expected`: it kept at least 16
/// cells (a lobe wrongly expected to be zero almost everywhere pools into one untested cell),
/// and the measured order-1 albedo `(e1, se)` matches the bins' sum by a z test at `level`.
pub(crate) fn assert_cells_and_albedo(
    (e1, se): (f64, f64),
    test: &ChiSquare,
    expected: &[f64],
    level: f64,
    label: &str,
) {
    assert!(test.dof >= 16, "{label}: only {} cells tested", test.dof);
    let total: f64 = expected.iter().sum();
    println!("{label}: E1 {e1:.5} +- {se:.5}, single scattering {total:.5}");
    assert!((e1 - total).abs() < two_sided_z(level) * se, "{label}: E1 = {e1} +- {se}, single scattering {total}");
}

#[test]
fn order_one_histograms_match_single_scattering() {
    let tests: usize = CASES.iter().map(|c| c.hemispheres.len()).sum();
    let level = sidak(0.01, 2 * tests);
    for (i, c) in CASES.iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {seed}\n[surface]\n{}\n[material]\n{}\n[incident]\ntheta_deg = {}\nphi_deg = {}\n[detector]\ncos_theta_bins = 16\nphi_bins = 32\nmax_order = 2\n",
            c.surface,
            c.material,
            c.theta,
            c.phi,
            seed = 100 + i
        );
        let sim = simulate(&toml, 2);
        let d = mono(&sim, 0);
        for &h in c.hemispheres {
            let expected = single_scattering_bins(&sim.cases[0], &d.grid, h, 0, 1e-10).expect("closed form applies");
            let test = chi_square(&weighted_bins(d, 1, h), &expected, d.tallies.photons, 5.0);
            assert_cells_and_albedo(albedo(d, 1, h), &test, &expected, level, &format!("case {i} {h:?}"));
            assert!(
                test.p_value > level,
                "case {i} ({} / {} at {} deg) {h:?}: order-1 histogram rejected\n{}",
                c.surface,
                c.material,
                c.theta,
                test.worst_cells(12)
            );
        }
    }
}

#[test]
fn order_one_albedo_matches_quadrature() {
    // (alpha, theta_i, E1 from docs/theory.md §9.4 quadrature)
    let refs = [(1.0, 0.0, 1.0 - std::f64::consts::LN_2), (1.0, 60.0, 0.450694), (0.5, 0.0, 0.687849)];
    for (i, (alpha, theta, e1)) in refs.into_iter().enumerate() {
        let toml = format!(
            "paths = 10_000_000\nseed = {}\n[surface]\nalpha = {alpha}\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 1\nphi_bins = 1\nmax_order = 2\n",
            200 + i
        );
        let sim = simulate(&toml, 2);
        let (e, se) = albedo(mono(&sim, 0), 1, Hemisphere::R);
        println!(
            "alpha {alpha} theta {theta}: E1 = {e:.5} +- {se:.5}, quadrature {e1:.5}, diff {:.2} SE",
            (e - e1) / se
        );
        assert!(se < 1.6e-4, "SE {se}");
        assert!((e - e1).abs() < 4.0 * se, "alpha {alpha} theta {theta}: E1 = {e} +- {se}, expected {e1}");
    }
}

#[test]
fn a_wrong_lobe_is_rejected() {
    // The histogram test must have power: the alpha = 0.5 histogram against the alpha = 0.55
    // single-scattering expectation is rejected.
    let toml = "paths = 1_000_000\nseed = 9\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 16\nphi_bins = 32\nmax_order = 2\n";
    let sim = simulate(toml, 2);
    let mut other = sim.cases[0].clone();
    other.surface.ndf = AnyNdf::Ggx(Ggx(Roughness::isotropic(0.55)));
    let d = mono(&sim, 0);
    let expected = single_scattering_bins(&other, &d.grid, Hemisphere::R, 0, 1e-10).unwrap();
    let test = chi_square(&weighted_bins(d, 1, Hemisphere::R), &expected, d.tallies.photons, 5.0);
    assert!(test.p_value < 1e-6, "p = {}", test.p_value);
}

#[test]
#[ignore = "heavy: 10^9 photons per case, about 3 minutes on 2 cores"]
fn order_one_albedo_to_four_decimals() {
    // At 10^9 photons the SE is about 1.5e-5, so agreement to 4 decimals (|diff| < 5e-5) is a
    // 3-sigma statement; the same quadrature references as above.
    let refs = [(1.0, 0.0, 1.0 - std::f64::consts::LN_2), (1.0, 60.0, 0.450694), (0.5, 0.0, 0.687849)];
    for (i, (alpha, theta, e1)) in refs.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000_000\nseed = {}\n[surface]\nalpha = {alpha}\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 1\nphi_bins = 1\nmax_order = 2\n",
            900 + i
        );
        let sim = simulate(&toml, 2);
        let (e, se) = albedo(mono(&sim, 0), 1, Hemisphere::R);
        println!(
            "alpha {alpha} theta {theta}: E1 = {e:.6} +- {se:.6}, quadrature {e1:.6}, diff {:.2} SE",
            (e - e1) / se
        );
        assert!((e - e1).abs() < 5e-5, "alpha {alpha} theta {theta}: E1 = {e} +- {se}, expected {e1} to 4 decimals");
    }
}

#[test]
fn order_one_of_scattering_facets_matches_single_scattering() {
    // Lambertian and Hammon facets on GGX and Beckmann (§5: the visible-normal integral by a
    // Gauss–Legendre rule, on the [DB23] cap for GGX and in the aligned slope frame for
    // Beckmann, then a 12 x 12 Gauss–Legendre rule over each bin), 10^6 photons, 8 x 16 bins,
    // cells with expected count < 5 pooled, at least 16 cells left, and the order-1 albedo
    // against the bins' sum by a z test; Sidak family level 0.01 over the 14 tests.
    let cases = [
        ("alpha = 0.3", "kind = \"diffuse\"\nalbedo = 0.8", 0.0),
        ("alpha = [[0.9, 0.4]]", "kind = \"diffuse\"", 80.0),
        ("alpha = 0.6", "kind = \"hammon\"\nf0 = 0.04\nalbedo = 0.75", 45.0),
        ("alpha = 1.0", "kind = \"hammon\"\nf0 = 0.02\nalbedo = 1.0", 82.0),
        ("ndf = \"beckmann\"\nalpha = 0.5", "kind = \"diffuse\"\nalbedo = 0.9", 0.0),
        ("ndf = \"beckmann\"\nalpha = [[1.0, 0.3]]", "kind = \"diffuse\"", 70.0),
        ("ndf = \"beckmann\"\nalpha = 0.7", "kind = \"hammon\"\nf0 = 0.04\nalbedo = 0.75", 84.0),
    ];
    let level = sidak(0.01, 2 * cases.len());
    for (i, (alpha, material, theta)) in cases.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {}\n[surface]\n{alpha}\n[material]\n{material}\n[incident]\ntheta_deg = {theta}\nphi_deg = 55\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n",
            150 + i
        );
        let sim = simulate(&toml, 2);
        let d = mono(&sim, 0);
        let expected = single_scattering_bins(&sim.cases[0], &d.grid, Hemisphere::R, 0, 1e-9).expect("true Smith");
        let test = chi_square(&weighted_bins(d, 1, Hemisphere::R), &expected, d.tallies.photons, 5.0);
        println!(
            "{material} {alpha} at {theta} deg: chi2 {:.1}, dof {}, p {:.3e}",
            test.statistic, test.dof, test.p_value
        );
        let label = format!("{material} {alpha} at {theta} deg");
        assert_cells_and_albedo(albedo(d, 1, Hemisphere::R), &test, &expected, level, &label);
        assert!(test.p_value > level, "{material} {alpha} at {theta} deg: order 1 rejected\n{}", test.worst_cells(10));
    }
}

#[test]
fn order_one_of_student_t_walks_matches_single_scattering() {
    // The Student-T NDF (§1.6) for every facet material: conductor, dielectric reflection and
    // transmission, Lambertian and Hammon facets, gamma 1.6 (tails near the limit 3/2) and 3,
    // one anisotropic; the diffuse parts by the Student-T visible-normal rule. 10^6 photons,
    // 16 x 32 bins (8 x 16 for the diffuse facets), cells with expected count < 5 pooled, at
    // least 16 cells left, and the order-1 albedo against the bins' sum by a z test; Sidak
    // family level 0.01 over the 10 tests.
    let cases = [
        ("gamma = 1.6\nalpha = 0.5", "kind = \"conductor\"", 30.0, &[Hemisphere::R][..], 16),
        ("gamma = 3\nalpha = 0.4", "kind = \"dielectric\"\neta = 1.5", 60.0, &[Hemisphere::R, Hemisphere::T][..], 16),
        ("gamma = 1.6\nalpha = [[0.8, 0.3]]", "kind = \"diffuse\"\nalbedo = 0.9", 70.0, &[Hemisphere::R][..], 8),
        ("gamma = 3\nalpha = 0.6", "kind = \"hammon\"\nf0 = 0.04\nalbedo = 0.75", 45.0, &[Hemisphere::R][..], 8),
    ];
    let level = sidak(0.01, 2 * 5);
    for (i, (surface, material, theta, hemispheres, cos_bins)) in cases.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {}\n[surface]\nndf = \"student-t\"\n{surface}\n[material]\n{material}\n[incident]\ntheta_deg = {theta}\nphi_deg = 25\n[detector]\ncos_theta_bins = {cos_bins}\nphi_bins = {}\nmax_order = 2\n",
            170 + i,
            2 * cos_bins
        );
        let sim = simulate(&toml, 2);
        let d = mono(&sim, 0);
        for &h in hemispheres {
            let expected = single_scattering_bins(&sim.cases[0], &d.grid, h, 0, 1e-9).expect("true Smith");
            let test = chi_square(&weighted_bins(d, 1, h), &expected, d.tallies.photons, 5.0);
            let label = format!("{surface} {material} at {theta} deg {h:?}").replace('\n', " ");
            println!("{label}: chi2 {:.1}, dof {}, p {:.3e}", test.statistic, test.dof, test.p_value);
            assert_cells_and_albedo(albedo(d, 1, h), &test, &expected, level, &label);
            assert!(test.p_value > level, "{label}: order 1 rejected\n{}", test.worst_cells(10));
        }
    }
}

#[test]
fn lambertian_single_scattering_albedo_matches_the_formula_values() {
    // docs/theory.md §9.4: E1 of Lambertian facets (rho = 1, isotropic GGX) by the [HD15] formula,
    // 10^6 samples there (SE about 5e-4): 0.7805 (alpha 0.5, 0 deg), 0.7557 (0.5, 60 deg),
    // 0.5817 (1.0, 0 deg), 0.5647 (1.0, 60 deg). Our quadrature over a 4 x 8 grid.
    let grid = Grid { cos_bins: 4, phi_bins: 8 };
    for (alpha, theta, reference) in [(0.5, 0.0, 0.7805), (0.5, 60.0, 0.7557), (1.0, 0.0, 0.5817), (1.0, 60.0, 0.5647)]
    {
        let toml = format!(
            "paths = 10\n[surface]\nalpha = {alpha}\n[material]\nkind = \"diffuse\"\n[incident]\ntheta_deg = {theta}\n"
        );
        let case = case_of(&toml);
        let e1: f64 = single_scattering_bins(&case, &grid, Hemisphere::R, 0, 1e-9).unwrap().iter().sum();
        assert!((e1 - reference).abs() < 2e-3, "alpha {alpha} theta {theta}: E1 = {e1}, formula {reference}");
    }
}

#[test]
fn single_scattering_is_offered_only_where_it_is_order_one_of_the_walk() {
    // §5 is the order-1 output of the walk with the true Smith Lambda and visible normals, light
    // from outside. Each case below differs from such a case in one of the three, and then no
    // lobe may be offered: `compare` would judge the walk against the wrong oracle.
    let grid = Grid { cos_bins: 2, phi_bins: 4 };
    let case = |surface: &str, incident: &str| {
        let toml = format!(
            "paths = 10\n[surface]\nalpha = 0.5\n{surface}\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = 30\n{incident}\n"
        );
        case_of(&toml)
    };
    assert!(single_scattering_bins(&case("", ""), &grid, Hemisphere::R, 0, 1e-6).is_some());
    for (surface, incident) in
        [("smith = \"symmetric\"", ""), ("normals = \"hammon-rejection\"", ""), ("", "side = \"inside\"")]
    {
        let lobe = single_scattering_bins(&case(surface, incident), &grid, Hemisphere::R, 0, 1e-6);
        assert!(lobe.is_none(), "offered for {surface}{incident}");
    }
}

/// The specular facets of the order-1 albedos below: conductors with Schlick's Fresnel of F0
/// (`Schlick(1.0)` is F = 1 exactly) or the exact Fresnel of the index `eta + i k`, and
/// dielectrics of relative index `eta`.
#[derive(Clone, Copy, Debug)]
enum Facet {
    Schlick(f64),
    Conductor { eta: f64, k: f64 },
    Dielectric(f64),
}

/// What a facet of normal `m` sends into `hemisphere` at order 1, before the division by
/// `G1(wi)`: its Fresnel weight `w(m)` (`F` in reflection, `1 - F` in transmission) times
/// `G2(wi, wo)`, where `wo` is the mirror or refracted direction (§5).
fn order_one_weight<N: Ndf>(ndf: &N, wi: DVec3, m: DVec3, facet: Facet, hemisphere: Hemisphere) -> f64 {
    let c = wi.dot(m);
    let f = match facet {
        Facet::Schlick(f0) => fresnel::schlick(f0, c),
        Facet::Conductor { eta, k } => fresnel::conductor(eta, k, c),
        Facet::Dielectric(eta) => fresnel::dielectric(eta, c),
    };
    match (hemisphere, facet) {
        (Hemisphere::R, _) => {
            let wo = 2.0 * c * m - wi;
            if wo.z > 0.0 { f * single::g2_reflection(ndf, wi, wo) } else { 0.0 }
        }
        (Hemisphere::T, Facet::Dielectric(eta)) => {
            let ct2 = 1.0 - (1.0 - c * c) / (eta * eta);
            if ct2 <= 0.0 {
                return 0.0;
            }
            let wo = (c / eta - ct2.sqrt()) * m - wi / eta;
            if wo.z < 0.0 { (1.0 - f) * single::g2_transmission(ndf, wi, wo) } else { 0.0 }
        }
        (Hemisphere::T, _) => 0.0,
    }
}

/// The order-1 albedo `E1 = ∫ D_wi(m) w(m) G2(wi, wo) / G1(wi) dm` (§5) of a GGX surface, by
/// quadrature over the visible normals rather than over `wo`: the normals are parametrised by
/// the spherical-cap map of §3.2 (`u` uniform on [0, 1], `phi` on [0, 2 pi), density 1 / 2 pi),
/// and `1 / G1(wi)` leaves the integral. A lobe as narrow as alpha in `wo` is then a smooth
/// integrand of `(u, phi)`.
fn ggx_order_one_albedo_over_the_normals(alpha: f64, wi: DVec3, facet: Facet, hemisphere: Hemisphere) -> f64 {
    let roughness = Roughness::isotropic(alpha);
    let ndf = Ggx(roughness);
    let ws = roughness.stretch(wi);
    let normal = |u: f64, phi: f64| {
        let z = (1.0 - u) * (1.0 + ws.z) - ws.z;
        let s = (1.0 - z * z).max(0.0).sqrt();
        let h = DVec3::new(s * phi.cos(), s * phi.sin(), z) + ws;
        roughness.unstretch_normal(DVec3::new(h.x, h.y, h.z.max(0.0)))
    };
    let weight = |u, phi| order_one_weight(&ndf, wi, normal(u, phi), facet, hemisphere);
    (1.0 + ndf.lambda(wi)) * integrate_2d(weight, (0.0, 1.0), (0.0, TAU), 1e-9).0 / TAU
}

/// The same albedo of a Beckmann surface, by quadrature over the slopes: with `D_wi(m) dm =
/// G1(wi) max(0, wi . m) P22(s) ds / (cos theta_i cos theta_m)` (§3.1, and `D cos theta_m dm =
/// P22 ds`, §1.1) and the isotropic Beckmann slopes `P22(s) = exp(-|s|^2 / alpha^2) / (pi
/// alpha^2)`, the radius `|s| = alpha sqrt(-ln(1 - t))` makes `t` uniform on [0, 1] and `phi`
/// on [0, 2 pi): `E1 = ∫∫ max(0, wi . m) / (cos theta_i cos theta_m) w G2 dt dphi / 2 pi`, the
/// `G1` of `D_wi` cancelling that of `E1`. However small alpha is, the integrand varies on a
/// scale of 1 in `t`, with kinks only where facets turn away from `wi` or send `wo` below the
/// horizon.
/// Independent of the bin quadrature, its grading and the reflection and refraction Jacobians;
/// it shares Lambda, G2 and Fresnel with the model.
fn beckmann_order_one_albedo_over_the_slopes(alpha: f64, wi: DVec3, facet: Facet, hemisphere: Hemisphere) -> f64 {
    let ndf = Beckmann(Roughness::isotropic(alpha));
    let integrand = |t: f64, phi: f64| {
        let r = alpha * (-(-t).ln_1p()).sqrt();
        // At grazing incidence the facets turned away from wi start near t = 1, where the
        // refinement reaches nodes that round to 1 (an infinite slope, of no mass).
        if r.is_infinite() {
            return 0.0;
        }
        let m = DVec3::new(-r * phi.cos(), -r * phi.sin(), 1.0).normalize();
        let projected = wi.dot(m).max(0.0) / (wi.z * m.z);
        if projected == 0.0 { 0.0 } else { projected * order_one_weight(&ndf, wi, m, facet, hemisphere) }
    };
    integrate_2d(integrand, (0.0, 1.0), (0.0, TAU), 1e-9).0 / TAU
}

#[test]
fn narrow_specular_lobes_are_integrated_where_they_peak() {
    // Nearly smooth surfaces: the lobe is a spike in one bin, which the bin quadrature must
    // find. Its bins' sum against the order-1 albedo over the normals (GGX) or the slopes
    // (Beckmann, above): within 2e-7 (128 bins at 1e-9 each, the references to 1e-9; they agree
    // to 2e-8 here). Beckmann's tails vanish like exp(-tan^2 / alpha^2): a cell whose nodes all
    // miss the spike sees zeros and an error estimate of zero, and the bins then sum to 0
    // (measured with the grading towards the peak removed: at alpha 1e-4 from 30 to 89 deg,
    // at 0.003 at 89 deg and in transmission).
    let grid = Grid { cos_bins: 8, phi_bins: 16 };
    let ggx = [0.003, 0.01].map(|alpha| ("ggx", alpha));
    let beckmann = [1e-4, 0.003].map(|alpha| ("beckmann", alpha));
    for (ndf, alpha) in ggx.into_iter().chain(beckmann) {
        // At 60 deg the mirror direction lies on a bin edge (cos 0.5), computed a rounding error
        // beyond it: Beckmann at alpha 1e-4 lost half its lobe there until the grading reached
        // across edges. GGX's tails were seen anyway, and its reference takes 20 s there.
        let edge = if ndf == "beckmann" { &[60.0][..] } else { &[] };
        let conductor = [0.0, 30.0, 75.0, 89.0].iter().chain(edge).map(|&theta| ("kind = \"conductor\"", None, theta));
        let dielectric = [0.0, 40.0].map(|theta| ("kind = \"dielectric\"\neta = 1.5", Some(1.5), theta));
        for (material, eta, theta) in conductor.chain(dielectric) {
            let toml = format!(
                "paths = 10\n[surface]\nndf = \"{ndf}\"\nalpha = {alpha}\n[material]\n{material}\n[incident]\ntheta_deg = {theta}\nphi_deg = 20\n"
            );
            let case = case_of(&toml);
            let wi = case.wi;
            let hemispheres: &[Hemisphere] =
                if eta.is_some() { &[Hemisphere::R, Hemisphere::T] } else { &[Hemisphere::R] };
            let facet = eta.map_or(Facet::Schlick(1.0), Facet::Dielectric);
            for &h in hemispheres {
                let bins: f64 = single_scattering_bins(&case, &grid, h, 0, 1e-9).unwrap().iter().sum();
                let reference = match ndf {
                    "ggx" => ggx_order_one_albedo_over_the_normals(alpha, wi, facet, h),
                    _ => beckmann_order_one_albedo_over_the_slopes(alpha, wi, facet, h),
                };
                println!("{ndf} alpha {alpha} {material} {theta} {h:?}: bins {bins:.9}, reference {reference:.9}");
                assert!(
                    (bins - reference).abs() < 2e-7,
                    "{ndf}, alpha {alpha}, {material}, {theta} deg, {h:?}: {bins} vs {reference}"
                );
            }
        }
    }
}

#[test]
fn exit_lobes_stopped_at_their_bound_are_within_half_a_standard_error() {
    // `compare` asks each bin for 0.05 of the measured bin's standard error; where the bound of
    // the diffuse part stops the refinement first, the bin's error estimate must still be a
    // small fraction of it, or the quadrature could sway a verdict. Here at 10^7 photons and
    // 80 deg, with the standard error `sqrt(E / N)` of a bin of energy E: exact to a factor
    // sqrt(1 - E) for the Lambertian facets of albedo 1 (photons of weight 1), an upper bound
    // for Hammon's (weights below 1). Within 0.5 of it in every bin (measured: at most 0.21,
    // the Beckmann diffuse case, in the 7 bins that stop at the bound; one cell per bin gives 2
    // to 40); some bins must stop there, or the test would not test the bound.
    let (grid, photons) = (Grid { cos_bins: 8, phi_bins: 16 }, 1e7);
    let mut stopped = 0;
    for (ndf, alpha, material) in
        [("ggx", 1.0, "diffuse"), ("beckmann", 0.5, "diffuse"), ("ggx", 1.0, "hammon"), ("beckmann", 0.5, "hammon")]
    {
        let case = case_of(&format!(
            "paths = 10\n[surface]\nndf = \"{ndf}\"\nalpha = {alpha}\n[material]\nkind = \"{material}\"\n[incident]\ntheta_deg = 80\nphi_deg = 20\n"
        ));
        let coarse = single_scattering_bins(&case, &grid, Hemisphere::R, 0, 1e-4).unwrap();
        let stderr: Vec<f64> = coarse.iter().map(|e| (e.max(0.0) / photons).sqrt().max(1.0 / photons)).collect();
        let tolerance = |bin: usize| 0.05 * stderr[bin];
        let lobe = single_scattering_lobe(&case, &grid, Hemisphere::R, 0, &tolerance).unwrap();
        let worst = lobe.error.iter().zip(&stderr).map(|(e, s)| e / s).fold(0.0, f64::max);
        let above = lobe.error.iter().enumerate().filter(|&(bin, e)| *e > tolerance(bin)).count();
        println!(
            "{ndf} alpha {alpha} {material}: {} bins stopped at the bound, {above} above their tolerance, worst {worst:.3} standard errors",
            lobe.capped
        );
        assert!(worst <= 0.5, "{ndf} alpha {alpha} {material}: an error estimate of {worst} standard errors");
        // What `compare` reports: the bins stopped are those left above their tolerance (one
        // part each for a Lambertian facet; a Hammon bin above it has a part above its half).
        if material == "diffuse" {
            assert_eq!(above, lobe.capped, "{ndf} alpha {alpha} {material}");
        } else {
            assert!(above <= lobe.capped, "{ndf} alpha {alpha} {material}: {above} > {}", lobe.capped);
        }
        stopped += lobe.capped;
    }
    assert!(stopped > 0, "no bin reached the bound");
}

#[test]
fn every_channel_of_an_rgb_run_matches_its_own_single_scattering() {
    // RGB runs whose channels differ strongly, on GGX: a Schlick conductor (F0 0.2, 0.6, 1),
    // gold (the exact Fresnel of eta + i k per channel), Lambertian facets of albedo 0.9, 0.5,
    // 0.1; 10^6 photons, 8 x 16 bins. In every channel, the order-1 histogram against the model
    // of that channel (chi-square, cells with expected count < 5 pooled, at least 16 left; the
    // albedo against the bins' sum by a z test), and for the conductors the order-1 albedo
    // against the integral over the visible normals with that channel's Fresnel, by a z test:
    // Sidak family level 0.01 over the 24 tests. Channel r's model (its parameters used for g
    // and b) is rejected on g and b, p < 1e-6.
    let cases = [
        ("ndf = \"ggx\"\nalpha = 0.5", "kind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.2, 0.6, 1.0]", 50.0),
        (
            "ndf = \"ggx\"\nalpha = 0.3",
            "kind = \"conductor\"\nfresnel = \"exact\"\neta = [0.143, 0.424, 1.367]\nk = [3.983, 2.469, 1.864]",
            70.0,
        ),
        ("ndf = \"ggx\"\nalpha = 0.8", "kind = \"diffuse\"\nalbedo = [0.9, 0.5, 0.1]", 30.0),
    ];
    // 9 histograms, 9 albedos against their bins, 6 against the integrals.
    let level = sidak(0.01, 24);
    for (i, (surface, material, theta)) in cases.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {}\n[surface]\n{surface}\n[material]\n{material}\n[incident]\ntheta_deg = {theta}\nphi_deg = 25\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n",
            300 + i
        );
        let sim = simulate(&toml, 2);
        let (case, d) = (&sim.cases[0], rgb(&sim, 0));
        let model = |channel| single_scattering_bins(case, &d.grid, Hemisphere::R, channel, 1e-9).unwrap();
        let red = model(0);
        for (channel, name) in ["r", "g", "b"].into_iter().enumerate() {
            let label = format!("{material} {surface} at {theta} deg, channel {name}").replace('\n', " ");
            let measured = channel_bins(d, 1, Hemisphere::R, channel);
            let expected = model(channel);
            let test = chi_square(&measured, &expected, d.tallies.photons, 5.0);
            println!("{label}: chi2 {:.1}, dof {}, p {:.3e}", test.statistic, test.dof, test.p_value);
            let e1 = channel_albedo(d, 1, Hemisphere::R, channel);
            assert_cells_and_albedo(e1, &test, &expected, level, &label);
            assert!(test.p_value > level, "{label}: order 1 rejected\n{}", test.worst_cells(10));
            let facet = match case.material_spec {
                MaterialConfig::Conductor { f0: Some(f0), .. } => Some(Facet::Schlick(f0.channel(channel))),
                MaterialConfig::Conductor { eta: Some(eta), k: Some(k), .. } => {
                    Some(Facet::Conductor { eta: eta.channel(channel), k: k.channel(channel) })
                }
                _ => None,
            };
            if let Some(facet) = facet {
                let wi = case.wi;
                let reference = ggx_order_one_albedo_over_the_normals(case.roughness().x, wi, facet, Hemisphere::R);
                println!("{label}: E1 {:.5} +- {:.5}, over the normals {reference:.5}", e1.0, e1.1);
                assert!(
                    (e1.0 - reference).abs() < two_sided_z(level) * e1.1,
                    "{label}: E1 = {} +- {}, over the normals {reference}",
                    e1.0,
                    e1.1
                );
            }
            if channel > 0 {
                let wrong = chi_square(&measured, &red, d.tallies.photons, 5.0);
                assert!(wrong.p_value < 1e-6, "{label}: channel r's model not rejected, p = {}", wrong.p_value);
            }
        }
    }
}
