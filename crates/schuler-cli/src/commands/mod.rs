//! One module per `schuler` subcommand: each parses its arguments and wires library
//! calls to readers and writers.

pub mod align;
pub mod allan;
pub mod channel;
pub mod compare;
pub mod demo;
pub mod kf_gins;
pub mod nav;
pub mod platform;
pub mod simulate;
pub mod vertical;
