//! `smithwalk compare` end to end: a run with a `[compare]` section writes models.csv and
//! compare.csv; the exact single-scattering model is accepted for every order-1 lobe (Sidak
//! family level 0.01 over the lobes), and the Wang correlated model is rejected for order 2 at
//! alpha 1, normal incidence, where docs/theory.md §6.6 puts a 27 % excess.

mod common;

const CONFIG: &str = r#"
paths = 1_000_000
seed = 17
[surface]
alpha = [1.0, [0.8, 0.2]]
[[material]]
kind = "conductor"
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 55]
[detector]
cos_theta_bins = 16
phi_bins = 32
max_order = 3
[compare]
models = ["single", "wang-correlated"]
paths = 500_000
"#;

#[test]
fn a_run_with_a_compare_section_measures_the_models() {
    let dir = tempfile::tempdir().unwrap();
    let (out, stdout) = common::run_config(dir.path(), "out", CONFIG);
    assert!(stdout.contains("single (exact oracle): 12 lobes") && stdout.contains("wang-correlated"), "{stdout}");
    assert!(out.join("models.csv").is_file());
    let mut reader = csv::Reader::from_path(out.join("compare.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (model, order, case, hemi, p, diff) =
        (col("model"), col("order"), col("case"), col("hemisphere"), col("p_value"), col("albedo_diff_se"));
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let single: Vec<&csv::StringRecord> = rows.iter().filter(|r| &r[model] == "single").collect();
    // 4 conductor lobes (R) and 4 dielectric cases with R and T.
    assert_eq!(single.len(), 12);
    let level = smithwalk::analysis::stats::sidak(0.01, single.len());
    for r in &single {
        let pv: f64 = r[p].parse().unwrap();
        assert!(pv > level, "single rejected: case {} {}: p = {pv}", &r[case], &r[hemi]);
        assert!(r[diff].parse::<f64>().unwrap().abs() < 4.0);
    }
    // Case 0: alpha 1, conductor, normal incidence.
    let wang_order2 = rows
        .iter()
        .find(|r| &r[model] == "wang-correlated" && &r[case] == "0" && &r[order] == "2" && &r[hemi] == "R")
        .unwrap();
    assert!(wang_order2[p].parse::<f64>().unwrap() < 1e-10);
    assert!(wang_order2[diff].parse::<f64>().unwrap() < -20.0, "E2 excess of the model not seen");
}
