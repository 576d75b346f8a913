//! `smithwalk.bsdf`: the multiple-scattering BSDF of theory §13 (`microsurface::bsdf`) over
//! numpy batches, one lane per row, for renderers (docs/rendering.md, "Python").
//!
//! The Python wrapper (`python/smithwalk/bsdf.py`) broadcasts every parameter to one value per
//! lane; here each lane's parameters are checked and built into a [`Bsdf`] ([`Description`], shared
//! with the C ABI) before any walk, and
//! the lanes then run in parallel on rayon with the GIL released. Each lane draws from its own
//! stream ([`stream`]) keyed by the caller's seed and the lane's numbers, so the results do not
//! depend on the thread count.

use numpy::ndarray::{Array1, Array2, ArrayView1, ArrayView2, Axis};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use smithwalk::microsurface::DVec3;
use smithwalk::microsurface::bsdf::{Bsdf, Description, Orders, Transport, stream};
use smithwalk::microsurface::material::Material;
use smithwalk::microsurface::ndf::{AnyNdf, Roughness};

/// The BSDF of one lane: RGB, any NDF, any facet material.
type LaneBsdf = Bsdf<AnyNdf, Material<3>, 3>;

/// Every lane's parameters, one row (or entry) per lane, as the wrapper broadcast them.
struct Lanes<'a> {
    material: &'a str,
    fresnel: &'a str,
    ndf: &'a str,
    alpha_u: ArrayView1<'a, f64>,
    alpha_v: ArrayView1<'a, f64>,
    gamma: ArrayView1<'a, f64>,
    eta: ArrayView2<'a, f64>,
    k: ArrayView2<'a, f64>,
    f0: ArrayView2<'a, f64>,
    albedo: ArrayView2<'a, f64>,
    orders: Orders,
}

fn rgb(a: &ArrayView2<'_, f64>, lane: usize) -> [f64; 3] {
    [a[[lane, 0]], a[[lane, 1]], a[[lane, 2]]]
}

impl Lanes<'_> {
    /// The lane's BSDF, its parameters checked by [`Description::bsdf`].
    fn bsdf(&self, lane: usize) -> PyResult<LaneBsdf> {
        let description = Description {
            ndf: self.ndf,
            alpha: Roughness { x: self.alpha_u[lane], y: self.alpha_v[lane] },
            gamma: self.gamma[lane],
            material: self.material,
            fresnel: self.fresnel,
            eta: rgb(&self.eta, lane),
            k: rgb(&self.k, lane),
            f0: rgb(&self.f0, lane),
            albedo: rgb(&self.albedo, lane),
            orders: self.orders,
        };
        description.bsdf().map_err(|e| PyValueError::new_err(format!("lane {lane}: {e}")))
    }

    /// Every lane's BSDF, or the first lane's error.
    fn all(&self) -> PyResult<Vec<LaneBsdf>> {
        (0..self.alpha_u.len()).map(|lane| self.bsdf(lane)).collect()
    }
}

fn transport(name: &str) -> PyResult<Transport> {
    match name {
        "importance" => Ok(Transport::Importance),
        "radiance" => Ok(Transport::Radiance),
        other => Err(PyValueError::new_err(format!(
            "`transport` = {other:?} is not allowed: \"importance\" or \"radiance\""
        ))),
    }
}

fn dir(a: &ArrayView2<'_, f64>, lane: usize) -> DVec3 {
    DVec3::new(a[[lane, 0]], a[[lane, 1]], a[[lane, 2]])
}

/// `f` of every lane `0..n`, in parallel on `threads` threads (rayon's global pool when
/// `None`), the GIL released. The lanes are independent, so the result does not depend on the
/// thread count.
fn per_lane<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    n: usize,
    f: impl Fn(usize) -> T + Sync,
) -> PyResult<Vec<T>> {
    let run = || (0..n).into_par_iter().map(&f).collect::<Vec<_>>();
    match threads {
        None => Ok(py.detach(run)),
        Some(0) => Err(PyValueError::new_err("`threads` = 0 is not allowed: at least 1 thread")),
        Some(t) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(|e| PyValueError::new_err(format!("`threads` = {t}: {e}")))?;
            Ok(py.detach(|| pool.install(run)))
        }
    }
}

/// The parameters common to the three calls: the dict the wrapper passes, one key per field.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct Params<'py> {
    material: String,
    fresnel: String,
    ndf: String,
    alpha: (PyReadonlyArray1<'py, f64>, PyReadonlyArray1<'py, f64>),
    gamma: PyReadonlyArray1<'py, f64>,
    eta: PyReadonlyArray2<'py, f64>,
    k: PyReadonlyArray2<'py, f64>,
    f0: PyReadonlyArray2<'py, f64>,
    albedo: PyReadonlyArray2<'py, f64>,
    orders: (u64, u32),
}

impl<'py> Params<'py> {
    fn lanes(&self) -> Lanes<'_> {
        Lanes {
            material: &self.material,
            fresnel: &self.fresnel,
            ndf: &self.ndf,
            alpha_u: self.alpha.0.as_array(),
            alpha_v: self.alpha.1.as_array(),
            gamma: self.gamma.as_array(),
            eta: self.eta.as_array(),
            k: self.k.as_array(),
            f0: self.f0.as_array(),
            albedo: self.albedo.as_array(),
            orders: Orders { mask: self.orders.0, from: self.orders.1 },
        }
    }
}

/// One photon per lane (§13.2): `(wo, weight, order)`. Lane `i` draws from
/// `stream(seed, u[i])` (`u` has zero columns when the caller gave none: the wrapper passes the
/// lane index then).
#[pyfunction]
#[pyo3(signature = (params, wi, u, seed, transport_mode, threads=None))]
#[allow(clippy::type_complexity)]
fn bsdf_sample<'py>(
    py: Python<'py>,
    params: Params<'py>,
    wi: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray2<'py, f64>,
    seed: u64,
    transport_mode: &str,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u32>>)> {
    let mode = transport(transport_mode)?;
    let lanes = params.lanes();
    let bsdfs = lanes.all()?;
    let (wi, u) = (wi.as_array(), u.as_array());
    let samples = per_lane(py, threads, bsdfs.len(), |i| {
        let numbers: Vec<f64> = u.index_axis(Axis(0), i).to_vec();
        bsdfs[i].sample(dir(&wi, i), mode, &mut stream(seed, &numbers))
    })?;
    let n = samples.len();
    let wo = Array2::from_shape_fn((n, 3), |(i, c)| samples[i].wo[c]);
    let weight = Array2::from_shape_fn((n, 3), |(i, c)| samples[i].weight[c]);
    let order = Array1::from_shape_fn(n, |i| samples[i].order);
    Ok((wo.into_pyarray(py), weight.into_pyarray(py), order.into_pyarray(py)))
}

/// `f(wi, wo) |cos theta_o|` per lane and channel (§13.3). Lane `i` draws from
/// `stream(seed, [wi[i], wo[i]])` (its six components).
#[pyfunction]
#[pyo3(signature = (params, wi, wo, seed, transport_mode, threads=None))]
fn bsdf_eval<'py>(
    py: Python<'py>,
    params: Params<'py>,
    wi: PyReadonlyArray2<'py, f64>,
    wo: PyReadonlyArray2<'py, f64>,
    seed: u64,
    transport_mode: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mode = transport(transport_mode)?;
    let lanes = params.lanes();
    let bsdfs = lanes.all()?;
    let (wi, wo) = (wi.as_array(), wo.as_array());
    let values = per_lane(py, threads, bsdfs.len(), |i| {
        let (a, b) = (dir(&wi, i), dir(&wo, i));
        bsdfs[i].eval(a, b, mode, &mut stream(seed, &[a.x, a.y, a.z, b.x, b.y, b.z]))
    })?;
    Ok(Array2::from_shape_fn((values.len(), 3), |(i, c)| values[i][c]).into_pyarray(py))
}

/// The sampling density of `wo` per lane (§13.4); no random numbers.
#[pyfunction]
#[pyo3(signature = (params, wi, wo, threads=None))]
fn bsdf_pdf<'py>(
    py: Python<'py>,
    params: Params<'py>,
    wi: PyReadonlyArray2<'py, f64>,
    wo: PyReadonlyArray2<'py, f64>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let lanes = params.lanes();
    let bsdfs = lanes.all()?;
    let (wi, wo) = (wi.as_array(), wo.as_array());
    let values = per_lane(py, threads, bsdfs.len(), |i| bsdfs[i].pdf(dir(&wi, i), dir(&wo, i)))?;
    Ok(Array1::from_vec(values).into_pyarray(py))
}

/// Registers the BSDF calls in the native module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bsdf_sample, m)?)?;
    m.add_function(wrap_pyfunction!(bsdf_eval, m)?)?;
    m.add_function(wrap_pyfunction!(bsdf_pdf, m)?)?;
    Ok(())
}
