//! Shared helpers for the integration tests.
#![allow(dead_code)]

use smithwalk::Simulation;
use smithwalk::analysis::stats::WeightedBin;
use smithwalk::engine::detector::{Detector, Hemisphere, OrderTallies};
use smithwalk::engine::run::CaseResult;
use smithwalk::setup::config::Config;

// `dir` and `two_sided_z`, shared with the physics crate's tests.
#[path = "../../crates/microsurface/tests/common/mod.rs"]
mod physics;
#[allow(unused_imports)] // not every test file uses them
pub use physics::{dir, hemisphere_midpoint, two_sided_z};

/// Both facet kinds (a conductor, and a dielectric that transmits) at two roughnesses and two
/// incident angles on an 8 x 16 grid, seed 11, without `paths` and `max_order` (the tests add
/// them, `paths` before and `max_order` after).
pub const CASES: &str = r#"
seed = 11
[surface]
alpha = [0.3, 1.0]
[[material]]
kind = "conductor"
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 60]
[detector]
cos_theta_bins = 8
phi_bins = 16
"#;

/// The `smithwalk` binary with `args`, its output discarded.
pub fn smithwalk_quiet(args: &[&str]) -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk"));
    c.args(args).stdout(std::process::Stdio::null()).stderr(std::process::Stdio::null());
    c
}

/// `smithwalk ARGS`, its exit status and output captured.
pub fn smithwalk(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk")).args(args).output().expect("the smithwalk binary runs")
}

/// `smithwalk compare RUN ARGS`, asserting that it succeeds; returns what it printed.
pub fn compare(run: &std::path::Path, args: &[&str]) -> String {
    let output = smithwalk(&[&["compare", run.to_str().unwrap()], args].concat());
    assert!(output.status.success(), "compare {args:?}: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8(output.stdout).unwrap()
}

/// Writes `toml` to `dir/<name>.toml` and runs `smithwalk run` on it into `dir/<name>`,
/// asserting that it succeeds; returns the run directory and what the run printed.
pub fn run_config(dir: &std::path::Path, name: &str, toml: &str) -> (std::path::PathBuf, String) {
    let config = dir.join(format!("{name}.toml"));
    std::fs::write(&config, toml).unwrap();
    let out = dir.join(name);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .expect("the smithwalk binary runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    (out, String::from_utf8(output.stdout).unwrap())
}

/// The bytes of a run directory's `lobes.csv` and `summary.csv`.
pub fn tables(dir: &std::path::Path) -> (Vec<u8>, Vec<u8>) {
    (std::fs::read(dir.join("lobes.csv")).unwrap(), std::fs::read(dir.join("summary.csv")).unwrap())
}

/// Parses a TOML config and runs it on `threads` threads without a progress bar.
pub fn simulate(toml: &str, threads: usize) -> Simulation {
    let config = Config::parse(toml).expect("test config is valid");
    smithwalk::simulate(&config, Some(threads), false).expect("simulation runs")
}

/// Parses a TOML config and runs it with `estimator` (the walk or a model) on 2 threads.
pub fn simulate_with(toml: &str, estimator: smithwalk::engine::run::Estimator) -> Simulation {
    let config = Config::parse(toml).expect("test config is valid");
    let options = smithwalk::RunOptions {
        estimator,
        shard: smithwalk::engine::run::Shard::WHOLE,
        threads: Some(2),
        show_progress: false,
        max_memory: None,
    };
    smithwalk::simulate_from(&config, &options, None, &mut |_, _, _| Ok(())).expect("simulation runs")
}

/// The single-channel detector of case `i`.
pub fn mono(sim: &Simulation, i: usize) -> &Detector<1> {
    match &sim.results[i] {
        CaseResult::Mono(d) => d,
        CaseResult::Rgb(_) => panic!("expected a mono case"),
    }
}

/// The three-channel detector of case `i` (an RGB run).
pub fn rgb(sim: &Simulation, i: usize) -> &Detector<3> {
    match &sim.results[i] {
        CaseResult::Rgb(d) => d,
        CaseResult::Mono(_) => panic!("expected an RGB case"),
    }
}

/// The per-photon moments of every bin of one order slot and hemisphere.
pub fn weighted_bins(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> Vec<WeightedBin> {
    channel_bins(d, slot, hemisphere, 0)
}

/// The per-photon moments of every bin of one order slot and hemisphere in colour channel
/// `channel`.
pub fn channel_bins<const C: usize>(
    d: &Detector<C>,
    slot: usize,
    hemisphere: Hemisphere,
    channel: usize,
) -> Vec<WeightedBin> {
    let n = d.tallies.photons as f64;
    let bins = d.grid.bins();
    let empty = OrderTallies { bins: vec![Default::default(); 2 * bins], albedo: Default::default() };
    let tallies = d.tallies.orders.get(slot).unwrap_or(&empty);
    tallies.bins[hemisphere as usize * bins..(hemisphere as usize + 1) * bins]
        .iter()
        .map(|t| WeightedBin { mean: t.sum[channel].to_f64() / n, second_moment: t.sum_sq[channel].to_f64() / n })
        .collect()
}

/// Photon counts of every bin of one order slot and hemisphere.
pub fn bin_counts(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> Vec<u64> {
    let bins = d.grid.bins();
    d.tallies.orders.get(slot).map_or(vec![0; bins], |t| {
        t.bins[hemisphere as usize * bins..(hemisphere as usize + 1) * bins].iter().map(|b| b.count).collect()
    })
}

/// Albedo and standard error of one order slot and hemisphere.
pub fn albedo(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> (f64, f64) {
    channel_albedo(d, slot, hemisphere, 0)
}

/// Albedo and standard error of one order slot and hemisphere in colour channel `channel`.
pub fn channel_albedo<const C: usize>(
    d: &Detector<C>,
    slot: usize,
    hemisphere: Hemisphere,
    channel: usize,
) -> (f64, f64) {
    d.tallies
        .orders
        .get(slot)
        .map_or((0.0, 0.0), |t| t.albedo[hemisphere as usize].mean_and_stderr(d.tallies.photons, channel))
}

/// docs/theory.md §9.4: per-order albedos E1..E6 of the random walk, conductor F = 1, isotropic
/// GGX, (alpha, theta_i deg); 2*10^6 photons, SE <= 4e-4, rounded to 4 decimals.
pub const CONDUCTOR_ORDERS: [(f64, f64, [f64; 6]); 8] = [
    (0.5, 0.0, [0.6883, 0.2316, 0.0642, 0.0135, 0.0021, 0.0003]),
    (0.5, 30.0, [0.6821, 0.2396, 0.0636, 0.0125, 0.0020, 0.0002]),
    (0.5, 60.0, [0.6982, 0.2400, 0.0524, 0.0083, 0.0010, 0.0001]),
    (0.5, 80.0, [0.8057, 0.1711, 0.0212, 0.0019, 0.0001, 0.0000]),
    (1.0, 0.0, [0.3069, 0.3225, 0.2110, 0.1025, 0.0397, 0.0127]),
    (1.0, 30.0, [0.3347, 0.3284, 0.2009, 0.0904, 0.0325, 0.0098]),
    (1.0, 60.0, [0.4509, 0.3307, 0.1506, 0.0506, 0.0135, 0.0030]),
    (1.0, 80.0, [0.6681, 0.2585, 0.0612, 0.0105, 0.0015, 0.0002]),
];

/// Checks per-order albedos (orders 1, 2, ...) of `d` against a reference row from
/// `ref_photons` photons rounded to 4 decimals: within 4 combined standard errors (ours, the
/// reference's binomial SE and its rounding).
pub fn check_orders(d: &Detector<1>, hemisphere: Hemisphere, reference: &[f64], ref_photons: f64, label: &str) {
    let rounding: f64 = 5e-5 / 3f64.sqrt();
    for (k, &r) in reference.iter().enumerate() {
        let (e, se) = albedo(d, k + 1, hemisphere);
        let se_ref = (r * (1.0 - r) / ref_photons).sqrt();
        let tol = 4.0 * (se * se + se_ref * se_ref + rounding * rounding).sqrt();
        assert!((e - r).abs() <= tol, "{label} E{}: {e:.5} +- {se:.5}, reference {r} (tol {tol:.5})", k + 1);
    }
}

/// Two estimators of the same lobes agree: for each order slot, a two-sample chi-square with
/// per-photon variances, pooling bins with fewer than 10 photons in `a` (at least 8 cells
/// left), at `level`; for each order of `orders`, the albedos by a z test below `z_limit`.
#[allow(clippy::too_many_arguments)]
pub fn assert_lobes_agree(
    a: &Detector<1>,
    b: &Detector<1>,
    hemisphere: Hemisphere,
    slots: &[usize],
    orders: std::ops::RangeInclusive<usize>,
    level: f64,
    z_limit: f64,
    label: &str,
) {
    for &slot in slots {
        let test = smithwalk::analysis::stats::two_sample(
            &weighted_bins(a, slot, hemisphere),
            a.tallies.photons,
            &weighted_bins(b, slot, hemisphere),
            b.tallies.photons,
            &bin_counts(a, slot, hemisphere),
            10,
        );
        println!(
            "{label} slot {slot} {hemisphere:?}: chi2 {:.1} dof {} p {:.3e}",
            test.statistic, test.dof, test.p_value
        );
        assert!(test.dof >= 8, "{label} slot {slot} {hemisphere:?}: only {} cells", test.dof);
        assert!(test.p_value > level, "{label} slot {slot} {hemisphere:?}: rejected\n{}", test.worst_cells(10));
    }
    for k in orders {
        let (x, y) = (albedo(a, k, hemisphere), albedo(b, k, hemisphere));
        let z = (x.0 - y.0) / (x.1 * x.1 + y.1 * y.1).sqrt();
        assert!(z.abs() < z_limit, "{label} order {k} {hemisphere:?}: {x:?} vs {y:?}, z = {z:.2}");
    }
}

/// Skips a test (or a part of it, `what`) that needs an optional tool, visibly: one line
/// `skipped: WHAT: REASON` written straight to the process's stderr, which the test harness does
/// not capture (it captures `eprintln!` and hides it for a passing test), so the line shows in
/// plain `cargo test` output and `cargo test 2>&1 | grep -c '^skipped:'` counts the skips. Under
/// CI (`CI` set and not empty, `false` or `0`; `.ci/run` sets it and installs every tool) a
/// missing tool fails the test instead.
pub fn skip(what: &str, reason: &str) {
    use std::io::Write as _;
    let in_ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
    assert!(!in_ci, "CI must run {what}, but {reason}");
    let _ = writeln!(std::io::stderr(), "skipped: {what}: {reason}");
}

/// Reseals the comparison in `dir` after a test changed its tables: `compare.json` records
/// their new digests and its own, so that a reader gets past the seal to the checks behind it.
pub fn reseal_comparison(dir: &std::path::Path) {
    use sha2::Digest;
    let hex = |bytes: &[u8]| -> String { sha2::Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect() };
    let path = dir.join("compare.json");
    let mut record: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    for table in ["models.csv", "compare.csv"] {
        let bytes = std::fs::read(dir.join(table)).unwrap();
        record["files"][table] = serde_json::json!({ "bytes": bytes.len(), "sha256": hex(&bytes) });
    }
    record["self_sha256"] = serde_json::json!("0".repeat(64));
    let mut text = serde_json::to_vec_pretty(&record).unwrap();
    let key = b"\"self_sha256\": \"";
    let at = text.windows(key.len()).rposition(|w| w == key).unwrap() + key.len();
    let digest = hex(&text);
    text[at..at + 64].copy_from_slice(digest.as_bytes());
    std::fs::write(path, text).unwrap();
}
