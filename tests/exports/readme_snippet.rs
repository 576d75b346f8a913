//! The pandas snippet of README.md's "Outputs" section, run as written on a quickstart run with
//! fewer photons, so that it cannot rot. Without python3 and pandas the test is skipped with a
//! visible `skipped:` line ([`common::skip`]), except under CI (`CI` set), where CI installs pandas
//! and a skip is a failure.

use std::process::Command;

use crate::common;

/// The first ```python block after the heading `## Outputs`.
fn outputs_snippet(readme: &str) -> String {
    let section = &readme[readme.find("\n## Outputs").expect("README has an `## Outputs` section")..];
    let section = &section[..section[1..].find("\n## ").map_or(section.len(), |end| end + 1)];
    let start = section.find("```python\n").expect("the Outputs section has a ```python block") + "```python\n".len();
    let end = section[start..].find("```").expect("the python block is closed");
    section[start..start + end].to_string()
}

#[test]
fn the_readme_pandas_snippet_runs_on_a_quickstart_run() {
    let pandas = Command::new("python3").args(["-c", "import pandas"]).output();
    if !pandas.as_ref().is_ok_and(|o| o.status.success()) {
        return common::skip(
            "tests/exports/readme_snippet.rs",
            "python3 with pandas is not installed (`pip install pandas`)",
        );
    }
    let root = env!("CARGO_MANIFEST_DIR");
    let snippet = outputs_snippet(&std::fs::read_to_string(format!("{root}/README.md")).unwrap());
    // The snippet reads out/quickstart/lobes.csv relative to where it runs.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out/quickstart");
    let status = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", &format!("{root}/configs/quickstart.toml"), "--paths", "20000", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("binary runs");
    assert!(status.success());
    let output =
        Command::new("python3").arg("-c").arg(&snippet).current_dir(dir.path()).output().expect("python3 runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "the snippet failed:\n{snippet}\n{}", String::from_utf8_lossy(&output.stderr));
    // What the snippet's comments promise: a 32 x 64 table (the quickstart's bins), and the
    // bins of a hemisphere add up to 2 pi steradians.
    let mut lines = stdout.lines();
    assert_eq!(lines.next(), Some("(32, 64)"), "{stdout}");
    let last = lines.next().unwrap_or_default();
    let steradians: f64 = last.rsplit(' ').next().unwrap().parse().unwrap();
    assert!((steradians - std::f64::consts::TAU).abs() < 1e-9, "{stdout}");
}
