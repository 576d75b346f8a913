//! Run directories are validated before use: `RunDir::open` (behind `compare`, `plot`, `merl`
//! and `rgl`) refuses tables that are not the ones `run.json` records, tables that are
//! incomplete, duplicated, non-finite or negative (even with forged digests), and a directory
//! that a run is writing; a run removes the leftovers of a killed run and the previous run's
//! derived files, and refuses a directory in use.

use std::path::Path;
use std::process::Command;

use sha2::Digest;
use smithwalk::atomic::{TEMP_PREFIX, lock_dir};
use smithwalk::io::rundir::RunDir;
use smithwalk::setup::config::Config;

/// A dielectric (R and T rows) at two angles, and an RGB conductor: both table layouts.
const MONO: &str = "paths = 5000\nseed = 2\n[surface]\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 60]\n[detector]\ncos_theta_bins = 3\nphi_bins = 4\nmax_order = 3\n";
const RGB: &str = "paths = 5000\nseed = 2\n[surface]\nalpha = [0.3, 0.6]\n[material]\nkind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.9, 0.6, 0.3]\n[incident]\ntheta_deg = 40\n[detector]\ncos_theta_bins = 2\nphi_bins = 3\n";

fn write_run(toml: &str, dir: &Path) {
    let config = Config::parse(toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    smithwalk::write_outputs(&sim, &config, dir).unwrap();
}

fn open_error(dir: &Path) -> String {
    match RunDir::open(dir) {
        Ok(_) => panic!("a damaged run directory was accepted"),
        Err(e) => format!("{e:#}"),
    }
}

fn hex(bytes: &[u8]) -> String {
    sha2::Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// Rewrites `run.json` with the digests of the tables as they now are (a forged run.json), so
/// that the checks behind the digests are reached.
fn forge_digests(dir: &Path) {
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("run.json")).unwrap()).unwrap();
    for table in ["lobes.csv", "summary.csv"] {
        json["files"][table]["sha256"] = hex(&std::fs::read(dir.join(table)).unwrap()).into();
    }
    json["self_sha256"] = "0".repeat(64).into();
    let mut text = serde_json::to_vec_pretty(&json).unwrap();
    text.push(b'\n');
    let key = b"\"self_sha256\": \"";
    let at = text.windows(key.len()).rposition(|w| w == key).unwrap() + key.len();
    let digest = hex(&text);
    text[at..at + 64].copy_from_slice(digest.as_bytes());
    std::fs::write(dir.join("run.json"), text).unwrap();
}

/// `table` of `dir` with `edit` applied to its lines (header first).
fn edit_lines(dir: &Path, table: &str, edit: impl FnOnce(&mut Vec<String>)) {
    let text = std::fs::read_to_string(dir.join(table)).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    edit(&mut lines);
    std::fs::write(dir.join(table), lines.join("\n") + "\n").unwrap();
}

/// Sets column `name` (found in the header, line 0) of CSV line `row` to `value`.
fn set_field(lines: &mut [String], row: usize, name: &str, value: &str) {
    let record = |line: &str| {
        let mut r = csv::ReaderBuilder::new().has_headers(false).from_reader(line.as_bytes());
        r.records().next().unwrap().unwrap()
    };
    let column = record(&lines[0]).iter().position(|h| h == name).unwrap();
    let fields: Vec<String> =
        record(&lines[row]).iter().enumerate().map(|(i, f)| if i == column { value } else { f }.to_string()).collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&fields).unwrap();
    lines[row] = String::from_utf8(w.into_inner().unwrap()).unwrap().trim_end().to_string();
}

#[test]
fn intact_runs_open_and_extra_columns_are_allowed() {
    for toml in [MONO, RGB] {
        let dir = tempfile::tempdir().unwrap();
        write_run(toml, dir.path());
        RunDir::open(dir.path()).unwrap();
        // A column added by a later smithwalk (read by name) is not damage.
        edit_lines(dir.path(), "lobes.csv", |lines| {
            for (i, line) in lines.iter_mut().enumerate() {
                line.push_str(if i == 0 { ",solid_angle" } else { ",0.5" });
            }
        });
        forge_digests(dir.path());
        RunDir::open(dir.path()).unwrap();
    }
}

#[test]
fn damage_is_refused_behind_the_digests_and_in_front_of_them() {
    type Damage = (&'static str, &'static str, fn(&mut Vec<String>), &'static str);
    let damages: [Damage; 9] = [
        ("lobes.csv", "header only", |l| l.truncate(1), "has 0 rows"),
        ("lobes.csv", "a row missing", |l| _ = l.remove(5), "rows, but the run"),
        ("lobes.csv", "a row twice", |l| l[7] = l[6].clone(), "the same row twice"),
        ("lobes.csv", "energy NaN", |l| set_field(l, 3, "energy", "NaN"), "energy = NaN"),
        ("lobes.csv", "energy -1", |l| set_field(l, 3, "energy", "-1"), "energy = -1"),
        ("lobes.csv", "bsdf inf", |l| set_field(l, 4, "bsdf", "inf"), "bsdf = inf"),
        ("lobes.csv", "order beyond the run's", |l| set_field(l, 2, "order", "99"), "order 99"),
        ("summary.csv", "albedo NaN", |l| set_field(l, 1, "albedo", "NaN"), "albedo = NaN"),
        ("summary.csv", "a row missing", |l| _ = l.pop(), "rows, but the run"),
    ];
    for toml in [MONO, RGB] {
        for (table, what, damage, message) in damages {
            let dir = tempfile::tempdir().unwrap();
            write_run(toml, dir.path());
            edit_lines(dir.path(), table, damage);
            let e = open_error(dir.path());
            assert!(e.contains("is not the") && e.contains("run.json records"), "{table} {what}: {e}");
            forge_digests(dir.path());
            let e = open_error(dir.path());
            assert!(e.contains(message), "{table} {what} with forged digests: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}

#[test]
fn a_changed_run_json_and_a_mix_of_two_runs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    write_run(MONO, dir.path());
    let intact = std::fs::read(dir.path().join("run.json")).unwrap();
    // Any byte of run.json: here the wall time, which no reader uses.
    let text = String::from_utf8(intact.clone()).unwrap().replacen("\"wall_seconds\": ", "\"wall_seconds\": 1", 1);
    std::fs::write(dir.path().join("run.json"), text).unwrap();
    assert!(open_error(dir.path()).contains("self_sha256"));
    // A run killed between renaming its lobes.csv and its run.json: new lobes, old rest.
    std::fs::write(dir.path().join("run.json"), &intact).unwrap();
    let other = tempfile::tempdir().unwrap();
    write_run(&MONO.replace("seed = 2", "seed = 3"), other.path());
    std::fs::copy(other.path().join("lobes.csv"), dir.path().join("lobes.csv")).unwrap();
    assert!(open_error(dir.path()).contains("is not the lobes.csv"));
}

#[test]
fn commands_on_a_damaged_run_fail_with_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write_run(MONO, dir.path());
    edit_lines(dir.path(), "lobes.csv", |l| set_field(l, 3, "energy", "NaN"));
    forge_digests(dir.path());
    let before: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    let run_dir = dir.path().to_str().unwrap();
    for args in [
        vec!["plot", run_dir],
        vec!["merl", run_dir],
        vec!["rgl", run_dir],
        vec!["compare", run_dir, "--models", "single"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_smithwalk")).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains("energy = NaN"), "{args:?}: {stderr}");
    }
    let after: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(before.len(), after.len(), "files written: {after:?}");
}

#[test]
fn a_directory_in_use_is_refused_and_a_run_clears_leftovers() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, MONO).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_smithwalk"))
            .args(["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .output()
            .unwrap()
    };
    {
        let _held = lock_dir(&out, true).unwrap();
        let refused = run();
        assert_eq!(refused.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&refused.stderr).contains("in use by another smithwalk process"));
        assert!(!out.join("lobes.csv").exists());
    }
    // A killed run's temporary file and the previous run's derived models.csv.
    let leftover = out.join(format!("{TEMP_PREFIX}killed"));
    std::fs::write(&leftover, b"half a table").unwrap();
    std::fs::write(out.join("models.csv"), b"of another run").unwrap();
    assert!(run().status.success());
    assert!(!leftover.exists(), "the leftover temporary file is still there");
    assert!(!out.join("models.csv").exists(), "the previous run's models.csv is still there");
    RunDir::open(&out).unwrap();
    // While a run writes (holds the lock), readers are refused rather than shown a mix.
    let _held = lock_dir(&out, true).unwrap();
    assert!(open_error(&out).contains("being written by a smithwalk run"));
}

/// `ndf = "student-t"` end to end: `gamma` is a sweep axis next to `alpha` (a GGX case and two
/// Student-T shapes make three cases), each case's shape is in `summary.csv`'s `gamma` column
/// (empty for GGX) and in `run.json`, the tables open as a run directory, and every case has
/// its R and T rows (the furnace tests of Student-T walks are in the physics crate's
/// walk_lobes.rs).
#[test]
fn a_student_t_sweep_runs_end_to_end_and_records_its_shapes() {
    let dir = tempfile::tempdir().unwrap();
    let toml = MONO.replace("alpha = 0.5", "alpha = 0.5\nndf = [\"ggx\", \"student-t\"]\ngamma = [1.6, 10]");
    write_run(&toml, dir.path());
    RunDir::open(dir.path()).unwrap();
    let summary = std::fs::read_to_string(dir.path().join("summary.csv")).unwrap();
    let mut lines = summary.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ndf, gamma, row, albedo) = (column("ndf"), column("gamma"), column("hemisphere"), column("albedo"));
    let mut shapes = std::collections::BTreeSet::new();
    let mut totals = std::collections::BTreeMap::<String, f64>::new();
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        shapes.insert((cells[ndf].to_string(), cells[gamma].to_string()));
        if cells[column("order")] == "0" && ["R", "T"].contains(&cells[row]) {
            *totals.entry(format!("{} {}", cells[0], cells[column("theta_i_deg")])).or_default() +=
                cells[albedo].parse::<f64>().unwrap();
        }
    }
    let expected: std::collections::BTreeSet<_> =
        [("ggx", ""), ("student-t", "1.6"), ("student-t", "10")].map(|(a, b)| (a.to_string(), b.to_string())).into();
    assert_eq!(shapes, expected);
    assert_eq!(totals.len(), 6, "{totals:?}");
    for (case, total) in totals {
        assert!(total.is_finite() && total > 0.5, "case {case}: R + T = {total}");
    }
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("run.json")).unwrap()).unwrap();
    let gammas: Vec<Option<f64>> = run["cases"].as_array().unwrap().iter().map(|c| c["gamma"].as_f64()).collect();
    assert_eq!(gammas, [None, None, Some(1.6), Some(1.6), Some(10.0), Some(10.0)]);
}
