//! `schuler nav`'s run: navigation of an IMU log, free-inertial or aided (GNSS,
//! barometer, vehicle aids), optionally after an alignment at rest, or started in
//! motion from the fixes.
//!
//! - [`args`]: the run described (flags and TOML keys of one name each),
//! - [`plan`]: flags merged over the configuration file and every value checked,
//! - [`start`]: the start (given, aligned at rest, in motion),
//! - [`run`]: the samples pushed through the session and the outputs written.
//!
//! Mechanizations (`--mechanization`): `ned` (latitude/longitude, singular at the
//! poles), `wander` (the all-latitude free-azimuth mechanization of seed 003, valid
//! everywhere), or `auto` (default): NED while `|lat| <= auto_latitude`, wander above
//! it, back to NED below `auto_latitude − auto_hysteresis` (defaults 75° and 0.5°),
//! in free and aided runs alike (the filter is carried across the hand-over).

pub mod args;
pub mod plan;
pub mod run;
pub mod start;

pub use args::{InitChoice, NavArgs, NavConfig};
pub use plan::{NavPlan, filter_grade, parse_nav_args, plan_of, resolve_aiding};
pub use run::{Navigated, navigate_samples};
pub use start::{BANK_MEMBERS, BANK_SECONDS, Began, align_start, begin, motion_start};
