//! Simulation: trajectories with exact truth and the IMU increments they produce.

pub mod analytic;
pub mod imu_model;
pub mod jet;
pub mod motion;
pub mod random;
pub mod scenario;
pub mod spline;
