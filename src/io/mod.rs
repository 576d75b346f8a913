//! The run directory: its format ([`schema`]), the tables a run writes ([`output`]) and reads
//! back ([`rundir`]).

pub mod output;
pub mod rundir;
pub mod schema;
