//! What an IMU stream's data say of its units and axes: the mean specific force's
//! size (≈ g = 9.8 m/s² when the accelerometers are read in m/s²), the axis gravity
//! lies on while the vehicle stands still at the start, and whether the samples are
//! continuous increments (their integration intervals cover the time between them).

use schuler::imu::ImuSample;
use serde::Serialize;

/// The start window looked at for rest and gravity's axis [s].
pub const START_WINDOW_S: f64 = 1.0;
/// At rest: the specific force's size varies by less than this (std) [m/s²] (a
/// consumer MEMS accelerometer's noise at 100–1000 Hz is a few hundredths; a walking
/// or driving vehicle's accelerations tenths and more).
pub const REST_FORCE_STD: f64 = 0.2;
/// At rest: the mean angular rate's size is below this [rad/s] (3°/s: above the
/// turn-on biases of MEMS gyros, below any turn).
pub const REST_RATE: f64 = 0.05;
/// Standard gravity [m/s²] (the yardstick of the units' verdict).
const G: f64 = 9.806_65;

/// Running sums of one IMU stream.
#[derive(Debug, Clone, Default)]
pub struct ImuAcc {
    n: u64,
    force_sum: f64,
    dt_sum: f64,
    t_first: Option<f64>,
    t_last: f64,
    // The start window.
    w_n: u64,
    w_f: nalgebra::Vector3<f64>,
    w_w: nalgebra::Vector3<f64>,
    w_fmag: f64,
    w_fmag2: f64,
}

impl ImuAcc {
    /// Takes in a sample.
    pub fn add(&mut self, s: &ImuSample) {
        if s.dt <= 0.0 {
            return;
        }
        let f = s.dvel / s.dt;
        let w = s.dtheta / s.dt;
        let t0 = *self.t_first.get_or_insert(s.t);
        if self.n > 0 {
            self.dt_sum += s.dt;
        }
        self.n += 1;
        self.t_last = s.t;
        self.force_sum += f.norm();
        if s.t - t0 <= START_WINDOW_S {
            self.w_n += 1;
            self.w_f += f;
            self.w_w += w;
            self.w_fmag += f.norm();
            self.w_fmag2 += f.norm_squared();
        }
    }

    /// The summary.
    pub fn finish(self) -> ImuSummary {
        let n = self.n.max(1) as f64;
        let mean_force = self.force_sum / n;
        let wn = self.w_n.max(1) as f64;
        let f0 = self.w_f / wn;
        let w0 = self.w_w / wn;
        let fmag = self.w_fmag / wn;
        let fstd = (self.w_fmag2 / wn - fmag * fmag).max(0.0).sqrt();
        let at_rest = self.w_n >= 10 && fstd < REST_FORCE_STD && w0.norm() < REST_RATE;
        let span = self.t_last - self.t_first.unwrap_or(self.t_last);
        let coverage = (span > 0.0).then(|| self.dt_sum / span);
        ImuSummary {
            mean_specific_force: mean_force,
            units: units_verdict(mean_force),
            start_specific_force: [f0.x, f0.y, f0.z],
            start_rate: [w0.x, w0.y, w0.z],
            at_rest_at_start: at_rest,
            gravity_axis: at_rest.then(|| gravity_axis(&f0)),
            increment_coverage: coverage,
            continuous_increments: coverage.map(|c| (0.9..=1.1).contains(&c)),
        }
    }
}

/// What the data say of an IMU stream (in `inspect --json`: these keys).
#[derive(Debug, Clone, Serialize)]
pub struct ImuSummary {
    /// The mean size of the specific force over the stream [m/s²] (≈ 9.8 for a
    /// vehicle on the ground or flying level, whatever its axes).
    pub mean_specific_force: f64,
    /// The verdict on the accelerometers' units from that size.
    pub units: String,
    /// The mean specific force over the first second, body axes [m/s²].
    pub start_specific_force: [f64; 3],
    /// The mean angular rate over the first second [rad/s].
    pub start_rate: [f64; 3],
    /// Whether the vehicle stood still over the first second ([`REST_FORCE_STD`],
    /// [`REST_RATE`]).
    pub at_rest_at_start: bool,
    /// Gravity's direction in body axes while at rest (`+z`: along +z, the FRD
    /// convention's down when level), the opposite of the specific force.
    pub gravity_axis: Option<String>,
    /// Sum of the samples' integration intervals over their span: 1 for continuous
    /// increments at the stream's rate; far below 1 for decimated samples.
    pub increment_coverage: Option<f64>,
    /// Whether the coverage is within 10 % of 1.
    pub continuous_increments: Option<bool>,
}

/// The axis gravity lies on: the largest component of −f, with its sign, and its
/// angle from that axis.
fn gravity_axis(f: &nalgebra::Vector3<f64>) -> String {
    let g = -f;
    let k = g.iamax();
    let axis = ["x", "y", "z"][k];
    let sign = if g[k] >= 0.0 { "+" } else { "-" };
    let tilt = (g[k].abs() / g.norm()).clamp(-1.0, 1.0).acos().to_degrees();
    let frd = match (k, sign) {
        (2, "+") => " (down: FRD, level)",
        (2, "-") => " (up: the z axis points up, FLU or ENU-like)",
        _ => " (the IMU is mounted on its side, or the vehicle tilted)",
    };
    format!("{sign}{axis}{frd}, {tilt:.1} deg off the axis")
}

/// The accelerometers' units as the mean specific force's size suggests them.
fn units_verdict(f: f64) -> String {
    let r = f / G;
    if (0.8..=1.25).contains(&r) {
        "m/s^2 (mean specific force within 25 % of g)".to_owned()
    } else if (0.8..=1.25).contains(&f) {
        "g? (mean specific force near 1: the accelerations may be in g)".to_owned()
    } else {
        format!("unclear (mean specific force {f:.3} m/s^2 is not near g)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn a_level_frd_imu_at_rest() {
        let mut a = ImuAcc::default();
        for k in 1..=300 {
            let t = k as f64 * 0.01;
            a.add(&ImuSample::from_mean_rates(
                t,
                0.01,
                Vector3::new(1e-4, 0.0, 7e-5),
                Vector3::new(0.0, 0.0, -9.80),
            ));
        }
        let s = a.finish();
        assert!(s.at_rest_at_start);
        assert!(
            s.gravity_axis
                .as_deref()
                .is_some_and(|g| g.starts_with("+z")),
            "{:?}",
            s.gravity_axis
        );
        assert!((s.mean_specific_force - 9.80).abs() < 1e-9);
        assert!(s.units.starts_with("m/s^2"));
        assert_eq!(s.continuous_increments, Some(true));
    }

    #[test]
    fn decimated_samples_and_g_units() {
        // 4 ms integrated every 10 ms: coverage 0.4. Accelerations of 1 (g units).
        let mut a = ImuAcc::default();
        for k in 1..=300 {
            let t = k as f64 * 0.01;
            a.add(&ImuSample::from_mean_rates(
                t,
                0.004,
                Vector3::zeros(),
                Vector3::new(0.0, -1.0, 0.0),
            ));
        }
        let s = a.finish();
        assert!((s.increment_coverage.expect("span") - 0.4).abs() < 1e-9);
        assert_eq!(s.continuous_increments, Some(false));
        assert!(s.units.starts_with("g?"));
        assert!(
            s.gravity_axis
                .as_deref()
                .is_some_and(|g| g.starts_with("+y"))
        );
    }
}
