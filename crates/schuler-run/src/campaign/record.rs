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

impl SimSink for Recorded {
    fn imu(
        &mut self,
        _exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
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
