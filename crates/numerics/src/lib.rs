//! The numerics the oracles rest on, independent of the physics they check: adaptive
//! quadrature ([`quadrature`]) and statistical tests of weighted histograms ([`stats`]).
//!
//! A crate of its own so that the physics crate's tests (`crates/microsurface/tests/`) use
//! them without building the `smithwalk` crate; `smithwalk::analysis` re-exports both.

pub mod quadrature;
pub mod stats;
