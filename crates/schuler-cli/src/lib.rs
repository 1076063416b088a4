//! The `schuler` command-line tool as a library: file formats, writers and the
//! commands, so that tests and benchmarks drive exactly what the binary runs.

pub mod aided;
pub mod alignment;
pub mod bag_input;
pub mod campaign;
pub mod commands;
pub mod drive;
pub mod imu_input;
pub mod interrupt;
pub mod navigate;
pub mod options;
pub mod plot;
pub mod report;
pub mod writer_thread;
