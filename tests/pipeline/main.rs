//! A run from config to files: bit-identical outputs for any thread count, shards and merge,
//! resume after SIGKILL, damaged shards and checkpoints, run-directory validation, and what a
//! user reads first. One test binary (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod corruption;
mod determinism;
mod first_use;
mod resume;
mod run_dir;
mod schema;
mod shards;
