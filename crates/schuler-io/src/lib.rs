//! File formats of the schuler toolkit: every reader and writer of a log, a
//! navigation result or a bag, turning bytes into the library's typed records and
//! back.
//!
//! Readers stream (one item at a time, bounded memory whatever the length of the
//! log), convert units, axes and time scales at the edge, and refuse bad input with an
//! error that names the file, the line (or offset) and the field. Writers print fixed
//! decimals and close their files on whole lines.
//!
//! This crate knows no command line, no terminal and no pipeline: it depends only on
//! the `schuler` library (see ARCHITECTURE.md).

pub mod bag;
pub mod fixed;
pub mod formats;
pub mod line_file;
pub mod logs;
pub mod named;
pub mod output;
pub mod text_block;
