//! A C ABI over the multiple-scattering BSDF of `microsurface::bsdf` (docs/theory.md §13), for
//! C and C++ renderers: `include/smithwalk.h` declares what this file defines, and
//! `cargo build --release -p smithwalk-capi` builds `libsmithwalk_capi.a` (docs/rendering.md,
//! "C and C++").
//!
//! Every call is a thin shell around the physics crate's [`Bsdf`]: the parameters become a
//! [`Description`] (the constructor the Python package shares), the random numbers a [`stream`]
//! keyed exactly as in Python, so that the same seed and numbers give the same bits in both.
//! Nothing unwinds across the boundary: each call runs under `catch_unwind`, and a failure is
//! a status code plus a message kept per thread ([`smithwalk_last_error`]). Outputs are
//! written on every path, zeros on failure, so a renderer never reads uninitialised memory.

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};

use microsurface::DVec3;
use microsurface::bsdf::{Bsdf, Description, Orders, Transport, stream};
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Roughness};

/// The call succeeded.
pub const SMITHWALK_OK: c_int = 0;
/// A parameter is out of range or not one of the allowed names.
pub const SMITHWALK_ERROR_PARAMETER: c_int = 1;
/// A required pointer is NULL.
pub const SMITHWALK_ERROR_NULL: c_int = 2;
/// A direction is not finite or not of unit length.
pub const SMITHWALK_ERROR_DIRECTION: c_int = 3;
/// An internal error (a panic) was caught: a bug in smithwalk.
pub const SMITHWALK_ERROR_INTERNAL: c_int = 4;

/// `wi` towards the camera (path tracing): transmission times `(n_i / n_o)^2` (§13.1).
pub const SMITHWALK_RADIANCE: u32 = 0;
/// `wi` towards the light (light tracing): the lobe of light arriving from `wi`.
pub const SMITHWALK_IMPORTANCE: u32 = 1;

/// How far a direction's length may be from 1: single-precision renderers normalise to about
/// 1e-7, and a direction that is not unit would silently change `Lambda` and the lobes.
const UNIT_TOLERANCE: f64 = 1e-5;

/// The BSDF a handle owns: RGB, any NDF, any facet material.
type CBsdf = Bsdf<AnyNdf, Material<3>, 3>;

/// An opaque BSDF (`smithwalk_bsdf` in C), made by [`smithwalk_bsdf_new`].
pub struct SmithwalkBsdf(CBsdf);

/// The parameters of [`smithwalk_bsdf_new`] (`smithwalk_params` in C): the fields of a
/// [`Description`], names as NUL-terminated UTF-8 strings.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SmithwalkParams {
    /// `"ggx"`, `"beckmann"` or `"student-t"`.
    pub ndf: *const c_char,
    /// `"conductor"`, `"dielectric"`, `"lambertian"` or `"hammon"`.
    pub material: *const c_char,
    /// A conductor's Fresnel mode: `"none"`, `"schlick"` or `"exact"`.
    pub fresnel: *const c_char,
    /// Roughness along the tangent x axis, finite and > 0.
    pub alpha_u: f64,
    /// Roughness along the tangent y axis, finite and > 0.
    pub alpha_v: f64,
    /// The Student-T shape (`ndf` `"student-t"`), finite and > 1.5; ignored by the other NDFs.
    pub gamma: f64,
    /// A conductor's real index per channel; a dielectric's `n_inside / n_outside` in `eta[0]`.
    pub eta: [f64; 3],
    /// A conductor's extinction coefficient per channel.
    pub k: [f64; 3],
    /// Reflectance at normal incidence (Schlick conductor, Hammon coat).
    pub f0: [f64; 3],
    /// Diffuse albedo (Lambertian, Hammon base).
    pub albedo: [f64; 3],
    /// Bit `k - 1` set: order `k` (1 to 64) is kept.
    pub orders_mask: u64,
    /// Every order from this one on is kept (`UINT32_MAX`: none).
    pub orders_from: u32,
}

/// Why a call failed: its status code and its message.
struct Failure {
    status: c_int,
    message: String,
}

impl Failure {
    fn new(status: c_int, message: impl Into<String>) -> Self {
        Failure { status, message: message.into() }
    }
}

thread_local! {
    /// The message of the last failed call on this thread.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Runs `f` with panics caught: its status, and the message of a failure kept for
/// [`smithwalk_last_error`]. A panic (a bug) becomes [`SMITHWALK_ERROR_INTERNAL`] rather than
/// an abort of the renderer.
fn guarded(f: impl FnOnce() -> Result<(), Failure>) -> c_int {
    let failure = match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => return SMITHWALK_OK,
        Ok(Err(failure)) => failure,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Failure::new(SMITHWALK_ERROR_INTERNAL, format!("internal error (a bug in smithwalk): {what}"))
        }
    };
    // A message cannot hold NUL bytes: none of ours does, but a panic payload might.
    let text = CString::new(failure.message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|last| *last.borrow_mut() = text);
    failure.status
}

/// The string `ptr` points to, read as the field `field`.
///
/// # Safety
/// `ptr` is NULL or points to a NUL-terminated string.
unsafe fn name<'a>(field: &str, ptr: *const c_char) -> Result<&'a str, Failure> {
    if ptr.is_null() {
        return Err(Failure::new(SMITHWALK_ERROR_NULL, format!("{field} = NULL is not allowed: a name")));
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's contract.
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .map_err(|_| Failure::new(SMITHWALK_ERROR_PARAMETER, format!("{field} is not UTF-8: allowed is a name")))
}

/// The reference `*ptr`, or a failure naming `field`.
///
/// # Safety
/// `ptr` is NULL or valid for reads of `T` for `'a`.
unsafe fn required<'a, T>(field: &str, ptr: *const T) -> Result<&'a T, Failure> {
    // SAFETY: the caller's contract.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::new(SMITHWALK_ERROR_NULL, format!("{field} = NULL is not allowed")))
}

/// A failure naming `field` if the output `ptr` is NULL.
fn present<T>(field: &str, ptr: *mut T) -> Result<(), Failure> {
    if ptr.is_null() {
        return Err(Failure::new(SMITHWALK_ERROR_NULL, format!("{field} = NULL is not allowed")));
    }
    Ok(())
}

/// The unit direction `v` as the field `field`.
fn direction(field: &str, v: &[f64; 3]) -> Result<DVec3, Failure> {
    let d = DVec3::from_array(*v);
    let length = d.length();
    if !(d.is_finite() && (length - 1.0).abs() <= UNIT_TOLERANCE) {
        return Err(Failure::new(
            SMITHWALK_ERROR_DIRECTION,
            format!(
                "{field} = ({}, {}, {}) has length {length}: allowed is a finite unit vector (length within {UNIT_TOLERANCE} of 1)",
                v[0], v[1], v[2]
            ),
        ));
    }
    Ok(d)
}

fn transport(mode: u32) -> Result<Transport, Failure> {
    match mode {
        SMITHWALK_RADIANCE => Ok(Transport::Radiance),
        SMITHWALK_IMPORTANCE => Ok(Transport::Importance),
        other => Err(Failure::new(
            SMITHWALK_ERROR_PARAMETER,
            format!("transport = {other} is not allowed: SMITHWALK_RADIANCE (0) or SMITHWALK_IMPORTANCE (1)"),
        )),
    }
}

/// Writes `value` through `out` if it is not NULL.
///
/// # Safety
/// `out` is NULL or valid for writes of `T`.
unsafe fn put<T>(out: *mut T, value: T) {
    // SAFETY: the caller's contract.
    if let Some(slot) = unsafe { out.as_mut() } {
        *slot = value;
    }
}

/// The defaults of [`SmithwalkParams`]: GGX, alpha 0.5, gamma NaN (unset), a lossless conductor (`fresnel`
/// `"none"`), `eta` 1, `k` 0, `f0` 1, `albedo` 1, every order. Writes nothing if `out` is NULL.
///
/// # Safety
/// `out` is NULL or valid for writes of a `smithwalk_params`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn smithwalk_params_default(out: *mut SmithwalkParams) {
    let defaults = SmithwalkParams {
        ndf: c"ggx".as_ptr(),
        material: c"conductor".as_ptr(),
        fresnel: c"none".as_ptr(),
        alpha_u: 0.5,
        alpha_v: 0.5,
        gamma: f64::NAN,
        eta: [1.0; 3],
        k: [0.0; 3],
        f0: [1.0; 3],
        albedo: [1.0; 3],
        orders_mask: Orders::ALL.mask,
        orders_from: Orders::ALL.from,
    };
    // SAFETY: the caller's contract.
    unsafe { put(out, defaults) };
}

/// Builds a BSDF from `params` into `*out` (NULL on failure). Status: [`SMITHWALK_OK`],
/// [`SMITHWALK_ERROR_PARAMETER`] (the message names the field, its value and what is
/// allowed) or [`SMITHWALK_ERROR_NULL`].
///
/// # Safety
/// `params` is NULL or points to a `smithwalk_params` whose strings are NULL or
/// NUL-terminated; `out` is NULL or valid for writes of a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn smithwalk_bsdf_new(params: *const SmithwalkParams, out: *mut *mut SmithwalkBsdf) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { put(out, std::ptr::null_mut()) };
    guarded(|| {
        // SAFETY: the caller's contract, for the pointers and the strings.
        let p = unsafe { required("params", params)? };
        present("out", out)?;
        let description = Description {
            ndf: unsafe { name("ndf", p.ndf)? },
            alpha: Roughness { x: p.alpha_u, y: p.alpha_v },
            gamma: p.gamma,
            material: unsafe { name("material", p.material)? },
            fresnel: unsafe { name("fresnel", p.fresnel)? },
            eta: p.eta,
            k: p.k,
            f0: p.f0,
            albedo: p.albedo,
            orders: Orders { mask: p.orders_mask, from: p.orders_from },
        };
        let bsdf = description.bsdf().map_err(|e| Failure::new(SMITHWALK_ERROR_PARAMETER, e.to_string()))?;
        // SAFETY: `out` is not NULL (checked above) and valid for writes by the contract.
        unsafe { *out = Box::into_raw(Box::new(SmithwalkBsdf(bsdf))) };
        Ok(())
    })
}

/// Frees a BSDF made by [`smithwalk_bsdf_new`]; NULL is ignored.
///
/// # Safety
/// `bsdf` is NULL or a pointer from `smithwalk_bsdf_new` not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn smithwalk_bsdf_free(bsdf: *mut SmithwalkBsdf) {
    if !bsdf.is_null() {
        // SAFETY: made by `Box::into_raw` in `smithwalk_bsdf_new` and not freed (contract).
        drop(unsafe { Box::from_raw(bsdf) });
    }
}

/// One photon from `wi` (§13.2, [`Bsdf::sample`]): its escape direction `wo`, its weight per
/// RGB channel (`f |cos theta_o| / density`) and its order (0: never escaped; `order` may be
/// NULL). Random numbers: the walk draws from `stream(seed, numbers[0..count])`.
///
/// # Safety
/// `bsdf` from `smithwalk_bsdf_new` or NULL; `wi`, `wo`, `weight` NULL or valid for 3
/// doubles; `numbers` valid for `count` doubles (or NULL with `count` 0); `order` NULL or
/// valid for writes.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn smithwalk_bsdf_sample(
    bsdf: *const SmithwalkBsdf,
    wi: *const [f64; 3],
    transport_mode: u32,
    seed: u64,
    numbers: *const f64,
    count: usize,
    wo: *mut [f64; 3],
    weight: *mut [f64; 3],
    order: *mut u32,
) -> c_int {
    // SAFETY: the caller's contract, for every output.
    unsafe {
        put(wo, [0.0, 0.0, 1.0]);
        put(weight, [0.0; 3]);
        put(order, 0);
    }
    guarded(|| {
        // SAFETY: the caller's contract.
        let (b, wi) = unsafe { (required("bsdf", bsdf)?, required("wi", wi)?) };
        present("wo", wo)?;
        present("weight", weight)?;
        let numbers: &[f64] = match count {
            0 => &[],
            // SAFETY: `count` doubles at `numbers` (contract), not NULL (checked).
            n => unsafe { std::slice::from_raw_parts(required("numbers", numbers)?, n) },
        };
        let (wi, mode) = (direction("wi", wi)?, transport(transport_mode)?);
        let sample = b.0.sample(wi, mode, &mut stream(seed, numbers));
        // SAFETY: the caller's contract; `wo` and `weight` are not NULL.
        unsafe {
            *wo = sample.wo.to_array();
            *weight = sample.weight;
            put(order, sample.order);
        }
        Ok(())
    })
}

/// An unbiased estimate of `f(wi, wo) |cos theta_o|` per RGB channel (§13.3, [`Bsdf::eval`]).
/// Random numbers: the walk draws from `stream(seed, [wi, wo])`, the six components.
///
/// # Safety
/// `bsdf` from `smithwalk_bsdf_new` or NULL; `wi`, `wo`, `value` NULL or valid for 3
/// doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn smithwalk_bsdf_eval(
    bsdf: *const SmithwalkBsdf,
    wi: *const [f64; 3],
    wo: *const [f64; 3],
    transport_mode: u32,
    seed: u64,
    value: *mut [f64; 3],
) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { put(value, [0.0; 3]) };
    guarded(|| {
        // SAFETY: the caller's contract.
        let (b, wi, wo) = unsafe { (required("bsdf", bsdf)?, required("wi", wi)?, required("wo", wo)?) };
        present("value", value)?;
        let (wi, wo, mode) = (direction("wi", wi)?, direction("wo", wo)?, transport(transport_mode)?);
        let estimate = b.0.eval(wi, wo, mode, &mut stream(seed, &[wi.x, wi.y, wi.z, wo.x, wo.y, wo.z]));
        // SAFETY: the caller's contract; `value` is not NULL.
        unsafe { *value = estimate };
        Ok(())
    })
}

/// The MIS density of `wo` given `wi` (§13.4, [`Bsdf::pdf`]); no random numbers. 0 where
/// `eval` is 0 by rule, and 0 on a failure ([`smithwalk_last_error`] says which).
///
/// # Safety
/// `bsdf` from `smithwalk_bsdf_new` or NULL; `wi`, `wo` NULL or valid for 3 doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn smithwalk_bsdf_pdf(
    bsdf: *const SmithwalkBsdf,
    wi: *const [f64; 3],
    wo: *const [f64; 3],
) -> f64 {
    let mut density = 0.0;
    guarded(|| {
        // SAFETY: the caller's contract.
        let (b, wi, wo) = unsafe { (required("bsdf", bsdf)?, required("wi", wi)?, required("wo", wo)?) };
        density = b.0.pdf(direction("wi", wi)?, direction("wo", wo)?);
        Ok(())
    });
    density
}

/// The message of the last failed call on the calling thread (empty if none failed): names
/// the field, its value and what is allowed. Valid until the next failing call on the thread.
#[unsafe(no_mangle)]
pub extern "C" fn smithwalk_last_error() -> *const c_char {
    LAST_ERROR.with(|last| last.borrow().as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        // SAFETY: a pointer into this thread's message, read before any other call.
        unsafe { CStr::from_ptr(smithwalk_last_error()) }.to_string_lossy().into_owned()
    }

    /// A panic inside a call becomes a status and a message, not an unwind or an abort.
    #[test]
    fn a_panic_is_caught_and_reported() {
        let status = guarded(|| panic!("planted"));
        assert_eq!(status, SMITHWALK_ERROR_INTERNAL);
        assert!(last_error().contains("planted"), "{}", last_error());
    }
}
