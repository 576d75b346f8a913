//! Issue 36 item 7: every bad config, of any type or shape, gets one line naming the field, the
//! value as written, what is allowed and where it is (`line N, column M`), in the user's terms:
//! never serde's ("internally tagged enum MaterialConfig", "unknown variant", "invalid type:
//! map", "expected struct SurfaceConfig"), and never a run with nothing said (`detector = []`).

use std::process::Command;

/// Lines: 1 paths, 2 [surface], 3 alpha, 4 [material], 5 kind, 6 [incident], 7 theta_deg.
const RUN: &str =
    "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n";

/// Lines: 1 [surface], 2 ndf, 3 [material], 4 kind, 5 [table], 6 mu, 7 paths.
const LUT: &str = "[surface]\nndf = \"ggx\"\n[material]\nkind = \"conductor\"\n[table]\nmu = 4\npaths = 100\n";

/// `base` with each `from` (which it must contain) replaced by its `to`.
fn edit(base: &str, edits: &[(&str, &str)]) -> Vec<u8> {
    let mut text = base.to_string();
    for (from, to) in edits {
        assert!(text.contains(from), "{from:?}");
        text = text.replacen(from, to, 1);
    }
    text.into_bytes()
}

/// Runs `smithwalk COMMAND CONFIG --out DIR` on `config`; returns the exit code, stderr and
/// whether the output directory was made.
fn smithwalk(command: &str, config: &[u8]) -> (Option<i32>, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.toml");
    std::fs::write(&path, config).unwrap();
    let out_dir = dir.path().join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args([command, path.to_str().unwrap(), "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned(), out_dir.exists())
}

#[test]
fn every_bad_config_names_its_field_value_allowed_values_line_and_column() {
    let kinds = "\"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"";
    let roughness = "a roughness > 0 and at most 1e4, a list of them (a sweep) or [[alpha_x, alpha_y]]";
    let material_5 = [("paths = 1000\n", "paths = 1000\nmaterial = 5\n"), ("[material]\nkind = \"conductor\"\n", "")];
    let two = "[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"glass\"";
    let (run, lut) = ("run", "lut");
    #[rustfmt::skip]
    let cases: Vec<(&str, Vec<u8>, String)> = vec![
        // A material: serde read it whole, as an internally tagged enum.
        (run, edit(RUN, &[("kind = \"conductor\"", "fresnel = \"none\"")]),
            format!("`material.kind` is missing from the table at line 4, column 1: {kinds}")),
        (run, edit(RUN, &[("\"conductor\"", "\"glass\"")]),
            format!("`material.kind` = \"glass\" is not allowed (line 5, column 8): {kinds}")),
        (run, edit(RUN, &[("\"conductor\"", "3")]),
            format!("`material.kind` = 3 is not allowed (line 5, column 8): {kinds}")),
        (run, edit(RUN, &material_5),
            format!("`material` = 5 is not allowed (line 2, column 12): a table with `kind` = {kinds}, or several")),
        (run, edit(RUN, &[("[material]\nkind = \"conductor\"", two)]),
            format!("`material[1].kind` = \"glass\" is not allowed (line 7, column 8): {kinds}")),
        (run, [RUN, "[[material]]\nkind = \"diffuse\"\n"].concat().into_bytes(),
            "`material` is given twice (line 8, column 3): one [material] table, or several [[material]] tables".into()),
        (run, edit(RUN, &[("\"conductor\"", "\"diffuse\"\ncolour = 0.5")]),
            "`material.colour` is not a known key (line 6, column 1): the keys here are `kind`, `albedo`, `name`".into()),
        (run, edit(RUN, &[("\"conductor\"", "\"conductor\"\nfresnel = 7")]),
            "`material.fresnel` = 7 is not allowed (line 6, column 11): \"none\", \"schlick\" or \"exact\"".into()),
        (run, edit(RUN, &[("\"conductor\"", "\"dielectric\"\neta = [1.4, 1.5, 1.6]")]),
            "`material.eta` = [1.4, 1.5, 1.6] is not allowed (line 6, column 7): one number, the relative index".into()),
        // Sweeps (one value or a list): serde's untagged enums.
        (run, edit(RUN, &[("alpha = 0.5", "alpha = \"x\"")]),
            format!("`surface.alpha` = \"x\" is not allowed (line 3, column 9): {roughness}")),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = [0.1, \"a\"]")]),
            format!("`surface.alpha[1]` = \"a\" is not allowed (line 3, column 15): {roughness}")),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = {}")]),
            format!("`surface.alpha` = {{}} is not allowed (line 3, column 9): {roughness}")),
        (run, edit(RUN, &[("theta_deg = 30", "theta_deg = {}")]),
            "`incident.theta_deg` = {} is not allowed (line 7, column 13): a polar angle in [0, 90) or a list of them".into()),
        (run, edit(RUN, &[("theta_deg = 30", "theta_deg = 30\nphi_deg = { from = 0, to = 90 }")]),
            "`incident.phi_deg` = { from = 0, to = 90 } is not allowed (line 8, column 11): an azimuth in degrees".into()),
        // Names (unit enums): serde's "expected enum NdfKind", "unknown variant".
        (run, edit(RUN, &[("alpha = 0.5", "alpha = 0.5\nndf = 3")]),
            "`surface.ndf` = 3 is not allowed (line 4, column 7): \"ggx\", \"beckmann\" or \"student-t\"".into()),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = 0.5\nndf = [\"ggx\", 3]")]),
            "`surface.ndf[1]` = 3 is not allowed (line 4, column 15): \"ggx\", \"beckmann\" or \"student-t\"".into()),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = 0.5\nsmith = { exact = 1 }")]),
            "`surface.smith` = { exact = 1 } is not allowed (line 4, column 9): \"exact\" or \"symmetric\"".into()),
        (run, edit(RUN, &[("theta_deg = 30", "theta_deg = 30\nside = 1")]),
            "`incident.side` = 1 is not allowed (line 8, column 8): \"outside\" or \"inside\"".into()),
        // Tables (structs): serde's "expected struct SurfaceConfig", and an array read as fields.
        (run, edit(RUN, &[("[surface]\nalpha = 0.5\n", ""), ("paths = 1000\n", "paths = 1000\nsurface = 1\n")]),
            "`surface` = 1 is not allowed (line 2, column 11): a table with `alpha`".into()),
        (run, edit(RUN, &[("paths = 1000\n", "paths = 1000\ndetector = []\n")]),
            "`detector` = [] is not allowed (line 2, column 12): a table, [detector] and its keys".into()),
        (run, [RUN, "[energy]\nsplit = 1\n"].concat().into_bytes(),
            "`energy.split` = 1 is not allowed (line 9, column 9): true or false".into()),
        (run, [RUN, "[compare]\nmodels = \"single\"\n"].concat().into_bytes(),
            "`compare.models` = \"single\" is not allowed (line 9, column 10): a list of models from single, ".into()),
        // Values checked after reading: they had no line.
        (run, [RUN, "[compare]\nmodels = [\"nope\"]\n"].concat().into_bytes(),
            "`compare.models` = \"nope\" is not allowed (line 9, column 10): \"nope\" is not a model; allowed: single".into()),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = -1")]),
            "`surface.alpha` = -1 is not allowed (line 3, column 9): a roughness > 0 and at most 1e4".into()),
        // Not TOML, and not UTF-8 (which gave no place at all).
        (run, [RUN, "foo = \n"].concat().into_bytes(), "not TOML (line 8, column 7): ".into()),
        (run, edit(RUN, &[("alpha = 0.5", "alpha = 0.5 # caf\u{1}")]).into_iter().map(|b| if b == 1 { 0xE9 } else { b }).collect(),
            "the byte 0xE9 at line 3, column 18 (byte offset 40) is not UTF-8: the file must be UTF-8 text".into()),
        // `smithwalk lut`'s table configs, which read [surface] and [material] with the run's types.
        (lut, edit(LUT, &[("\"conductor\"", "\"glass\"")]),
            format!("`material.kind` = \"glass\" is not allowed (line 4, column 8): {kinds}")),
        (lut, edit(LUT, &[("[material]", "[[material]]")]),
            "`material` = [[material]] is not allowed (line 3, column 1): one [material] table".into()),
        (lut, edit(LUT, &[("mu = 4", "mu = 4\nnodes = 3")]),
            "`table.nodes` = 3 is not allowed (line 7, column 9): \"cells\" or \"edges\"".into()),
        (lut, edit(LUT, &[("mu = 4", "mu = 0")]),
            "`table.mu` = 0 is not allowed (line 6, column 6): a node count from 1 to 1024".into()),
    ];
    let serde_words = ["enum", "untagged", "variant", "struct", "invalid type", "data did not match", "identifier"];
    let mut failures = Vec::new();
    for (command, config, expected) in &cases {
        let (code, e, made) = smithwalk(command, config);
        let e = e.trim_end();
        let words: Vec<&&str> = serde_words.iter().filter(|w| e.to_lowercase().contains(**w)).collect();
        let ok = code == Some(1)
            && !made
            && e.lines().count() == 1
            && e.contains(expected.as_str())
            && words.is_empty()
            && e.contains(", column ");
        if !ok {
            let config = String::from_utf8_lossy(config);
            failures.push(format!(
                "{command} {config:?}\n  exit {code:?}, output made: {made}\n  got:      {e}\n  expected: {expected}"
            ));
        }
    }
    assert!(failures.is_empty(), "{} of {} bad configs:\n{}", failures.len(), cases.len(), failures.join("\n"));
}

/// A config given as a dict (the Python package's, here its TOML table) gets the same words,
/// named `config <dict>`, without lines and columns, which a dict does not have.
#[test]
fn a_bad_dict_gets_the_same_words_without_a_place() {
    use smithwalk::setup::config::Config;
    let kinds = "\"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"";
    let cases = [
        (("\"conductor\"", "\"glass\""), format!("`material.kind` = \"glass\" is not allowed: {kinds}")),
        (("alpha = 0.5", "alpha = {}"), "`surface.alpha` = {} is not allowed: a roughness > 0".to_string()),
        (
            ("alpha = 0.5", "alpha = 0.5\nndf = 3"),
            "`surface.ndf` = 3 is not allowed: \"ggx\", \"beckmann\" or \"student-t\"".into(),
        ),
        (("alpha = 0.5", "alpha = -1"), "`surface.alpha` = -1 is not allowed: a roughness > 0".into()),
        (("kind = \"conductor\"", "fresnel = \"none\""), format!("`material.kind` is missing: {kinds}")),
    ];
    for ((from, to), expected) in cases {
        let table: toml::Table = RUN.replacen(from, to, 1).parse().unwrap();
        let e = Config::from_table(&table).unwrap_err().to_string();
        assert!(e.starts_with("config <dict> is not valid: ") && e.contains(&expected), "{e:?} lacks {expected:?}");
        assert!(!e.contains("line") && !e.contains("enum") && !e.contains("invalid type"), "{e}");
    }
}
