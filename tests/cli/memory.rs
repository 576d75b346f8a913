//! A run's memory, estimated before any work (engine::resources, docs/reliability.md
//! "Memory"): over random valid configs the estimate is never below the measured peak
//! resident memory and at most 4x above it; a config over `--max-memory` is refused in one line
//! naming the fields to change, before anything is written; and a surface that scatters light
//! thousands of times (diffuse facets at alpha 100, which needed more than 6 GB before orders
//! were folded at 64 by default) runs in little memory.
//!
//! Case count: 12 configs (proptest, fixed seed, no persistence), each walked with 2 000
//! photons on 2 threads (in release on 2 cores, a few seconds in all).

use std::process::Command;

use proptest::prelude::*;
use proptest::test_runner::{Config as ProptestConfig, RngAlgorithm, TestRng, TestRunner};

/// The figure that follows `prefix` on a line of `stdout`, in bytes ("48 MB", "1.35 GB").
fn bytes_after(stdout: &str, prefix: &str) -> f64 {
    let line = stdout.lines().find(|l| l.starts_with(prefix)).unwrap_or_else(|| panic!("no {prefix:?} in\n{stdout}"));
    let mut words = line[prefix.len()..].split_whitespace();
    let value: f64 = words.next().unwrap().parse().unwrap();
    match words.next() {
        Some("MB") => value * 1e6,
        Some("GB") => value * 1e9,
        other => panic!("unit {other:?} in {line}"),
    }
}

/// Runs `toml` on 2 threads; returns the output and whether every case reached its last order
/// slot (`detector.max_order`, from run.json).
fn run(toml: &str) -> (std::process::Output, bool) {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, toml).unwrap();
    let out = dir.path().join("out");
    let output = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", config.to_str().unwrap(), "--out", out.to_str().unwrap(), "--threads", "2"])
        .output()
        .unwrap();
    let json: serde_json::Value =
        std::fs::read(out.join("run.json")).ok().and_then(|b| serde_json::from_slice(&b).ok()).unwrap_or_default();
    let max_order = &json["config"]["detector"]["max_order"];
    let cases = json["cases"].as_array().cloned().unwrap_or_default();
    let reached = !cases.is_empty() && cases.iter().all(|c| &c["energy"]["highest_order"] == max_order);
    (output, reached)
}

fn config_strategy() -> impl Strategy<Value = String> {
    let material = prop_oneof![
        Just("kind = \"conductor\"\n"),
        Just("kind = \"dielectric\"\neta = 1.5\n"),
        Just("kind = \"diffuse\"\n"),
        Just("kind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.9, 0.6, 0.3]\n"),
    ];
    let alpha = prop_oneof![Just(0.1), Just(0.5), Just(1.5), Just(100.0)];
    let bins = prop_oneof![Just((4, 8)), Just((32, 64)), Just((64, 128))];
    let max_order =
        prop_oneof![Just(String::new()), Just("max_order = 1\n".to_string()), Just("max_order = 6\n".to_string())];
    (material, alpha, bins, max_order, 1usize..5).prop_map(|(material, alpha, (cos, phi), max_order, cases)| {
        let thetas: Vec<String> = (0..cases).map(|i| (i * 20).to_string()).collect();
        format!(
            "paths = 2000\n[surface]\nalpha = {alpha}\n[material]\n{material}[incident]\ntheta_deg = [{}]\n\
             [detector]\ncos_theta_bins = {cos}\nphi_bins = {phi}\n{max_order}",
            thetas.join(", ")
        )
    })
}

#[test]
fn the_estimate_bounds_the_measured_peak_within_a_factor_of_four() {
    let config = ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() };
    let reached = std::cell::Cell::new(0);
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]));
    runner
        .run(&config_strategy(), |toml| {
            let (output, every_slot) = run(&toml);
            let stdout = String::from_utf8_lossy(&output.stdout);
            prop_assert!(output.status.success(), "{toml}\n{}", String::from_utf8_lossy(&output.stderr));
            let estimate = bytes_after(&stdout, "memory: about ");
            let peak = bytes_after(&stdout, "peak memory: ");
            // The printed figures are rounded to 1 MB.
            prop_assert!(peak <= estimate + 1e6, "peak {peak} above the estimate {estimate} for\n{toml}");
            // The estimate counts every order slot up to max_order; runs that stop short of it
            // hold less by the slots they do not reach.
            if every_slot {
                prop_assert!(estimate <= 4.0 * peak, "estimate {estimate} over 4x the peak {peak} for\n{toml}");
                reached.set(reached.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    assert!(reached.get() >= 3, "only {} of the random configs reached their last slot", reached.get());
}

#[test]
fn a_run_over_the_memory_limit_is_refused_before_any_work() {
    let toml = "paths = 1000\n[surface]\nalpha = [0.2, 0.5]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = [0, 40]\n[detector]\ncos_theta_bins = 256\nphi_bins = 512\n";
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, toml).unwrap();
    let out = dir.path().join("out");
    let output = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", config.to_str().unwrap(), "--out", out.to_str().unwrap(), "--max-memory", "200M"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    for named in ["--max-memory allows 210 MB", "detector.cos_theta_bins", "detector.max_order = 64", "--threads"] {
        assert!(stderr.contains(named), "{named:?} not in {stderr}");
    }
    assert!(!out.exists(), "a refused run created its output directory");
    let bad = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", config.to_str().unwrap(), "--max-memory", "lots"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("\"lots\" is not a size"));
}

#[test]
fn diffuse_facets_at_alpha_100_fold_their_orders_and_stay_small() {
    let (output, _) =
        run("paths = 2000\n[surface]\nalpha = 100\n[material]\nkind = \"diffuse\"\n[incident]\ntheta_deg = 30\n");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    // Before the default fold, this run held one slot per order reached (thousands).
    assert!(bytes_after(&stdout, "peak memory: ") < 300e6, "{stdout}");
    assert!(stdout.contains("64+"), "orders from 64 on are folded: {stdout}");
}
