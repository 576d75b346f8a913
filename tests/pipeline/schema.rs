//! The run directory's format is the one `io::schema` declares: every file a run and `compare`
//! write is declared there, each table's header is exactly the schema's (in order), `run.json`
//! carries the format version, a newer format is refused, and docs/run-directory.md describes
//! every file, every column and every field of `compare.json` the schema declares.

use std::path::Path;

use smithwalk::io::schema::{self, TableSchema};

use crate::common::run_config;

/// A dielectric (R and T rows, a folded slot) and an RGB conductor: both table layouts.
const MONO: &str = "paths = 4000\nseed = 3\n[surface]\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 60]\n[detector]\ncos_theta_bins = 3\nphi_bins = 4\nmax_order = 3\n";
const RGB: &str = "paths = 4000\nseed = 3\n[surface]\nalpha = [0.3, 0.6]\n[material]\nkind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.9, 0.6, 0.3]\n[incident]\ntheta_deg = 40\n[detector]\ncos_theta_bins = 2\nphi_bins = 3\n";

fn header(dir: &Path, table: &TableSchema) -> Vec<String> {
    let mut reader = csv::Reader::from_path(dir.join(table.file)).unwrap();
    reader.headers().unwrap().iter().map(String::from).collect()
}

fn compare(dir: &Path, models: &str) {
    let status =
        crate::common::smithwalk_quiet(&["compare", dir.to_str().unwrap(), "--models", models]).status().unwrap();
    assert!(status.success(), "compare --models {models} failed");
}

#[test]
fn every_file_and_column_written_is_the_one_the_schema_declares() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, toml, rgb, models) in
        [("mono", MONO, false, ["single", "heitz-nee"]), ("rgb", RGB, true, ["single", "turquin"])]
    {
        let (dir, _) = run_config(tmp.path(), name, toml);
        compare(&dir, &models.join(","));
        let mut written: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        written.sort();
        // The lock file stays behind (docs/run-directory.md); a finished run leaves no checkpoint.
        let mut declared: Vec<String> = schema::RUN_FILES
            .iter()
            .chain(&schema::COMPARE_FILES)
            .chain(&[smithwalk::atomic::LOCK_FILE])
            .map(|f| f.to_string())
            .collect();
        declared.sort();
        assert_eq!(written, declared, "{name}: the files of the run directory");
        for table in schema::TABLES {
            assert_eq!(header(&dir, &table), table.header(rgb, &models), "{name}: the header of {}", table.file);
        }
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join(schema::RUN_JSON)).unwrap()).unwrap();
        assert_eq!(json["format_version"], schema::FORMAT_VERSION, "{name}: run.json's format_version");
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join(schema::COMPARE_JSON.file)).unwrap()).unwrap();
        let mut written: Vec<&str> = record.as_object().unwrap().keys().map(String::as_str).collect();
        let mut declared: Vec<&str> = schema::COMPARE_JSON.fields.iter().map(|f| f.name).collect();
        written.sort();
        declared.sort();
        assert_eq!(written, declared, "{name}: the fields of compare.json");
    }
}

#[test]
fn a_run_directory_of_a_newer_format_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, _) = run_config(tmp.path(), "mono", MONO);
    let path = dir.join(schema::RUN_JSON);
    let text = std::fs::read_to_string(&path).unwrap();
    let key = format!("\"format_version\": {}", schema::FORMAT_VERSION);
    assert!(text.contains(&key), "run.json has no {key}");
    let newer = text.replacen(&key, &format!("\"format_version\": {}", schema::FORMAT_VERSION + 1), 1);
    std::fs::write(&path, reseal(newer.into_bytes())).unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["compare", dir.to_str().unwrap(), "--models", "single"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(stderr.contains("format_version") && stderr.contains("newer smithwalk"), "{stderr}");
    assert!(!dir.join(schema::COMPARE.file).exists(), "compare wrote into a run it refused");
}

/// `run.json` text with its self digest recomputed (sha256 of the text with the digest as
/// zeros), so that the check behind the seal is reached.
fn reseal(mut text: Vec<u8>) -> Vec<u8> {
    use sha2::Digest;
    let key = b"\"self_sha256\": \"";
    let at = text.windows(key.len()).rposition(|w| w == key).unwrap() + key.len();
    text[at..at + 64].fill(b'0');
    let digest: String = sha2::Sha256::digest(&text).iter().map(|b| format!("{b:02x}")).collect();
    text[at..at + 64].copy_from_slice(digest.as_bytes());
    text
}

#[test]
fn docs_describe_every_column_of_every_table() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/run-directory.md")).unwrap();
    assert!(doc.contains(&format!("format_version` is {}", schema::FORMAT_VERSION)), "the doc's format version");
    for table in schema::TABLES {
        // The table's section: from its heading to the next one.
        let heading = format!("## `{}`", table.file);
        let start = doc.find(&heading).unwrap_or_else(|| panic!("docs/run-directory.md has no {heading}"));
        let section = &doc[start + heading.len()..];
        let section = &section[..section.find("\n## ").unwrap_or(section.len())];
        for column in table.columns {
            let row = format!("| `{}` | {} | {} |", column.name, column.unit, column.meaning);
            assert!(section.contains(&row), "{}: docs/run-directory.md lacks the row\n{row}", table.file);
        }
    }
    // Every file in the table of files, and every field of compare.json in its section.
    for file in schema::RUN_FILES.iter().chain(&schema::COMPARE_FILES) {
        assert!(doc.contains(&format!("\n| `{file}` | ")), "docs/run-directory.md does not list {file}");
    }
    let heading = format!("## `{}`", schema::COMPARE_JSON.file);
    let section = &doc[doc.find(&heading).unwrap_or_else(|| panic!("docs/run-directory.md has no {heading}"))..];
    for field in schema::COMPARE_JSON.fields {
        let row = format!("| `{}` |  | {} |", field.name, field.meaning);
        assert!(section.contains(&row), "compare.json: docs/run-directory.md lacks the row\n{row}");
    }
}
