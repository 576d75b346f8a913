//! The laws the walk draws from, each against an independent computation: NDF identities, slope
//! space masses, visible normals, facet phase functions and the height process. One test binary
//! (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod height_process;
mod identities;
mod phase_normalization;
mod slope_space;
mod tabulated;
mod visible_normals;
