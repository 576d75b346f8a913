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
//!   `phi_m` that facet-forge's draws are counted on, by globally adaptive cubature (absolute
//!   tolerance 1e-8 a bin).

use std::f64::consts::TAU;
use std::io::BufRead;

use microsurface::DVec3;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::student_t::StudentT;
use numerics::quadrature::cubature;

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
    let density = |u: f64, phi: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        let m = DVec3::new(s * phi.cos(), s * phi.sin(), u);
        w.dot(m).max(0.0) * ndf.d(m) / area
    };
    let edges = |i: usize, width: f64| (i as f64 * width, (i + 1) as f64 * width);
    for ic in 0..BINS {
        for ip in 0..BINS {
            // Globally adaptive cubature of each bin; 1e-8 a bin is 1e-2 of a count in 10^6
            // draws, far below the Poisson noise of any cell the chi-square keeps.
            let bin =
                cubature(density, edges(ic, 1.0 / BINS as f64), edges(ip, TAU / BINS as f64), None, 1e-8, 4_000_000);
            assert!(!bin.capped, "bin ({ic}, {ip}): the cubature did not reach 1e-8 (error {:e})", bin.error);
            println!("{:.17e}", bin.value);
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
