//! Strapdown mechanizations: integrate IMU increments into position, velocity and
//! attitude, one sample per call, with no heap allocation.
//!
//! Every mechanization implements [`Mechanization`], so the CLI, the filter and the
//! alignment are written once for all of them:
//!
//! - [`LocalLevel`]: NED, latitude and longitude as position (singular at the poles);
//! - [`Wander`]: all-latitude free-azimuth frame with quaternion position (seed 003),
//!   valid everywhere including exactly at a pole.
//!
//! Both share the increment algorithm of [`strapdown`], and either hands its state
//! and step history to the other without loss ([`Wander::from_local_level`],
//! [`Wander::to_local_level`]).

pub mod baro_loop;
pub mod frame;
pub mod local_level;
pub mod state;
pub mod strapdown;
pub mod wander;

pub use baro_loop::BaroLoop;
pub use frame::{ErrorFrame, FrameSnapshot, NavErrors};
pub use local_level::LocalLevel;
pub use state::NavState;
pub use strapdown::StepHistory;
pub use wander::{Wander, WanderEarth, WanderState};

use crate::imu::ImuSample;

/// Which second-order corrections a mechanization applies (both on by default; off
/// only to study their effect).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corrections {
    /// Two-sample coning correction `(1/12) dtheta_{k-1} x dtheta_k` in the attitude
    /// update.
    pub coning: bool,
    /// Two-sample sculling correction
    /// `(1/12)(dtheta_{k-1} x dvel_k + dvel_{k-1} x dtheta_k)` in the velocity update.
    pub sculling: bool,
}

impl Default for Corrections {
    fn default() -> Self {
        Self {
            coning: true,
            sculling: true,
        }
    }
}

/// A strapdown mechanization stepping one IMU sample at a time.
pub trait Mechanization {
    /// Integrate one sample: advance the state from `sample.t - sample.dt` to
    /// `sample.t`. The sample's interval must start at the current state's time.
    fn step(&mut self, sample: &ImuSample);

    /// Give the sample that ends at the initial time (its interval precedes the start,
    /// so it is not integrated) as the "previous" sample of the two-sample corrections;
    /// without it the first step has no coning or sculling correction.
    fn prime(&mut self, previous: &ImuSample);

    /// The current state in the local-level NED frame.
    fn state(&self) -> NavState;
}
