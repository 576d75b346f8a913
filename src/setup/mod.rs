//! What to measure: the TOML configuration ([`config`]) and its expansion into cases ([`cases`]).

pub mod cases;
pub mod config;
