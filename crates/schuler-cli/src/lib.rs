//! The `schuler` command-line tool as a library: the commands' clap definitions and
//! what they print, over the application layer (`schuler_run`), so that tests and
//! benchmarks drive exactly what the binary runs.

pub mod commands;
