//! Bit-identical outputs for any thread count (the detector sums in fixed point), and the
//! command line's handling of bad input: one clear error naming the field, the value and what
//! is allowed, a non-zero exit, and no output file.

use std::path::Path;
use std::process::Command;

use smithwalk::setup::config::Config;

const CONFIG: &str = r#"
paths = 40_000
seed = 77
[surface]
ndf = ["ggx", "beckmann"]
alpha = [0.3, [1.2, 0.4]]
[[material]]
kind = "dielectric"
eta = 1.5
[[material]]
kind = "hammon"
f0 = [0.04, 0.02, 0.01]
albedo = [0.75, 0.5, 0.25]
[[material]]
kind = "conductor"
fresnel = "exact"
eta = [0.2, 0.9, 1.1]
k = [3.0, 2.5, 2.2]
[incident]
theta_deg = [10, 70]
phi_deg = 25
"#;

/// lobes.csv and summary.csv of `config` run on `threads` threads, written into `dir`.
fn outputs(config: &Config, threads: usize, dir: &Path) -> (Vec<u8>, Vec<u8>) {
    let sim = smithwalk::simulate(config, Some(threads), false).unwrap();
    assert_eq!(sim.results[0].photons(), config.paths);
    smithwalk::write_outputs(&sim, config, dir).unwrap();
    (std::fs::read(dir.join("lobes.csv")).unwrap(), std::fs::read(dir.join("summary.csv")).unwrap())
}

#[test]
fn one_and_two_threads_give_identical_files() {
    let config = Config::parse(CONFIG).unwrap();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let one = outputs(&config, 1, a.path());
    let two = outputs(&config, 2, b.path());
    assert!(one.0 == two.0, "lobes.csv differs between 1 and 2 threads");
    assert!(one.1 == two.1, "summary.csv differs between 1 and 2 threads");
    // The run is RGB with splitting: the channel column is there and nothing is NaN or inf.
    let text = String::from_utf8(one.0).unwrap();
    assert!(text.lines().next().unwrap().contains(",channel,"));
    assert!(!text.contains("NaN") && !text.contains("inf"));
}

/// A run of several rounds (32 chunks of 16384 photons each) on one thread and on more
/// threads than a round has chunks, where threads walk ahead into later rounds while earlier
/// ones finish: identical tables.
#[test]
fn rounds_walked_ahead_give_identical_files() {
    let toml = "paths = 1_200_000\nseed = 5\n[surface]\nalpha = 0.7\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 50\n";
    let config = Config::parse(toml).unwrap();
    let tables = |threads| outputs(&config, threads, tempfile::tempdir().unwrap().path());
    let one = tables(1);
    assert!(one == tables(2), "2 threads differ from 1");
    assert!(one == tables(37), "37 threads differ from 1");
}

fn smithwalk(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_smithwalk")).args(args).output().expect("binary runs")
}

const GOOD: &str =
    "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n";

/// Runs the CLI on a config with `from` replaced by `to`; expects a failure mentioning every
/// string of `expect` and no output file.
fn rejects(from: &str, to: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("bad.toml");
    let text = GOOD.replacen(from, to, 1);
    assert_ne!(text, GOOD, "replacement {from:?} did not apply");
    std::fs::write(&config, text).unwrap();
    let out = dir.path().join("out");
    let result = smithwalk(&["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success(), "{from} -> {to}: accepted");
    for e in expect {
        assert!(stderr.contains(e), "{from} -> {to}: error {stderr:?} does not mention {e:?}");
    }
    assert_eq!(stderr.matches("error:").count(), 1, "one error expected, got {stderr:?}");
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none(), "output written for a bad config");
}

/// (text to replace in a good config, its replacement, what the error must mention)
const BAD_INPUT: [(&str, &str, &[&str]); 15] = [
    ("paths = 1000\n", "", &["`paths` is missing", "photons per case"]),
    ("[surface]", "colour = 3\n[surface]", &["`colour` is not a known key", "line 2", "`surface`"]),
    ("alpha = 0.5", "alpha = -0.5", &["surface.alpha", "-0.5", "> 0"]),
    ("alpha = 0.5", "alpha = [0.5, 0.0]", &["surface.alpha", "0", "> 0"]),
    ("alpha = 0.5", "alpha = []", &["surface.alpha", "at least one value"]),
    ("kind = \"conductor\"", "kind = \"dielectric\"\neta = -1.5", &["material.eta", "-1.5", "> 0"]),
    ("kind = \"conductor\"", "kind = \"dielectric\"\neta = 1.0", &["material.eta", "!= 1"]),
    (
        "kind = \"conductor\"",
        "kind = \"conductor\"\nfresnel = \"exact\"",
        &["`material.eta` is missing", "fresnel = \"exact\" needs"],
    ),
    ("theta_deg = 30", "theta_deg = 90", &["incident.theta_deg", "90", "[0, 90)"]),
    ("theta_deg = 30", "theta_deg = -1", &["incident.theta_deg", "-1"]),
    ("theta_deg = 30", "theta_deg = []", &["incident.theta_deg", "at least one"]),
    ("theta_deg = 30", "theta_deg = 30\nside = \"inside\"", &["incident.side", "dielectric"]),
    (
        "theta_deg = 30\n",
        "theta_deg = 30\n[detector]\ncos_theta_bins = 0\n",
        &["detector.cos_theta_bins", "0", "1 to 4096"],
    ),
    ("theta_deg = 30\n", "theta_deg = 30\n[detector]\nphi_bins = 0\n", &["detector.phi_bins", "0"]),
    ("theta_deg = 30\n", "theta_deg = 30\n[energy]\nthreshold = 0.0\n", &["energy.threshold", "0"]),
];

#[test]
fn bad_input_is_rejected_with_a_clear_error_and_no_output() {
    for (from, to, expect) in BAD_INPUT {
        rejects(from, to, expect);
    }
}

/// A temporary directory holding a valid config file.
fn good_config() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("good.toml");
    std::fs::write(&config, GOOD).unwrap();
    (dir, config)
}

#[test]
fn unwritable_output_directory_is_rejected_before_running() {
    let (dir, config) = good_config();
    // A regular file where the output directory should be.
    let blocker = dir.path().join("blocker");
    std::fs::write(&blocker, "").unwrap();
    let out = blocker.join("out");
    let result = smithwalk(&["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success());
    assert!(stderr.contains("cannot create the output directory") && stderr.contains("blocker"), "{stderr}");
}

#[test]
fn a_good_run_writes_all_three_files() {
    let (dir, config) = good_config();
    let out = dir.path().join("out");
    let result =
        smithwalk(&["run", config.to_str().unwrap(), "--out", out.to_str().unwrap(), "--threads", "1", "--seed", "3"]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    for f in ["lobes.csv", "summary.csv", "run.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(json["seed"], 3);
    assert_eq!(json["paths"], 1000);
}

#[test]
fn sweeps_parse_unambiguously_and_round_trip() {
    use smithwalk::setup::config::{Alpha, OneOrMany};
    let parse = |alpha: &str| {
        let text = GOOD.replace("alpha = 0.5", &format!("alpha = {alpha}"));
        let config = Config::parse(&text).unwrap();
        // The resolved config written to run.json and shard files parses back to itself.
        let again = Config::parse(&toml::to_string(&config).unwrap()).unwrap();
        assert_eq!(again, config, "{alpha}");
        config.surface.alpha.values()
    };
    assert_eq!(parse("[0.5, 1.0]"), vec![Alpha::Isotropic(0.5), Alpha::Isotropic(1.0)]);
    assert_eq!(parse("[[0.5, 1.0]]"), vec![Alpha::Anisotropic([0.5, 1.0])]);
    assert_eq!(parse("0.25"), vec![Alpha::Isotropic(0.25)]);
    assert_eq!(parse("[0.1, [1.0, 0.1]]"), vec![Alpha::Isotropic(0.1), Alpha::Anisotropic([1.0, 0.1])]);
    assert!(matches!(Config::parse(GOOD).unwrap().surface.alpha, OneOrMany::One(_)));
}

#[test]
fn bench_rejects_bad_counts_with_a_clear_error_and_no_table() {
    for (args, expect) in [
        (["--paths", "0", "--repeats", "1"], ["`--paths` = 0", "at least 2"]),
        (["--paths", "1", "--repeats", "1"], ["`--paths` = 1", "at least 2"]),
        (["--paths", "100", "--repeats", "0"], ["`--repeats` = 0", "at least 1"]),
    ] {
        let result = smithwalk(&[&["bench"][..], &args].concat());
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        for e in expect {
            assert!(stderr.contains(e), "{args:?}: error {stderr:?} does not mention {e:?}");
        }
        assert!(result.stdout.is_empty(), "{args:?}: a table was started");
    }
}
