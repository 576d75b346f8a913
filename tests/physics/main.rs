//! The physics of the whole program against exact oracles and independent references: energy
//! conservation and per-order tables, exact single scattering, the height-form walk, next-event
//! estimation, the position-free form, the joint and Wang chains, Hammon's fit and variants, the
//! side-by-side walk, error bars over independent seeds, and the theory citations they rest on.
//! One test binary (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod energy;
mod error_bars;
mod hammon_fit;
mod hammon_variants;
mod height_independence;
mod height_walk;
mod inside;
mod joint_chains;
mod next_event;
mod position_free;
mod side_by_side;
mod single_scattering;
mod theory_refs;
mod wang_models;
