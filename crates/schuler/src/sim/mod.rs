//! Simulation: trajectories with exact truth and the IMU increments they produce.

pub mod analytic;
pub mod exact;
pub mod gnss_ins_sim;
pub mod imu_model;
pub mod jet;
pub mod motion;
pub mod raw_gnss;
pub mod receivers;
pub mod run;
pub mod scenario;
pub mod sensor_spec;
pub mod spline;
pub mod vehicle;
