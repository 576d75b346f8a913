//! Compensation models evaluated from a user's albedo table (`smithwalk compare
//! --albedo-table`, `analysis::albedo_table`, docs/compensation.md) against the same models on
//! the exact functions. Deterministic quadrature, no random numbers:
//! - a table written here in `smithwalk lut`'s CSV format from the exact `E(mu, alpha)`
//!   (`directional_albedo`) and `E_avg(alpha)` (Gauss–Legendre over mu of the same function) at
//!   29 x 64 nodes gives Kulla-Conty and Turquin lobes within the bilinear interpolation error of
//!   the exact models; the same table subsampled to 8 x 8 nodes gives a larger, visible
//!   difference;
//! - the interpolation is bilinear between nodes and clamped outside them;
//! - malformed tables (NaN, wrong quantity, too few nodes, a missing node, no `_avg` file) are
//!   refused by `smithwalk compare` with a one-line error naming the file and the field, exit
//!   status 1, and no models.csv or compare.csv written.

use crate::common;

use rayon::prelude::*;
use smithwalk::analysis::albedo_table::{AlbedoTable, linear};
use smithwalk::analysis::compensation::*;
use smithwalk::analysis::quadrature::gauss_legendre;
use smithwalk::engine::detector::Grid;
use smithwalk::microsurface::ndf::{AnyNdf, Ggx, Roughness};
use smithwalk::setup::cases::{Case, expand};
use smithwalk::setup::config::*;

const GRID: Grid = Grid { cos_bins: 8, phi_bins: 8 };
/// Fine table: `ALPHAS` alpha nodes on [0.25, 0.75] (spacing 1/56, as fine as 57 nodes on
/// [0, 1]) and `MUS` mu nodes on [0, 1] (spacing 1/63), equally spaced; the alpha range holds
/// the tested roughnesses, and a narrower range keeps the test's CPU time down.
const ALPHAS: usize = 29;
const MUS: usize = 64;
/// The coarse table takes every `STRIDES`-th node of the fine one: 8 x 8 nodes.
const STRIDES: (usize, usize) = (4, 9);
const ALPHA_RANGE: (f64, f64) = (0.25, 0.75);
/// The tolerance of each exact `E` evaluation of the table.
const TOL: f64 = 1e-8;

/// A GGX conductor with F = 1 of roughness `alpha`, lit from `theta` degrees.
fn case(alpha: f64, theta: f64) -> Case {
    let toml = format!(
        "paths = 2\n[surface]\nalpha = {alpha}\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = {theta}\n"
    );
    expand(&Config::parse(&toml).unwrap()).unwrap().remove(0)
}

fn alpha_node(i: usize) -> f64 {
    ALPHA_RANGE.0 + (ALPHA_RANGE.1 - ALPHA_RANGE.0) * i as f64 / (ALPHAS - 1) as f64
}

fn mu_node(j: usize) -> f64 {
    j as f64 / (MUS - 1) as f64
}

/// The exact `E(mu)` at every fine node and `E_avg` per alpha node (Gauss–Legendre, 16 nodes in
/// mu on [0, 1/4] and 12 on [1/4, 1]).
fn exact_grid() -> (Vec<Vec<f64>>, Vec<f64>) {
    let avg_rule: Vec<(f64, f64)> = [gauss_legendre(16, 0.0, 0.25), gauss_legendre(12, 0.25, 1.0)].concat();
    let rows: Vec<(Vec<f64>, f64)> = (0..ALPHAS)
        .into_par_iter()
        .map(|i| {
            let ndf = Ggx::with_alpha(alpha_node(i));
            let e = |mu: f64| directional_albedo(&ndf, mu, Fresnel::One, TOL);
            let avg = 2.0 * avg_rule.iter().map(|&(mu, w)| w * mu * e(mu)).sum::<f64>();
            ((0..MUS).map(|j| e(mu_node(j))).collect(), avg)
        })
        .collect();
    rows.into_iter().unzip()
}

/// Writes `dir/lut.csv` and `dir/lut_avg.csv` as `smithwalk lut` does (quantities R_1 and, as
/// decoys the reader must skip, R_all), from every `strides.0`-th alpha and `strides.1`-th mu
/// node of the fine grid.
fn write_table(dir: &std::path::Path, e: &[Vec<f64>], e_avg: &[f64], strides: (usize, usize)) {
    std::fs::create_dir_all(dir).unwrap();
    let mut lut = String::from("quantity,side,hemisphere,order,eta,alpha,mu,E,E_stderr,photons\n");
    let mut avg = String::from("quantity,side,hemisphere,order,eta,alpha,E_avg,E_avg_stderr\n");
    for (q, order) in [("R_1", "1"), ("R_all", "all")] {
        for i in (0..ALPHAS).step_by(strides.0) {
            let alpha = alpha_node(i);
            for j in (0..MUS).step_by(strides.1) {
                let v = if order == "1" { e[i][j] } else { 1.0 };
                lut += &format!("{q},outside,R,{order},,{alpha},{},{v},0,1000000\n", mu_node(j));
            }
            let v = if order == "1" { e_avg[i] } else { 1.0 };
            avg += &format!("{q},outside,R,{order},,{alpha},{v},0\n");
        }
    }
    std::fs::write(dir.join("lut.csv"), lut).unwrap();
    std::fs::write(dir.join("lut_avg.csv"), avg).unwrap();
}

/// Largest `|E_table(mu) - E(mu)|` over 200 points in mu, and the relative L1 distance
/// `sum |a - b| / sum |b|` of two lobes.
fn albedo_error(table: &Albedo, exact: &Albedo, from: f64) -> f64 {
    (0..=200)
        .map(|k| from + (1.0 - from) * k as f64 / 200.0)
        .map(|mu| (table.at(mu) - exact.at(mu)).abs())
        .fold(0.0, f64::max)
}

fn relative_l1(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / b.iter().map(|y| y.abs()).sum::<f64>()
}

/// A fine table of the exact functions (29 alpha x 64 mu nodes) reproduces the exact models to
/// the interpolation error; an 8 x 8 table of the same functions visibly does not. Measured
/// (GGX, F = 1, alpha 0.4 at 0 deg and 0.6 at 70 deg, 8 x 8 bins, Kulla-Conty and Turquin):
/// - largest `|E_table - E|` over mu in [0.1, 1]: fine 1.2e-4 and 1.6e-4, coarse 1.6e-2 and
///   2.0e-2 (over [0, 1], where the steep rise of E at grazing dominates: 2.1e-3, 3.1e-3 and
///   2.3e-2, 3.0e-2); asserted: fine below 5e-4, coarse above 10 times fine;
/// - the lobes' relative L1 distance to the exact model's: fine 2.2e-5 to 5.7e-5, coarse 9.6e-4
///   to 4.3e-3, 36 to 78 times the fine one; asserted: fine below 1e-4, coarse above 5e-4 and
///   above 20 times fine.
#[test]
fn a_fine_table_reproduces_the_exact_models_and_a_coarse_one_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let (e, e_avg) = exact_grid();
    write_table(&dir.path().join("fine"), &e, &e_avg, (1, 1));
    write_table(&dir.path().join("coarse"), &e, &e_avg, STRIDES);
    let fine = AlbedoTable::read(&dir.path().join("fine")).unwrap();
    let coarse = AlbedoTable::read(&dir.path().join("coarse/lut.csv")).unwrap();
    assert_eq!((fine.alpha.len(), fine.mu.len(), coarse.alpha.len(), coarse.mu.len()), (29, 64, 8, 8));
    for (alpha, theta) in [(0.4, 0.0), (0.6, 70.0)] {
        let c = case(alpha, theta);
        let mut exact_cache = AlbedoCache::default();
        let exact_albedo = exact_cache.get(AnyNdf::Ggx(Ggx(Roughness::isotropic(alpha))), Fresnel::One).clone();
        let errors = [&fine, &coarse].map(|t| albedo_error(&Albedo::from_table(t, alpha), &exact_albedo, 0.0));
        let above = [&fine, &coarse].map(|t| albedo_error(&Albedo::from_table(t, alpha), &exact_albedo, 0.1));
        eprintln!(
            "alpha {alpha}: largest |E_table - E|: fine {:.2e}, coarse {:.2e}; mu >= 0.1: {:.2e}, {:.2e}",
            errors[0], errors[1], above[0], above[1]
        );
        assert!(above[0] < 5e-4 && above[1] > 10.0 * above[0] && errors[1] > errors[0], "{errors:?} {above:?}");
        for model in [Compensation::KullaConty, Compensation::Turquin] {
            let lobe = |cache: &mut AlbedoCache| {
                let [l] = compensated_bins::<1>(model, &c, &GRID, &|_| 1e-9, cache).unwrap();
                l.energy
            };
            let exact = lobe(&mut exact_cache);
            let d_fine = relative_l1(&lobe(&mut AlbedoCache::with_table(fine.clone())), &exact);
            let d_coarse = relative_l1(&lobe(&mut AlbedoCache::with_table(coarse.clone())), &exact);
            eprintln!(
                "{model:?} alpha {alpha}, {theta} deg: relative L1 to exact: fine {d_fine:.2e}, coarse {d_coarse:.2e}"
            );
            assert!(d_fine < 1e-4, "{model:?} alpha {alpha}: {d_fine}");
            assert!(d_coarse > 5e-4 && d_coarse > 20.0 * d_fine, "{model:?} alpha {alpha}: {d_coarse} vs {d_fine}");
        }
    }
}

/// Bilinear between nodes, clamped outside them, with E_avg linear in alpha.
#[test]
fn the_table_is_interpolated_bilinearly_and_clamped() {
    let dir = tempfile::tempdir().unwrap();
    let lut = "alpha,mu,E\n0.2,0.25,0.9\n0.2,0.75,0.95\n0.6,0.25,0.5\n0.6,0.75,0.7\n";
    std::fs::write(dir.path().join("mine.csv"), lut).unwrap();
    std::fs::write(dir.path().join("mine_avg.csv"), "alpha,E_avg\n0.2,0.92\n0.6,0.6\n").unwrap();
    let table = AlbedoTable::read(&dir.path().join("mine.csv")).unwrap();
    // At alpha 0.3 (a quarter of the way): rows 0.9 + (0.5 - 0.9)/4 = 0.8 and 0.95 + (0.7 - 0.95)/4 = 0.8875.
    let e = Albedo::from_table(&table, 0.3);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
    assert!(close(e.at(0.25), 0.8) && close(e.at(0.75), 0.8875));
    assert!(close(e.at(0.5), 0.84375), "{}", e.at(0.5));
    assert!(close(e.at(0.0), 0.8) && close(e.at(1.0), 0.8875), "mu is clamped");
    assert!(close(e.average(), 0.84));
    assert!(
        close(Albedo::from_table(&table, 0.01).at(0.0), 0.9) && close(Albedo::from_table(&table, 2.0).at(1.0), 0.7),
        "alpha is clamped"
    );
    assert!(close(Albedo::from_table(&table, 2.0).average(), 0.6));
    assert!(close(linear(&[0.0, 1.0], &[1.0, 3.0], 0.25), 1.5));
}

/// `smithwalk compare --albedo-table` refuses malformed tables: one line naming the file and
/// the field, exit status 1, nothing written.
#[test]
fn malformed_tables_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = common::run_config(
        dir.path(),
        "tiny",
        "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n[detector]\ncos_theta_bins = 2\n\
         phi_bins = 2\nmax_order = 2\n",
    );
    let head = "quantity,side,hemisphere,order,eta,alpha,mu,E,E_stderr,photons\n";
    let good: String = [(0.25, 0.25, 0.9), (0.25, 0.75, 0.95), (0.75, 0.25, 0.5), (0.75, 0.75, 0.7)]
        .iter()
        .map(|(a, m, e)| format!("R_1,outside,R,1,,{a},{m},{e},0,1000\n"))
        .collect();
    let avg = "quantity,side,hemisphere,order,eta,alpha,E_avg,E_avg_stderr\nR_1,outside,R,1,,0.25,0.9,0\n\
               R_1,outside,R,1,,0.75,0.6,0\n";
    let compare = |table: &std::path::Path, models: &str| {
        common::smithwalk(&[
            "compare",
            run.to_str().unwrap(),
            "--models",
            models,
            "--albedo-table",
            table.to_str().unwrap(),
        ])
    };
    let refused = |lut: &str, avg: Option<&str>, expected: &[&str]| {
        let table = tempfile::tempdir().unwrap();
        std::fs::write(table.path().join("lut.csv"), format!("{head}{lut}")).unwrap();
        if let Some(avg) = avg {
            std::fs::write(table.path().join("lut_avg.csv"), avg).unwrap();
        }
        let output = compare(table.path(), "kulla-conty");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        for e in expected {
            assert!(stderr.contains(e), "{stderr:?} lacks {e:?}");
        }
        assert!(!run.join("models.csv").exists() && !run.join("compare.csv").exists(), "something was written");
    };
    refused(&good.replace("0.95", "NaN"), Some(avg), &["lut.csv, line 3, column `E`", "\"NaN\"", "[0, 1]"]);
    refused(&good.replace("R_1", "R_all"), Some(avg), &["lut.csv", "no rows of quantity `R_1`", "found: R_all"]);
    refused(&good.replace("0.75,", "0.25,"), Some(avg), &["lut.csv", "1 alpha node(s)", "at least 2"]);
    refused(
        &good.lines().take(3).map(|l| format!("{l}\n")).collect::<String>(),
        Some(avg),
        &["no E at alpha 0.75, mu 0.75"],
    );
    refused(&good, None, &["lut_avg.csv"]);
    refused(&good, Some(&avg.replace("0.6", "inf")), &["lut_avg.csv, line 3, column `E_avg`"]);
    refused(&good.replace(",0.25,", ",-1,"), Some(avg), &["column `alpha`", "alpha >= 0"]);
    // A table no model reads is refused too.
    let table = tempfile::tempdir().unwrap();
    std::fs::write(table.path().join("lut.csv"), format!("{head}{good}")).unwrap();
    std::fs::write(table.path().join("lut_avg.csv"), avg).unwrap();
    let output = compare(table.path(), "single");
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("only read by the models kulla-conty"));
    assert!(!run.join("models.csv").exists(), "something was written");
}

/// `smithwalk compare --albedo-table` refuses a table whose `lut.json` says it was made for
/// another NDF, another facet than the F = 1 conductor, or an alpha range without the run's
/// alpha: one line naming the table's and the run's, exit status 1, nothing written. The
/// matching table, and a table without a `lut.json` (a user's own), are read.
#[test]
fn a_table_made_for_another_ndf_facet_or_range_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run_of = |name: &str, ndf: &str| {
        common::run_config(
            dir.path(),
            name,
            &format!(
                "paths = 1000\n[surface]\nndf = \"{ndf}\"\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\n\
                 theta_deg = 0\n[detector]\ncos_theta_bins = 2\nphi_bins = 2\nmax_order = 2\n"
            ),
        )
        .0
    };
    let (ggx, beckmann) = (run_of("ggx", "ggx"), run_of("beckmann", "beckmann"));
    let lut: String = [(0.25, 0.25, 0.9), (0.25, 0.75, 0.95), (0.75, 0.25, 0.5), (0.75, 0.75, 0.7)]
        .iter()
        .map(|(a, m, e)| format!("R_1,outside,R,1,,{a},{m},{e},0,1000\n"))
        .collect();
    let table = |record: Option<(&str, &str, [f64; 2])>| {
        let table = tempfile::tempdir().unwrap();
        let head = "quantity,side,hemisphere,order,eta,alpha,mu,E,E_stderr,photons\n";
        std::fs::write(table.path().join("lut.csv"), format!("{head}{lut}")).unwrap();
        std::fs::write(
            table.path().join("lut_avg.csv"),
            "quantity,side,hemisphere,order,eta,alpha,E_avg,E_avg_stderr\nR_1,outside,R,1,,0.25,0.9,0\nR_1,outside,R,1,,0.75,0.6,0\n",
        )
        .unwrap();
        if let Some((kind, ndf, [lo, hi])) = record {
            // The record as `smithwalk lut` writes it (data/lut/ggx-conductor/lut.json's form).
            let json = format!(
                "{{\"config\": {{\"table\": \"{kind}\", \"ndf\": \"{ndf}\", \"alpha_range\": [{lo:?}, {hi:?}], \
                 \"eta_range\": [1.0, 3.0], \"max_order\": 4, \"avg_nodes\": 16, \"paths\": 1000, \"seed\": 1}}}}"
            );
            std::fs::write(table.path().join("lut.json"), json).unwrap();
        }
        table
    };
    let compare = |run: &std::path::Path, table: &std::path::Path| {
        let output = common::smithwalk(&[
            "compare",
            run.to_str().unwrap(),
            "--models",
            "kulla-conty",
            "--albedo-table",
            table.to_str().unwrap(),
        ]);
        (
            output.status.code(),
            String::from_utf8_lossy(&output.stderr).to_string(),
            String::from_utf8_lossy(&output.stdout).to_string(),
        )
    };
    let refused = |run: &std::path::Path, record: (&str, &str, [f64; 2]), expected: &[&str]| {
        let t = table(Some(record));
        let (code, stderr, _) = compare(run, t.path());
        assert_eq!(code, Some(1), "{record:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        for e in expected {
            assert!(stderr.contains(e), "{stderr:?} lacks {e:?}");
        }
        assert!(!run.join("models.csv").exists() && !run.join("compare.csv").exists(), "something was written");
    };
    refused(
        &beckmann,
        ("conductor", "ggx", [0.0, 1.0]),
        &["the table is for ggx conductor facets", "is beckmann, alpha 0.5"],
    );
    refused(&ggx, ("hammon", "ggx", [0.0, 1.0]), &["ggx hammon facets", "F = 1 conductor table"]);
    refused(&ggx, ("conductor", "ggx", [0.6, 1.0]), &["alpha in [0.6, 1]", "is ggx, alpha 0.5"]);
    refused(&beckmann, ("conductor", "ggx", [0.6, 1.0]), &["the table is for ggx"]);
    let matching = table(Some(("conductor", "beckmann", [0.0, 1.0])));
    let (code, stderr, report) = compare(&beckmann, matching.path());
    assert_eq!(code, Some(0), "{stderr}");
    assert!(report.contains("beckmann conductor; 2 alpha x 2 mu nodes"), "{report}");
    let own = table(None);
    let (code, stderr, report) = compare(&ggx, own.path());
    assert_eq!(code, Some(0), "{stderr}");
    assert!(report.contains("without a lut.json: NDF and facet unchecked"), "{report}");
}

/// The committed table's `lut.json`, written before the record gained fields, reads.
#[test]
fn the_committed_tables_record_reads() {
    use smithwalk::io::table_record::{Nodes, TableKind, TableRecord};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/lut/ggx-conductor/lut.json");
    let record = TableRecord::read(&path).unwrap();
    assert_eq!(
        (record.table, record.ndf, record.alpha_range, record.nodes),
        (TableKind::Conductor, NdfKind::Ggx, [0.0, 1.0], Nodes::Cells)
    );
}
