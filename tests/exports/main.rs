//! What leaves a run: `plot` and its report (also in a real browser), `lut` tables, MERL and RGL
//! files read back independently, and the README's pandas snippet. One test binary (each file a
//! module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod lut;
mod merl;
mod plot;
mod readme_snippet;
mod report_browser;
mod rgl;
mod skips;
