//! smithwalk's side of the comparison with facet-forge (docs/validation.md, "Side by side with
//! facet-forge"; scripts/peers/facet_forge/): prints the exact Student-T quantities that the
//! peer's fitted ones are held against. `cargo run --release -p smithwalk-microsurface
//! --example peer_student_t -- MODE`:
//!
//! - `lambda`: reads lines `ndf gamma alpha theta_deg` (ndf `student-t` or `ggx`, the direction
//!   at polar angle theta in the x-z plane, below the horizon past 90) from standard input and
//!   prints `Lambda(w)` (§1.4, §1.6) and the projected area `A(w)` (§1.5), which is facet-forge's
//!   cross section `sigma(w)`.
//! - `vndf-bins NDF GAMMA ALPHA THETA_DEG` (NDF `student-t` or `beckmann`, whose GAMMA is
//!   ignored): the probabilities of the visible-normal density
//!   `D_w(m) = <w·m>_+ D(m) / A(w)` (§3.1) on the 16 x 16 grid uniform in `cos theta_m` x
//!   `phi_m` that facet-forge's draws are counted on, by adaptive quadrature (as in
//!   tests/distributions/visible_normals.rs: 4 x 4 sub-panels a bin, absolute tolerance 1e-8).

use std::f64::consts::TAU;
use std::io::BufRead;

use microsurface::DVec3;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::student_t::StudentT;
use numerics::quadrature::integrate_2d_nested;

const BINS: usize = 16;

/// The unit direction at polar angle `theta` (degrees) in the x-z plane.
fn dir(theta: f64) -> DVec3 {
    let (s, c) = theta.to_radians().sin_cos();
    DVec3::new(s, 0.0, c)
}

fn student_t(gamma: f64, alpha: f64) -> StudentT {
    StudentT::new(Roughness::isotropic(alpha), gamma)
        .unwrap_or_else(|| panic!("gamma {gamma}: must be finite and above 3/2"))
}

fn lambda() {
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("stdin");
        let f: Vec<&str> = line.split_whitespace().collect();
        let [ndf, gamma, alpha, theta] = f[..] else { panic!("expected 'ndf gamma alpha theta_deg', got '{line}'") };
        let num = |s: &str| s.parse::<f64>().unwrap_or_else(|_| panic!("not a number: '{s}'"));
        let (gamma, alpha, w) = (num(gamma), num(alpha), dir(num(theta)));
        let (l, a) = match ndf {
            "student-t" => {
                let n = student_t(gamma, alpha);
                (n.lambda(w), n.projected_area(w))
            }
            "ggx" => {
                let n = Ggx(Roughness::isotropic(alpha));
                (n.lambda(w), n.projected_area(w))
            }
            _ => panic!("ndf '{ndf}': allowed are student-t and ggx"),
        };
        println!("{l:.17e} {a:.17e}");
    }
}

fn vndf_bins(ndf: &str, gamma: f64, alpha: f64, theta: f64) {
    match ndf {
        "student-t" => print_vndf_bins(&student_t(gamma, alpha), dir(theta)),
        "beckmann" => print_vndf_bins(&Beckmann(Roughness::isotropic(alpha)), dir(theta)),
        _ => panic!("ndf '{ndf}': allowed are student-t and beckmann"),
    }
}

fn print_vndf_bins<N: Ndf>(ndf: &N, w: DVec3) {
    let area = ndf.projected_area(w);
    let density = |m: DVec3| w.dot(m).max(0.0) * ndf.d(m) / area;
    for ic in 0..BINS {
        for ip in 0..BINS {
            let u = (ic as f64 / BINS as f64, (ic + 1) as f64 / BINS as f64);
            let p = (ip as f64 * TAU / BINS as f64, (ip + 1) as f64 * TAU / BINS as f64);
            let over_u = |phi: f64| {
                let (sin_phi, cos_phi) = phi.sin_cos();
                move |u: f64| {
                    let s = (1.0 - u * u).max(0.0).sqrt();
                    density(DVec3::new(s * cos_phi, s * sin_phi, u))
                }
            };
            let mut sum = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    let su = (u.0 + (u.1 - u.0) * a as f64 / 4.0, u.0 + (u.1 - u.0) * (a + 1) as f64 / 4.0);
                    let sp = (p.0 + (p.1 - p.0) * b as f64 / 4.0, p.0 + (p.1 - p.0) * (b + 1) as f64 / 4.0);
                    sum += integrate_2d_nested(over_u, sp, su, 1e-8).0;
                }
            }
            println!("{sum:.17e}");
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |s: &String| s.parse::<f64>().unwrap_or_else(|_| panic!("not a number: '{s}'"));
    match args.as_slice() {
        [m] if m == "lambda" => lambda(),
        [m, n, g, a, t] if m == "vndf-bins" => vndf_bins(n, num(g), num(a), num(t)),
        _ => panic!(
            "usage: peer_student_t lambda < 'ndf gamma alpha theta_deg' lines | vndf-bins NDF GAMMA ALPHA THETA_DEG"
        ),
    }
}
