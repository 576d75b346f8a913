//! What a run becomes: figures and the HTML report ([`plot`]), energy-compensation tables
//! ([`lut`]), and measured-BRDF files ([`merl`], [`rgl`]) sampled from a reflective [`sweep`].

pub mod lut;
pub mod merl;
pub mod plot;
pub mod rgl;
pub mod sweep;
