//! Error statistics and sensor characterization.
//!
//! - [`errors`]: a navigation result's errors against a truth, epoch by epoch;
//! - [`statistics`]: RMS, maximum, 95th percentile, CEP and per-outage maxima;
//! - [`consistency`]: NIS and NEES against their chi-square bounds;
//! - [`budget`]: covariance analysis, each error source's share of the navigation error;
//! - [`allan`]: Allan deviation of IMU logs, its confidence and the IEEE Std 952 noise
//!   terms fitted to it.

pub mod allan;
pub mod budget;
pub mod consistency;
pub mod errors;
pub mod statistics;
