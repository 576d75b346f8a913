//! `models.csv` is `lobes.csv`'s rows with the models' values beside them (issue 15.4,
//! docs/compare.md): row for row the same key columns as `lobes.csv` (mono and RGB runs), then
//! per model compared, in that order, `<model>` and `<model>_stderr`, empty exactly where the
//! model gives no lobe (`single` outside order 1, closed-form models' standard errors 0,
//! `exact-position-free` outside one-sided facets), finite and non-negative elsewhere, and the
//! closed-form models on every channel of RGB runs, each with its own parameters; a model lobe
//! of a slot the run has no light in is not written. Readers find the models by the header and
//! refuse a models.csv whose rows are not those of lobes.csv.
//!
//! Small runs (8 x 16 bins, fixed seeds); nothing here is statistical.

use crate::common;

use std::collections::{HashMap, HashSet};
use std::path::Path;

use smithwalk::analysis::compare::compare;
use smithwalk::io::rundir::RunDir;
use smithwalk::setup::config::Model;

const RGB: &str = r#"
paths = 5000
seed = 6
[surface]
alpha = 0.5
[material]
kind = "hammon"
albedo = [0.9, 0.5, 0.1]
[incident]
theta_deg = [0, 60]
[detector]
cos_theta_bins = 8
phi_bins = 16
max_order = 2
"#;

const KEYS: [&str; 8] = ["case", "order", "hemisphere", "channel", "cos_lo", "cos_hi", "phi_lo_deg", "phi_hi_deg"];

struct Table {
    headers: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn read(path: &Path) -> Self {
        let mut reader = csv::Reader::from_path(path).unwrap();
        let headers = reader.headers().unwrap().iter().map(String::from).collect();
        let rows = reader.records().map(|r| r.unwrap().iter().map(String::from).collect()).collect();
        Self { headers, rows }
    }

    fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }
}

/// Runs `toml`, compares it with `models` (`paths` photons per case for the Monte Carlo
/// models) and checks the shape of models.csv against lobes.csv; returns both tables.
fn compared(dir: &Path, toml: &str, models: &[Model], paths: u64) -> (Table, Table) {
    let (out, _) = common::run_config(dir, "run", toml);
    compare(&out, models, Some(paths), Some(2)).unwrap();
    let (lobes, table) = (Table::read(&out.join("lobes.csv")), Table::read(&out.join("models.csv")));
    assert_eq!(table.rows.len(), lobes.rows.len(), "models.csv has a row per row of lobes.csv");
    // Key columns first, then `folded`, then a value and a standard error per model, in order.
    let keys: Vec<&str> = KEYS.iter().copied().filter(|k| lobes.column(k).is_some()).collect();
    let mut expected: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    expected.push("folded".into());
    for m in models {
        expected.extend([m.name().to_string(), format!("{}_stderr", m.name())]);
    }
    assert_eq!(table.headers, expected);
    let columns: Vec<(usize, usize)> =
        keys.iter().map(|k| (lobes.column(k).unwrap(), table.column(k).unwrap())).collect();
    for (i, (l, m)) in lobes.rows.iter().zip(&table.rows).enumerate() {
        for &(a, b) in &columns {
            assert_eq!(l[a], m[b], "row {i}: {} differs from lobes.csv", table.headers[b]);
        }
        for pair in m[keys.len() + 1..].chunks(2) {
            assert_eq!(pair[0].is_empty(), pair[1].is_empty(), "row {i}: {m:?}");
            for cell in pair.iter().filter(|c| !c.is_empty()) {
                let v: f64 = cell.parse().unwrap_or_else(|_| panic!("row {i}: {cell:?} is not a number"));
                assert!(v.is_finite() && v >= 0.0, "row {i}: {cell}");
            }
        }
    }
    (lobes, table)
}

/// The cells `(value, stderr)` of `model` in every row.
fn cells<'a>(table: &'a Table, model: &str) -> impl Iterator<Item = (&'a Vec<String>, &'a str, &'a str)> + 'a {
    let (e, se) = (table.column(model).unwrap(), table.column(&format!("{model}_stderr")).unwrap());
    table.rows.iter().map(move |r| (r, r[e].as_str(), r[se].as_str()))
}

#[test]
fn a_mono_run_has_the_rows_of_lobes_csv_and_a_cell_per_model_where_it_applies() {
    let dir = tempfile::tempdir().unwrap();
    let models = [Model::Single, Model::HeitzNee, Model::ExactPositionFree, Model::WangUncorrelated];
    // No `max_order`: each case has the slots its light reached; the models walk ten times more
    // photons, so some reach orders the run does not have.
    let (lobes, table) = compared(dir.path(), &format!("paths = 2000\n{}", common::CASES), &models, 20_000);
    let (case, order) = (table.column("case").unwrap(), table.column("order").unwrap());
    let material = lobes.column("material").unwrap();
    let dielectric: HashSet<&str> =
        lobes.rows.iter().filter(|r| r[material].starts_with("dielectric")).map(|r| r[0].as_str()).collect();
    assert_eq!(dielectric.len(), 4);
    for (r, e, se) in cells(&table, "single") {
        assert_eq!(!e.is_empty(), r[order] == "1", "single is order 1 alone: {r:?}");
        assert!(se.is_empty() || se == "0", "a closed-form model has no standard error: {r:?}");
    }
    for (r, e, _) in cells(&table, "exact-position-free") {
        assert_eq!(e.is_empty(), dielectric.contains(r[case].as_str()), "one-sided facets only: {r:?}");
    }
    // Monte Carlo models give every lobe of the cases they apply to: 0 where their walk reached
    // no light at an order the run has (wang-uncorrelated here, which stops earlier).
    for model in ["heitz-nee", "wang-uncorrelated"] {
        assert!(cells(&table, model).all(|(_, e, se)| !e.is_empty() && !se.is_empty()), "{model} gives every lobe");
    }
    assert!(table.rows.iter().all(|r| r[table.column("folded").unwrap()] == "false"), "nothing folded");
    // The models walked 10 times more photons and reached orders that lobes.csv does not have
    // (compare.csv tests them against an empty lobe); models.csv has no row for them.
    let slots: HashMap<&str, usize> = lobes.rows.iter().fold(HashMap::new(), |mut m, r| {
        let s = m.entry(r[0].as_str()).or_insert(0);
        *s = (*s).max(r[lobes.column("order").unwrap()].parse::<usize>().unwrap() + 1);
        m
    });
    let out = dir.path().join("run");
    let compared = Table::read(&out.join("compare.csv"));
    let (cc, co) = (compared.column("case").unwrap(), compared.column("order").unwrap());
    assert!(
        compared.rows.iter().any(|r| r[co].parse::<usize>().unwrap() >= slots[r[cc].as_str()]),
        "no model reached an order beyond the run's: the test does not test that"
    );
    // RunDir reads the models back by the header; a model's lobes are whole where it has them.
    let read = RunDir::open(&out).unwrap().models().unwrap();
    let mut names: Vec<&str> = read.keys().map(String::as_str).collect();
    names.sort_unstable();
    assert_eq!(names, ["exact-position-free", "heitz-nee", "single", "wang-uncorrelated"]);
    let single = &read["single"];
    assert!(single.lobes.keys().all(|k| k.1 == 1) && single.lobes.len() == 8 + 4, "8 cases' R lobes, 4 T lobes");
    let heitz = &read["heitz-nee"];
    let first = cells(&table, "heitz-nee").next().unwrap().1.parse::<f64>().unwrap();
    assert_eq!(heitz.get(0, 0, "R", 0).unwrap()[0].energy, first);
}

#[test]
fn an_rgb_run_has_the_rows_of_lobes_csv_with_closed_form_models_on_every_channel() {
    let dir = tempfile::tempdir().unwrap();
    let models = [Model::HammonFit, Model::HeitzNee, Model::Single];
    let (_, table) = compared(dir.path(), RGB, &models, 5_000);
    let (order, channel, folded) =
        (table.column("order").unwrap(), table.column("channel").unwrap(), table.column("folded").unwrap());
    for (r, e, se) in cells(&table, "single") {
        assert_eq!(!e.is_empty(), r[order] == "1", "{r:?}");
        assert!(se.is_empty() || se == "0");
    }
    for (r, e, _) in cells(&table, "hammon-fit") {
        assert_eq!(!e.is_empty(), r[order] != "2", "orders 0 and 1 only: {r:?}");
    }
    // Each channel with its own albedo (0.9, 0.5, 0.1): the rows of a bin come r, g, b, and
    // the closed-form models' values fall with the albedo wherever the bin has light.
    for model in ["single", "hammon-fit"] {
        let values: Vec<(&str, &str)> = cells(&table, model).map(|(r, e, _)| (r[channel].as_str(), e)).collect();
        let rgb: Vec<&[(&str, &str)]> = values.chunks(3).filter(|c| !c[0].1.is_empty()).collect();
        assert!(!rgb.is_empty());
        for c in rgb {
            assert_eq!(c.iter().map(|v| v.0).collect::<Vec<_>>(), ["r", "g", "b"]);
            let [r, g, b] = [0, 1, 2].map(|i| c[i].1.parse::<f64>().unwrap());
            assert!(r == 0.0 || (r > g && g > b), "{model}: channels r, g, b {c:?}");
        }
    }
    assert!(cells(&table, "heitz-nee").all(|(_, e, _)| !e.is_empty()), "heitz-nee gives every channel");
    for r in &table.rows {
        assert_eq!(r[folded] == "true", r[order] == "2", "the \"2+\" slot is folded: {r:?}");
    }
}

#[test]
fn a_models_csv_that_is_not_row_for_row_lobes_csv_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = common::run_config(dir.path(), "run", RGB);
    compare(&out, &[Model::HeitzNee], Some(2000), Some(2)).unwrap();
    let path = out.join("models.csv");
    let good = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    // Each damage behind a resealed compare.json: the checks behind the seal refuse it too.
    let error = |text: String| {
        std::fs::write(&path, text).unwrap();
        common::reseal_comparison(&out);
        RunDir::open(&out).unwrap().models().err().map(|e| format!("{e:#}"))
    };
    assert_eq!(error(good.clone()), None);
    // Rows 2 and 3 (the r and g channels of the first bin) swapped.
    let mut swapped = lines.clone();
    swapped.swap(1, 2);
    let err = error(swapped.join("\n") + "\n").unwrap();
    assert!(err.contains("line 2: not the bin of lobes.csv's line 2"), "{err}");
    // A row missing.
    let err = error(lines[..lines.len() - 1].join("\n") + "\n").unwrap();
    assert!(err.contains("rows, but the run in run.json has"), "{err}");
    // A value that is not finite, and a value without its standard error.
    let heitz = lines[0].split(',').position(|h| h == "heitz-nee").unwrap();
    for (cell, expected) in
        [("NaN", "heitz-nee = NaN is not allowed"), ("", "heitz-nee and heitz-nee_stderr must be both empty")]
    {
        let mut row: Vec<&str> = lines[5].split(',').collect();
        row[heitz] = cell;
        let mut bad = lines.clone();
        let row = row.join(",");
        bad[5] = &row;
        let err = error(bad.join("\n") + "\n").unwrap();
        assert!(err.contains("line 6") && err.contains(expected), "{err}");
    }
}
