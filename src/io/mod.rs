//! The run directory: its format ([`schema`]), the tables a run writes ([`output`]) and reads
//! back ([`rundir`]); the record a `smithwalk lut` table carries ([`table_record`]); and the
//! seal of `compare`'s tables ([`compare_json`]).

pub mod compare_json;
pub mod output;
pub mod rundir;
pub mod schema;
pub mod table_record;
