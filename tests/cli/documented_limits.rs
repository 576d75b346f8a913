//! The numbers that docs/reliability.md and README.md quote are read from the code, so that the
//! docs cannot drift from it again (issue 36 item 8: docs/reliability.md said the sealed shard
//! format was version 2 while the binary wrote version 3). Each check is a phrase of the doc with
//! the constant written into it: a changed constant, or a doc rephrased around it, fails here
//! until the doc says what the code does.

use smithwalk::engine::resources::{DEFAULT_MEMORY_SHARE, MAX_THREADS};
use smithwalk::engine::run::{CHUNK, ROUND_CHUNKS};
use smithwalk::engine::sealed;
use smithwalk::input::{MAX_CONFIG_BYTES, MAX_RUN_JSON_BYTES, MAX_TABLE_BYTES, size_text};
use smithwalk::io::schema;
use smithwalk::setup::config::{DEFAULT_MAX_ORDER, MAX_ALPHA, MAX_CASES, MAX_NAME_CHARS, MAX_PATHS};

fn doc(name: &str) -> String {
    std::fs::read_to_string(format!("{}/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// `n` as the docs write powers of ten (`10^15`), failing for a number that is not one.
fn power_of_ten(n: f64) -> String {
    let exponent = n.log10().round();
    assert_eq!(10f64.powf(exponent), n, "{n} is not a power of ten");
    format!("10^{exponent}")
}

/// `n` with a thin space (a plain space in the docs) every three digits: `16 384`.
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, d) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(d);
    }
    out
}

#[test]
fn the_numbers_the_docs_quote_are_the_codes() {
    let reliability = doc("docs/reliability.md");
    let run_directory = doc("docs/run-directory.md");
    let readme = doc("README.md");
    let checks: Vec<(&str, &String, String)> = vec![
        ("sealed files", &reliability, format!("the format version ({})", sealed::FORMAT_VERSION)),
        ("run directory", &run_directory, format!("`run.json`'s `format_version` is {}", schema::FORMAT_VERSION)),
        ("paths", &reliability, format!("| 2 to {} per case |", power_of_ten(MAX_PATHS as f64))),
        (
            "compare paths",
            &reliability,
            format!("| `compare --paths` | 2 to {} per case |", power_of_ten(MAX_PATHS as f64)),
        ),
        ("cases", &reliability, format!("| cases of a sweep | at most {} |", power_of_ten(MAX_CASES as f64))),
        ("threads", &reliability, format!("| `--threads` | 1 to {MAX_THREADS} ")),
        ("memory share", &reliability, format!("by default {}% of the least", (DEFAULT_MEMORY_SHARE * 100.0).round())),
        ("alpha", &reliability, format!("| `surface.alpha` | > 0, at most {} |", power_of_ten(MAX_ALPHA))),
        ("max_order", &reliability, format!("which is **{DEFAULT_MAX_ORDER} when the config leaves it out**")),
        ("name", &reliability, format!("| `material.name` | at most {MAX_NAME_CHARS} characters |")),
        (
            "checkpoint",
            &reliability,
            format!(
                "| `--checkpoint-seconds` | > 0, at most {} ",
                power_of_ten(smithwalk::commands::run::MAX_CHECKPOINT_SECONDS)
            ),
        ),
        ("config size", &reliability, format!("| at most {} |", size_text(MAX_CONFIG_BYTES))),
        ("table size", &reliability, format!("| at most {}, and an external model", size_text(MAX_TABLE_BYTES))),
        ("run.json size", &reliability, format!("| `run.json` | at most {} |", size_text(MAX_RUN_JSON_BYTES))),
        ("chunk", &reliability, format!("chunks of {} photons", grouped(CHUNK))),
        ("round", &readme, format!("round of {ROUND_CHUNKS} chunks of {} photons", grouped(CHUNK))),
    ];
    let drifted: Vec<String> = checks
        .iter()
        .filter(|(_, text, phrase)| !text.contains(phrase.as_str()))
        .map(|(what, _, phrase)| format!("{what}: the doc lacks {phrase:?}"))
        .collect();
    assert!(drifted.is_empty(), "the docs do not say what the code does:\n{}", drifted.join("\n"));
}

#[test]
fn the_check_reads_numbers_as_the_docs_write_them() {
    assert_eq!(power_of_ten(1e15), "10^15");
    assert_eq!(grouped(16_384), "16 384");
    assert_eq!(grouped(1_000_000), "1 000 000");
}
