//! Energy-compensation tables (`smithwalk lut`) against exact values:
//! - conductor F = 1: all orders together are exactly 1 in every cell and on average (white
//!   furnace, docs/theory.md §9.2), and the order slots add up to it;
//! - order 1 of conductor, dielectric (R and T from outside) and Hammon tables against the
//!   single-scattering albedo integrated by adaptive quadrature (`models::single_scattering_bins`
//!   on a 1 x 1 grid, docs/theory.md §5), cell by cell: z = (table - quadrature) / SE, two-sided, Sidak
//!   family level 0.01 over the cells of each test; E_avg of order 1 against an adaptive
//!   Gauss–Kronrod integral over mu of the same quadrature albedo;
//! - dielectric: R + T of all orders is 1 from both sides (energy is conserved);
//! - the files: the C header compiled by the system C compiler, the Rust source compiled by
//!   rustc, and the OpenEXR image decoded, all hold the values of lut.csv.

use smithwalk::analysis::models::single_scattering_bins;
use smithwalk::analysis::quadrature::integrate;
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::{Grid, Hemisphere};
use smithwalk::exports::lut::{Lut, LutConfig, build};
use smithwalk::setup::cases::{Case, expand};

fn lut(toml: &str) -> Lut {
    let config: LutConfig = toml::from_str(toml).expect("test table config parses");
    build(&config, Some(2), false).expect("table builds")
}

/// The case of the table's run at (alpha, mu) for the first material and side `outside`.
fn case_at(lut: &Lut, alpha: f64, mu: f64, eta: Option<f64>) -> Case {
    use smithwalk::setup::config::{Alpha, MaterialConfig, OneOrMany};
    let mut config = lut.config.run_config();
    config.surface.alpha = OneOrMany::One(Alpha::Isotropic(alpha));
    if let Some(eta) = eta {
        config.material = OneOrMany::One(MaterialConfig::Dielectric { eta, name: None });
    }
    config.incident.theta_deg = Some(OneOrMany::One(mu.acos().to_degrees()));
    expand(&config).expect("the table's run config expands").remove(0)
}

/// Order-1 albedo into `hemisphere` by quadrature of the single-scattering BSDF: adaptive over
/// the whole hemisphere for specular facets; for facets that scatter about their normal the
/// model uses a fixed rule per bin, so it is summed over 16 x 32 bins.
fn single_albedo(case: &Case, hemisphere: Hemisphere) -> f64 {
    let grid = match case.material.kind() {
        "hammon" | "diffuse" => Grid { cos_bins: 16, phi_bins: 32 },
        _ => Grid { cos_bins: 1, phi_bins: 1 },
    };
    single_scattering_bins(case, &grid, hemisphere, 0, 1e-9).expect("single scattering applies").iter().sum()
}

/// The two-sided z threshold of one of `cells` tests at Sidak family level 0.01.
fn z_limit(cells: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::standard().inverse_cdf(1.0 - sidak(0.01, cells) / 2.0)
}

#[test]
fn conductor_all_orders_are_one_and_orders_add_up() {
    // 4 x 3 cells x 20 000 photons (+ 16 E_avg nodes per alpha), including grazing mu = 1/8.
    let lut =
        lut("table = \"conductor\"\nmu = 4\nalpha = 3\nalpha_range = [0.0, 1.5]\navg_nodes = 16\npaths = 20000\n");
    let all = lut.table("R_all").unwrap();
    assert!(all.e.iter().all(|&e| (e - 1.0).abs() < 1e-12), "{:?}", all.e);
    assert!(all.e_stderr.iter().all(|&s| s < 1e-9), "{:?}", all.e_stderr);
    // Exactly: the average's weights are normalised by their sum (16 nodes summed to
    // 1 - 2.2e-15 and wrote E_avg = 0.9999999999999978).
    assert!(all.avg.iter().all(|&e| e == 1.0), "{:?}", all.avg);
    let parts = ["R_1", "R_2", "R_3", "R_4plus"].map(|q| lut.table(q).unwrap());
    for i in 0..all.e.len() {
        let sum: f64 = parts.iter().map(|t| t.e[i]).sum();
        assert!((sum - 1.0).abs() < 1e-9, "cell {i}: orders add to {sum}");
    }
    // Multiple scattering grows with roughness: order >= 2 at normal incidence.
    let multiple = |a: usize| 1.0 - parts[0].e[a * 4 + 3];
    assert!(multiple(0) < multiple(1) && multiple(1) < multiple(2));
}

#[test]
fn order_one_matches_single_scattering_quadrature() {
    // GGX and Beckmann conductor F = 1: 4 x 2 cells each at 400 000 photons.
    for ndf in ["ggx", "beckmann"] {
        let lut = lut(&format!(
            "table = \"conductor\"\nndf = \"{ndf}\"\nmu = 4\nalpha = 2\nalpha_range = [0.2, 1.0]\navg_nodes = 8\npaths = 400000\n"
        ));
        let e1 = lut.table("R_1").unwrap();
        let limit = z_limit(e1.e.len() + lut.alpha.len());
        for (a, &alpha) in lut.alpha.iter().enumerate() {
            for (m, &mu) in lut.mu.iter().enumerate() {
                let i = a * lut.mu.len() + m;
                let expected = single_albedo(&case_at(&lut, alpha, mu, None), Hemisphere::R);
                let z = (e1.e[i] - expected) / e1.e_stderr[i];
                assert!(z.abs() < limit, "{ndf} alpha {alpha} mu {mu}: {} vs {expected} (z = {z:.2})", e1.e[i]);
            }
            // E_avg = ∫ E1(mu) 2 mu dmu by adaptive quadrature (independent of the table's rule).
            let (expected, _) = integrate(
                |mu: f64| 2.0 * mu * single_albedo(&case_at(&lut, alpha, mu.max(1e-6), None), Hemisphere::R),
                0.0,
                1.0,
                1e-6,
            );
            let z = (e1.avg[a] - expected) / e1.avg_stderr[a];
            assert!(z.abs() < limit, "{ndf} alpha {alpha} E_avg: {} vs {expected} (z = {z:.2})", e1.avg[a]);
        }
    }
}

#[test]
fn dielectric_tables_conserve_energy_and_match_single_scattering() {
    // 3 mu x 2 alpha x 2 eta, both sides, 200 000 photons per cell.
    let lut = lut(
        "table = \"dielectric\"\nmu = 3\nalpha = 2\nalpha_range = [0.2, 1.0]\neta = 2\neta_range = [1.2, 2.0]\navg_nodes = 6\npaths = 200000\n",
    );
    for side in ["outside", "inside"] {
        let (r, t) = (lut.table(&format!("{side}_R_all")).unwrap(), lut.table(&format!("{side}_T_all")).unwrap());
        for i in 0..r.e.len() {
            let total = r.e[i] + t.e[i];
            // Roulette makes R + T noisy per photon; the SEs of R and T bound its SE.
            let bound = 4.0 * (r.e_stderr[i] + t.e_stderr[i]) + 1e-12;
            assert!((total - 1.0).abs() < bound, "{side} cell {i}: R + T = {total}");
        }
    }
    let (r1, t1) = (lut.table("outside_R_1").unwrap(), lut.table("outside_T_1").unwrap());
    let limit = z_limit(2 * r1.e.len());
    for (s, &eta) in lut.eta.iter().enumerate() {
        for (a, &alpha) in lut.alpha.iter().enumerate() {
            for (m, &mu) in lut.mu.iter().enumerate() {
                let i = (s * lut.alpha.len() + a) * lut.mu.len() + m;
                let case = case_at(&lut, alpha, mu, Some(eta));
                for (table, h) in [(r1, Hemisphere::R), (t1, Hemisphere::T)] {
                    let expected = single_albedo(&case, h);
                    let z = (table.e[i] - expected) / table.e_stderr[i];
                    assert!(z.abs() < limit, "eta {eta} alpha {alpha} mu {mu} {h:?}: {} vs {expected}", table.e[i]);
                }
            }
        }
    }
}

#[test]
fn hammon_order_one_matches_single_scattering() {
    let lut = lut(
        "table = \"hammon\"\nf0 = 0.04\nalbedo = 0.8\nmu = 3\nalpha = 2\nalpha_range = [0.2, 1.0]\navg_nodes = 4\npaths = 200000\n",
    );
    let e1 = lut.table("R_1").unwrap();
    let limit = z_limit(e1.e.len());
    for (a, &alpha) in lut.alpha.iter().enumerate() {
        for (m, &mu) in lut.mu.iter().enumerate() {
            let i = a * lut.mu.len() + m;
            let expected = single_albedo(&case_at(&lut, alpha, mu, None), Hemisphere::R);
            let z = (e1.e[i] - expected) / e1.e_stderr[i];
            assert!(z.abs() < limit, "alpha {alpha} mu {mu}: {} vs {expected} (z = {z:.2})", e1.e[i]);
        }
    }
}

#[test]
fn a_precision_target_stops_cells_early() {
    let lut = lut(
        "table = \"conductor\"\nmu = 2\nalpha = 1\nalpha_range = [0.4, 0.6]\navg_nodes = 2\npaths = 50_000_000\ntarget_stderr = 1e-3\n",
    );
    assert!(lut.photons.iter().all(|&n| n < 50_000_000), "{:?}", lut.photons);
    for t in &lut.tables {
        assert!(t.e_stderr.iter().all(|&s| s <= 1e-3), "{}: {:?}", t.quantity.name, t.e_stderr);
    }
}

/// The error of loading `toml` as a table config from a file, and the prefix that names that
/// file (`config <path> is not valid: `).
fn load_error(toml: &str) -> (String, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.toml");
    std::fs::write(&path, toml).unwrap();
    let err = LutConfig::load(&path).expect_err(toml).to_string();
    (err, format!("config {} is not valid: ", path.display()))
}

#[test]
fn bad_table_configs_name_the_field() {
    let cases = [
        ("table = \"conductor\"\nmu = 0\npaths = 10\n", "`mu` = 0"),
        ("table = \"conductor\"\neta = 4\npaths = 10\n", "`eta` = 4"),
        ("table = \"conductor\"\nalpha_range = [0.5, 0.2]\npaths = 10\n", "`alpha_range`"),
        ("table = \"dielectric\"\neta = 1\neta_range = [0.5, 1.5]\npaths = 10\n", "`eta_range`"),
        ("table = \"hammon\"\nf0 = 1.5\npaths = 10\n", "`f0` = 1.5"),
        ("table = \"conductor\"\nf0 = 0.5\npaths = 10\n", "`f0` = 0.5"),
        ("table = \"conductor\"\ntarget_stderr = -1\npaths = 10\n", "`target_stderr` = -1"),
        ("table = \"conductor\"\npaths = 1\n", "`paths` = 1"),
    ];
    for (toml, field) in cases {
        let (err, prefix) = load_error(toml);
        assert!(err.contains(field) && err.contains("not allowed"), "{toml}: {err}");
        // Like a run's config, a table's names the file the value is in.
        assert!(err.starts_with(&prefix), "{toml}: {err}");
    }
}

#[test]
fn a_table_config_that_does_not_read_gets_one_line_naming_the_key() {
    let cases = [
        ("table = \"conductor\"\nmu_nodes = 3\npaths = 10\n", "`mu_nodes` is not a known key (line 2)"),
        ("table = \"conductor\"\nmu = \"x\"\npaths = 10\n", "`mu` = \"x\" is not allowed (line 2)"),
        ("table = \"metal\"\npaths = 10\n", "`table` = \"metal\" is not allowed (line 1)"),
        ("paths = 10\n", "`table` is missing: the table config's facet, \"conductor\", \"dielectric\" or \"hammon\""),
    ];
    for (toml, expected) in cases {
        let (err, prefix) = load_error(toml);
        assert!(err.starts_with(&prefix), "{toml}: {err}");
        assert!(err.contains(expected) && !err.contains('\n'), "{toml}: {err}");
    }
}

#[test]
fn a_bad_photon_count_on_the_command_line_is_named_as_typed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.toml");
    std::fs::write(&path, "table = \"conductor\"\nmu = 2\nalpha = 2\npaths = 10\n").unwrap();
    let out_dir = dir.path().join("out");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_smithwalk"))
        .args(["lut", path.to_str().unwrap(), "--paths", "1", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("`--paths` = 1 is not allowed") && e.contains("at least 2"), "{e}");
    assert!(!out_dir.exists(), "{e}");
}

/// The value of `quantity` at table index `i` as lut.csv wrote it.
fn csv_values(dir: &std::path::Path, quantity: &str) -> Vec<f32> {
    let mut reader = csv::Reader::from_path(dir.join("lut.csv")).unwrap();
    reader
        .records()
        .map(|r| r.unwrap())
        .filter(|r| &r[0] == quantity)
        .map(|r| r[7].parse::<f64>().unwrap() as f32)
        .collect()
}

#[test]
fn c_header_rust_source_and_exr_hold_the_csv_values() {
    let lut = lut("table = \"dielectric\"\nmu = 3\nalpha = 2\neta = 2\nmax_order = 2\navg_nodes = 2\npaths = 2000\n");
    let dir = tempfile::tempdir().unwrap();
    smithwalk::exports::lut::write(&lut, dir.path()).unwrap();
    let expected = csv_values(dir.path(), "inside_T_all");
    assert_eq!(expected.len(), 12);
    let printed = |out: std::process::Output| -> Vec<f32> {
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap().split_whitespace().map(|v| v.parse().unwrap()).collect()
    };

    // C: print every value of the [eta][alpha][mu] array in order with full precision.
    let c = dir.path().join("main.c");
    std::fs::write(
        &c,
        "#include <stdio.h>\n#include \"lut.h\"\nint main(void) {\n  for (int e = 0; e < 2; e++) for (int a = 0; a < 2; a++) for (int m = 0; m < 3; m++)\n    printf(\"%.9g\\n\", smithwalk_E_inside_T_all[e][a][m]);\n  return 0;\n}\n",
    )
    .unwrap();
    let exe = dir.path().join("c_lut");
    let status = std::process::Command::new("cc")
        .args(["-std=c99", "-Wall", "-Werror", "-o"])
        .arg(&exe)
        .arg(&c)
        .status()
        .expect("a C compiler (cc)");
    assert!(status.success());
    assert_eq!(printed(std::process::Command::new(&exe).output().unwrap()), expected);

    // Rust: include the source and print the flattened array.
    let rs = dir.path().join("main.rs");
    std::fs::write(
        &rs,
        "#![allow(dead_code)]\ninclude!(\"lut.rs\");\nfn main() { for e in E_INSIDE_T_ALL { for a in e { for v in a { println!(\"{v:?}\"); } } } }\n",
    )
    .unwrap();
    let exe = dir.path().join("rust_lut");
    let status = std::process::Command::new(std::env::var("RUSTC").unwrap_or("rustc".into()))
        .args(["--edition", "2021", "-o"])
        .arg(&exe)
        .arg(&rs)
        .status()
        .expect("rustc");
    assert!(status.success());
    assert_eq!(printed(std::process::Command::new(&exe).output().unwrap()), expected);

    // OpenEXR: layer E, channel inside_T_all, rows eta * n_alpha + alpha, columns mu.
    let image = exr::prelude::read_all_flat_layers_from_file(dir.path().join("lut.exr")).unwrap();
    let layer =
        image.layer_data.iter().find(|l| l.attributes.layer_name.as_ref().is_some_and(|n| n == "E")).expect("layer E");
    assert_eq!((layer.size.0, layer.size.1), (3, 4));
    let channel = layer.channel_data.list.iter().find(|c| c.name == *"inside_T_all").expect("channel");
    let values: Vec<f32> = channel.sample_data.values_as_f32().collect();
    assert_eq!(values, expected);
}
