//! What the end-to-end benchmarks share: the maneuvering flight they navigate and the
//! settings of a run from its start.

use schuler::earth::{Geodetic, Wgs84};
use schuler::sim::analytic::{self, Maneuvering};
use schuler_io::formats::ImuReadOptions;
use schuler_run::navigate::NavSettings;
use schuler_run::options::EarthChoice;
use std::path::PathBuf;

/// The flight (Wuhan, 500 m: climbs, turns, accelerations).
pub fn flight() -> Maneuvering {
    Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0))
}

/// A run of the IMU log `imu` from the flight's state at t = 0, 1-Hz output into
/// `out`, GPS week 2200.
pub fn settings(imu: PathBuf, out: PathBuf) -> NavSettings {
    let init = analytic::state(&Wgs84, &flight(), 0.0);
    NavSettings {
        imu,
        read: ImuReadOptions::default(),
        init_pos: init.pos,
        init_vel: init.v_n,
        init_att: init.euler(),
        output_rate: Some(1.0),
        out,
        earth: EarthChoice::Wgs84,
        week: 2200,
        mechanization: Default::default(),
        out_bag: None,
    }
}
