//! `smithwalk compare --models lee2018` (Lee et al. 2018's specular V-grooves, docs/theory.md
//! §14) end to end: the report names it an approximation on another microsurface, skips what it
//! does not take with one line, and its bins hold what an independent computation gives: order 1
//! is the Torrance–Sparrow (V-cavity) lobe, integrated here by a quadrature written out below,
//! and with F = 1 all orders hold all the light. (The per-order physics is tested against a 2-D
//! ray tracer and two quadratures in crates/microsurface/tests/walk/vgroove_oracles.rs.)

use std::f64::consts::PI;

use smithwalk::microsurface::DVec3;

use crate::common;

/// GGX 0.5 conductors with F = 1 at 0 and 60 degrees (the cases the model takes), beside what it
/// does not take: dielectrics, anisotropic roughness, Student-T.
const WALK: &str = r#"
paths = 4_000
seed = 41
[surface]
ndf = ["ggx", "student-t"]
gamma = 2.0
alpha = [0.5, [0.5, 0.2]]
[[material]]
kind = "conductor"
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 60]
[detector]
cos_theta_bins = 4
phi_bins = 8
max_order = 2
"#;

/// The order-1 albedo of V-grooves on isotropic GGX `alpha` with F = 1 from `theta_i`: the
/// Cook–Torrance lobe with the Torrance–Sparrow shadowing-masking,
/// `∫ D(h) min(1, 2 h_z mu_i / wi·h, 2 h_z mu_o / wo·h) / (4 mu_i) dwo`, GGX's D written out,
/// by the midpoint rule in (s, phi), `mu_o = 1 - s^2`, 400 x 800 nodes.
fn torrance_sparrow_albedo(alpha: f64, theta_i: f64) -> f64 {
    let wi = DVec3::new(theta_i.sin(), 0.0, theta_i.cos());
    let ggx = |h: DVec3| {
        let t2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        1.0 / (PI * alpha * alpha * h.z.powi(4) * (1.0 + t2 / (alpha * alpha)).powi(2))
    };
    common::hemisphere_midpoint(400, |wo| {
        let h = (wi + wo).normalize();
        let g = (2.0 * h.z * wi.z / wi.dot(h)).min(2.0 * h.z * wo.z / wo.dot(h)).clamp(0.0, 1.0);
        ggx(h) * g / (4.0 * wi.z)
    })
}

#[test]
fn compare_names_lee2018_a_v_groove_model_skips_what_it_does_not_take_and_its_orders_are_right() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(dir.path(), "vgroove", WALK);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["compare", run.to_str().unwrap(), "--models", "lee2018", "--threads", "2"])
        .output()
        .expect("the smithwalk binary runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let stdout = String::from_utf8(output.stdout).unwrap();
    assert!(stdout.contains("lee2018 (approximation: V-groove microsurface, not Smith's): "), "{stdout}");
    let skips: Vec<&str> = stdout.lines().filter(|l| l.contains("lee2018: skips")).collect();
    assert_eq!(
        skips,
        ["  lee2018: skips 14 of 16 cases: not a conductor (8), anisotropic (2), Student-T NDF (4)"],
        "{stdout}"
    );
    let mut reader = csv::Reader::from_path(run.join("compare.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (case, order, theta, albedo) = (col("case"), col("order"), col("theta_i_deg"), col("albedo_model"));
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    // Two cases, three slots each (all, 1, 2+).
    assert_eq!(rows.len(), 6, "{rows:?}");
    for row in &rows {
        let theta_i: f64 = row[theta].parse().unwrap();
        let model: f64 = row[albedo].parse().unwrap();
        let expected = match &row[order] {
            // All orders with F = 1: every ray that enters a groove leaves it; orders beyond 64
            // (left out) hold 1.5e-4 at alpha 0.5, the bins' quadrature less.
            "0" => 1.0,
            "1" => torrance_sparrow_albedo(0.5, theta_i.to_radians()),
            _ => continue,
        };
        eprintln!("case {} order {}: model {model:.5}, expected {expected:.5}", &row[case], &row[order]);
        assert!((model - expected).abs() < 2e-3, "case {} order {}: {model} vs {expected}", &row[case], &row[order]);
    }
}
