//! Issue 36 items 5 and 13: `compare`'s files are one sealed set of the run beside them, and
//! `compare` shows every step on a terminal without changing a byte of what it writes.
//!
//! `compare.json` records the SHA-256 of `models.csv` and `compare.csv`, the digests of the
//! run's tables and the settings; the digests here are computed independently (sha2 over the
//! files' bytes). `plot` and `RunDir::models` refuse, in one line and writing nothing: a
//! `models.csv` of another comparison beside the old `compare.csv` (what a killed compare
//! left, before the seal), another run's whole set copied in, a model renamed inside
//! `models.csv` (also behind a resealed `compare.json`), and tables without their seal.

use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::Digest;
use smithwalk::io::rundir::RunDir;

use crate::common;

/// Two conductor cases on a small grid, orders folded at 3.
const RUN: &str = "paths = 4000\nseed = 3\n[surface]\nalpha = [0.3, 0.7]\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 40\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 3\n";

fn compare(dir: &Path, models: &str) {
    common::compare(dir, &["--models", models, "--paths", "3000"]);
}

/// A copy of the run directory `from` at `to`.
fn copy(from: &Path, to: &Path) -> PathBuf {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
    to.to_path_buf()
}

/// `plot`'s one error line for `dir`, asserting that it failed and wrote no report.
fn plot_refuses(dir: &Path) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_smithwalk")).args(["plot", dir.to_str().unwrap()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(!output.status.success(), "plot accepted {}", dir.display());
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(!dir.join("index.html").exists(), "plot wrote a report of {}", dir.display());
    stderr
}

fn sha256(path: &Path) -> String {
    sha2::Sha256::digest(std::fs::read(path).unwrap()).iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn compare_json_seals_the_tables_with_the_run_and_the_settings() {
    let tmp = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(tmp.path(), "run", RUN);
    compare(&run, "single,heitz-nee");
    let record: serde_json::Value = serde_json::from_slice(&std::fs::read(run.join("compare.json")).unwrap()).unwrap();
    let run_json: serde_json::Value = serde_json::from_slice(&std::fs::read(run.join("run.json")).unwrap()).unwrap();
    for table in ["models.csv", "compare.csv"] {
        assert_eq!(record["files"][table]["sha256"], sha256(&run.join(table)), "{table}");
    }
    for table in ["lobes.csv", "summary.csv"] {
        assert_eq!(record["run_tables"][table], sha256(&run.join(table)), "{table}");
    }
    assert_eq!(record["run_id"], run_json["run_id"]);
    assert_eq!(record["settings"]["models"], serde_json::json!(["single", "heitz-nee"]));
    assert_eq!(record["settings"]["paths"], 3000);
    assert_eq!(record["settings"]["family_level"], 0.01);
    // The sealed set is read and drawn.
    assert_eq!(RunDir::open(&run).unwrap().models().unwrap().len(), 2);
    let status = common::smithwalk_quiet(&["plot", run.to_str().unwrap()]).status().unwrap();
    assert!(status.success());
}

#[test]
fn a_comparison_that_is_not_one_sealed_set_of_this_run_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(tmp.path(), "run", RUN);
    compare(&run, "single,heitz-nee");

    // A compare killed after its new models.csv was renamed into place, before compare.csv.
    let newer = copy(&run, &tmp.path().join("newer"));
    compare(&newer, "heitz-nee");
    let killed = copy(&run, &tmp.path().join("killed"));
    std::fs::copy(newer.join("models.csv"), killed.join("models.csv")).unwrap();
    let e = plot_refuses(&killed);
    assert!(e.contains("is not the models.csv that") && e.contains("compare.json records"), "{e}");

    // Another run's comparison, all three files, copied in.
    let other_config = RUN.replace("seed = 3", "seed = 4");
    let (other, _) = common::run_config(tmp.path(), "other", &other_config);
    compare(&other, "single,heitz-nee");
    let foreign = copy(&run, &tmp.path().join("foreign"));
    for file in ["models.csv", "compare.csv", "compare.json"] {
        std::fs::copy(other.join(file), foreign.join(file)).unwrap();
    }
    let e = plot_refuses(&foreign);
    assert!(e.contains("belongs to another run"), "{e}");

    // A model renamed inside models.csv: drawn under the wrong name before the seal.
    let renamed = copy(&run, &tmp.path().join("renamed"));
    let text = std::fs::read_to_string(renamed.join("models.csv")).unwrap();
    let (header, rows) = text.split_once('\n').unwrap();
    let forged = header.replace(",single,", ",hammon-fit,").replace(",single_stderr,", ",hammon-fit_stderr,");
    std::fs::write(renamed.join("models.csv"), format!("{forged}\n{rows}")).unwrap();
    let e = plot_refuses(&renamed);
    assert!(e.contains("is not the models.csv that"), "{e}");
    // Behind a resealed compare.json, the models must still be the ones it records.
    common::reseal_comparison(&renamed);
    let e = plot_refuses(&renamed);
    assert!(e.contains("its models (hammon-fit, heitz-nee) are not the ones compare.json records"), "{e}");
    let e = format!("{:#}", RunDir::open(&renamed).unwrap().models().unwrap_err());
    assert!(e.contains("are not the ones compare.json records"), "{e}");

    // Tables without their seal, and a seal without a table.
    let unsealed = copy(&run, &tmp.path().join("unsealed"));
    std::fs::remove_file(unsealed.join("compare.json")).unwrap();
    let e = plot_refuses(&unsealed);
    assert!(e.contains("models.csv and compare.csv without compare.json"), "{e}");
    let missing = copy(&run, &tmp.path().join("missing"));
    std::fs::remove_file(missing.join("compare.csv")).unwrap();
    let e = plot_refuses(&missing);
    assert!(e.contains("records compare.csv, which is missing"), "{e}");
}

/// Item 13: on a terminal (a pseudo-terminal from util-linux `script`) `compare` shows the
/// steps outside the models too (reading the run, writing the tables); without one it draws
/// nothing; the files are byte-identical either way. Skipped, with a line saying so, where
/// `script` is missing.
#[test]
fn compare_shows_every_step_on_a_terminal_and_writes_the_same_bytes() {
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("SKIPPED compare_shows_every_step_on_a_terminal: util-linux `script` is not installed");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(tmp.path(), "run", RUN);
    let piped = copy(&run, &tmp.path().join("piped"));
    let bin = env!("CARGO_BIN_EXE_smithwalk");
    let command = format!("{bin} compare {} --models single,heitz-nee --paths 3000", run.display());
    let terminal = Command::new("script").args(["-qefc", &command, "/dev/null"]).output().unwrap();
    assert!(terminal.status.success(), "{}", String::from_utf8_lossy(&terminal.stderr));
    let shown = String::from_utf8_lossy(&terminal.stdout);
    for step in ["compare: reading", "compare: single (1/2)", "compare: heitz-nee (2/2)", "compare: writing models.csv"]
    {
        assert!(shown.contains(step), "{step:?} not shown on the terminal: {shown}");
    }
    let output = Command::new(bin)
        .args(["compare", piped.to_str().unwrap(), "--models", "single,heitz-nee", "--paths", "3000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("compare: reading") && !stderr.contains('\r'), "{stderr}");
    for file in ["models.csv", "compare.csv", "compare.json"] {
        assert_eq!(std::fs::read(run.join(file)).unwrap(), std::fs::read(piped.join(file)).unwrap(), "{file}");
    }
}
