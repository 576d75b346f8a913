//! `smithwalk compare` and the models it judges: verdicts end to end, `models.csv`, its seal, the
//! energy-compensation models and the albedo tables they read, Cui et al.'s released model, Lee et al.'s V-grooves. One
//! test binary (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod albedo_table;
mod compare;
mod compare_verdicts;
mod compensation;
mod cui_released;
mod materialx;
mod models_table;
mod sealed;
mod vgroove;
