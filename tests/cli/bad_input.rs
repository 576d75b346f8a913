//! Every bad config gets one line naming the field, the value as written and what is allowed
//! (never serde's "did not match any variant of untagged enum"; tests/cli/wording.rs checks each
//! type and shape of value, with its line and column); long inputs are quoted
//! shortened; configs beyond the documented limits (photons, roughness, threads, memory) are
//! refused before any work, with nothing written; a run config given to `smithwalk lut`, or a
//! table config to `smithwalk run`, says which command reads it.

use std::process::Command;

use smithwalk::setup::config::Config;

const BASE: &str =
    "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 30\n";

fn error_of(toml: &str) -> String {
    match Config::parse(toml) {
        Ok(_) => panic!("accepted:\n{toml}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn every_bad_config_names_its_field_value_and_what_is_allowed() {
    let with = |from: &str, to: &str| BASE.replace(from, to);
    let cases = [
        (
            with("alpha = 0.5", "alpha = 0.5\nndf = \"gaussian\""),
            ["`surface.ndf` = \"gaussian\"", "\"beckmann\" or \"student-t\""],
        ),
        (with("\"conductor\"", "\"metal\""), ["`material.kind` = \"metal\"", "\"dielectric\""]),
        (with("theta_deg = 30", "theta_deg = 30\nside = \"bottom\""), ["`incident.side` = \"bottom\"", "\"inside\""]),
        (with("alpha = 0.5", "alpha = 0.5\nsmith = \"Exact\""), ["`surface.smith` = \"Exact\"", "\"exact\""]),
        (with("alpha = 0.5", "alpha = 0.5\nnormals = \"foo\""), ["`surface.normals` = \"foo\"", "\"vndf\""]),
        (with("\"conductor\"", "\"conductor\"\ncolor = 3"), ["`material.color` is not a known key", "`fresnel`"]),
        (
            with("\"conductor\"", "\"dielectric\""),
            ["`material.eta` is missing from the table at line 4", "n_inside / n_outside, > 0 and != 1"],
        ),
        // A key that a Fresnel kind needs: what it must be, with no "= missing".
        (
            with("\"conductor\"", "\"conductor\"\nfresnel = \"schlick\""),
            [
                "`material.f0` is missing from the table at line 4, column 1: fresnel = \"schlick\" needs a reflectance in [0, 1]",
                "[r, g, b]",
            ],
        ),
        (
            with("\"conductor\"", "\"conductor\"\nfresnel = \"exact\"\neta = 0.2"),
            [
                "`material.k` is missing from the table at line 4, column 1: fresnel = \"exact\" needs the extinction coefficient, >= 0",
                "[r, g, b]",
            ],
        ),
        (
            with("theta_deg = 30", "theta_deg = 30\ntheta_rad = 0.5"),
            ["`incident.theta_deg` and `incident.theta_rad` are both given (line 8, column 1): give one of them", ""],
        ),
        (
            with("theta_deg = 30", "phi_deg = 30"),
            [
                "`incident.theta_deg` is missing from the table at line 6, column 1: a polar angle in [0, 90)",
                "`theta_rad`",
            ],
        ),
        // One material table is `material`, as the text names it; a list's are `material[i]`.
        (with("\"conductor\"", "\"dielectric\"\neta = 1.0"), ["`material.eta` = 1 is not allowed", "!= 1"]),
        (
            with(
                "[material]\nkind = \"conductor\"",
                "[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"dielectric\"",
            ),
            ["`material[1].eta` is missing from the table at line 6", "n_inside / n_outside"],
        ),
        // A value inside a material is named by its key and line, though serde reports it at
        // the whole table (tagged by `kind`).
        (
            with("\"conductor\"", "\"diffuse\"\nalbedo = [0.5, 0.5]"),
            ["`material.albedo` = [0.5, 0.5] is not allowed (line 6, column 10)", "three values [r, g, b]"],
        ),
        (
            with("\"conductor\"", "\"dielectric\"\nname = \"glass\"\neta = [1.4, 1.5, 1.6]"),
            ["`material.eta` = [1.4, 1.5, 1.6] is not allowed (line 7, column 7)", "dispersion, is not modelled"],
        ),
        (
            with(
                "[material]\nkind = \"conductor\"",
                "[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"conductor\"\nfresnel = \"exact\"\neta = 0.2\nk = [3.9, 2.4]",
            ),
            ["`material[1].k` = [3.9, 2.4] is not allowed (line 10, column 5)", "three values [r, g, b]"],
        ),
        (
            with("alpha = 0.5", "alpha = [[0.1, 0.2, 0.3]]"),
            ["`surface.alpha[0]` = [0.1, 0.2, 0.3]", "[alpha_x, alpha_y]"],
        ),
        // Range checks name the config, like the errors found while reading it.
        (
            with("alpha = 0.5", "alpha = 1e5"),
            ["config <text> is not valid: `surface.alpha` = 100000 is not allowed", "> 0 and at most 1e4"],
        ),
        (with("paths = 1000", "paths = 1_000_000_000_000_001"), ["`paths` = 1000000000000001", "at most 10^15"]),
        (
            format!("{BASE}[detector]\nmax_order = 4\n[precision]\ntarget_rel_stderr = 0.01\norders = 1000\n"),
            ["`precision.orders` = 1000", "detector.max_order = 4"],
        ),
        (
            with("theta_deg = 30", "theta_deg = 30\nphi_deg = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]\nside = [\"outside\"]"),
            ["", ""],
        ),
    ];
    for (toml, fragments) in &cases[..cases.len() - 1] {
        let e = error_of(toml);
        assert!(!e.contains("untagged") && !e.contains('\n'), "{e}");
        for f in fragments {
            assert!(e.contains(f), "{e:?} lacks {f:?}");
        }
    }
    Config::parse(&cases[cases.len() - 1].0).expect("a valid sweep");
}

#[test]
fn type_errors_say_what_is_allowed_in_user_terms() {
    let with = |from: &str, to: &str| BASE.replace(from, to);
    let cases = [
        (
            with("paths = 1000", "paths = 1e6"),
            "`paths` = 1e6 is not allowed (line 1, column 9)",
            "e.g. 1000000 or 1_000_000",
        ),
        (with("paths = 1000", "paths = -5"), "`paths` = -5 is not allowed", "an integer from 2 to 10^15"),
        (format!("{BASE}[detector]\nphi_bins = 2.5\n"), "`detector.phi_bins` = 2.5", "an integer from 1 to 4096"),
        (format!("{BASE}[detector]\nmax_order = \"3\"\n"), "`detector.max_order` = \"3\"", "an integer >= 1"),
        (with("theta_deg = 30", "theta_deg = \"30\""), "`incident.theta_deg` = \"30\"", "a polar angle in [0, 90)"),
    ];
    for (toml, value, allowed) in cases {
        let e = error_of(&toml);
        assert!(e.contains(value) && e.contains(allowed), "{e}");
        assert!(!["u32", "u64", "usize", "f64"].iter().any(|rust| e.contains(rust)), "{e}");
    }
}

/// Questions a tool should refuse (issue 36 item 6): a `[compare]` table that names no model
/// would test nothing and pass; an azimuth beyond one turn either way is a typo.
#[test]
fn an_empty_model_list_and_an_azimuth_beyond_a_turn_are_refused() {
    let with = |from: &str, to: &str| BASE.replace(from, to);
    let cases = [
        (format!("{BASE}[compare]\nmodels = []\n"), "`compare.models` = []", "at least one model"),
        (with("theta_deg = 30", "theta_deg = 30\nphi_deg = 1e300"), "`incident.phi_deg` = ", "in [-360, 360]"),
        (with("theta_deg = 30", "theta_deg = 30\nphi_deg = [0, -360.5]"), "`incident.phi_deg` = -360.5", "[-360, 360]"),
    ];
    for (toml, value, allowed) in cases {
        let e = error_of(&toml);
        assert!(e.contains(value) && e.contains(allowed), "{e}");
    }
    // The exact position-free chain ends only by Russian roulette: no threshold, no end.
    let endless =
        format!("{BASE}[energy]\nsplit = false\nthreshold = 0\n[compare]\nmodels = [\"exact-position-free\"]\n");
    let e = error_of(&endless);
    assert!(e.contains("`compare.models` = \"exact-position-free\"") && e.contains("energy.threshold > 0"), "{e}");
    // The bounds themselves are azimuths.
    assert!(Config::parse(&with("theta_deg = 30", "theta_deg = 30\nphi_deg = [-360, 360]")).is_ok());
}

/// `compare --models exact-position-free` on a run walked with no roulette threshold is refused
/// before any work, with one line, and writes no comparison.
#[test]
fn compare_refuses_the_position_free_chain_on_a_run_without_roulette() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, format!("{BASE}[energy]\nsplit = false\nthreshold = 0\n")).unwrap();
    let out_dir = dir.path().join("out");
    let smithwalk = || Command::new(env!("CARGO_BIN_EXE_smithwalk"));
    let run = smithwalk()
        .args(["run", config.to_str().unwrap(), "--paths", "100", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let out =
        smithwalk().args(["compare", out_dir.to_str().unwrap(), "--models", "exact-position-free"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("exact-position-free needs energy.threshold > 0") && stderr.contains("is 0"), "{stderr}");
    assert!(!out_dir.join("models.csv").exists() && !out_dir.join("compare.csv").exists());
}

#[test]
fn a_huge_sweep_is_refused_before_it_is_expanded() {
    let thetas: Vec<String> = (0..1000).map(|i| format!("{}", i as f64 * 0.09)).collect();
    let phis: Vec<String> = (0..1001).map(|i| format!("{}", i as f64 * 0.3)).collect();
    let toml =
        BASE.replace("theta_deg = 30", &format!("theta_deg = [{}]\nphi_deg = [{}]", thetas.join(","), phis.join(",")));
    let e = error_of(&toml);
    assert!(e.contains("1001000 cases") && e.contains("at most 10^6"), "{e}");
}

#[test]
fn a_50_mb_line_is_quoted_shortened() {
    let junk = "x".repeat(50_000_000);
    for toml in [junk.clone(), format!("paths = \"{junk}\"\n"), BASE.replace("\"conductor\"", &format!("\"{junk}\""))] {
        let e = error_of(&toml);
        assert!(e.len() < 1000 && !e.contains('\n'), "{} bytes: {}", e.len(), &e[..e.len().min(300)]);
    }
}

/// Runs `smithwalk run` on `config` (written to a temporary file) with `args`; returns the
/// exit code and stderr, and checks that the output directory was not created.
fn run(config: &str, args: &[&str]) -> (Option<i32>, String) {
    run_command("run", config, args)
}

/// [`run`] with the command `command` (`run` or `lut`, which take a config and `--out`).
fn run_command(command: &str, config: &str, args: &[&str]) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.toml");
    std::fs::write(&path, config).unwrap();
    let out_dir = dir.path().join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args([command, path.to_str().unwrap(), "--out", out_dir.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap();
    assert!(!out_dir.exists(), "{command} {args:?}: an output directory was made");
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn a_config_given_to_the_other_command_says_which_command_reads_it() {
    let config =
        |name: &str| std::fs::read_to_string(format!("{}/configs/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let (code, e) = run_command("lut", &config("quickstart.toml"), &[]);
    assert_eq!(code, Some(1), "{e}");
    for part in [
        "c.toml is not valid: ",
        "`[incident]`, `[detector]`",
        "run config for `smithwalk run`",
        "configs/lut-*.toml",
        "docs/exports.md",
    ] {
        assert!(e.contains(part), "{e:?} lacks {part:?}");
    }
    assert_eq!(e.lines().count(), 1, "{e}");
    let (code, e) = run_command("run", &config("lut-conductor.toml"), &[]);
    assert_eq!(code, Some(1), "{e}");
    for part in [
        "c.toml is not valid: ",
        "`table` = { alpha = 32",
        "table config for `smithwalk lut`",
        "configs/quickstart.toml",
    ] {
        assert!(e.contains(part), "{e:?} lacks {part:?}");
    }
    assert_eq!(e.lines().count(), 1, "{e}");
}

#[test]
fn a_missing_table_or_key_says_what_is_expected_with_no_output() {
    let without = |part: &str| {
        assert!(BASE.contains(part), "{part:?}");
        BASE.replace(part, "")
    };
    let cases = [
        (without("[incident]\ntheta_deg = 30\n"), "`[incident]` is missing: a table with `theta_deg` or `theta_rad`"),
        (without("paths = 1000\n"), "`paths` is missing: photons per case, an integer from 2 to 10^15"),
        (without("[surface]\nalpha = 0.5\n"), "`[surface]` is missing: a table with `alpha`"),
        (without("[material]\nkind = \"conductor\"\n"), "`[material]` is missing: a table with `kind` = \"conductor\""),
        (without("alpha = 0.5\n"), "`surface.alpha` is missing from the table at line 2, column 1: a roughness > 0"),
        (
            without("kind = \"conductor\"\n"),
            "`material.kind` is missing from the table at line 4, column 1: \"conductor\"",
        ),
    ];
    for (config, expected) in cases {
        let (code, e) = run(&config, &[]);
        assert_eq!(code, Some(1), "{e}");
        assert!(e.starts_with("error: config ") && e.contains("c.toml is not valid: "), "{e}");
        assert!(e.contains(expected), "{e:?} lacks {expected:?}");
        // A line number only where it points at the table the key belongs in.
        assert_eq!(e.contains("(line") || e.contains("at line"), expected.contains("at line"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn an_unreadable_config_gives_its_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let path = dir.path().join("quickstart.tom");
    let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", path.to_str().unwrap(), "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(!out_dir.exists());
    assert!(e.starts_with("error: cannot read config ") && e.contains("quickstart.tom: "), "{e}");
    assert_eq!(e.matches("os error 2").count(), 1, "{e}");
}

#[test]
fn limits_are_checked_before_any_work() {
    // Once a loop over every chunk of 10^19 photons, and minutes of spawning threads.
    let (code, e) = run(BASE, &["--paths", "10000000000000000000"]);
    assert_eq!(code, Some(1));
    // Named as typed: the value came from the command line, not from the file.
    assert!(e.contains("`--paths` = 10000000000000000000") && e.contains("10^15"), "{e}");
    let (code, e) = run(BASE, &["--paths", "1"]);
    assert_eq!(code, Some(1));
    assert!(e.contains("`--paths` = 1 is not allowed") && e.contains("at least 2"), "{e}");
    let (code, e) = run(BASE, &["--threads", "100000"]);
    assert_eq!(code, Some(1));
    assert!(e.contains("`--threads` = 100000") && e.contains("at most 1024"), "{e}");
    // 4096 x 4096 bins (the grid's maximum) over 24 cases: ~10^3 GB of tallies, once an abort
    // on a failed allocation.
    let big = BASE
        .replace("theta_deg = 30", "theta_deg = [0, 10, 20, 30, 40, 50, 60, 70, 80, 85, 88, 89]")
        .replace("alpha = 0.5", "alpha = [0.5, 1.0]")
        + "[detector]\ncos_theta_bins = 4096\nphi_bins = 4096\n";
    let (code, e) = run(&big, &["--threads", "1"]);
    assert_eq!(code, Some(1));
    assert!(e.contains("detector.cos_theta_bins") && e.contains("detector.max_order") && e.contains("GB"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// Issue 36 item 4: a 70 000-character material name panicked (a table column's width beyond
/// what `format!` pads); `--checkpoint-seconds 1e20` panicked converting to a `Duration`.
/// Both are refused with one line and nothing written.
#[test]
fn a_huge_name_and_a_huge_checkpoint_interval_are_refused_with_one_line() {
    let long = BASE.replace("\"conductor\"", &format!("\"conductor\"\nname = \"{}\"", "x".repeat(70_000)));
    let (code, e) = run(&long, &[]);
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("`material.name` = a name of 70000 characters") && e.contains("at most 100"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    // 100 characters, the most allowed, run.
    let longest = BASE.replace("\"conductor\"", &format!("\"conductor\"\nname = \"{}\"", "é".repeat(100)));
    Config::parse(&longest).unwrap();
    for seconds in ["1e20", "inf", "0", "1000001"] {
        let (code, e) = run(BASE, &["--checkpoint-seconds", seconds]);
        assert_eq!(code, Some(1), "{seconds}: {e}");
        assert!(e.contains("`--checkpoint-seconds` = ") && e.contains("at most 1e6"), "{seconds}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

/// Issue 36 item 4: a config read from an endless file (`/dev/zero`) grew memory until the
/// process was killed. Every file read is bounded (`smithwalk::input`): a config one byte past
/// 16 MiB (a sparse file) and `/dev/zero` are refused with one line, nothing written.
#[test]
fn files_beyond_their_size_limit_are_refused_with_one_line() {
    use smithwalk::input::MAX_CONFIG_BYTES;
    let dir = tempfile::tempdir().unwrap();
    // A sparse file of 16 MiB + 1 byte.
    let big = dir.path().join("big.toml");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len(MAX_CONFIG_BYTES + 1).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["run", big.to_str().unwrap(), "--out", dir.path().join("out").to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("cannot read config") && e.contains("larger than 16 MiB, the most allowed"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(!dir.path().join("out").exists());
    // /dev/zero itself, where there is one: endless, and refused at the same limit.
    if std::path::Path::new("/dev/zero").exists() {
        let e = Config::load(std::path::Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("larger than 16 MiB"), "{e}");
    }
}

/// As [`files_beyond_their_size_limit_are_refused_with_one_line`] for the tables `compare`
/// reads, an external model and an albedo table one byte past 1 GiB: ignored in CI, where
/// reading 1 GiB into the CSV reader's buffer costs seconds and gigabytes (run with `--ignored`).
#[test]
#[ignore]
fn tables_beyond_their_size_limit_are_refused_with_one_line() {
    use smithwalk::input::MAX_TABLE_BYTES;
    let dir = tempfile::tempdir().unwrap();
    let (run_dir, _) = crate::common::run_config(dir.path(), "small", BASE);
    let table = dir.path().join("table.csv");
    let file = std::fs::File::create(&table).unwrap();
    file.set_len(MAX_TABLE_BYTES + 1).unwrap();
    for option in ["--external", "--albedo-table"] {
        let models = if option == "--external" { "single" } else { "kulla-conty" };
        let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
            .args(["compare", run_dir.to_str().unwrap(), "--models", models, option, table.to_str().unwrap()])
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{option}: {e}");
        assert!(e.contains("larger than 1 GiB, the most allowed"), "{option}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(!run_dir.join("models.csv").exists());
    }
}

/// Issue 36 item 4: `compare --paths` above 10^15 ran unbounded; it is refused like `run`'s.
#[test]
fn compare_paths_beyond_the_run_limit_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (run_dir, _) = crate::common::run_config(dir.path(), "small", BASE);
    let out = Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["compare", run_dir.to_str().unwrap(), "--models", "heitz-nee", "--paths", "1000000000000001"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("`--paths` = 1000000000000001 is not allowed") && e.contains("10^15"), "{e}");
    assert!(!run_dir.join("models.csv").exists());
}

/// `gamma` is the shape of `ndf = "student-t"`, finite and > 1.5, and of no other NDF: each bad
/// combination is refused in one line naming the field, the value and what is allowed, with
/// no output directory.
#[test]
fn student_t_shapes_are_checked_before_any_work() {
    let st = |gamma: &str| BASE.replace("alpha = 0.5", &format!("alpha = 0.5\nndf = \"student-t\"\n{gamma}"));
    let cases = [
        (st("gamma = 1.5"), vec!["`surface.gamma` = 1.5", "finite and > 1.5"]),
        (st("gamma = [3, -2]"), vec!["`surface.gamma` = -2", "finite and > 1.5"]),
        (st("gamma = inf"), vec!["`surface.gamma` = inf", "finite and > 1.5"]),
        (st("gamma = nan"), vec!["`surface.gamma` = NaN", "finite and > 1.5"]),
        (st("gamma = []"), vec!["surface.gamma"]),
        (st(""), vec!["surface.gamma", "finite and > 1.5"]),
        (
            BASE.replace("alpha = 0.5", "alpha = 0.5\ngamma = 3"),
            vec!["`surface.gamma` = 3", "only with ndf = \"student-t\""],
        ),
    ];
    for (config, parts) in cases {
        let (code, e) = run(&config, &[]);
        assert_eq!(code, Some(1), "{config}: {e}");
        for part in parts {
            assert!(e.contains(part), "{e:?} lacks {part:?}");
        }
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
