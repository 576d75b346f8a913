//! Visible-normal sampling against the visible-normal density integrated over bins
//! (docs/theory.md §3.1, §3.2, §3.3).
//!
//! For each NDF, roughness and direction (above and below the horizon) 200 000 normals are
//! drawn and binned on a 16 x 16 grid uniform in cos(theta_m) x phi_m. The expected bin
//! probabilities are the integrals of `D_w(m) = <w·m> D(m) / A(w)` by adaptive quadrature.
//! Cells with an expected count below 5 are pooled. Each chi-square test runs at the Sidak
//! level that keeps the family-wise level at 0.01 over all tests in this file.
//!
//! The Beckmann sampler's slope along the view direction is also tested on its own, at values
//! of `mu = cot theta'` on both sides of each switch between its rejection proposals: 200 000
//! slopes per `mu` on 40 bins, against bin integrals of its density by adaptive quadrature.
//!
//! The lane sampler of the side-by-side walk (`Normals::sample_lanes`, GGX's own on 4 lanes,
//! Beckmann's and Hammon's on 2) is tested the same way, each lane with its own direction:
//! 200 000 normals per lane against that direction's law.

use crate::common;

use common::dir;

use std::f64::consts::TAU;

use microsurface::DVec3;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness, visible_slope_beckmann};
use microsurface::normals::Normals;
use microsurface::student_t::StudentT;
use numerics::quadrature::{integrate, integrate_2d_nested};
use numerics::stats::{WeightedBin, chi_square, sidak};
use rand_pcg::Pcg64Mcg;

const SAMPLES: u64 = 200_000;
const COS_BINS: usize = 16;
const PHI_BINS: usize = 16;

fn bin_of(m: DVec3) -> usize {
    let ic = ((m.z * COS_BINS as f64) as usize).min(COS_BINS - 1);
    let mut phi = m.y.atan2(m.x);
    if phi < 0.0 {
        phi += TAU;
    }
    let ip = ((phi / TAU * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    ic * PHI_BINS + ip
}

/// Bin integrals of a density over normals, `∫∫ p(m) d(cos theta) d(phi)`.
fn expected(density: impl Fn(DVec3) -> f64) -> Vec<f64> {
    let mut out = Vec::new();
    for ic in 0..COS_BINS {
        for ip in 0..PHI_BINS {
            let u = (ic as f64 / COS_BINS as f64, (ic + 1) as f64 / COS_BINS as f64);
            let p = (ip as f64 * TAU / PHI_BINS as f64, (ip + 1) as f64 * TAU / PHI_BINS as f64);
            // Azimuth outside, cosine inside, so that each azimuth's sine and cosine are
            // computed once for its whole inner integral.
            let density = &density;
            let over_u = |phi: f64| {
                let (sin_phi, cos_phi) = phi.sin_cos();
                move |u: f64| {
                    let s = (1.0 - u * u).max(0.0).sqrt();
                    density(DVec3::new(s * cos_phi, s * sin_phi, u))
                }
            };
            // 4 x 4 sub-panels per bin, so that the adaptive rule sees narrow features. An
            // absolute tolerance of 1e-8 a sub-panel bounds a bin's error by 1.6e-7, 0.03 of a
            // count in 200 000 draws, against a standard deviation of at least 2.2 in a pooled
            // cell (expected count 5 or more); a tighter tolerance only slows the kink at
            // w·m = 0.
            let mut sum = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    let su = (u.0 + (u.1 - u.0) * a as f64 / 4.0, u.0 + (u.1 - u.0) * (a + 1) as f64 / 4.0);
                    let sp = (p.0 + (p.1 - p.0) * b as f64 / 4.0, p.0 + (p.1 - p.0) * (b + 1) as f64 / 4.0);
                    sum += integrate_2d_nested(over_u, sp, su, 1e-8).0;
                }
            }
            out.push(sum);
        }
    }
    out
}

fn sampled<N: Ndf>(ndf: &N, normals: Normals, w: DVec3, seed: u64) -> Vec<WeightedBin> {
    let mut rng = Pcg64Mcg::new(0xfeed_0000 + seed as u128);
    let mut counts = vec![0u64; COS_BINS * PHI_BINS];
    for _ in 0..SAMPLES {
        // A ray travelling along d = -w hits a facet drawn for w.
        let m = normals.sample(ndf, -w, &mut rng);
        assert!(m.is_finite() && (m.length() - 1.0).abs() < 1e-12 && m.z >= 0.0, "bad normal {m}");
        if normals == Normals::Visible {
            assert!(w.dot(m) > -1e-12, "normal {m} faces away from {w}");
        }
        counts[bin_of(m)] += 1;
    }
    counts.iter().map(|&c| WeightedBin::of_count(c, SAMPLES)).collect()
}

/// (theta_deg, phi_deg) of the viewing directions: above the horizon, and below it on both
/// sides of the Beckmann sampler's switch between its two proposals below the horizon
/// (`mu = -1/sqrt(2)`; `mu` is -0.35 and -0.68 for the first two roughnesses at 100 and 135
/// deg, -2 and -5.5 at 135 and 160 deg).
const DIRECTIONS: [(f64, f64); 4] = [(30.0, 40.0), (100.0, 200.0), (135.0, 10.0), (160.0, 290.0)];
const ROUGHNESSES: [(f64, f64); 3] = [(0.5, 0.5), (0.5, 0.2), (1.5, 0.8)];

/// (NDF, (alpha_x, alpha_y), (theta_deg, phi_deg)).
type NormalCase = (&'static str, (f64, f64), (f64, f64));

fn all_cases() -> Vec<NormalCase> {
    let mut v = Vec::new();
    for ndf in ["ggx", "beckmann"] {
        for r in ROUGHNESSES {
            for d in DIRECTIONS {
                v.push((ndf, r, d));
            }
        }
    }
    v
}

/// The bin probabilities of the law `normals` draws for `w` (the visible normals, or §3.3's
/// law of Hammon's sampler), by quadrature.
fn law<N: Ndf>(ndf: &N, normals: Normals, w: DVec3) -> Vec<f64> {
    match normals {
        Normals::Visible => {
            let area = ndf.projected_area(w);
            expected(|m| ndf.d(m) * w.dot(m).max(0.0) / area)
        }
        Normals::HammonRejection => {
            // §3.3: p_H(m) = D(m) m_z 1[w·m > 0] / N(w).
            let unnormalized = expected(|m| if w.dot(m) > 0.0 { ndf.d(m) * m.z } else { 0.0 });
            let norm: f64 = unnormalized.iter().sum();
            unnormalized.into_iter().map(|p| p / norm).collect()
        }
    }
}

fn check<N: Ndf>(ndf: &N, normals: Normals, w: DVec3, level: f64, seed: u64, label: &str) {
    let expect = law(ndf, normals, w);
    if normals == Normals::Visible {
        // §9.1: D_w integrates to 1 for every w (to the quadrature accuracy of the kink at w·m = 0).
        let total: f64 = expect.iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "{label}: ∫ D_w = {total}");
    }
    let test = chi_square(&sampled(ndf, normals, w, seed), &expect, SAMPLES, 5.0);
    assert!(test.p_value > level, "{label}: visible-normal histogram rejected\n{}", test.worst_cells(12));
}

#[test]
fn visible_normals_match_the_visible_normal_density() {
    let cases = all_cases();
    let level = sidak(0.01, FAMILY);
    for (i, (ndf, (ax, ay), (t, p))) in cases.into_iter().enumerate() {
        let r = Roughness { x: ax, y: ay };
        let w = dir(t, p);
        let label = format!("{ndf} alpha=({ax},{ay}) w=({t},{p})");
        match ndf {
            "ggx" => check(&Ggx(r), Normals::Visible, w, level, i as u64, &label),
            _ => check(&Beckmann(r), Normals::Visible, w, level, i as u64, &label),
        }
    }
}

#[test]
fn visible_normals_at_normal_incidence_match_the_density() {
    // Light straight down: the stretched direction is the pole, where Beckmann's sampler has
    // no view-plane slope (`mu = cot theta'` is infinite) and draws both slopes from the
    // normal law instead (§3.1); GGX's cap is the whole upper sphere.
    let level = sidak(0.01, FAMILY);
    for (i, (ax, ay)) in ROUGHNESSES.into_iter().enumerate() {
        let r = Roughness { x: ax, y: ay };
        let seed = 1000 + 2 * i as u64;
        check(&Ggx(r), Normals::Visible, DVec3::Z, level, seed, &format!("ggx alpha=({ax},{ay}) w=z"));
        check(&Beckmann(r), Normals::Visible, DVec3::Z, level, seed + 1, &format!("beckmann alpha=({ax},{ay}) w=z"));
    }
}

const HAMMON_TESTS: usize = 8;

/// Shapes of the Student-T tests: heavy tails (gamma < 2, where D_w is unbounded like
/// m_z^(2 gamma - 4) at the horizon of normals; at 1.6 the bin quadrature misses 2e-5 of the
/// mass, so 1.8), between GGX and Beckmann, and near Beckmann.
const STUDENT_T_GAMMAS: [f64; 3] = [1.8, 3.0, 10.0];
/// Student-T roughnesses: anisotropic, smooth and rough.
const STUDENT_T_ROUGHNESSES: [(f64, f64); 2] = [(0.5, 0.2), (1.5, 0.8)];
const STUDENT_T_TESTS: usize = STUDENT_T_GAMMAS.len() * (STUDENT_T_ROUGHNESSES.len() * DIRECTIONS.len() + 1);

/// Student-T near Beckmann below the horizon, where its sampler draws from the joint proposal
/// of §3.4 ((gamma - 5/2) k is 4 to 30 here, `mu` -2 and -5.5 for roughness (0.5, 0.2)).
/// Closer to the nadir the visible normals gather in one or two cells of the grid, and the
/// bin quadrature of the narrow law takes minutes; there the test below checks validity and cost.
const NADIR_GAMMAS: [f64; 2] = [1e3, 1e6];
const NADIR_DIRECTIONS: [(f64, f64); 2] = [(135.0, 10.0), (160.0, 290.0)];

/// The chi-square tests of this file at the family level 0.01: the cases of `all_cases` (2
/// NDFs) and of normal incidence, Hammon's, the slope tests, the lanes and Student-T's.
const FAMILY: usize = 2 * ROUGHNESSES.len() * (DIRECTIONS.len() + 1)
    + HAMMON_TESTS
    + SLOPE_MUS.len()
    + LANE_TESTS
    + STUDENT_T_TESTS
    + TABLE_TESTS
    + NADIR_GAMMAS.len() * NADIR_DIRECTIONS.len();

/// The tables of the tabulated sampler's test: GGX of roughness 0.5 and 1.5 and Student-T
/// (gamma 3, roughness 0.5), each at `DIRECTIONS` and normal incidence, plus Hammon's normals
/// on the GGX 0.5 table at two directions.
const TABLE_TESTS: usize = 3 * (DIRECTIONS.len() + 1) + 2;

/// The bin probabilities of an analytic NDF's law of normals for a direction.
type BinLaw<'a> = dyn Fn(DVec3, Normals) -> Vec<f64> + 'a;

/// The tabulated NDF's visible normals (§3.5) against those of the analytic NDF its table was
/// sampled from (at the recommended step, where the two laws differ by less than 1e-4 of a
/// bin's probability, §1.7, under a tenth of a standard deviation at these counts): each
/// branch of the sampler, above the horizon (both proposals), below it (the conditioned
/// proposal; `DIRECTIONS` reach 45 and 70 degrees below) and at normal incidence; and
/// Hammon's rejection normals (§3.3), which draw from the table's slope-radius quantiles.
#[test]
fn tabulated_visible_normals_match_the_analytic_visible_normal_density() {
    use crate::common::table_of;
    use microsurface::tabulated::RECOMMENDED_STEP_DEG;
    let level = sidak(0.01, FAMILY);
    let mut seed = 3000;
    let mut compare = |analytic: &BinLaw<'_>, table, w, normals, label: String| {
        seed += 1;
        let test = chi_square(&sampled(table, normals, w, seed), &analytic(w, normals), SAMPLES, 5.0);
        println!("{label}: chi2 {:.1} dof {} p {:.3e}", test.statistic, test.dof, test.p_value);
        assert!(test.p_value > level, "{label}: visible-normal histogram rejected\n{}", test.worst_cells(12));
    };
    let ggx = |alpha| Ggx(Roughness::isotropic(alpha));
    let student_t = StudentT::new(Roughness::isotropic(0.5), 3.0).unwrap();
    let cases: [(&BinLaw<'_>, _, &str); 3] = [
        (&|w, n| law(&ggx(0.5), n, w), table_of(&ggx(0.5), RECOMMENDED_STEP_DEG, 1.0), "ggx 0.5"),
        (&|w, n| law(&ggx(1.5), n, w), table_of(&ggx(1.5), RECOMMENDED_STEP_DEG, 1.0), "ggx 1.5"),
        (&|w, n| law(&student_t, n, w), table_of(&student_t, RECOMMENDED_STEP_DEG, 1.0), "student-t 3, 0.5"),
    ];
    for (analytic, table, name) in &cases {
        for (t, p) in DIRECTIONS {
            compare(analytic, table, dir(t, p), Normals::Visible, format!("{name} table w=({t},{p})"));
        }
        compare(analytic, table, DVec3::Z, Normals::Visible, format!("{name} table w=z"));
    }
    let (analytic, table, name) = &cases[0];
    for (t, p) in [(40.0, 70.0), (110.0, 200.0)] {
        compare(
            analytic,
            table,
            dir(t, p),
            Normals::HammonRejection,
            format!("{name} table, Hammon's normals, w=({t},{p})"),
        );
    }
}

/// The Student-T sampler's proposal near the nadir (§3.4) at `NADIR_GAMMAS` and
/// `NADIR_DIRECTIONS`: 200 000 normals each on the 16 x 16 grid, cells pooled to an expected
/// count of 5, at the file's Sidak level.
#[test]
fn student_t_visible_normals_towards_the_nadir_match_the_density() {
    let level = sidak(0.01, FAMILY);
    let mut seed = 3000;
    for gamma in NADIR_GAMMAS {
        let ndf = StudentT::new(Roughness { x: 0.5, y: 0.2 }, gamma).unwrap();
        for (t, p) in NADIR_DIRECTIONS {
            seed += 1;
            check(&ndf, Normals::Visible, dir(t, p), level, seed, &format!("student-t {gamma} w=({t},{p})"));
        }
    }
}

/// The Student-T scale-mixture sampler (§3.4), each of its branches: above the horizon (both
/// components), below it (`DIRECTIONS` reach `mu` from -0.35 to -5.5) and at normal incidence
/// (`mu = inf`), for every shape of `STUDENT_T_GAMMAS`.
#[test]
fn student_t_visible_normals_match_the_visible_normal_density() {
    let level = sidak(0.01, FAMILY);
    let mut seed = 2000;
    for gamma in STUDENT_T_GAMMAS {
        for (ax, ay) in STUDENT_T_ROUGHNESSES {
            let ndf = StudentT::new(Roughness { x: ax, y: ay }, gamma).unwrap();
            for (t, p) in DIRECTIONS {
                seed += 1;
                let label = format!("student-t {gamma} alpha=({ax},{ay}) w=({t},{p})");
                check(&ndf, Normals::Visible, dir(t, p), level, seed, &label);
            }
        }
        seed += 1;
        let ndf = StudentT::new(Roughness { x: 0.5, y: 0.2 }, gamma).unwrap();
        check(&ndf, Normals::Visible, DVec3::Z, level, seed, &format!("student-t {gamma} w=z"));
    }
}

#[test]
fn hammon_rejection_samples_the_unweighted_restricted_ndf() {
    let level = sidak(0.01, FAMILY);
    let cases = [
        // Normal incidence: the travel direction has no azimuth, so the sampler's frame is
        // its fallback.
        ((0.5, 0.5), (0.0, 0.0)),
        ((0.5, 0.5), (40.0, 70.0)),
        ((0.5, 0.5), (120.0, 130.0)),
        ((0.8, 0.3), (60.0, 100.0)),
        ((0.8, 0.3), (150.0, 300.0)),
        // Travel upward at 70 deg: in the stretched frame cot^2 = 0.53, so the sampler shrinks
        // X1 to [0.35, 1) (§3.3 item 3); at the cases above the shrunk range is empty or whole.
        ((0.5, 0.5), (110.0, 200.0)),
    ];
    for (i, ((ax, ay), (t, p))) in cases.into_iter().enumerate() {
        let w = dir(t, p);
        check(
            &Ggx(Roughness { x: ax, y: ay }),
            Normals::HammonRejection,
            w,
            level,
            100 + i as u64,
            &format!("hammon {ax},{ay} {t},{p}"),
        );
    }
    // Beckmann, with its own slope-radius inversion and CDF bound: downward, and upward where
    // X1 is shrunk (cot^2 = 0.53 in the stretched frame, as above).
    for (i, (t, p)) in [(40.0, 70.0), (110.0, 200.0)].into_iter().enumerate() {
        let ndf = Beckmann(Roughness::isotropic(0.5));
        check(&ndf, Normals::HammonRejection, dir(t, p), level, 110 + i as u64, &format!("hammon beckmann {t},{p}"));
    }
}

#[test]
fn hammon_rejection_differs_from_visible_normals() {
    // The test above must be able to tell the two laws apart (§3.3): at 60 deg the Hammon
    // histogram is rejected as a sample of D_w.
    let ndf = Ggx(Roughness::isotropic(0.5));
    let w = dir(60.0, 0.0);
    let area = ndf.projected_area(w);
    let expect = expected(|m| ndf.d(m) * w.dot(m).max(0.0) / area);
    let test = chi_square(&sampled(&ndf, Normals::HammonRejection, w, 7), &expect, SAMPLES, 5.0);
    assert!(test.p_value < 1e-6, "p = {}", test.p_value);
}

/// `mu = cot theta'` of the direct slope tests: deep below the horizon, both sides of the switch
/// at `-1/sqrt(2)`, both sides of 0 (where the proposals change), the least efficient `mu` of the
/// mixture (0.52), and towards the pole.
const SLOPE_MUS: [f64; 12] = [-3.0, -0.75, -0.7, -0.3, -1e-9, 0.0, 1e-9, 0.52, 1.15, 5.0, 1e6, 1e300];

#[test]
fn beckmann_visible_slope_matches_its_density() {
    const SLOPES: u64 = 200_000;
    const BINS: usize = 40;
    let level = sidak(0.01, FAMILY);
    for (i, mu) in SLOPE_MUS.into_iter().enumerate() {
        // §3.1 in the stretched frame: p(x) ∝ (mu - x) e^{-x^2} on x < mu. Bins cover where the
        // mass is; the cells below and above them take the rest.
        let (lo, hi) = if mu >= 0.0 { (-4.0, mu.min(4.0)) } else { (mu - 4.0 / (1.0 - mu), mu) };
        // Scaled to a peak near 1, so that one absolute tolerance suits every mu.
        let scale = (0..=1000)
            .map(|k| lo + (hi - lo) * k as f64 / 1000.0)
            .map(|x| (mu - x) * (-x * x).exp())
            .fold(0.0, f64::max);
        let density = |x: f64| if x < mu { (mu - x) * (-x * x).exp() / scale } else { 0.0 };
        let top = mu.min(10.0);
        let total = integrate(density, lo - 10.0, top, 1e-13).0;
        let edge = |k: usize| lo + (hi - lo) * k as f64 / BINS as f64;
        let mut expect: Vec<f64> =
            (0..BINS).map(|k| integrate(density, edge(k), edge(k + 1), 1e-13).0 / total).collect();
        expect.push(integrate(density, hi, top, 1e-13).0 / total);
        expect.push(1.0 - expect.iter().sum::<f64>());
        let mut counts = vec![0u64; BINS + 2];
        let mut rng = Pcg64Mcg::new(0x51_0be + i as u128);
        for _ in 0..SLOPES {
            let x = visible_slope_beckmann(mu, &mut rng);
            assert!(x <= mu, "mu {mu}: slope {x} above mu");
            let cell = if x < lo {
                BINS + 1
            } else if x >= hi {
                BINS
            } else {
                (((x - lo) / (hi - lo) * BINS as f64) as usize).min(BINS - 1)
            };
            counts[cell] += 1;
        }
        let observed: Vec<WeightedBin> = counts.iter().map(|&c| WeightedBin::of_count(c, SLOPES)).collect();
        let test = chi_square(&observed, &expect, SLOPES, 5.0);
        assert!(test.p_value > level, "mu {mu}: p = {}\n{}", test.p_value, test.worst_cells(8));
    }
}

#[test]
fn visible_normals_stay_unit_at_the_poles_and_the_horizon() {
    // §10: directions whose tangential part underflows the slope ratio (1e-310), the poles
    // themselves, and the horizon from both sides give unit upper-hemisphere normals that face
    // the direction (at -z, where A = 0, the samplers return +z). Hammon's sampler too: a ray
    // travelling straight up hits no facet (its rejection loop would never end) and gets +z.
    let tiny = 1e-310;
    let directions = [
        DVec3::Z,
        -DVec3::Z,
        DVec3::new(tiny, 0.0, 1.0),
        DVec3::new(tiny, -tiny, -1.0),
        DVec3::new(1.0, 0.0, 1e-300),
        DVec3::new(0.6, 0.8, -1e-300),
        DVec3::X,
        DVec3::new(0.0, 1.0, -0.0),
    ];
    let mut rng = Pcg64Mcg::new(0x9013);
    for w in directions {
        for _ in 0..1000 {
            let ms = [
                Ggx(Roughness { x: 0.4, y: 0.9 }).sample_visible(w, &mut rng),
                Beckmann(Roughness { x: 0.4, y: 0.9 }).sample_visible(w, &mut rng),
                Normals::HammonRejection.sample(&Ggx(Roughness { x: 0.4, y: 0.9 }), -w, &mut rng),
                Normals::HammonRejection.sample(&Beckmann(Roughness { x: 0.4, y: 0.9 }), -w, &mut rng),
            ];
            for m in ms {
                assert!(m.is_finite() && (m.length() - 1.0).abs() < 1e-12 && m.z >= 0.0, "w {w}: normal {m}");
                assert!(w.dot(m) >= -1e-12 || w.z <= -1.0 + 1e-12, "w {w}: normal {m} faces away");
            }
        }
    }
}

/// Directions of the lanes (one per lane, different, above and below the horizon), so that a
/// lane given another lane's direction or normal is rejected too.
const LANE_DIRECTIONS: [(f64, f64); 4] = [(30.0, 40.0), (135.0, 10.0), (60.0, 100.0), (100.0, 200.0)];
/// GGX's own lane sampler on 4 lanes; Beckmann's (the trait's default) and Hammon's on 2.
const LANE_TESTS: usize = 4 + 2 + 2;

/// Draws [`SAMPLES`] normals per lane with `Normals::sample_lanes` (the side-by-side walk's
/// sampler) and tests each lane's histogram against its own direction's law.
fn check_lanes<N: Ndf, const L: usize>(ndf: &N, normals: Normals, level: f64, seed: u64, label: &str) {
    let w: [DVec3; L] = std::array::from_fn(|i| dir(LANE_DIRECTIONS[i].0, LANE_DIRECTIONS[i].1));
    let mut rng = Pcg64Mcg::new(0xfeed_1000 + seed as u128);
    let mut counts = [[0u64; COS_BINS * PHI_BINS]; L];
    for _ in 0..SAMPLES {
        let m = normals.sample_lanes(ndf, w.map(|w| -w), &mut rng);
        for (lane, m) in m.into_iter().enumerate() {
            assert!(m.is_finite() && (m.length() - 1.0).abs() < 1e-12 && m.z >= 0.0, "{label}: bad normal {m}");
            counts[lane][bin_of(m)] += 1;
        }
    }
    for lane in 0..L {
        let bins: Vec<WeightedBin> = counts[lane].iter().map(|&c| WeightedBin::of_count(c, SAMPLES)).collect();
        let test = chi_square(&bins, &law(ndf, normals, w[lane]), SAMPLES, 5.0);
        assert!(test.p_value > level, "{label} lane {lane}: histogram rejected\n{}", test.worst_cells(12));
    }
}

#[test]
fn lanes_draw_each_lanes_law() {
    let level = sidak(0.01, FAMILY);
    let r = Roughness { x: 0.5, y: 0.2 };
    check_lanes::<_, 4>(&Ggx(r), Normals::Visible, level, 0, "ggx lanes");
    check_lanes::<_, 2>(&Beckmann(r), Normals::Visible, level, 1, "beckmann lanes");
    check_lanes::<_, 2>(&Ggx(r), Normals::HammonRejection, level, 2, "hammon lanes");
}

/// Counts the 64-bit words a sampler draws, the cost of its rejection loops.
struct Counted(Pcg64Mcg, u64);

impl rand::TryRng for Counted {
    type Error = std::convert::Infallible;
    fn try_next_u32(&mut self) -> Result<u32, Self::Error> {
        self.1 += 1;
        Ok(rand::Rng::next_u32(&mut self.0))
    }
    fn try_next_u64(&mut self) -> Result<u64, Self::Error> {
        self.1 += 1;
        Ok(rand::Rng::next_u64(&mut self.0))
    }
    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Self::Error> {
        self.1 += dst.len().div_ceil(8) as u64;
        rand::Rng::fill_bytes(&mut self.0, dst);
        Ok(())
    }
}

/// §3.4: below the horizon the Student-T sampler's loops accept with probability at least 1/4
/// at every shape and direction, so that a sample costs O(1) up to the nadir (it took about
/// 1e6 passes at gamma = 1e6 within 1e-3 rad of the nadir before). 10^4 normals at gamma 1e6,
/// 1e3, 3.2 (at the switch between its proposals) and 1.6, from directions 1e-3, 1e-8, 1e-160
/// and 1e-300 rad from the nadir, are finite, unit, upper-hemisphere and face the direction,
/// and draw on average fewer than 40 random words each (measured: at most 21).
#[test]
fn student_t_visible_normals_near_the_nadir_are_cheap_and_valid() {
    const DRAWS: u64 = 10_000;
    let mut worst: f64 = 0.0;
    for gamma in [1e6, 1e3, 3.2, 1.6] {
        let ndf = StudentT::new(Roughness { x: 0.4, y: 0.9 }, gamma).unwrap();
        for eps in [1e-3, 1e-8, 1e-160, 1e-300] {
            for phi in [0.0f64, 1.1] {
                let w = DVec3::new(eps * phi.cos(), eps * phi.sin(), -1.0);
                let mut rng = Counted(Pcg64Mcg::new(0x5a_d1e5), 0);
                for _ in 0..DRAWS {
                    let m = ndf.sample_visible(w, &mut rng);
                    assert!(
                        m.is_finite() && (m.length() - 1.0).abs() < 1e-12 && m.z >= 0.0,
                        "gamma {gamma} w {w}: {m}"
                    );
                    assert!(w.dot(m) >= -1e-12, "gamma {gamma} w {w}: normal {m} faces away");
                }
                let words = rng.1 as f64 / DRAWS as f64;
                println!("gamma {gamma:e}, {eps:e} rad from the nadir, azimuth {phi}: {words:.2} words a normal");
                assert!(words < 40.0, "gamma {gamma} w {w}: {words} words a normal");
                worst = worst.max(words);
            }
        }
    }
    println!("most words a normal: {worst:.2}");
}
