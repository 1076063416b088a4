//! One simulation held in memory as the budget needs it: the exact (error-free) IMU
//! samples with the truth at each, and the aiding readings' times and accuracies.

use crate::campaign::record::HELD_SAMPLES;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{self, BaroReading};
use schuler::sim::run::SimSink;

/// The streams of one simulation, for a budget.
#[derive(Debug, Clone, Default)]
pub struct Held {
    /// Exact samples and the true state at each one's end, in time order.
    pub imu: Vec<(ImuSample, NavState)>,
    /// GNSS fixes (their times and standard deviations are what the budget uses).
    pub fixes: Vec<GnssFix>,
    /// Barometer readings: time [s], height [m] (the budget uses their times).
    pub baro: Vec<(f64, f64)>,
}

impl SimSink for Held {
    fn imu(
        &mut self,
        exact: &ImuSample,
        _measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        HELD_SAMPLES
            .check(self.imu.len() as u64 + 1)
            .map_err(std::io::Error::other)?;
        self.imu.push((*exact, *truth));
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
