//! The run directory: its format ([`schema`]), the tables a run writes ([`output`]) and reads
//! back ([`rundir`]); and the record a `smithwalk lut` table carries ([`table_record`]).

pub mod output;
pub mod rundir;
pub mod schema;
pub mod table_record;
