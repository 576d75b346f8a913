//! Measurements against models: the analytic bin expectations ([`models`], [`vgroove`]), the comparison
//! of a run with them ([`compare`]), and the quadrature and statistics they rest on.

pub mod albedo_table;
pub mod compare;
pub mod compensation;
pub mod external;
pub mod models;
pub mod vgroove;
mod visible;

// The quadrature and statistics live in their own crate (`crates/numerics`), so that the
// physics crate's tests use them without building this one.
pub use numerics::{quadrature, stats};
