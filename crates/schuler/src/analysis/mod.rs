//! Error statistics and sensor characterization.

pub mod allan;
