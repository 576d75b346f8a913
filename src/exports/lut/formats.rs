//! The files of a table: `lut.csv`, `lut_avg.csv`, `lut.exr`, `lut.h`, `lut.rs` and `lut.json`
//! (docs/exports.md).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

use super::config::MU_GRAZING;
use super::tables::{Lut, Quantity, QuantityTable};
use crate::atomic::write_atomically;
use crate::io::table_record::{Nodes, TableRecord};
use crate::setup::config::values::name;

/// The leading CSV fields of a quantity at eta slice `slice` (eta empty for tables without
/// eta) and roughness `alpha`.
fn quantity_fields(lut: &Lut, q: &Quantity, slice: usize, alpha: f64) -> Vec<String> {
    vec![
        q.name.clone(),
        name(&q.side),
        format!("{:?}", q.hemisphere),
        q.order.clone(),
        lut.eta.get(slice).map_or(String::new(), |e| e.to_string()),
        alpha.to_string(),
    ]
}

/// `lut.csv`: one row per quantity and cell, with the standard error and photon count.
pub fn csv_table(lut: &Lut) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["quantity", "side", "hemisphere", "order", "eta", "alpha", "mu", "E", "E_stderr", "photons"])?;
    let n_mu = lut.mu.len();
    for t in &lut.tables {
        let q = &t.quantity;
        for slice in 0..lut.slices() {
            for (a, alpha) in lut.alpha.iter().enumerate() {
                for (m, mu) in lut.mu.iter().enumerate() {
                    let i = (slice * lut.alpha.len() + a) * n_mu + m;
                    let mut row = quantity_fields(lut, q, slice, *alpha);
                    row.extend([mu.to_string(), t.e[i].to_string(), t.e_stderr[i].to_string()]);
                    row.push(lut.photons[i].to_string());
                    w.write_record(&row)?;
                }
            }
        }
    }
    Ok(w.into_inner()?)
}

/// `lut_avg.csv`: E_avg per quantity, eta and alpha.
pub fn csv_avg(lut: &Lut) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["quantity", "side", "hemisphere", "order", "eta", "alpha", "E_avg", "E_avg_stderr"])?;
    for t in &lut.tables {
        let q = &t.quantity;
        for slice in 0..lut.slices() {
            for (a, alpha) in lut.alpha.iter().enumerate() {
                let i = slice * lut.alpha.len() + a;
                let mut row = quantity_fields(lut, q, slice, *alpha);
                row.extend([t.avg[i].to_string(), t.avg_stderr[i].to_string()]);
                w.write_record(&row)?;
            }
        }
    }
    Ok(w.into_inner()?)
}

/// `lut.exr`: two layers. `E` is n_mu wide and n_eta * n_alpha high (row = eta * n_alpha +
/// alpha, column = mu), one channel per quantity plus `<quantity>_stderr`; `E_avg` is one pixel
/// wide with the same rows. Samples are 32-bit floats.
pub fn exr_image(lut: &Lut) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let rows = lut.slices() * lut.alpha.len();
    let samples = |v: &[f64]| FlatSamples::F32(v.iter().map(|&x| x as f32).collect());
    let layer = |name: &str, width: usize, columns: Vec<(String, FlatSamples)>| {
        let channels = columns.into_iter().map(|(n, v)| AnyChannel::new(n.as_str(), v)).collect();
        Layer::new((width, rows), LayerAttributes::named(name), Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels))
    };
    let with_stderr = |t: &QuantityTable, values: &[f64], errors: &[f64]| {
        [(t.quantity.name.clone(), samples(values)), (format!("{}_stderr", t.quantity.name), samples(errors))]
    };
    let e = layer("E", lut.mu.len(), lut.tables.iter().flat_map(|t| with_stderr(t, &t.e, &t.e_stderr)).collect());
    let avg = layer("E_avg", 1, lut.tables.iter().flat_map(|t| with_stderr(t, &t.avg, &t.avg_stderr)).collect());
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((lut.mu.len(), rows))),
        SmallVec::from_vec(vec![e, avg]),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes).context("cannot encode the OpenEXR image")?;
    Ok(bytes.into_inner())
}

/// Shortest text that reads back as the same `f32`.
fn f32_literal(x: f64) -> String {
    format!("{:?}", x as f32)
}

/// Writes `values` (row-major over `dims`) as nested braces, one innermost row per line.
fn nested(out: &mut String, values: &[f64], dims: &[usize], suffix: &str, indent: usize) {
    if let [n] = dims {
        let items: Vec<String> = values.iter().take(*n).map(|&v| format!("{}{suffix}", f32_literal(v))).collect();
        let _ = write!(out, "{:indent$}{{{}}}", "", items.join(", "));
        return;
    }
    let inner: usize = dims[1..].iter().product();
    let _ = writeln!(out, "{:indent$}{{", "");
    for i in 0..dims[0] {
        nested(out, &values[i * inner..(i + 1) * inner], &dims[1..], suffix, indent + 4);
        out.push_str(if i + 1 < dims[0] { ",\n" } else { "\n" });
    }
    let _ = write!(out, "{:indent$}}}", "");
}

/// The dimensions of E (`[eta][alpha][mu]`, or `[alpha][mu]`) and of E_avg.
fn dims(lut: &Lut) -> (Vec<usize>, Vec<usize>) {
    let mut avg = vec![lut.alpha.len()];
    if !lut.eta.is_empty() {
        avg.insert(0, lut.eta.len());
    }
    let mut e = avg.clone();
    e.push(lut.mu.len());
    (e, avg)
}

fn provenance(lut: &Lut) -> String {
    let c = &lut.record;
    let nodes = match c.nodes {
        Nodes::Cells => "cell centres mu_i = (i + 1/2) / n_mu (cos theta_i)".to_string(),
        Nodes::Edges => format!(
            "nodes on the end points mu_i = i / (n_mu - 1) (cos theta_i; mu = 0 holds E at mu = {}, alpha = 0 the \
             flat surface's exact albedo)",
            MU_GRAZING
        ),
    };
    format!(
        "smithwalk {} lut: table = {}, ndf = {}, paths <= {} per cell, target_stderr = {}, seed = {}.\n\
         E[{}] is the directional albedo at {nodes}, alpha over \
         {:?}{}; E_avg = 2 * integral of E(mu) mu dmu. Every array has a matching _stderr array.",
        env!("CARGO_PKG_VERSION"),
        name(&c.table),
        name(&c.ndf),
        c.paths,
        c.target_stderr.map_or("none".to_string(), |t| t.to_string()),
        c.seed,
        if lut.eta.is_empty() { "alpha][mu" } else { "eta][alpha][mu" },
        c.alpha_range,
        if lut.eta.is_empty() { String::new() } else { format!(", eta over {:?}", c.eta_range) },
    )
}

/// Every array a source file carries, in order: the nodes, then per quantity E, its
/// standard error, E_avg and its standard error; each with its name and dimensions.
fn source_arrays(lut: &Lut) -> Vec<(String, &[f64], Vec<usize>)> {
    let (e_dims, avg_dims) = dims(lut);
    let mut arrays = vec![("mu".to_string(), lut.mu.as_slice(), vec![lut.mu.len()])];
    arrays.push(("alpha".to_string(), &lut.alpha, vec![lut.alpha.len()]));
    if !lut.eta.is_empty() {
        arrays.push(("eta".to_string(), &lut.eta, vec![lut.eta.len()]));
    }
    for t in &lut.tables {
        let q = &t.quantity.name;
        arrays.push((format!("E_{q}"), &t.e, e_dims.clone()));
        arrays.push((format!("E_{q}_stderr"), &t.e_stderr, e_dims.clone()));
        arrays.push((format!("E_avg_{q}"), &t.avg, avg_dims.clone()));
        arrays.push((format!("E_avg_{q}_stderr"), &t.avg_stderr, avg_dims.clone()));
    }
    arrays
}

/// `lut.h`: a C header with the node arrays and, per quantity, `smithwalk_E_<q>`,
/// `smithwalk_E_<q>_stderr`, `smithwalk_E_avg_<q>` and `smithwalk_E_avg_<q>_stderr`.
pub fn c_header(lut: &Lut) -> Vec<u8> {
    let mut out = String::new();
    let _ = writeln!(out, "/* {} */", provenance(lut));
    out.push_str("#ifndef SMITHWALK_LUT_H\n#define SMITHWALK_LUT_H\n\n");
    for (name, values, dims) in source_arrays(lut) {
        let shape: String = dims.iter().map(|d| format!("[{d}]")).collect();
        let _ = writeln!(out, "static const float smithwalk_{name}{shape} =");
        nested(&mut out, values, &dims, "f", 0);
        out.push_str(";\n\n");
    }
    out.push_str("#endif /* SMITHWALK_LUT_H */\n");
    out.into_bytes()
}

/// `lut.rs`: the same arrays as Rust constants (`MU`, `E_R_ALL`, `E_AVG_R_ALL_STDERR`, ...),
/// for `include!`.
pub fn rust_source(lut: &Lut) -> Vec<u8> {
    let mut out = String::new();
    for line in provenance(lut).lines() {
        let _ = writeln!(out, "// {line}");
    }
    for (name, values, dims) in source_arrays(lut) {
        let ty = dims.iter().rev().fold("f32".to_string(), |inner, d| format!("[{inner}; {d}]"));
        let _ = writeln!(out, "#[rustfmt::skip]\npub const {}: {ty} =", name.to_uppercase());
        let mut text = String::new();
        nested(&mut text, values, &dims, "", 0);
        out.push_str(&text.replace('{', "[").replace('}', "]"));
        out.push_str(";\n\n");
    }
    out.into_bytes()
}

#[derive(Serialize)]
struct LutReport<'a> {
    smithwalk_version: &'static str,
    config: &'a TableRecord,
    mu: &'a [f64],
    alpha: &'a [f64],
    eta: &'a [f64],
    avg_rule: Vec<(f64, f64)>,
    quantities: Vec<&'a str>,
    layout: String,
    wall_seconds: f64,
    photons_total: u64,
}

fn lut_json(lut: &Lut) -> Result<Vec<u8>> {
    let report = LutReport {
        smithwalk_version: env!("CARGO_PKG_VERSION"),
        config: &lut.record,
        mu: &lut.mu,
        alpha: &lut.alpha,
        eta: &lut.eta,
        avg_rule: lut.config.avg_rule(),
        quantities: lut.tables.iter().map(|t| t.quantity.name.as_str()).collect(),
        layout: provenance(lut),
        wall_seconds: lut.wall_seconds,
        photons_total: lut.photons.iter().sum(),
    };
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    Ok(text)
}

/// Writes `lut.csv`, `lut_avg.csv`, `lut.exr`, `lut.h`, `lut.rs` and `lut.json`, atomically.
pub fn write(lut: &Lut, dir: &Path) -> Result<Vec<PathBuf>> {
    write_atomically(
        dir,
        &[
            ("lut.csv", csv_table(lut)?),
            ("lut_avg.csv", csv_avg(lut)?),
            ("lut.exr", exr_image(lut)?),
            ("lut.h", c_header(lut)),
            ("lut.rs", rust_source(lut)),
            ("lut.json", lut_json(lut)?),
        ],
    )
}
