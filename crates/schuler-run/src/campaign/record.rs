//! One simulated run held in memory: the measured IMU samples, the truth at each of
//! them, and the aiding readings, as the simulator's streams deliver them.

use schuler::analysis::errors::NavRecord;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{self, BaroReading};
use schuler::sim::run::SimSink;

/// The streams of one simulation.
#[derive(Debug, Clone, Default)]
pub struct Recorded {
    /// Measured IMU samples, in time order.
    pub imu: Vec<ImuSample>,
    /// The true state at each sample's time.
    pub truth: Vec<NavRecord>,
    /// GNSS fixes (with the receiver's velocities).
    pub fixes: Vec<GnssFix>,
    /// Barometer readings: time [s], height [m].
    pub baro: Vec<(f64, f64)>,
}

/// The IMU samples one run may hold: 2^21 (35 min at 1 kHz, 2.9 h at 200 Hz). Each
/// costs 144 bytes with its truth, so a run holds at most 300 MB (twice that while its
/// vectors grow), and a campaign as many runs as it has threads.
pub const HELD_SAMPLES: schuler::domain::Count = schuler::domain::Count {
    quantity: "IMU samples held by one run",
    min: 0,
    max: 1 << 21,
    why: "a campaign holds each run in memory; shorten the scenario or lower imu.rate_hz",
};

impl SimSink for Recorded {
    fn imu(
        &mut self,
        _exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        HELD_SAMPLES
            .check(self.imu.len() as u64 + 1)
            .map_err(std::io::Error::other)?;
        self.imu.push(*measured);
        self.truth.push(truth.into());
        Ok(())
    }

    fn gnss(&mut self, f: &receivers::GnssFix) -> std::io::Result<()> {
        self.fixes.push(GnssFix {
            t: f.t,
            pos: f.pos,
            pos_std: f.pos_std,
            vel: Some((f.v_n, f.vel_std)),
        });
        Ok(())
    }

    fn baro(&mut self, r: &BaroReading) -> std::io::Result<()> {
        self.baro.push((r.t, r.h));
        Ok(())
    }
}
