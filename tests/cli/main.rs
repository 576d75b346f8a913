//! The command line and bad input: every bad config and option gets one line naming the field,
//! the value and what is allowed, and random configs, command lines and damaged run directories
//! never panic. One test binary (each file a module) so that the crate is linked once.

#[path = "../common/mod.rs"]
mod common;

mod bad_input;
mod documented_limits;
mod memory;
mod properties;
mod wording;
