//! Energy-compensation tables (`smithwalk lut`) against exact values:
//! - conductor F = 1: all orders together are exactly 1 in every cell and on average (white
//!   furnace, docs/theory.md §9.2), and the order slots add up to it;
//! - order 1 of conductor, dielectric (R and T from outside) and Hammon tables against the
//!   single-scattering albedo integrated by adaptive quadrature (`models::single_scattering_bins`
//!   on a 1 x 1 grid, docs/theory.md §5), cell by cell: z = (table - quadrature) / SE, two-sided, Sidak
//!   family level 0.01 over the cells of each test; E_avg of order 1 against an adaptive
//!   Gauss–Kronrod integral over mu of the same quadrature albedo;
//! - dielectric: R + T of all orders is 1 from both sides (energy is conserved);
//! - edge nodes: alpha = 0 is the flat interface (Fresnel from Snell's law, independent of the
//!   code's formula), the walk's limit; mu = 0 is the walk at grazing `MU_GRAZING`;
//! - configs: bad values, the flat form of before and swept values are refused in one line;
//! - the files: the C header compiled by the system C compiler, the Rust source compiled by
//!   rustc, and the OpenEXR image decoded, all hold the values of lut.csv.

use smithwalk::analysis::models::single_scattering_bins;
use smithwalk::analysis::quadrature::integrate;
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::{Grid, Hemisphere};
use smithwalk::exports::lut::{Lut, LutConfig, build};
use smithwalk::setup::cases::{Case, expand};

fn lut(toml: &str) -> Lut {
    let config = LutConfig::parse(toml).expect("test table config parses");
    build(&config, Some(2), false).expect("table builds")
}

/// A table config of facet `kind` (with more `[material]` keys in `material`) and grid `table`.
fn form(material: &str, table: &str) -> String {
    format!("[material]\nkind = {material}\n[table]\n{table}")
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
        lut(&form("\"conductor\"", "mu = 4\nalpha = 3\nalpha_range = [0.0, 1.5]\navg_nodes = 16\npaths = 20000\n"));
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
            "[surface]\nndf = \"{ndf}\"\n{}",
            form("\"conductor\"", "mu = 4\nalpha = 2\nalpha_range = [0.2, 1.0]\navg_nodes = 8\npaths = 400000\n")
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
    let lut = lut(&form(
        "\"dielectric\"",
        "mu = 3\nalpha = 2\nalpha_range = [0.2, 1.0]\neta = 2\neta_range = [1.2, 2.0]\navg_nodes = 6\npaths = 200000\n",
    ));
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
    let lut = lut(&form(
        "\"hammon\"\nf0 = 0.04\nalbedo = 0.8",
        "mu = 3\nalpha = 2\nalpha_range = [0.2, 1.0]\navg_nodes = 4\npaths = 200000\n",
    ));
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
    let lut = lut(&form(
        "\"conductor\"",
        "mu = 2\nalpha = 1\nalpha_range = [0.4, 0.6]\navg_nodes = 2\npaths = 50_000_000\ntarget_stderr = 1e-3\n",
    ));
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
    let conductor = "\"conductor\"";
    let cases = [
        (form(conductor, "mu = 0\npaths = 10\n"), "`table.mu` = 0"),
        (form(conductor, "eta = 4\npaths = 10\n"), "`table.eta` = 4"),
        (form(conductor, "alpha_range = [0.5, 0.2]\npaths = 10\n"), "`table.alpha_range`"),
        (form("\"dielectric\"", "eta = 1\neta_range = [0.5, 1.5]\npaths = 10\n"), "`table.eta_range`"),
        (form("\"hammon\"\nf0 = 1.5", "paths = 10\n"), "`material.f0` = 1.5"),
        (form("\"conductor\"\nfresnel = \"schlick\"\nf0 = 0.5", "paths = 10\n"), "`material.fresnel` = \"schlick\""),
        (form("\"diffuse\"", "paths = 10\n"), "`material.kind` = \"diffuse\""),
        (form(conductor, "target_stderr = -1\npaths = 10\n"), "`table.target_stderr` = -1"),
        (form(conductor, "paths = 1\n"), "`table.paths` = 1"),
        (form(conductor, "nodes = \"edges\"\nmu = 1\npaths = 10\n"), "`table.mu` = 1"),
        (format!("[surface]\nndf = [\"ggx\", \"beckmann\"]\n{}", form(conductor, "paths = 10\n")), "`surface.ndf`"),
    ];
    for (toml, field) in &cases {
        let (err, prefix) = load_error(toml);
        assert!(err.contains(field) && err.contains("not allowed"), "{toml}: {err}");
        // Like a run's config, a table's names the file the value is in.
        assert!(err.starts_with(&prefix), "{toml}: {err}");
    }
}

#[test]
fn a_table_config_that_does_not_read_gets_one_line_naming_the_key() {
    let conductor = "\"conductor\"";
    let cases = [
        (form(conductor, "mu_nodes = 3\npaths = 10\n"), "`table.mu_nodes` is not a known key (line 4, column 1)"),
        (form(conductor, "mu = \"x\"\npaths = 10\n"), "`table.mu` = \"x\" is not allowed (line 4, column 6)"),
        (form("\"metal\"", "paths = 10\n"), "`material.kind` = \"metal\" is not allowed (line 2, column 8)"),
        ("[material]\nkind = \"conductor\"\n".to_string(), "`[table]` is missing: a table with the grid"),
        (
            form(conductor, "nodes = \"corners\"\npaths = 10\n"),
            "`table.nodes` = \"corners\" is not allowed (line 4, column 9)",
        ),
    ];
    for (toml, expected) in &cases {
        let (err, prefix) = load_error(toml);
        assert!(err.starts_with(&prefix), "{toml}: {err}");
        assert!(err.contains(expected) && !err.contains('\n'), "{toml}: {err}");
    }
}

#[test]
fn a_bad_photon_count_on_the_command_line_is_named_as_typed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.toml");
    std::fs::write(&path, form("\"conductor\"", "mu = 2\nalpha = 2\npaths = 10\n")).unwrap();
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
    let lut = lut(&form("\"dielectric\"", "mu = 3\nalpha = 2\neta = 2\nmax_order = 2\navg_nodes = 2\npaths = 2000\n"));
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

#[test]
fn a_table_config_in_the_flat_form_of_before_gets_one_line_naming_the_new_form() {
    // configs/lut-conductor.toml as it was written before [surface], [material] and [table].
    let old = "table = \"conductor\"\nndf = \"ggx\"\nmu = 32\nalpha = 32\nalpha_range = [0.0, 1.0]\nmax_order = 4\n\
               paths = 4_000_000\ntarget_stderr = 2e-4\n";
    let (err, prefix) = load_error(old);
    assert!(err.starts_with(&prefix) && !err.contains('\n'), "{err}");
    for part in [
        "form before",
        "`table`, `ndf`, `mu`",
        "[surface] ndf",
        "[material] kind",
        "into [table]",
        "configs/lut-*.toml",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
}

#[test]
fn a_value_the_table_sweeps_is_refused_in_surface_and_material() {
    let cases = [
        (
            format!("[surface]\nalpha = 0.5\n{}", form("\"conductor\"", "paths = 10\n")),
            "`surface.alpha` = 0.5 is not allowed (line 2, column 9): a table sweeps alpha",
        ),
        (
            form("\"dielectric\"\neta = 1.5", "paths = 10\n"),
            "`material.eta` = 1.5 is not allowed (line 3, column 7): a dielectric table sweeps eta",
        ),
    ];
    for (toml, expected) in &cases {
        let (err, _) = load_error(toml);
        assert!(err.contains(expected) && !err.contains('\n'), "{toml}: {err}");
    }
}

/// The reflectance of a flat interface of relative index `eta` (transmitted side over incident
/// side) at incidence cosine `mu`, from Snell's law and the s- and p-polarised amplitudes
/// (Hecht, Optics, section 4.6.2), unpolarised; 1 under total internal reflection.
fn fresnel_hecht(eta: f64, mu: f64) -> f64 {
    let sin_t = (1.0 - mu * mu).sqrt() / eta;
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (mu - eta * cos_t) / (mu + eta * cos_t);
    let rp = (eta * mu - cos_t) / (eta * mu + cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn edge_nodes_put_the_flat_surface_at_alpha_0_and_the_ranges_ends_on_nodes() {
    // Dielectric, nodes on the edges: mu {0, 0.5, 1}, alpha {0, 1e-4}, eta {1.2, 2}; 20 000
    // photons per walked cell. At alpha = 0 every albedo is the flat interface's exact one, in
    // order 1; the walk at alpha 1e-4 and mu > 0 must agree with it within its standard error
    // (the flat surface is the walk's limit). GGX's tails put a share ~ (alpha / s)^2 of the
    // facets beyond a slope s: from inside at eta 1.2 and mu 0.5, 3.6 deg (s = 0.063) past the
    // critical angle, 2.5e-6 of them, far below the error ~2e-3 (at alpha 0.004 it was 4e-3
    // and the walk transmitted 6e-4 where the flat interface reflects all). z two-sided, Sidak
    // family level 0.01 over the 16 cells compared; a cell whose walk has no spread (total
    // internal reflection: every photon reflected) must equal the flat value to 1e-9.
    let lut = lut(&form(
        "\"dielectric\"",
        "nodes = \"edges\"\nmu = 3\nalpha = 2\nalpha_range = [0.0, 1e-4]\neta = 2\neta_range = [1.2, 2.0]\n\
         avg_nodes = 4\npaths = 20000\n",
    ));
    assert_eq!(
        (lut.mu.clone(), lut.alpha.clone(), lut.eta.clone()),
        (vec![0.0, 0.5, 1.0], vec![0.0, 1e-4], vec![1.2, 2.0])
    );
    for t in &lut.tables {
        let all = t.e.iter().chain(&t.e_stderr).chain(&t.avg).chain(&t.avg_stderr);
        assert!(all.clone().all(|v| v.is_finite() && (0.0..=1.0).contains(v)), "{}: {:?}", t.quantity.name, t.e);
    }
    let limit = z_limit(16);
    for (s, &eta) in lut.eta.iter().enumerate() {
        for side in ["outside", "inside"] {
            let seen = if side == "outside" { eta } else { 1.0 / eta };
            for (m, &mu) in lut.mu.iter().enumerate() {
                let (flat, walked) = ((s * 2) * 3 + m, (s * 2 + 1) * 3 + m);
                let r = fresnel_hecht(seen, mu);
                for (hemisphere, expected) in [("R", r), ("T", 1.0 - r)] {
                    for order in ["all", "1"] {
                        let t = lut.table(&format!("{side}_{hemisphere}_{order}")).unwrap();
                        assert!(
                            (t.e[flat] - expected).abs() < 1e-12,
                            "{side} {hemisphere}_{order} eta {eta} mu {mu}: {}",
                            t.e[flat]
                        );
                        assert_eq!(t.e_stderr[flat], 0.0);
                    }
                    for order in ["2", "3", "4plus"] {
                        assert_eq!(lut.table(&format!("{side}_{hemisphere}_{order}")).unwrap().e[flat], 0.0);
                    }
                    let all = lut.table(&format!("{side}_{hemisphere}_all")).unwrap();
                    if mu > 0.0 {
                        let off = (all.e[walked] - expected).abs();
                        assert!(
                            off <= limit * all.e_stderr[walked] + 1e-9,
                            "{side} {hemisphere} eta {eta} mu {mu}: walk {} +- {} vs flat {expected}",
                            all.e[walked],
                            all.e_stderr[walked]
                        );
                    }
                }
                assert_eq!(lut.photons[(s * 2) * 3 + m], 0, "the flat surface is not walked");
            }
        }
    }
}

#[test]
fn a_node_at_mu_0_holds_the_walk_at_grazing_incidence() {
    // Conductor F = 1, nodes on the edges: mu {0, 1}, alpha {0.3, 1}, 200 000 photons per cell.
    // Order 1 at mu = 0 is the walk at mu = MU_GRAZING: against the single-scattering albedo
    // there by quadrature (docs/theory.md §5). With F = 1 each photon adds 0 or 1 to order 1,
    // and near grazing almost all add 1 (1 - E_1 ~ 4e-6): the z-score takes the binomial
    // standard error of the expected albedo, sqrt(E (1 - E) / n), which is not 0 when no photon
    // of the cell scattered twice. Two-sided, Sidak family level 0.01 over 2 cells.
    let lut = lut(&form(
        "\"conductor\"",
        "nodes = \"edges\"\nmu = 2\nalpha = 2\nalpha_range = [0.3, 1.0]\navg_nodes = 2\npaths = 200000\n",
    ));
    assert_eq!(lut.mu, vec![0.0, 1.0]);
    let e1 = lut.table("R_1").unwrap();
    let limit = z_limit(2);
    for (a, &alpha) in lut.alpha.iter().enumerate() {
        let expected = single_albedo(&case_at(&lut, alpha, smithwalk::exports::lut::MU_GRAZING, None), Hemisphere::R);
        let se = (expected * (1.0 - expected) / lut.photons[a * 2] as f64).sqrt();
        let z = (e1.e[a * 2] - expected) / se;
        assert!(z.abs() < limit, "alpha {alpha}: {} vs {expected} (z = {z:.2})", e1.e[a * 2]);
        assert_eq!(lut.table("R_all").unwrap().e[a * 2], 1.0);
    }
}
