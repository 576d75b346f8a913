//! Long runs: a run killed with SIGKILL at arbitrary moments and continued with `--resume`
//! ends with tables bit-identical to an uninterrupted run; precision targets stop cases at
//! the same point whatever the thread count.

use crate::common;

use std::process::Stdio;
use std::time::Duration;

use common::{smithwalk_quiet, tables};

const CONFIG: &str = r#"
paths = 3_000_000
seed = 5
[surface]
alpha = [0.3, 1.0]
[[material]]
kind = "dielectric"
eta = 1.5
[[material]]
kind = "conductor"
[incident]
theta_deg = [20, 70]
[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 4
"#;

#[test]
fn killed_and_resumed_runs_equal_an_uninterrupted_run() {
    let root = tempfile::tempdir().unwrap();
    let config = root.path().join("long.toml");
    std::fs::write(&config, CONFIG).unwrap();
    let config = config.to_str().unwrap();
    let reference = root.path().join("reference");
    let status = smithwalk_quiet(&["run", config, "--out", reference.to_str().unwrap()]).status().unwrap();
    assert!(status.success());

    let out = root.path().join("interrupted");
    let out_arg = out.to_str().unwrap();
    let args = ["run", config, "--out", out_arg, "--resume", "--checkpoint-seconds", "0.05"];
    // Each run is killed at a moment after it has written a new checkpoint, plus a delay
    // from a fixed linear congruential sequence (reproducible "random moments"). Waiting for
    // the checkpoint rather than for a fixed time keeps the test meaningful on a loaded
    // machine, where a process may need seconds before its first checkpoint.
    let checkpoint = out.join("checkpoint.bin");
    let written = || std::fs::metadata(&checkpoint).and_then(|m| m.modified()).ok();
    let mut state: u64 = 12345;
    let mut resumed_from_checkpoint = 0;
    for _ in 0..5 {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let delay = (state >> 33) % 300;
        let before = written();
        if before.is_some() {
            resumed_from_checkpoint += 1;
        }
        let mut child = smithwalk_quiet(&args).spawn().unwrap();
        let start = std::time::Instant::now();
        while written() == before && child.try_wait().unwrap().is_none() {
            assert!(start.elapsed() < Duration::from_secs(120), "no checkpoint written in 120 s");
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(Duration::from_millis(delay));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap(); // SIGKILL
        }
        child.wait().unwrap();
    }
    assert!(resumed_from_checkpoint >= 4, "only {resumed_from_checkpoint} runs resumed from a checkpoint");
    assert!(smithwalk_quiet(&args).status().unwrap().success());
    assert!(tables(&reference) == tables(&out), "resumed run differs from the uninterrupted run");
    assert!(!out.join("checkpoint.bin").exists(), "checkpoint left behind after the run finished");
}

#[test]
fn resume_refuses_a_checkpoint_of_another_config() {
    let root = tempfile::tempdir().unwrap();
    let config = root.path().join("long.toml");
    std::fs::write(&config, CONFIG).unwrap();
    let out = root.path().join("out");
    let (config, out_arg) = (config.to_str().unwrap(), out.to_str().unwrap());
    let mut child =
        smithwalk_quiet(&["run", config, "--out", out_arg, "--checkpoint-seconds", "0.05"]).spawn().unwrap();
    let start = std::time::Instant::now();
    while !out.join("checkpoint.bin").exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "no checkpoint written");
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let result = smithwalk_quiet(&["run", config, "--out", out_arg, "--resume", "--seed", "6"])
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(!result.status.success());
    assert!(String::from_utf8_lossy(&result.stderr).contains("another config"));
}

#[test]
fn precision_targets_stop_early_and_deterministically() {
    let toml = "paths = 20_000_000\nseed = 2\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 40\n[detector]\ncos_theta_bins = 4\nphi_bins = 4\n[precision]\ntarget_rel_stderr = 0.002\norders = 2\n";
    let config = smithwalk::setup::config::Config::parse(toml).unwrap();
    let one = smithwalk::simulate(&config, Some(1), false).unwrap();
    let two = smithwalk::simulate(&config, Some(2), false).unwrap();
    // More threads than a round has chunks (32): parts of later rounds are walked before the
    // stopping round is complete, and must be dropped.
    let many = smithwalk::simulate(&config, Some(40), false).unwrap();
    let photons = one.results[0].photons();
    assert_eq!(photons, two.results[0].photons(), "the stopping round depends on threads");
    assert_eq!(photons, many.results[0].photons(), "the stopping round depends on threads");
    assert!(photons < 20_000_000, "the target did not stop the case early");
    let albedos = one.results[0].albedo_stderrs(2);
    assert!(!albedos.is_empty() && albedos.iter().all(|&(mean, se)| se <= 0.002 * mean), "{albedos:?}");
    // E2 ~ 0.24 at this setting needs about (1-p)/(p r^2) ≈ 8e5 photons: it stopped near there.
    assert!(photons > 400_000, "{photons}");
    let (a, b, c) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    smithwalk::write_outputs(&one, &config, a.path()).unwrap();
    smithwalk::write_outputs(&two, &config, b.path()).unwrap();
    smithwalk::write_outputs(&many, &config, c.path()).unwrap();
    assert!(tables(a.path()) == tables(b.path()));
    assert!(tables(a.path()) == tables(c.path()));
}
