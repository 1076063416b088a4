//! Errors of the single-channel models: every input is checked before a run starts.

/// Why a single-channel or vertical-channel run cannot start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ChannelError {
    /// A parameter is NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NonFinite {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter that must be positive is not.
    #[error("{name} must be positive, got {value}")]
    NotPositive {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter is outside its valid range.
    #[error("{name} = {value} is out of range: {reason}")]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Why.
        reason: String,
    },
    /// The integration step is too coarse for the fastest motion of the run.
    #[error("step dt = {dt} s is too coarse: {reason}; use dt <= {max_dt} s")]
    StepTooCoarse {
        /// The step \[s\].
        dt: f64,
        /// The largest acceptable step \[s\].
        max_dt: f64,
        /// Which motion limits it.
        reason: String,
    },
    /// Leveling is impossible: the accelerometer cannot read zero at any tilt.
    #[error(
        "cannot level: accelerometer bias {bias} m/s^2 exceeds the specific force {force} m/s^2"
    )]
    CannotLevel {
        /// The bias [m/s^2].
        bias: f64,
        /// The specific force magnitude [m/s^2].
        force: f64,
    },
    /// The feedback gains of (34) do not make (37) asymptotically stable.
    #[error(
        "gains k1 = {k1} 1/s, k2 = {k2} 1/s^2 are not stabilizing: (37) needs k1 < 0 and k2 + 2 w0^2 < 0 (2 w0^2 = {two_w0_sq} 1/s^2)"
    )]
    UnstableGains {
        /// Gain k1 [1/s].
        k1: f64,
        /// Gain k2 [1/s^2].
        k2: f64,
        /// 2 ω0² [1/s²].
        two_w0_sq: f64,
    },
    /// The reference-height series does not match the run's time grid.
    #[error("reference has {got} samples, the run needs {expected}")]
    ReferenceLength {
        /// Samples the run needs.
        expected: usize,
        /// Samples given.
        got: usize,
    },
    /// A matrix exponential could not be formed (singular Padé denominator).
    #[error("matrix exponential failed: {0}")]
    Expm(String),
}

/// Checks that `value` is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, ChannelError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ChannelError::NonFinite { name, value })
    }
}

/// Checks that `value` is finite and > 0.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, ChannelError> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(ChannelError::NotPositive { name, value })
    }
}
