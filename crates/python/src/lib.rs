//! The native half of the `smithwalk` Python package (`smithwalk._native`): runs a
//! configuration with the GIL released and Ctrl-C checked between rounds, hands the detector's
//! tallies over as numpy arrays, writes and reads run directories with the crate's own writers
//! and readers, and runs the crate's `compare`. The Python half (`python/smithwalk/`) builds the
//! user-facing objects on top of these functions.

mod bsdf;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyFloat, PyInt, PyList, PyTuple};
use smithwalk::engine::detector::{Detector, Grid};
use smithwalk::engine::run::{CaseResult, Estimator, Shard};
use smithwalk::io::schema::{self, Column};
use smithwalk::setup::config::{Config, ConfigError, Model, shorten};
use smithwalk::{RunOptions, Simulation};

/// The message the command line prints for an error (`error: {e:#}` without the prefix).
fn message(e: impl Into<anyhow::Error>) -> String {
    format!("{:#}", e.into())
}

/// A configuration error as Python sees it: `OSError` when the file cannot be read,
/// `ValueError` otherwise, with the command line's message.
fn config_error(e: ConfigError) -> PyErr {
    match e {
        ConfigError::Read { .. } => PyOSError::new_err(message(e)),
        _ => PyValueError::new_err(message(e)),
    }
}

fn runtime_error(e: anyhow::Error) -> PyErr {
    PyRuntimeError::new_err(message(e))
}

/// Reads and validates a configuration given as `kind`: `"path"` (a TOML file), `"toml"` (TOML
/// text) or `"dict"` (a Python dict, turned into a TOML table so that it goes through exactly
/// the parser and checks of a file).
fn load_config(source: &Bound<'_, PyAny>, kind: &str) -> PyResult<Config> {
    let parsed = match kind {
        "path" => Config::load(Path::new(&source.extract::<String>()?)),
        "toml" => Config::parse(&source.extract::<String>()?),
        "dict" => return load_dict(source),
        _ => return Err(PyValueError::new_err(format!("unknown config kind {kind:?}"))),
    };
    parsed.map_err(config_error)
}

/// Reads and validates a config dict. Its `seed` may be any integer from 0 to 2^64 - 1, Python's
/// or numpy's, as the command line's `--seed`: TOML integers stop at 2^63 - 1, so a larger seed
/// is taken out of the table and set on the parsed config.
fn load_dict(source: &Bound<'_, PyAny>) -> PyResult<Config> {
    let Ok(dict) = source.cast::<PyDict>() else {
        return Err(PyValueError::new_err("config <dict> is not valid: not a dict"));
    };
    let large_seed = match dict.get_item("seed")? {
        Some(seed) if !seed.is_instance_of::<PyBool>() => seed.extract::<u64>().ok().filter(|&s| s > i64::MAX as u64),
        _ => None,
    };
    let source = match large_seed {
        Some(_) => {
            let copy = dict.copy()?;
            copy.del_item("seed")?;
            copy
        }
        None => dict.clone(),
    };
    let table = match to_toml(source.as_any(), "", 0) {
        Ok(toml::Value::Table(table)) => table,
        Ok(_) => return Err(PyValueError::new_err("config <dict> is not valid: not a dict")),
        Err(e) => return Err(config_error(e.in_source("<dict>"))),
    };
    let mut config = Config::from_table(&table).map_err(config_error)?;
    if let Some(seed) = large_seed {
        config.seed = seed;
    }
    Ok(config)
}

/// The deepest nesting of a config dict's values: a config's deepest value, an `[alpha_x,
/// alpha_y]` pair in a list of roughnesses, is 3 deep. The bound also ends a dict or list that
/// holds itself, which would otherwise recurse until the stack overflows.
const MAX_DEPTH: usize = 16;

/// A Python value of a config dict at `field`, `depth` tables and lists deep, as TOML: dicts,
/// lists and tuples, booleans, integers, floats (NaN and infinities too, for the checks to name
/// them) and strings; numpy scalars and arrays by their `tolist()`.
fn to_toml(value: &Bound<'_, PyAny>, field: &str, depth: usize) -> Result<toml::Value, ConfigError> {
    let invalid = |allowed: &str| ConfigError::Invalid {
        field: field.to_string(),
        value: value.repr().map_or_else(|_| "?".to_string(), |r| shorten(&r.to_string_lossy(), 60)),
        allowed: allowed.to_string(),
    };
    if depth > MAX_DEPTH {
        return Err(ConfigError::Invalid {
            field: field.to_string(),
            value: "a value nested deeper".to_string(),
            allowed: format!(
                "dicts and lists nested at most {MAX_DEPTH} deep (a config's deepest value is 3 deep; a dict or list \
                 that holds itself is never allowed)"
            ),
        });
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        // A snapshot of the items: the dict may change while its values are converted.
        for item in dict.items().iter() {
            let (key, item): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
                item.extract().map_err(|_| invalid("a dict of key-value pairs"))?;
            let key: String = key.extract().map_err(|_| invalid("a dict with string keys"))?;
            let inner = if field.is_empty() { key.clone() } else { format!("{field}.{key}") };
            table.insert(key, to_toml(&item, &inner, depth + 1)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value.try_iter().map_err(|_| invalid("a list"))?;
        let values = items
            .enumerate()
            .map(|(i, item)| to_toml(&item.map_err(|_| invalid("a list"))?, &format!("{field}[{i}]"), depth + 1))
            .collect::<Result<_, _>>()?;
        return Ok(toml::Value::Array(values));
    }
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.is_truthy().map_err(|_| invalid("a boolean"))?));
    }
    if value.is_instance_of::<PyInt>() {
        // `seed` from 2^63 to 2^64 - 1 never gets here ([`load_dict`]).
        let range = if field == "seed" { "an integer from 0 to 2^64 - 1" } else { "an integer from -2^63 to 2^63 - 1" };
        return value.extract().map(toml::Value::Integer).map_err(|_| invalid(range));
    }
    if value.is_instance_of::<PyFloat>() {
        return value.extract().map(toml::Value::Float).map_err(|_| invalid("a number"));
    }
    if let Ok(text) = value.extract::<String>() {
        return Ok(toml::Value::String(text));
    }
    match value.call_method0("tolist") {
        Ok(plain) if !plain.is(value) => to_toml(&plain, field, depth + 1),
        _ => Err(invalid("a number, a string, a boolean, a list or a dict (leave the key out for its default)")),
    }
}

/// A finished run: its resolved configuration and the simulation's measurements.
#[pyclass(frozen, module = "smithwalk._native")]
struct NativeRun {
    config: Config,
    sim: Simulation,
}

/// Runs every case of a configuration (`source` read as `kind`, see [`load_config`]) with the
/// command line's overrides, the GIL released. After every round of chunks the walk takes the
/// GIL back for a moment to let Python handle signals: Ctrl-C stops the run and raises
/// `KeyboardInterrupt`, with nothing written.
#[pyfunction]
#[pyo3(signature = (source, kind, paths=None, seed=None, threads=None, progress=false))]
fn run(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    kind: &str,
    paths: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    progress: bool,
) -> PyResult<NativeRun> {
    let mut config = load_config(source, kind)?;
    if let Some(p) = paths {
        config.paths = p;
    }
    if let Some(s) = seed {
        config.seed = s;
    }
    config.validate().map_err(config_error)?;
    if threads == Some(0) {
        return Err(PyValueError::new_err("`threads` = 0 is not allowed: at least 1 thread"));
    }
    let options = RunOptions {
        shard: Shard::WHOLE,
        threads,
        show_progress: progress,
        estimator: Estimator::Walk,
        max_memory: None,
    };
    let mut signal: Option<PyErr> = None;
    let sim = py.detach(|| {
        smithwalk::simulate_from(&config, &options, None, &mut |_, _, _| {
            Python::attach(|py| py.check_signals()).map_err(|e| {
                signal = Some(e);
                anyhow::anyhow!("interrupted")
            })
        })
    });
    match (sim, signal) {
        (_, Some(e)) => Err(e),
        (Ok(sim), None) => Ok(NativeRun { config, sim }),
        (Err(e), None) => Err(runtime_error(e)),
    }
}

/// Per-bin arrays of one source (the measurement or a model), flat in the order of the shape
/// `(case, order, hemisphere, cos_bin, phi_bin[, channel])`.
struct BinArrays {
    shape: Vec<usize>,
    columns: BTreeMap<&'static str, Vec<f64>>,
    count: Option<Vec<u64>>,
}

impl BinArrays {
    fn new(shape: Vec<usize>, columns: &[&'static str], with_count: bool) -> Self {
        let n = shape.iter().product();
        Self {
            shape,
            columns: columns.iter().map(|&c| (c, vec![0.0; n])).collect(),
            count: with_count.then(|| vec![0; n]),
        }
    }

    /// The flat index of bin `bin` (`cos index * phi_bins + phi index`) and `channel` of the
    /// lobe `[case, order, hemisphere]`.
    fn at(&self, [case, order, hemisphere]: [usize; 3], bin: usize, channel: usize) -> usize {
        let (orders, bins, channels) =
            (self.shape[1], self.shape[3] * self.shape[4], self.shape.get(5).map_or(1, |c| *c));
        (((case * orders + order) * 2 + hemisphere) * bins + bin) * channels + channel
    }

    fn into_dict<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        let shape = self.shape;
        for (name, values) in self.columns {
            dict.set_item(name, PyArray1::from_vec(py, values).reshape(shape.clone())?)?;
        }
        if let Some(count) = self.count {
            dict.set_item(schema::COUNT.name, PyArray1::from_vec(py, count).reshape(shape)?)?;
        }
        Ok(dict)
    }
}

/// The shape of a run's arrays, with the channel axis only for RGB runs.
fn shape(cases: usize, orders: usize, grid: Grid, channels: Option<usize>) -> Vec<usize> {
    let mut shape = vec![cases, orders, 2, grid.cos_bins, grid.phi_bins];
    shape.extend(channels);
    shape
}

/// The measured values per bin, named as their columns of `lobes.csv`.
const MEASURED: [&str; 4] =
    [schema::ENERGY.name, schema::ENERGY_STDERR.name, schema::BSDF.name, schema::BSDF_STDERR.name];

/// Copies one case's detector into the arrays: the same means, standard errors, counts and
/// projected solid angles that `lobes.csv` is written from.
fn fill<const C: usize>(d: &Detector<C>, case: usize, arrays: &mut BinArrays) {
    let grid = d.grid;
    let n = d.tallies.photons;
    for (slot, tallies) in d.tallies.orders.iter().enumerate() {
        for (i, tally) in tallies.bins.iter().enumerate() {
            // `i` runs over hemisphere, cos bin and phi bin, the arrays' next three axes.
            let solid = grid.projected_solid_angle(i % grid.bins() / grid.phi_bins);
            for c in 0..C {
                let at = arrays.at([case, slot, 0], i, c);
                let (energy, se) = tally.mean_and_stderr(n, c);
                for (name, value) in MEASURED.into_iter().zip([energy, se, energy / solid, se / solid]) {
                    arrays.columns.get_mut(name).expect("a measured column")[at] = value;
                }
                arrays.count.as_mut().expect("measured counts")[at] = tally.count;
            }
        }
    }
}

#[pymethods]
impl NativeRun {
    /// The measured lobes as a dict of arrays shaped `(case, order, hemisphere, cos_bin,
    /// phi_bin[, channel])`: `energy`, `energy_stderr`, `bsdf`, `bsdf_stderr` (float64) and
    /// `count` (uint64). Orders a case never reached are zero.
    fn lobes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let orders = self.sim.results.iter().map(|r| highest_slot(r) + 1).max().unwrap_or(1);
        let grid = Grid { cos_bins: self.config.detector.cos_theta_bins, phi_bins: self.config.detector.phi_bins };
        let channels = self.sim.rgb.then_some(3);
        let mut arrays = BinArrays::new(shape(self.sim.cases.len(), orders, grid, channels), &MEASURED, true);
        for (case, result) in self.sim.results.iter().enumerate() {
            match result {
                CaseResult::Mono(d) => fill(d, case, &mut arrays),
                CaseResult::Rgb(d) => fill(d, case, &mut arrays),
            }
        }
        arrays.into_dict(py)
    }

    /// The text of `summary.csv`.
    fn summary_csv<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = smithwalk::io::output::summary_csv(&self.sim).map_err(runtime_error)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The text of `run.json`.
    fn run_json<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        use smithwalk::io::output::{lobes_csv, run_json, summary_csv};
        let tables = (lobes_csv(&self.sim), summary_csv(&self.sim));
        let (lobes, summary) = (tables.0.map_err(runtime_error)?, tables.1.map_err(runtime_error)?);
        let bytes = run_json(&self.sim, &self.config, [&lobes, &summary]).map_err(runtime_error)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Writes `lobes.csv`, `summary.csv` and `run.json` into `dir` with the command line's
    /// writer (atomically); returns the paths written.
    fn save(&self, py: Python<'_>, dir: PathBuf) -> PyResult<Vec<PathBuf>> {
        py.detach(|| {
            smithwalk::atomic::prepare_dir(&dir)?;
            smithwalk::write_outputs(&self.sim, &self.config, &dir)
        })
        .map_err(|e| PyOSError::new_err(message(e)))
    }
}

fn highest_slot(r: &CaseResult) -> usize {
    match r {
        CaseResult::Mono(d) => d.highest_slot(),
        CaseResult::Rgb(d) => d.highest_slot(),
    }
}

/// The resolved, validated config of a run directory (from its `run.json`), as JSON text.
#[pyfunction]
fn read_config(dir: PathBuf) -> PyResult<String> {
    let config = smithwalk::io::rundir::read_config(&dir).map_err(|e| PyValueError::new_err(message(e)))?;
    serde_json::to_string(&config).map_err(|e| runtime_error(e.into()))
}

/// The columns of `lobes.csv` that [`read_lobes`] needs.
struct BinColumns {
    case: usize,
    order: usize,
    hemisphere: usize,
    channel: Option<usize>,
    cos_lo: usize,
    cos_hi: usize,
    phi_lo: usize,
    count: Option<usize>,
    values: Vec<(&'static str, usize)>,
}

impl BinColumns {
    fn of(headers: &csv::StringRecord) -> anyhow::Result<Self> {
        let find = |c: Column| headers.iter().position(|h| h == c.name);
        let need = |c: Column| find(c).with_context(|| format!("no column {}", c.name));
        let values = [schema::ENERGY, schema::ENERGY_STDERR, schema::BSDF, schema::BSDF_STDERR]
            .into_iter()
            .filter_map(|c| find(c).map(|i| (c.name, i)))
            .collect();
        Ok(Self {
            case: need(schema::CASE)?,
            order: need(schema::ORDER)?,
            hemisphere: need(schema::HEMISPHERE)?,
            channel: find(schema::CHANNEL),
            cos_lo: need(schema::COS_LO)?,
            cos_hi: need(schema::COS_HI)?,
            phi_lo: need(schema::PHI_LO_DEG)?,
            count: find(schema::COUNT),
            values,
        })
    }
}

/// One parsed row of `lobes.csv`: its position in the arrays and values.
struct BinRow {
    index: [usize; 5],
    channel: usize,
    values: Vec<f64>,
    count: u64,
}

fn parse_row(c: &BinColumns, r: &csv::StringRecord, grid: Grid) -> anyhow::Result<BinRow> {
    let number =
        |i: usize| -> anyhow::Result<f64> { r[i].parse().with_context(|| format!("not a number: {:?}", &r[i])) };
    let hemisphere = match &r[c.hemisphere] {
        "R" => 0,
        "T" => 1,
        other => anyhow::bail!("hemisphere {other:?} is not R or T"),
    };
    // |cos| of the bin's centre finds its cos index in either hemisphere.
    let ic = ((0.5 * (number(c.cos_lo)? + number(c.cos_hi)?)).abs() * grid.cos_bins as f64) as usize;
    let ip = (number(c.phi_lo)? / 360.0 * grid.phi_bins as f64).round() as usize;
    anyhow::ensure!(
        ic < grid.cos_bins && ip < grid.phi_bins,
        "a bin outside the run's {} x {} grid",
        grid.cos_bins,
        grid.phi_bins
    );
    let channel = match c.channel.map(|i| &r[i]) {
        None | Some("r") => 0,
        Some("g") => 1,
        Some("b") => 2,
        Some(other) => anyhow::bail!("channel {other:?} is not r, g or b"),
    };
    Ok(BinRow {
        index: [r[c.case].parse()?, r[c.order].parse()?, hemisphere, ic, ip],
        channel,
        values: c.values.iter().map(|&(_, i)| number(i)).collect::<anyhow::Result<_>>()?,
        count: c.count.map(|i| r[i].parse()).transpose()?.unwrap_or(0),
    })
}

/// Reads the `lobes.csv` of a run with `cases` cases on a `cos_bins` x `phi_bins` grid into
/// arrays shaped `(case, order, hemisphere, cos_bin, phi_bin[, channel])` with as many orders
/// as the table has; bins without a row are zero.
#[pyfunction]
fn read_lobes<'py>(
    py: Python<'py>,
    path: PathBuf,
    cases: usize,
    cos_bins: usize,
    phi_bins: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let grid = Grid { cos_bins, phi_bins };
    let parsed = py.detach(|| -> anyhow::Result<_> {
        let mut reader = csv::Reader::from_path(&path).with_context(|| format!("cannot read {}", path.display()))?;
        let columns = BinColumns::of(reader.headers()?).with_context(|| path.display().to_string())?;
        let rows = reader
            .records()
            .enumerate()
            .map(|(line, r)| {
                r.map_err(anyhow::Error::from)
                    .and_then(|r| parse_row(&columns, &r, grid))
                    .with_context(|| format!("{}: row {}", path.display(), line + 2))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let names: Vec<&'static str> = columns.values.iter().map(|&(name, _)| name).collect();
        let channels = columns.channel.map(|_| 3);
        let orders = rows.iter().map(|r| r.index[1] + 1).max().unwrap_or(1);
        let mut arrays = BinArrays::new(shape(cases, orders, grid, channels), &names, columns.count.is_some());
        for row in rows {
            let [case, order, hemisphere, ic, ip] = row.index;
            anyhow::ensure!(case < cases, "{}: case {case} of a run with {cases}", path.display());
            let at = arrays.at([case, order, hemisphere], ic * phi_bins + ip, row.channel);
            for (&name, value) in names.iter().zip(row.values) {
                arrays.columns.get_mut(name).expect("a parsed column")[at] = value;
            }
            if let Some(count) = arrays.count.as_mut() {
                count[at] = row.count;
            }
        }
        Ok(arrays)
    });
    parsed.map_err(|e| PyValueError::new_err(message(e)))?.into_dict(py)
}

/// The models' lobes of the run directory `dir`, from its `models.csv` as the command line
/// reads and checks it (`RunDir::models`): per model name `energy`, `energy_stderr` and `bsdf`,
/// arrays shaped like the run's `(case, order, hemisphere, cos_bin, phi_bin[, channel])` with
/// the run's order slots; lobes the model does not give are zero.
#[pyfunction]
fn read_models<'py>(py: Python<'py>, dir: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    const MODEL: [&str; 3] = [schema::ENERGY.name, schema::ENERGY_STDERR.name, schema::BSDF.name];
    let parsed = py.detach(|| -> anyhow::Result<_> {
        let run = smithwalk::io::rundir::RunDir::open(&dir)?;
        let orders = run.slots.iter().copied().max().unwrap_or(1);
        let channels = run.config.is_rgb().then_some(3);
        let mut out = BTreeMap::new();
        for (model, lobes) in run.models()? {
            let mut arrays = BinArrays::new(shape(run.cases.len(), orders, run.grid, channels), &MODEL, false);
            for ((case, order, hemisphere, channel), bins) in lobes.lobes {
                let lobe = [case, order, usize::from(hemisphere == "T")];
                for (bin, v) in bins.iter().enumerate() {
                    let at = arrays.at(lobe, bin, channel);
                    for (name, value) in MODEL.into_iter().zip([v.energy, v.energy_stderr, v.bsdf]) {
                        arrays.columns.get_mut(name).expect("a model column")[at] = value;
                    }
                }
            }
            out.insert(model, arrays);
        }
        Ok(out)
    });
    let dict = PyDict::new(py);
    for (model, arrays) in parsed.map_err(|e| PyValueError::new_err(message(e)))? {
        dict.set_item(model, arrays.into_dict(py)?)?;
    }
    Ok(dict)
}

type Array<'py> = Bound<'py, PyArray1<f64>>;

/// The detector grid of a run: `(cos_edges, phi_edges_deg, projected_solid_angle)`, bin edges
/// in |cos theta| and in degrees from the incident azimuth, and each cos bin's projected solid
/// angle `∫ |cos theta| dω` (per phi bin), the divisor that turns `energy` into `bsdf`.
#[pyfunction]
fn grid<'py>(py: Python<'py>, cos_bins: usize, phi_bins: usize) -> (Array<'py>, Array<'py>, Array<'py>) {
    let grid = Grid { cos_bins, phi_bins };
    let edges = |n: usize, edge: &dyn Fn(usize) -> (f64, f64)| {
        (0..n).map(|i| edge(i).0).chain(std::iter::once(edge(n - 1).1)).collect::<Vec<f64>>()
    };
    (
        PyArray1::from_vec(py, edges(cos_bins, &|i| grid.cos_edges(i))),
        PyArray1::from_vec(py, edges(phi_bins, &|i| grid.phi_edges_deg(i))),
        PyArray1::from_vec(py, (0..cos_bins).map(|i| grid.projected_solid_angle(i)).collect()),
    )
}

/// Runs `smithwalk compare` on a run directory (writes `models.csv` and `compare.csv` into it)
/// with the GIL released; returns the report the command prints.
#[pyfunction]
#[pyo3(signature = (dir, models, paths=None, threads=None))]
fn compare(
    py: Python<'_>,
    dir: PathBuf,
    models: Vec<String>,
    paths: Option<u64>,
    threads: Option<usize>,
) -> PyResult<String> {
    let models =
        models.iter().map(|m| Model::parse(m)).collect::<Result<Vec<_>, _>>().map_err(PyValueError::new_err)?;
    if paths.is_some_and(|p| p < 2) {
        return Err(PyValueError::new_err(format!(
            "`paths` = {} is not allowed: at least 2 photons per case",
            paths.unwrap_or(0)
        )));
    }
    if threads == Some(0) {
        return Err(PyValueError::new_err("`threads` = 0 is not allowed: at least 1 thread"));
    }
    py.detach(|| smithwalk::analysis::compare::compare(&dir, &models, paths, threads)).map_err(runtime_error)
}

/// Writes files (name, bytes) into `dir` atomically: all of them or none.
#[pyfunction]
fn write_files(py: Python<'_>, dir: PathBuf, files: Vec<(String, Vec<u8>)>) -> PyResult<Vec<PathBuf>> {
    py.detach(|| {
        smithwalk::atomic::prepare_dir(&dir)?;
        let (names, bytes): (Vec<String>, Vec<Vec<u8>>) = files.into_iter().unzip();
        let files: Vec<(&str, Vec<u8>)> = names.iter().map(String::as_str).zip(bytes).collect();
        smithwalk::atomic::write_atomically(&dir, &files)
    })
    .map_err(|e| PyOSError::new_err(message(e)))
}

/// The run directory's tables ([`smithwalk::io::schema`]): per file name its columns in order,
/// each as `(name, unit, meaning)`; `channel` is written by RGB runs only, and `models.csv`'s
/// `<model>` and `<model>_stderr` stand for one pair of columns per model compared.
#[pyfunction]
fn columns() -> BTreeMap<&'static str, Vec<(&'static str, &'static str, &'static str)>> {
    schema::TABLES.iter().map(|t| (t.file, t.columns.iter().map(|c| (c.name, c.unit, c.meaning)).collect())).collect()
}

/// The files of a run directory: `(written by a run, written by compare)`, each set written
/// atomically.
#[pyfunction]
fn files() -> (Vec<&'static str>, Vec<&'static str>) {
    (schema::RUN_FILES.to_vec(), schema::COMPARE_FILES.to_vec())
}

/// The names of the comparison models, in the command line's order.
#[pyfunction]
fn model_names() -> Vec<&'static str> {
    Model::ALL.iter().map(|m| m.name()).collect()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<NativeRun>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(read_config, m)?)?;
    m.add_function(wrap_pyfunction!(read_lobes, m)?)?;
    m.add_function(wrap_pyfunction!(read_models, m)?)?;
    m.add_function(wrap_pyfunction!(grid, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(write_files, m)?)?;
    m.add_function(wrap_pyfunction!(model_names, m)?)?;
    m.add_function(wrap_pyfunction!(columns, m)?)?;
    m.add_function(wrap_pyfunction!(files, m)?)?;
    bsdf::register(m)?;
    Ok(())
}
