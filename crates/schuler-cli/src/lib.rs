//! The `schuler` command-line tool as a library: file formats, writers and the
//! commands, so that tests and benchmarks drive exactly what the binary runs.

pub mod aided;
pub mod alignment;
pub mod bag;
pub mod bag_input;
pub mod campaign;
pub mod commands;
pub mod drive;
pub mod fixed;
pub mod formats;
pub mod imu_input;
pub mod interrupt;
pub mod line_file;
pub mod navigate;
pub mod options;
pub mod output;
pub mod plot;
pub mod report;
pub mod text_block;
pub mod writer_thread;
