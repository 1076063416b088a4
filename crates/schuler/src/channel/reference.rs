//! The external height that aids the vertical channel (33)-(38): a barometric altimeter
//! or GNSS height `h* = h + bias + noise`, with isolated outliers and dropouts (no data),
//! sampled once per integration step (the text's `r*` is `a + h*`).

use super::ChannelError;
use super::error::finite;
use super::ode::Grid;
use crate::imu::random::Noise as Draws;

/// One injected outlier: the sample nearest `t` \[s\] is offset by `size` \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outlier {
    /// Time \[s\].
    pub t: f64,
    /// Offset \[m\].
    pub size: f64,
}

/// A dropout: no reference samples in `[start, start + duration)` \[s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dropout {
    /// Start \[s\].
    pub start: f64,
    /// Length \[s\].
    pub duration: f64,
}

/// Errors of the reference height (SI) and the seed of its random parts.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReferenceConfig {
    /// White-noise standard deviation per sample \[m\].
    pub noise: f64,
    /// Constant bias \[m\].
    pub bias: f64,
    /// Outliers at given times.
    pub outliers: Vec<Outlier>,
    /// Probability that any one sample is an outlier (random sign, size `outlier_size`).
    pub outlier_probability: f64,
    /// Size of random outliers \[m\].
    pub outlier_size: f64,
    /// Dropouts.
    pub dropouts: Vec<Dropout>,
    /// Master seed: stream 0 draws the noise, stream 1 the random outliers.
    pub seed: u64,
}

impl ReferenceConfig {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), ChannelError> {
        finite("reference noise", self.noise)?;
        if self.noise < 0.0 {
            return Err(ChannelError::OutOfRange {
                name: "reference noise",
                value: self.noise,
                reason: "a standard deviation is >= 0".to_owned(),
            });
        }
        finite("reference bias", self.bias)?;
        finite("outlier size", self.outlier_size)?;
        if !(0.0..=1.0).contains(&self.outlier_probability) {
            return Err(ChannelError::OutOfRange {
                name: "outlier probability",
                value: self.outlier_probability,
                reason: "a probability is in [0, 1]".to_owned(),
            });
        }
        for o in &self.outliers {
            finite("outlier time", o.t)?;
            finite("outlier size", o.size)?;
        }
        for d in &self.dropouts {
            finite("dropout start", d.start)?;
            finite("dropout duration", d.duration)?;
            if d.duration < 0.0 {
                return Err(ChannelError::OutOfRange {
                    name: "dropout duration",
                    value: d.duration,
                    reason: "a duration is >= 0".to_owned(),
                });
            }
        }
        Ok(())
    }

    /// The reference heights `h*` \[m\] at every grid point of `grid` for a true height
    /// `height` \[m\]; `None` inside a dropout.
    pub fn generate(&self, height: f64, grid: &Grid) -> Result<Vec<Option<f64>>, ChannelError> {
        self.validate()?;
        let mut noise = Draws::new(self.seed, 0);
        let mut outliers = Draws::new(self.seed, 1);
        let mut out = Vec::with_capacity(grid.steps + 1);
        for k in 0..=grid.steps {
            let t = grid.time(k);
            // Draw for every sample, dropouts included, so that a dropout does not shift
            // the noise of later samples.
            let n = noise.normal() * self.noise;
            let u = outliers.uniform();
            let sign = if outliers.uniform() < 0.5 { -1.0 } else { 1.0 };
            if self
                .dropouts
                .iter()
                .any(|d| t >= d.start && t < d.start + d.duration)
            {
                out.push(None);
                continue;
            }
            let mut h = height + self.bias + n;
            if u < self.outlier_probability {
                h += sign * self.outlier_size;
            }
            out.push(Some(h));
        }
        for o in &self.outliers {
            let k = (o.t / grid.dt).round();
            if k >= 0.0
                && let Some(Some(h)) = out.get_mut(k as usize)
            {
                *h += o.size;
            }
        }
        Ok(out)
    }
}
