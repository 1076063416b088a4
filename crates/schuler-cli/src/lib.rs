//! The `schuler` command-line tool as a library: file formats, writers and the
//! commands, so that tests and benchmarks drive exactly what the binary runs.

pub mod commands;
pub mod fixed;
pub mod formats;
pub mod output;
pub mod plot;
pub mod report;
