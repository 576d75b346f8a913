//! The command line's commands that do more than call one library function: each file is one
//! subcommand of `smithwalk` (`run`, `merge`, `lut`, `bench`), with the console summary they
//! print ([`summary`]) and the checks of the options they share ([`options`]). `main.rs` parses
//! the arguments and calls them; nothing in the library imports this module.

pub mod bench;
pub mod lut;
pub mod merge;
pub mod options;
pub mod run;
pub mod summary;
