//! The library's scenario and closed-form tests, in one test binary: each module is
//! one subject (its own doc says what it checks against). One binary, not one per
//! file, so that the library's generic code (the mechanizations, the filter on each
//! Earth model) is compiled and optimized once for all of them.

#[path = "../common/mod.rs"]
mod common;

mod alignment;
mod calibration;
mod channel_closed_forms;
mod channel_fundamental;
mod channel_leveling;
mod channel_vertical;
mod gnss_integration;
mod imu_error_stats;
mod imu_spec_stats;
mod in_motion;
mod platform_systems;
mod raw_sim;
mod refine_invariant;
mod refine_second_unit;
mod seed18;
mod session_stream;
mod strapdown_exact;
mod tight_coupling;
mod vehicle_aiding;
mod wander_agrees_with_ned;
mod wander_polar;
