//! What a user reads first: the energy balance `smithwalk run` prints, and the bin geometry
//! columns of `lobes.csv` (`theta_o_deg`, `phi_o_deg`, `solid_angle`). The geometry is checked
//! against closed forms computed here from the bin limits, not against the writer's own code.

use crate::common;

use std::collections::HashMap;
use std::path::Path;

/// Runs `smithwalk run` on `toml` into `out` of a fresh directory; returns its stdout and the
/// directory.
fn run(toml: &str) -> (String, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let (_, stdout) = common::run_config(dir.path(), "out", toml);
    (stdout, dir)
}

/// The table rows of the printed energy balance, split on runs of two or more spaces.
fn balance_rows(stdout: &str) -> Vec<Vec<String>> {
    let start = stdout.lines().position(|l| l.starts_with("case ")).expect("a header line starting with `case`");
    stdout
        .lines()
        .skip(start)
        .take_while(|l| !l.starts_with("wrote "))
        .map(|l| l.split("  ").map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect())
        .collect()
}

/// `absorbed` printed as `value ± stderr`.
fn value_and_stderr(cell: &str) -> (f64, f64) {
    let (v, se) = cell.split_once(" ± ").expect("absorbed is printed with its standard error");
    (v.parse().unwrap(), se.parse().unwrap())
}

#[test]
fn the_energy_balance_names_what_the_config_says_and_gives_every_channel() {
    // Lambertian facets of albedo (0.75, 0.5, 0.25) absorb; a dielectric absorbs nothing.
    let (stdout, _dir) = run(r#"
        paths = 40_000
        seed = 3
        [surface]
        alpha = [0.5, [1.0, 0.1]]
        [[material]]
        kind = "diffuse"
        albedo = [0.75, 0.5, 0.25]
        [[material]]
        kind = "dielectric"
        eta = 1.5
        [incident]
        theta_deg = 30
        [detector]
        cos_theta_bins = 4
        phi_bins = 8
        max_order = 3
    "#);
    // Every column is explained once, above the table.
    for column in ["R, T", "absorbed", "lost", "orders"] {
        assert!(stdout.lines().any(|l| l.trim_start().starts_with(column)), "no legend for `{column}`:\n{stdout}");
    }
    let rows = balance_rows(&stdout);
    let header = &rows[0];
    assert_eq!(
        header,
        &["case", "ndf", "alpha", "material", "channel", "theta_i_deg", "R", "T", "absorbed", "lost", "orders"]
    );
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    // 4 cases (2 roughnesses x 2 materials), each in 3 channels.
    assert_eq!(rows.len(), 1 + 4 * 3, "{stdout}");
    let mut channels: HashMap<String, Vec<String>> = HashMap::new();
    for row in &rows[1..] {
        assert_eq!(row.len(), header.len(), "{row:?}");
        assert_eq!(row[col("ndf")], "ggx");
        assert!(["0.5", "[1, 0.1]"].contains(&row[col("alpha")].as_str()), "{row:?}");
        assert_eq!(row[col("theta_i_deg")], "30.00");
        channels.entry(row[col("case")].clone()).or_default().push(row[col("channel")].clone());
        let number = |name: &str| row[col(name)].parse::<f64>().unwrap();
        let (absorbed, se) = value_and_stderr(&row[col("absorbed")]);
        let lost = number("lost");
        assert_eq!(lost, 0.0, "the true Smith walk loses nothing: {row:?}");
        // Every value is printed with 6 decimals: the balance closes to rounding.
        let sum = number("R") + number("T") + absorbed + lost;
        assert!((sum - 1.0).abs() <= 2e-6, "R + T + absorbed + lost = {sum}: {row:?}");
        // max_order = 3 folds orders >= 3; both materials send light that far at 40 000 photons.
        assert_eq!(row[col("orders")], "3+");
        if row[col("material")].starts_with("dielectric") {
            // Absorbs nothing: 0 within 4 standard errors, and the error is the roulette's.
            assert!(se > 0.0 && absorbed.abs() < 4.0 * se, "{row:?}");
        } else {
            assert_eq!(row[col("T")], "0.000000");
            // An albedo-0.25 facet absorbs most of the light; the walk's estimate is precise.
            assert!(absorbed > 0.2 && se < 0.01, "{row:?}");
        }
    }
    for (case, names) in channels {
        assert_eq!(names, ["r", "g", "b"], "case {case}");
    }
}

#[derive(Debug, serde::Deserialize)]
struct LobeRow {
    case: usize,
    order: usize,
    hemisphere: String,
    cos_lo: f64,
    cos_hi: f64,
    phi_lo_deg: f64,
    phi_hi_deg: f64,
    energy: f64,
    bsdf: f64,
    theta_o_deg: f64,
    phi_o_deg: f64,
    solid_angle: f64,
}

fn lobe_rows(dir: &Path) -> Vec<LobeRow> {
    csv::Reader::from_path(dir.join("lobes.csv")).unwrap().deserialize().map(|r| r.unwrap()).collect()
}

#[test]
fn lobes_csv_gives_bin_centres_and_solid_angles_for_every_bin_written() {
    let (cos_bins, phi_bins) = (8, 12);
    let (_, dir) = run(&format!(
        r#"
        paths = 20_000
        [surface]
        alpha = 0.7
        [[material]]
        kind = "conductor"
        [[material]]
        kind = "dielectric"
        eta = 1.5
        [incident]
        theta_deg = 50
        [detector]
        cos_theta_bins = {cos_bins}
        phi_bins = {phi_bins}
        "#
    ));
    let rows = lobe_rows(&dir.path().join("out"));
    let run: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/run.json")).unwrap()).unwrap();
    // Which rows are written: every bin of every order slot from 0 (all orders) to the highest
    // order that received light, in R, and in T for the dielectric only.
    let mut expected = 0;
    for (case, hemispheres) in [(0, 1), (1, 2)] {
        let highest = run["cases"][case]["energy"]["highest_order"].as_u64().unwrap() as usize;
        assert!(highest >= 3, "case {case}: highest order {highest}");
        let slots: Vec<usize> = rows.iter().filter(|r| r.case == case).map(|r| r.order).collect();
        assert_eq!(slots.iter().max(), Some(&highest));
        assert_eq!(slots.len(), (highest + 1) * hemispheres * cos_bins * phi_bins);
        expected += slots.len();
    }
    assert_eq!(rows.len(), expected);

    let mut solid_per_lobe: HashMap<(usize, usize, String), f64> = HashMap::new();
    for r in &rows {
        // Centres: the mid-point in cos theta (signed: T lies below the surface, theta > 90) and in phi.
        let theta = (0.5 * (r.cos_lo + r.cos_hi)).acos().to_degrees();
        assert!((r.theta_o_deg - theta).abs() < 1e-9, "{r:?}");
        assert_eq!(r.theta_o_deg > 90.0, r.hemisphere == "T", "{r:?}");
        assert!((r.phi_o_deg - 0.5 * (r.phi_lo_deg + r.phi_hi_deg)).abs() < 1e-9, "{r:?}");
        // Solid angle of a bin uniform in cos theta and phi: delta cos times delta phi.
        let solid = (r.cos_hi - r.cos_lo) * (r.phi_hi_deg - r.phi_lo_deg).to_radians();
        assert!((r.solid_angle - solid).abs() < 1e-12, "{r:?}");
        // `bsdf` is the energy over the projected solid angle, which for such a bin is the
        // solid angle times |cos| at the centre in cos.
        let projected = r.solid_angle * (0.5 * (r.cos_lo + r.cos_hi)).abs();
        assert!((r.bsdf - r.energy / projected).abs() <= 1e-12 * r.bsdf.abs().max(1.0), "{r:?}");
        *solid_per_lobe.entry((r.case, r.order, r.hemisphere.clone())).or_default() += r.solid_angle;
    }
    // Each lobe's bins tile a hemisphere: 2 pi steradians.
    for (lobe, total) in solid_per_lobe {
        assert!((total - std::f64::consts::TAU).abs() < 1e-12, "{lobe:?}: {total}");
    }
}
