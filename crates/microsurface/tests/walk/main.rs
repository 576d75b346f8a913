//! Whole walks against oracles that do not share their code: per-order lobes, the bookkeeping of
//! weight, reciprocity, the position-free depth profile and the path term of Cui et al.'s
//! released code; the V-groove microsurface. One test binary (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod cui_path_term;
mod depth_profile;
mod reciprocity;
mod vgroove_oracles;
mod walk_bookkeeping;
mod walk_lobes;
