//! smithwalk: a virtual gonioreflectometer for the Smith microsurface.
//!
//! The `smithwalk` command line (see the README) is one user of this library; a program can
//! run the same measurements itself: parse a [`Config`], [`simulate`] it, read the albedos and
//! lobes of the [`Simulation`], and, if it likes, [`write_outputs`] the run directory that the
//! command line writes (`lobes.csv`, `summary.csv`, `run.json`).
//!
//! ```
//! use smithwalk::engine::detector::Hemisphere;
//! use smithwalk::engine::run::CaseResult;
//! use smithwalk::{Config, Simulation, simulate};
//!
//! // A GGX conductor with F = 1 (the default Fresnel mode), alpha 0.5, lit from 60 degrees.
//! let config = Config::parse(
//!     r#"
//!     paths = 200_000
//!     [surface]
//!     alpha = 0.5
//!     [material]
//!     kind = "conductor"
//!     [incident]
//!     theta_deg = 60
//!     [detector]
//!     cos_theta_bins = 16
//!     phi_bins = 32
//!     "#,
//! )?;
//! let sim: Simulation = simulate(&config, None, false)?;
//! let case = &sim.results[0];
//!
//! // Albedos per order slot (0 = all orders) with their standard errors. Nothing is absorbed,
//! // so all orders reflect everything; single scattering reflects 0.698251 (exact, by
//! // quadrature: docs/theory.md §9.4).
//! let (all, _) = case.albedo(0, Hemisphere::R);
//! let (e1, se1) = case.albedo(1, Hemisphere::R);
//! assert!((all - 1.0).abs() < 1e-12);
//! assert!((e1 - 0.698251).abs() < 4.0 * se1, "E1 = {e1} +- {se1}");
//!
//! // The order-1 lobe: the energy in every bin of the reflected hemisphere (bin
//! // `ic * phi_bins + ip`: cos theta in [ic, ic + 1] / cos_theta_bins, phi from the incident
//! // azimuth in [ip, ip + 1] * 360 / phi_bins degrees). The bins add up to the albedo.
//! let CaseResult::Mono(detector) = case else { unreachable!("one channel") };
//! let (grid, photons) = (detector.grid, detector.tallies.photons);
//! let lobe: Vec<f64> = detector.tallies.orders[1].bins[..grid.bins()]
//!     .iter()
//!     .map(|bin| bin.mean_and_stderr(photons, 0).0)
//!     .collect();
//! assert!((lobe.iter().sum::<f64>() - e1).abs() < 1e-9);
//! // Its brightest bin faces the mirror direction, phi = 180 degrees.
//! let brightest = (0..grid.bins()).max_by(|&a, &b| lobe[a].total_cmp(&lobe[b])).unwrap();
//! let (phi_lo, phi_hi) = grid.phi_edges_deg(brightest % grid.phi_bins);
//! assert!(phi_lo <= 180.0 && 180.0 <= phi_hi, "brightest bin at phi {phi_lo}..{phi_hi}");
//! # Ok::<(), anyhow::Error>(())
//! ```
//!
//! # Layout
//!
//! Data flows one way, and the modules are grouped in that order: [`setup`] reads a
//! [`setup::config::Config`] and expands it into [`setup::cases::Case`]s; the [`engine`] walks
//! each case with the [`microsurface`] crate in fixed chunks and bins the escaping light in a
//! [`engine::detector::Detector`]; [`io`] writes the run directory and reads it back; the
//! [`analysis`] compares measurements with analytic models; the [`exports`] turn a run into
//! figures, energy-compensation tables and measured-BRDF files; the [`commands`] are the command
//! line's subcommands, on top of every layer. A lower layer never imports a higher one
//! (`tests/architecture.rs` checks it); [`atomic`] (whole-or-nothing file writes) serves them all.

pub mod analysis;
pub mod atomic;
pub mod commands;
pub mod engine;
pub mod exports;
pub mod input;
pub mod io;
pub mod setup;

pub use engine::{RoundHook, RunOptions, Simulation, simulate, simulate_from, simulate_shard};
pub use io::output::write_outputs;
pub use microsurface;
pub use setup::config::Config;
