//! `smithwalk rgl`: an isotropic reflective sweep as an RGL material file (`.bsdf`), the tensor
//! file of Dupuy and Jakob 2018 ("An adaptive parameterization for efficient material
//! acquisition and rendering") that Mitsuba 3's `measured` plugin renders, in its RGB form.
//!
//! The tensor file (little-endian): the 12 bytes `tensor_file\0`, the version bytes (1, 0) and
//! a `u32` field count; per field a `u16` name length, the name, a `u16` rank, a `u8` type
//! (1 = u8, 10 = f32), a `u64` byte offset and `rank` `u64` extents; then each field's data,
//! row-major, at its offset (8-byte aligned here).
//!
//! The fields: `description` (u8 text), `jacobian` (`[1]` u8), `theta_i` (the swept incident
//! angles in radians, ascending), `phi_i` (`[0]`: one azimuth, isotropic), `ndf` and `sigma`
//! ([2, n]), `vndf` and `luminance` ([1, n_theta, n, n]) and `rgb` ([1, n_theta, 3, n, n]).
//!
//! The parameterization: a pair of directions is addressed by its half vector m at
//! u = (sqrt(theta_m / (pi/2)), (phi_m - phi_i + pi) / 2pi). A reader maps a sample square to u
//! through the warp of the `vndf` density, interpolates `rgb` bilinearly over that square (grid
//! vertices at j / (n - 1)) and linearly in theta_i, and returns f cos(theta_o), times
//! D(m) / (4 sigma(wi)) when `jacobian` is 1.
//!
//! What this export chooses:
//! - `vndf` is constant, so the warp is the identity and the `rgb` grid lies on u itself. The
//!   grid is dense near the normal already (theta_m grows as u^2).
//! - `jacobian` is 0, so `rgb` holds f cos(theta_o) itself: a multiple-scattering lobe does not
//!   follow D(m), and dividing by it would blow up where D is small.
//! - `luminance`, the sampling density over the square, is the lobe's luminance times
//!   |d omega_o / d u| = 2 pi^2 u_x sin(theta_m) 4 (wi . m), so a renderer draws directions
//!   nearly in proportion to the lobe.
//! - `ndf` and `sigma` hold the surface's D(m) and projected area A(wi) (docs/theory.md §1.2, §1.5)
//!   on the same u axis, for tools that read them.
//!
//! The lobe values come from [`Sweep::brdf`] at the swept incident angles themselves, so the
//! only interpolation in theta_i is the reader's.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use glam::DVec3;
use microsurface::ndf::Ndf;

use crate::atomic::write_file_atomically;
use crate::exports::sweep::Sweep;
use crate::io::rundir::RunDir;

/// The grid points per axis of the u square unless `--resolution` says otherwise.
pub const DEFAULT_RESOLUTION: usize = 64;
/// The allowed grid points per axis.
pub const RESOLUTIONS: std::ops::RangeInclusive<usize> = 2..=1024;
/// Rec. 709 luminance weights of linear red, green and blue.
const LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// The values of one tensor field.
enum Values {
    U8(Vec<u8>),
    F32(Vec<f32>),
}

/// One named tensor of a tensor file.
struct Field {
    name: &'static str,
    shape: Vec<usize>,
    values: Values,
}

impl Field {
    fn f32(name: &'static str, shape: Vec<usize>, values: Vec<f32>) -> Self {
        debug_assert_eq!(shape.iter().product::<usize>(), values.len());
        Self { name, shape, values: Values::F32(values) }
    }

    fn type_code(&self) -> u8 {
        match self.values {
            Values::U8(_) => 1,
            Values::F32(_) => 10,
        }
    }

    fn data(&self) -> Vec<u8> {
        match &self.values {
            Values::U8(v) => v.clone(),
            Values::F32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }
}

/// The bytes of a tensor file holding `fields` in order.
fn tensor_file(fields: &[Field]) -> Vec<u8> {
    let align = |n: usize| n.div_ceil(8) * 8;
    let header_len: usize =
        12 + 2 + 4 + fields.iter().map(|f| 2 + f.name.len() + 2 + 1 + 8 + 8 * f.shape.len()).sum::<usize>();
    let data: Vec<Vec<u8>> = fields.iter().map(Field::data).collect();
    let mut out = Vec::new();
    out.extend(b"tensor_file\0");
    out.extend([1u8, 0]);
    out.extend((fields.len() as u32).to_le_bytes());
    let mut offset = align(header_len);
    for (field, bytes) in fields.iter().zip(&data) {
        out.extend((field.name.len() as u16).to_le_bytes());
        out.extend(field.name.as_bytes());
        out.extend((field.shape.len() as u16).to_le_bytes());
        out.push(field.type_code());
        out.extend((offset as u64).to_le_bytes());
        for &extent in &field.shape {
            out.extend((extent as u64).to_le_bytes());
        }
        offset = align(offset + bytes.len());
    }
    for bytes in data {
        out.resize(align(out.len()), 0);
        out.extend(bytes);
    }
    out
}

/// The polar angle of the u coordinate `u_x` (theta = (pi/2) u^2).
fn u_to_theta(u_x: f64) -> f64 {
    FRAC_PI_2 * u_x * u_x
}

/// The half vector at grid coordinates (u_x, u_y), its azimuth relative to the incidence plane.
fn half_vector(u_x: f64, u_y: f64) -> DVec3 {
    let (st, ct) = u_to_theta(u_x).sin_cos();
    let (sp, cp) = ((2.0 * u_y - 1.0) * PI).sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// `ndf` and `sigma`: D at the polar angles of the u axis, and A(w) at the same angles, each
/// as two equal rows (the azimuth axis of an isotropic surface).
fn surface_fields<N: Ndf>(ndf: &N, n: usize) -> [Field; 2] {
    let axis = |j: usize| u_to_theta(j as f64 / (n - 1) as f64);
    let rows = |f: &dyn Fn(DVec3) -> f64| -> Vec<f32> {
        let row: Vec<f32> = (0..n)
            .map(|j| {
                let (s, c) = axis(j).sin_cos();
                let v = f(DVec3::new(s, 0.0, c));
                if v.is_finite() { v as f32 } else { 0.0 }
            })
            .collect();
        [row.clone(), row].concat()
    };
    [
        Field::f32("ndf", vec![2, n], rows(&|m| ndf.d(m))),
        Field::f32("sigma", vec![2, n], rows(&|w| ndf.projected_area(w))),
    ]
}

/// The `rgb` and `luminance` grids of one incident angle: f cos(theta_o) per channel in
/// [channel][u_y][u_x] order, and the sampling density in [u_y][u_x] order.
fn lobe_grids(sweep: &Sweep, theta_i: f64, n: usize) -> (Vec<f32>, Vec<f32>) {
    let wi = DVec3::new(theta_i.sin(), 0.0, theta_i.cos());
    let mut rgb = vec![0.0_f32; 3 * n * n];
    let mut luminance = vec![0.0_f64; n * n];
    let mut jacobians = vec![0.0_f64; n * n];
    let step = 1.0 / (n - 1) as f64;
    for y in 0..n {
        for x in 0..n {
            let (u_x, u_y) = (x as f64 * step, y as f64 * step);
            let m = half_vector(u_x, u_y);
            let cos_d = wi.dot(m);
            let wo = 2.0 * cos_d * m - wi;
            // Only pairs above the horizon whose half vector faces wi are ever looked up.
            if cos_d <= 0.0 || wo.z <= 0.0 {
                continue;
            }
            let k = y * n + x;
            let f = sweep.brdf(wi, wo);
            for c in 0..3 {
                rgb[c * n * n + k] = (f[c] * wo.z) as f32;
            }
            jacobians[k] = TAU * PI * u_x * m.z.mul_add(-m.z, 1.0).max(0.0).sqrt() * 4.0 * cos_d;
            luminance[k] = (0..3).map(|c| LUMINANCE[c] * f[c] * wo.z).sum::<f64>() * jacobians[k];
        }
    }
    // A black lobe still needs a sampling density: then uniform in solid angle.
    let density = if luminance.iter().any(|&l| l > 0.0) { luminance } else { jacobians };
    (rgb, density.into_iter().map(|v| v as f32).collect())
}

/// The bytes of the RGL file of a sweep at `n` x `n` grid points per incident angle.
pub fn rgl_bytes(sweep: &Sweep, n: usize) -> Vec<u8> {
    let n_theta = sweep.theta_i.len();
    let (mut rgb, mut luminance) = (Vec::new(), Vec::new());
    for &theta in &sweep.theta_i {
        let (r, l) = lobe_grids(sweep, theta, n);
        rgb.extend(r);
        luminance.extend(l);
    }
    let [ndf, sigma] = surface_fields(&sweep.ndf, n);
    tensor_file(&[
        Field {
            name: "description",
            shape: vec![sweep.description.len()],
            values: Values::U8(sweep.description.clone().into_bytes()),
        },
        Field { name: "jacobian", shape: vec![1], values: Values::U8(vec![0]) },
        Field::f32("theta_i", vec![n_theta], sweep.theta_i.iter().map(|&t| t as f32).collect()),
        Field::f32("phi_i", vec![1], vec![0.0]),
        ndf,
        sigma,
        Field::f32("vndf", vec![1, n_theta, n, n], vec![1.0; n_theta * n * n]),
        Field::f32("luminance", vec![1, n_theta, n, n], luminance),
        Field::f32("rgb", vec![1, n_theta, 3, n, n], rgb),
    ])
}

/// Writes the RGL file of the sweep in `run_dir` to `out` (atomically), `resolution` grid points
/// per axis.
pub fn export(run_dir: &Path, out: &Path, resolution: usize) -> Result<PathBuf> {
    if !RESOLUTIONS.contains(&resolution) {
        bail!(
            "--resolution {resolution} is not allowed: the grid needs {} to {} points per axis",
            RESOLUTIONS.start(),
            RESOLUTIONS.end()
        );
    }
    let run = RunDir::open(run_dir)?;
    let sweep = Sweep::read(&run)?;
    if let Some(note) = run.dropped_transmission()? {
        eprintln!("{note}");
    }
    write_file_atomically(out, rgl_bytes(&sweep, resolution))
}
