//! Property tests (proptest, fixed case counts, no persistence files): random configs never
//! panic the parser and every rejection is one line naming a field (or, for text that is not
//! TOML, its line); random command lines never panic the binary and every error is one line;
//! random damage to a run directory never panics `RunDir::open` and is never accepted.
//!
//! Case counts: 512 configs, 48 command lines, 256 damaged run directories (in
//! release on 2 cores, measured 0.9 s).

use std::path::Path;
use std::process::Command;

use proptest::prelude::*;
use smithwalk::io::rundir::RunDir;
use smithwalk::setup::config::Config;

const BASE: &str = "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n[detector]\ncos_theta_bins = 2\nphi_bins = 2\n";

/// Keys (with their table) and values to put in them: valid, mistyped and out of range.
const KEYS: [(&str, &str); 22] = [
    ("", "paths"),
    ("", "seed"),
    ("", "bogus"),
    ("[surface]", "ndf"),
    ("[surface]", "alpha"),
    ("[surface]", "smith"),
    ("[surface]", "normals"),
    ("[surface]", "height"),
    ("[material]", "kind"),
    ("[material]", "eta"),
    ("[material]", "f0"),
    ("[material]", "fresnel"),
    ("[material]", "albedo"),
    ("[material]", "k"),
    ("[incident]", "theta_deg"),
    ("[incident]", "theta_rad"),
    ("[incident]", "side"),
    ("[incident]", "phi_deg"),
    ("[detector]", "max_order"),
    ("[detector]", "phi_bins"),
    ("[energy]", "threshold"),
    ("[precision]", "orders"),
];
const VALUES: [&str; 24] = [
    "0",
    "1",
    "-1",
    "2.5",
    "1e300",
    "nan",
    "inf",
    "4097",
    "18446744073709551615",
    "\"ggx\"",
    "\"beckmann\"",
    "\"dielectric\"",
    "\"schlick\"",
    "\"inside\"",
    "\"x\"",
    "[]",
    "[0.5, 0.7]",
    "[[0.5, 0.7]]",
    "[[1, 2, 3]]",
    "[0.1, 0.2, 0.3]",
    "[\"ggx\", 1]",
    "{ a = 1 }",
    "true",
    "1979-05-27",
];

/// BASE with `key = value` lines added to their tables (a table is opened again where BASE
/// has none, and a repeated key is a TOML error, which must be reported as well).
fn config_text(edits: &[(usize, usize)], junk: &[u8]) -> String {
    let mut text = BASE.to_string();
    for &(k, v) in edits {
        let (table, key) = KEYS[k];
        let line = format!("{key} = {}\n", VALUES[v]);
        match text.find(&format!("{table}\n")).filter(|_| !table.is_empty()) {
            Some(at) => text.insert_str(at + table.len() + 1, &line),
            None if table.is_empty() => text.insert_str(0, &line),
            None => text.push_str(&format!("{table}\n{line}")),
        }
    }
    text.push_str(&String::from_utf8_lossy(junk));
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_configs_never_panic_and_every_rejection_names_a_field(
        edits in prop::collection::vec((0..KEYS.len(), 0..VALUES.len()), 0..5),
        junk in prop::collection::vec(prop::sample::select(b"=[]\"\n a1.,{}#".to_vec()), 0..4),
    ) {
        let text = config_text(&edits, &junk);
        if let Err(e) = Config::parse(&text) {
            let e = e.to_string();
            prop_assert!(!e.contains('\n') && !e.contains("untagged"), "{e}");
            prop_assert!(e.contains('`') || e.contains("not TOML (line"), "names no field: {e}\n{text}");
        }
    }
}

/// Command-line words: commands, options and values, valid and not.
const WORDS: [&str; 26] = [
    "run",
    "merge",
    "compare",
    "plot",
    "merl",
    "rgl",
    "CONFIG",
    "RUN",
    "OUT",
    "missing.toml",
    "--paths",
    "--seed",
    "--threads",
    "--out",
    "--shard",
    "--resume",
    "--checkpoint-seconds",
    "--models",
    "0",
    "1",
    "2",
    "5000",
    "10000000000000000000",
    "0/2",
    "3/2",
    "nan",
];

fn command_line(words: &[usize], config: &Path, run: &Path, out: &Path) -> Vec<String> {
    words
        .iter()
        .map(|&w| match WORDS[w] {
            "CONFIG" => config.display().to_string(),
            "RUN" => run.display().to_string(),
            "OUT" => out.display().to_string(),
            other => other.to_string(),
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_command_lines_never_panic_and_errors_are_one_line(
        words in prop::collection::vec(0..WORDS.len(), 1..7),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("c.toml");
        std::fs::write(&config, BASE).unwrap();
        let run = dir.path().join("run");
        std::fs::create_dir_all(&run).unwrap();
        let args = command_line(&words, &config, &run, &dir.path().join("out"));
        let out = Command::new(env!("CARGO_BIN_EXE_smithwalk")).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        prop_assert!(!stderr.contains("panicked") && out.status.code() != Some(101), "{args:?}: {stderr}");
        if out.status.code() == Some(1) {
            prop_assert!(stderr.lines().count() == 1 && stderr.starts_with("error: "), "{args:?}: {stderr}");
        }
    }
}

/// A finished run's files, made once.
fn intact_run() -> &'static [(String, Vec<u8>)] {
    static RUN: std::sync::OnceLock<Vec<(String, Vec<u8>)>> = std::sync::OnceLock::new();
    RUN.get_or_init(|| {
        let toml =
            BASE.replace("\"conductor\"", "\"dielectric\"\neta = 1.5").replace("theta_deg = 30", "theta_deg = [0, 60]");
        let config = Config::parse(&toml).unwrap();
        let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
        let dir = tempfile::tempdir().unwrap();
        smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
        ["lobes.csv", "summary.csv", "run.json"]
            .iter()
            .map(|f| (f.to_string(), std::fs::read(dir.path().join(f)).unwrap()))
            .collect()
    })
}

/// Damage to one file: flip a byte, cut the file, drop or repeat a line, insert text.
#[derive(Debug, Clone)]
enum Damage {
    Flip(usize, u8),
    Truncate(usize),
    DropLine(usize),
    RepeatLine(usize),
    Insert(usize, String),
}

fn damage(bytes: &[u8], d: &Damage) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let lines: Vec<&[u8]> = bytes.split_inclusive(|&c| c == b'\n').collect();
    match d {
        Damage::Flip(at, x) => b[at % bytes.len()] ^= x,
        Damage::Truncate(at) => b.truncate(at % bytes.len()),
        Damage::DropLine(i) => {
            b = lines.iter().enumerate().filter(|(j, _)| *j != i % lines.len()).flat_map(|(_, l)| l.to_vec()).collect()
        }
        Damage::RepeatLine(i) => {
            b = lines
                .iter()
                .enumerate()
                .flat_map(|(j, l)| if j == i % lines.len() { [*l, *l].concat() } else { l.to_vec() })
                .collect()
        }
        Damage::Insert(at, text) => {
            let at = at % (bytes.len() + 1);
            b.splice(at..at, text.bytes());
        }
    }
    b
}

fn damages() -> impl Strategy<Value = Damage> {
    prop_oneof![
        (any::<usize>(), 1..=255u8).prop_map(|(a, x)| Damage::Flip(a, x)),
        any::<usize>().prop_map(Damage::Truncate),
        any::<usize>().prop_map(Damage::DropLine),
        any::<usize>().prop_map(Damage::RepeatLine),
        (any::<usize>(), prop::sample::select(vec!["NaN", "-1", "inf", ",", "\n", "1e400", " "]))
            .prop_map(|(a, t)| Damage::Insert(a, t.to_string())),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_run_directory_damage_is_never_accepted(file in 0..3usize, d in damages()) {
        let files = intact_run();
        let damaged = damage(&files[file].1, &d);
        prop_assume!(damaged != files[file].1);
        let dir = tempfile::tempdir().unwrap();
        for (i, (name, bytes)) in files.iter().enumerate() {
            std::fs::write(dir.path().join(name), if i == file { &damaged } else { bytes }).unwrap();
        }
        match RunDir::open(dir.path()) {
            Ok(_) => prop_assert!(false, "{} with {d:?} was accepted", files[file].0),
            Err(e) => prop_assert!(!format!("{e:#}").contains('\n'), "{e:#}"),
        }
    }
}
