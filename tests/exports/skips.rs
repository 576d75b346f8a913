//! A test that needs an optional tool says so when it is skipped (issue 36 item 11: the browser
//! and pandas tests printed their skip with `eprintln!`, which the harness hides for a passing
//! test, so a machine without the tool reported a plain `ok`). This binary runs itself on the
//! browser test with an empty PATH and without `CI`, and reads the `skipped:` line.

use std::process::Command;

#[test]
fn a_test_skipped_for_a_missing_tool_prints_a_skipped_line() {
    for test in [
        "report_browser::a_console_error_and_a_missing_image_are_caught",
        "readme_snippet::the_readme_pandas_snippet_runs_on_a_quickstart_run",
    ] {
        let out = Command::new(std::env::current_exe().unwrap())
            .args([test, "--exact", "--test-threads=1"])
            .env("PATH", "/nonexistent")
            .env_remove("CI")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{test}:\n{stdout}\n{stderr}");
        assert!(stdout.contains("1 passed"), "{test} did not run:\n{stdout}");
        let skipped: Vec<&str> = stderr.lines().filter(|l| l.starts_with("skipped: tests/exports/")).collect();
        assert_eq!(skipped.len(), 1, "{test} printed no `skipped:` line:\n{stderr}");
    }
}
