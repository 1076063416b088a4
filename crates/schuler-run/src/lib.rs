//! The application layer of the schuler toolkit: a run described as data (its inputs,
//! start, session configuration and outputs, with one name, default and check for
//! each option) and the code that executes it — sources read into the library's
//! session, epochs and events written out, alignment first or a start in motion,
//! Monte-Carlo campaigns.
//!
//! Both front ends build these descriptions (the CLI from its flags, the Python
//! package from keyword arguments) and call this crate; it never prints to a
//! terminal. File formats are `schuler_io`'s, reports `schuler_report`'s (see
//! ARCHITECTURE.md).

pub mod aided;
pub mod alignment;
pub mod allan;
pub mod bag_input;
pub mod budget;
pub mod campaign;
pub mod channel;
pub mod compare;
pub mod demo;
pub mod drive;
pub mod earth;
pub mod flat_options;
pub mod gnss;
pub mod imu_input;
pub mod inspect;
pub mod interrupt;
pub mod kf_gins;
pub mod log_input;
pub mod log_reference;
pub mod nav;
pub mod navigate;
pub mod options;
pub mod platform;
pub mod progress;
pub mod scenario;
pub mod simulate;
pub mod vertical;
