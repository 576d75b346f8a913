//! smithwalk: a virtual gonioreflectometer for the Smith microsurface.
//!
//! Data flows one way, and the modules are grouped in that order: [`setup`] reads a
//! [`setup::config::Config`] and expands it into [`setup::cases::Case`]s; the [`engine`] walks
//! each case with the [`microsurface`] crate in fixed chunks and bins the escaping light in a
//! [`engine::detector::Detector`]; [`io`] writes the run directory and reads it back; the
//! [`analysis`] compares measurements with analytic models; the [`exports`] turn a run into
//! figures, energy-compensation tables and measured-BRDF files. A lower layer never imports a
//! higher one; [`atomic`] (whole-or-nothing file writes) serves them all.

pub mod analysis;
pub mod atomic;
pub mod engine;
pub mod exports;
pub mod io;
pub mod setup;

pub use engine::{RoundHook, RunOptions, Simulation, simulate, simulate_from, simulate_shard};
pub use io::output::write_outputs;
pub use microsurface;
pub use setup::config::Config;
