//! `smithwalk compare` end to end: a run with a `[compare]` section writes models.csv and
//! compare.csv; the exact single-scattering model is accepted for every order-1 lobe (Sidak
//! family level 0.01 over the lobes), and the Wang correlated model is rejected for order 2 at
//! alpha 1, normal incidence, where docs/theory.md §6.6 puts a 27 % excess. In an RGB run the
//! exact single-scattering model is evaluated and accepted on every channel, each with its own
//! Fresnel.

use crate::common;

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

const RGB: &str = r#"
paths = 1_000_000
seed = 19
[surface]
alpha = 0.5
[[material]]
kind = "conductor"
fresnel = "schlick"
f0 = [0.2, 0.6, 1.0]
[[material]]
kind = "conductor"
fresnel = "exact"
eta = [0.143, 0.424, 1.367]
k = [3.983, 2.469, 1.864]
[[material]]
kind = "conductor"
[incident]
theta_deg = [0, 60]
[detector]
cos_theta_bins = 16
phi_bins = 32
max_order = 2
[compare]
models = ["single"]
"#;

#[test]
fn an_rgb_run_is_compared_with_single_scattering_on_every_channel() {
    // Three conductors (Schlick F0 0.2, 0.6, 1; gold; F = 1, whose channels are equal) at 0 and
    // 60 deg, 10^6 photons: the order-1 lobe of every case and channel is tested, the three equal
    // channels of F = 1 once, as channel r (4 cases x 3 + 2 cases x 1 = 14 lobes), none is
    // rejected at the Sidak level of family level 0.01, and the albedos differ by less than 4
    // standard errors. A model that gave g and b channel r's Fresnel would be rejected there:
    // at 10^6 photons the Schlick channels' order-1 albedos differ by hundreds of standard errors.
    let dir = tempfile::tempdir().unwrap();
    let (out, stdout) = common::run_config(dir.path(), "rgb", RGB);
    assert!(stdout.contains("single (exact oracle): 14 lobes"), "{stdout}");
    let mut reader = csv::Reader::from_path(out.join("compare.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (case, channel, p, diff, albedo) =
        (col("case"), col("channel"), col("p_value"), col("albedo_diff_se"), col("albedo_model"));
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let level = smithwalk::analysis::stats::sidak(0.01, 14);
    let mut lobes: Vec<(String, String)> = Vec::new();
    for r in &rows {
        let pv: f64 = r[p].parse().unwrap();
        assert!(pv > level, "single rejected: case {} channel {}: p = {pv}", &r[case], &r[channel]);
        assert!(r[diff].parse::<f64>().unwrap().abs() < 4.0, "case {} channel {}", &r[case], &r[channel]);
        lobes.push((r[case].to_string(), r[channel].to_string()));
    }
    lobes.sort();
    // Cases 0-3 (Schlick, gold) per channel, cases 4-5 (F = 1) once.
    let expected: Vec<(String, String)> = (0..6)
        .flat_map(|c| ["b", "g", "r"].map(|ch| (c.to_string(), ch.to_string())))
        .filter(|(c, ch)| c.as_str() < "4" || ch == "r")
        .collect();
    assert_eq!(lobes, expected, "one lobe per case and channel of a per-channel material, one per one-valued case");
    // The Schlick conductor at normal incidence (case 0): its channels' model albedos rise with F0.
    let model_albedo = |ch: &str| -> f64 {
        rows.iter().find(|r| &r[case] == "0" && &r[channel] == ch).unwrap()[albedo].parse().unwrap()
    };
    assert!(model_albedo("r") < model_albedo("g") && model_albedo("g") < model_albedo("b"));
}

#[test]
fn single_says_which_cases_it_skips_and_why() {
    // A dielectric lit from outside and from inside at two angles: single scattering is given
    // for light from outside alone, and the report says it skips the other 2 of the 4 cases.
    let dir = tempfile::tempdir().unwrap();
    let (_, stdout) = common::run_config(
        dir.path(),
        "sides",
        r#"
paths = 20_000
seed = 23
[surface]
alpha = 0.5
[material]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 40]
side = ["outside", "inside"]
[detector]
cos_theta_bins = 4
phi_bins = 8
max_order = 2
[compare]
models = ["single"]
"#,
    );
    assert!(stdout.contains("single (exact oracle): 4 lobes"), "{stdout}");
    assert!(stdout.contains("  single: skips 2 of 4 cases: light from inside\n"), "{stdout}");
}

#[test]
fn hammon_fit_says_which_cases_it_skips_and_why() {
    // A Hammon facet and a conductor at one angle: Hammon's fit is given for the Hammon facet
    // alone, and the report says it skips the other case.
    let dir = tempfile::tempdir().unwrap();
    let (_, stdout) = common::run_config(
        dir.path(),
        "materials",
        r#"
paths = 20_000
seed = 29
[surface]
alpha = 0.5
[[material]]
kind = "hammon"
[[material]]
kind = "conductor"
[incident]
theta_deg = 30
[detector]
cos_theta_bins = 4
phi_bins = 8
max_order = 2
[compare]
models = ["hammon-fit"]
"#,
    );
    assert!(stdout.contains("  hammon-fit: skips 1 of 2 cases: not a Hammon facet\n"), "{stdout}");
}
