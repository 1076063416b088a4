//! Error-state (indirect) Kalman filter for strapdown navigation, with closed-loop
//! feedback into the mechanization.
//!
//! - [`layout`]: which errors are states and where they sit in the vector;
//! - [`noise`]: the IMU noise model the process noise comes from;
//! - [`error_model`]: the psi-angle error dynamics `F`, their transition matrix and
//!   discrete process noise (non-singular at the poles, see [`crate::nav::frame`]);
//! - [`interval`]: the sums over one propagation interval;
//! - [`measurement`]: GNSS position and velocity with lever arm, barometric height;
//! - [`calibration`]: the lever arm and the GNSS time offset as states;
//! - [`vehicle`]: zero velocity and angular rate at rest, the non-holonomic
//!   constraint, odometer speed, dual-antenna heading;
//! - [`integration`]: the INS/GNSS filter loop;
//! - [`ranging`]: tight coupling, pseudoranges and rates with the receiver clock;
//! - [`smoother`]: the Rauch–Tung–Striebel backward pass, over [`spill`]'s records
//!   (memory up to a budget, then a temporary file);
//! - [`seed18`]: the flight-test paper's 18-state model on the wander mechanization;
//! - [`kalman`]: covariance propagation, Joseph-form update and the chi-square
//!   innovation gate.

pub mod calibration;
pub mod error_model;
pub mod gate_book;
pub mod integration;
pub mod interval;
pub mod kalman;
pub mod layout;
pub mod measurement;
pub mod noise;
pub mod ranging;
pub mod seed18;
pub mod smoother;
pub mod spill;
pub mod vehicle;

pub use calibration::{Calibration, CalibrationState, Estimate};
pub use error_model::{ClockNoise, ErrorModel, IntervalMeans};
pub use integration::{FixSource, GnssFix, IntegrationConfig, Integrator, SensorEstimates};
pub use kalman::{Gate, Kalman, Rejection, Update};
pub use layout::Layout;
pub use noise::ImuNoise;
pub use ranging::{Clocks, TightConfig};
pub use vehicle::{Baseline, HeadingReading, VehicleMount};
