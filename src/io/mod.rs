//! The run directory: the tables a run writes ([`output`]) and reads back ([`rundir`]).

pub mod output;
pub mod rundir;
