//! `cui2023-released` (Cui et al. 2023 as its released code computes it, docs/theory.md §7.3) end
//! to end on conductors:
//!
//! * `compare --models cui2023-released,exact-position-free` runs; a diffuse case is skipped with
//!   a one-line note; every lobe of cui2023-released (orders 1, 2, 3, 4+ and all; GGX and
//!   Beckmann, alpha 1 and (1.2, 0.6), a conductor with exact Fresnel (eta 0.2, k 3), at 0 and
//!   70 degrees: 8 cases; 4*10^5 photons each side, 8 x 16 bins) agrees with the walk by the two-sample chi-square at Sidak family
//!   level 0.01. Orders 1 and 2 are fixed by the term equalling `S` on one-turn paths (every
//!   path of order <= 2 has one turn); higher orders because a conductor's chain never turns
//!   twice (§7.3). The albedo differences per order are printed.
//! * On one chain of directions (`compare` with three chain models), cui2023-released equals
//!   exact-position-free bin by bin to 1e-9 relative: the two evaluate different formulas
//!   (the released path term, the exact depth profile) that agree on every path a conductor
//!   produces.

use crate::common;

const CONFIG: &str = r#"
paths = 400_000
seed = 39
[surface]
ndf = ["ggx", "beckmann"]
alpha = [1.0, [1.2, 0.6]]
[[material]]
kind = "conductor"
fresnel = "exact"
eta = 0.2
k = 3.0
[[material]]
kind = "diffuse"
albedo = 0.9
[incident]
theta_deg = [0, 70]
[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 4
[compare]
models = ["cui2023-released", "exact-position-free"]
"#;

#[test]
fn cui2023_released_agrees_with_the_walk_and_the_exact_chain_on_conductors() {
    let dir = tempfile::tempdir().unwrap();
    let (out, stdout) = common::run_config(dir.path(), "out", CONFIG);
    assert!(stdout.contains("cui2023-released: skips 8 of 16 cases: not a conductor"), "{stdout}");
    let mut reader = csv::Reader::from_path(out.join("compare.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (model, order, case, p, diff) =
        (col("model"), col("order"), col("case"), col("p_value"), col("albedo_diff_se"));
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let cui: Vec<&csv::StringRecord> = rows.iter().filter(|r| &r[model] == "cui2023-released").collect();
    // 8 conductor cases, 5 slots each.
    assert_eq!(cui.len(), 40);
    let level = smithwalk::analysis::stats::sidak(0.01, cui.len());
    for r in &cui {
        let pv: f64 = r[p].parse().unwrap();
        eprintln!("cui2023-released case {} order {}: p = {pv:.3}, albedo diff {} SE", &r[case], &r[order], &r[diff]);
        assert!(pv > level, "case {} order {}: p = {pv}", &r[case], &r[order]);
    }

    // One chain of directions: the two models' lobes are equal bin by bin.
    common::compare(&out, &["--models", "wang-correlated,exact-position-free,cui2023-released", "--paths", "100000"]);
    let mut reader = csv::Reader::from_path(out.join("models.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (exact, cui) = (col("exact-position-free"), col("cui2023-released"));
    let mut compared = 0;
    for r in reader.records().map(Result::unwrap) {
        let (Ok(e), Ok(c)) = (r[exact].parse::<f64>(), r[cui].parse::<f64>()) else { continue };
        assert!((e - c).abs() <= 1e-9 * e.abs().max(1e-300), "{r:?}");
        compared += usize::from(e > 0.0);
    }
    assert!(compared > 1000, "{compared} bins compared");
}
