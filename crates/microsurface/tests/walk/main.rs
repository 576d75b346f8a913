//! Whole walks against oracles that do not share their code: per-order lobes, the bookkeeping of
//! weight, reciprocity and the position-free depth profile. One test binary (each file a module)
//! so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod depth_profile;
mod reciprocity;
mod walk_bookkeeping;
mod walk_lobes;
