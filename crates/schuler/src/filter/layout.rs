//! The error-state vector: position, velocity and attitude errors, residual sensor
//! errors, and optional extras, at fixed offsets.

/// Offsets of the error states. The first fifteen are always present:
/// `δr` (0..3), `δv` (3..6), `ψ` (6..9), residual gyro bias (9..12) and accelerometer
/// bias (12..15); optional blocks follow in the order they are added (the builders
/// below), each at the offset it records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Number of states.
    pub n: usize,
    /// Gyro scale-factor errors (3), if estimated.
    pub gyro_scale: Option<usize>,
    /// Accelerometer scale-factor errors (3), if estimated.
    pub accel_scale: Option<usize>,
    /// Barometer bias (1), if estimated.
    pub baro_bias: Option<usize>,
    /// Attitude error at a reference time (3), for the "attitude unchanged" invariant of
    /// a stationary base.
    pub attitude_ref: Option<usize>,
    /// Odometer scale-factor error (1), if estimated.
    pub odometer_scale: Option<usize>,
    /// Mounting errors of the vehicle frame (2: pitch, then yaw, about the vehicle's
    /// y and z axes), if estimated.
    pub mounting: Option<usize>,
    /// Receiver clock biases [m], one per system in the order the filter keeps
    /// ([`super::ranging::Clocks`]), then the common clock drift [m/s], if tight
    /// coupling: the offset of the first bias.
    pub clock: Option<usize>,
    /// How many clock biases (systems) [`Layout::clock`] holds.
    pub clock_systems: usize,
    /// The GNSS antenna's lever arm (3, body axes), if calibrated
    /// ([`super::calibration`]).
    pub lever_arm: Option<usize>,
    /// The GNSS-to-IMU time offset (1), if calibrated.
    pub time_offset: Option<usize>,
}

impl Layout {
    /// Position error offset.
    pub const POS: usize = 0;
    /// Velocity error offset.
    pub const VEL: usize = 3;
    /// Attitude error offset.
    pub const ATT: usize = 6;
    /// Residual gyro bias offset.
    pub const GYRO_BIAS: usize = 9;
    /// Residual accelerometer bias offset.
    pub const ACCEL_BIAS: usize = 12;

    /// The fifteen core states only.
    pub fn core() -> Self {
        Self {
            n: 15,
            gyro_scale: None,
            accel_scale: None,
            baro_bias: None,
            attitude_ref: None,
            odometer_scale: None,
            mounting: None,
            clock: None,
            clock_systems: 0,
            lever_arm: None,
            time_offset: None,
        }
    }

    /// The core plus gyro and accelerometer scale factors (21 states, as KF-GINS).
    pub fn with_scale_factors(mut self) -> Self {
        self.gyro_scale = Some(self.n);
        self.accel_scale = Some(self.n + 3);
        self.n += 6;
        self
    }

    /// Add a barometer bias state.
    pub fn with_baro_bias(mut self) -> Self {
        self.baro_bias = Some(self.n);
        self.n += 1;
        self
    }

    /// Add a reference attitude error (stationary alignment).
    pub fn with_attitude_ref(mut self) -> Self {
        self.attitude_ref = Some(self.n);
        self.n += 3;
        self
    }

    /// Add an odometer scale-factor state.
    pub fn with_odometer_scale(mut self) -> Self {
        self.odometer_scale = Some(self.n);
        self.n += 1;
        self
    }

    /// Add the vehicle frame's pitch and yaw mounting errors.
    pub fn with_mounting(mut self) -> Self {
        self.mounting = Some(self.n);
        self.n += 2;
        self
    }

    /// Add receiver clock biases for `systems` systems and the clock drift.
    pub fn with_clock(mut self, systems: usize) -> Self {
        self.clock = Some(self.n);
        self.clock_systems = systems;
        self.n += systems + 1;
        self
    }

    /// Add the GNSS antenna's lever arm.
    pub fn with_lever_arm(mut self) -> Self {
        self.lever_arm = Some(self.n);
        self.n += 3;
        self
    }

    /// Add the GNSS-to-IMU time offset.
    pub fn with_time_offset(mut self) -> Self {
        self.time_offset = Some(self.n);
        self.n += 1;
        self
    }

    /// The offset of the clock drift, with a clock.
    pub fn clock_drift(&self) -> Option<usize> {
        self.clock.map(|o| o + self.clock_systems)
    }

    /// Names of the states, for reports (`dr_x`, ..., `psi_z`, `bg_x`, ...), each at
    /// its block's offset.
    pub fn names(&self) -> Vec<String> {
        let mut names = vec![String::new(); self.n];
        let mut block = |at: Option<usize>, prefix: &str| {
            if let Some(o) = at {
                for (i, axis) in ["x", "y", "z"].iter().enumerate() {
                    names[o + i] = format!("{prefix}_{axis}");
                }
            }
        };
        for (o, p) in [
            (Self::POS, "dr"),
            (Self::VEL, "dv"),
            (Self::ATT, "psi"),
            (Self::GYRO_BIAS, "bg"),
            (Self::ACCEL_BIAS, "ba"),
        ] {
            block(Some(o), p);
        }
        block(self.gyro_scale, "sg");
        block(self.accel_scale, "sa");
        block(self.attitude_ref, "psi_ref");
        block(self.lever_arm, "lever");
        for (at, name) in [
            (self.baro_bias, "baro_bias"),
            (self.odometer_scale, "odometer_scale"),
            (self.time_offset, "gnss_time_offset"),
        ] {
            if let Some(o) = at {
                names[o] = name.into();
            }
        }
        if let Some(o) = self.mounting {
            names[o] = "mount_pitch".into();
            names[o + 1] = "mount_yaw".into();
        }
        if let Some(o) = self.clock {
            for i in 0..self.clock_systems {
                names[o + i] = format!("clock_bias_{i}");
            }
            names[o + self.clock_systems] = "clock_drift".into();
        }
        names
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_follow_each_other_without_gaps() {
        let l = Layout::core()
            .with_scale_factors()
            .with_baro_bias()
            .with_attitude_ref()
            .with_odometer_scale();
        assert_eq!(l.n, 26);
        assert_eq!(l.gyro_scale, Some(15));
        assert_eq!(l.accel_scale, Some(18));
        assert_eq!(l.baro_bias, Some(21));
        assert_eq!(l.attitude_ref, Some(22));
        assert_eq!(l.odometer_scale, Some(25));
        let names = l.names();
        assert_eq!(names.len(), l.n);
        assert!(names.iter().all(|n| !n.is_empty()));
        assert_eq!(names[18], "sa_x");
        assert_eq!(names[24], "psi_ref_z");
        assert_eq!(names[25], "odometer_scale");
        // Another order of the builders: the names follow the offsets.
        let l = Layout::core().with_odometer_scale().with_baro_bias();
        assert_eq!(l.names()[15..], ["odometer_scale", "baro_bias"]);
        let l = Layout::core().with_time_offset().with_lever_arm();
        assert_eq!((l.n, l.time_offset, l.lever_arm), (19, Some(15), Some(16)));
        assert_eq!(
            l.names()[15..],
            ["gnss_time_offset", "lever_x", "lever_y", "lever_z"]
        );
        let l = Layout::core().with_clock(2);
        assert_eq!((l.n, l.clock, l.clock_drift()), (18, Some(15), Some(17)));
        assert_eq!(
            l.names()[15..],
            ["clock_bias_0", "clock_bias_1", "clock_drift"]
        );
    }
}
