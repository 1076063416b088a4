//! The error-state vector: position, velocity and attitude errors, residual sensor
//! errors, and optional extras, at fixed offsets.

/// Offsets of the error states. The first fifteen are always present:
/// `δr` (0..3), `δv` (3..6), `ψ` (6..9), residual gyro bias (9..12) and accelerometer
/// bias (12..15); optional blocks follow in the order scale factors (gyro, then
/// accelerometer), barometer bias, reference attitude.
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

    /// Names of the states, for reports (`dr_x`, ..., `psi_z`, `bg_x`, ...).
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::with_capacity(self.n);
        let mut block = |prefix: &str| {
            for axis in ["x", "y", "z"] {
                names.push(format!("{prefix}_{axis}"));
            }
        };
        for p in ["dr", "dv", "psi", "bg", "ba"] {
            block(p);
        }
        if self.gyro_scale.is_some() {
            block("sg");
            block("sa");
        }
        if self.baro_bias.is_some() {
            names.push("baro_bias".into());
        }
        if self.attitude_ref.is_some() {
            for axis in ["x", "y", "z"] {
                names.push(format!("psi_ref_{axis}"));
            }
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
            .with_attitude_ref();
        assert_eq!(l.n, 25);
        assert_eq!(l.gyro_scale, Some(15));
        assert_eq!(l.accel_scale, Some(18));
        assert_eq!(l.baro_bias, Some(21));
        assert_eq!(l.attitude_ref, Some(22));
        assert_eq!(l.names().len(), l.n);
        assert_eq!(l.names()[24], "psi_ref_z");
    }
}
