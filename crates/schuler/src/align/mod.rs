//! Initial alignment on a base at rest (seed 003: coarse 0–190 s, fine 190–860 s).
//!
//! 1. [`prefilter`]: spikes are rejected robustly and counted; the motion detector
//!    compares the data's scatter with the sensor noise and says when the base moves
//!    or vibrates.
//! 2. [`coarse`]: leveling and analytic gyrocompassing from the means over the coarse
//!    stage (averaging is the vibration filter: a line of frequency `f` leaves at most
//!    `A/(π f T)` in a mean over `T`), or leveling with an external heading. Before
//!    anything else, the heading accuracy this IMU can reach at this latitude is
//!    predicted, and gyrocompassing is refused past a limit.
//! 3. [`fine`]: the Kalman filter on the invariants, started from the coarse result
//!    with a prior that carries the coarse errors' correlation with the sensor biases.
//!
//! [`rest`] runs the same motion detector on a stream to find rests for
//! zero-velocity updates during navigation.

pub mod coarse;
pub mod fine;
pub mod in_motion;
pub mod prefilter;
pub mod rest;

pub use coarse::{CoarseAlignment, HeadingSource};
pub use fine::{Convergence, FineAlignment, FineConfig};
pub use prefilter::{MotionReport, Spike};
pub use rest::{Gravity, RestDetector, RestVerdict};

use crate::earth::{EarthModel, Geodetic};
use crate::filter::kalman::duplicate_states;
use crate::filter::{ImuNoise, Layout};
use crate::imu::ImuSample;
use crate::nav::NavState;
use crate::rotation::Euler;
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::fmt;

/// Alignment settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignConfig {
    /// Coarse stage length [s].
    pub coarse: f64,
    /// Fine stage length [s] (0: coarse only).
    pub fine: f64,
    /// Averaging block [s]: the spike test's window, the motion detector's block and
    /// the fine filter's measurement window.
    pub block: f64,
    /// Spike threshold in robust standard deviations.
    pub spike_sigmas: f64,
    /// Refuse gyrocompassing when the predicted heading standard deviation exceeds
    /// this [rad].
    pub max_heading_std: f64,
    /// Gyrocompassing or an external heading.
    pub heading: HeadingSource,
    /// How still the base is (fine-stage measurement noise; raised automatically
    /// when the motion detector sees more).
    pub stillness: FineConfig,
}

impl Default for AlignConfig {
    fn default() -> Self {
        Self {
            coarse: 190.0,
            fine: 670.0,
            block: 1.0,
            spike_sigmas: 8.0,
            max_heading_std: 1f64.to_radians(),
            heading: HeadingSource::Gyrocompass,
            stillness: FineConfig {
                window: 1.0,
                position_std: 0.01,
                velocity_std: 1e-3,
                attitude_std: 1e-6,
            },
        }
    }
}

/// Why an alignment could not be done.
#[derive(Debug, Clone, PartialEq)]
pub enum AlignError {
    /// The log is shorter than the stages.
    NotEnoughData {
        /// Seconds available.
        have: f64,
        /// Seconds needed.
        need: f64,
    },
    /// Gyrocompassing cannot find north here with this IMU.
    HeadingUnobservable {
        /// Latitude [rad].
        lat: f64,
        /// Predicted heading standard deviation [rad] (infinite at a pole).
        predicted: f64,
        /// The configured limit [rad].
        limit: f64,
        /// Horizontal Earth rate `Ω cos φ` [rad/s].
        horizontal_earth_rate: f64,
    },
    /// The specific force is zero (not a base at rest).
    NoGravity,
    /// The fine stage's estimate of the attitude it started from contradicts the
    /// coarse stage that gave it ([`coarse_consistency`]): the data do not behave as
    /// a base at rest with this IMU's noise.
    Inconsistent {
        /// The chi-square statistic.
        chi2: f64,
        /// Its degrees of freedom.
        dof: usize,
        /// The threshold it exceeds.
        threshold: f64,
        /// The fine stage's correction of the coarse heading [rad].
        heading_change: f64,
        /// What the motion detector saw (angular motion, vibration).
        moving: bool,
    },
}

impl fmt::Display for AlignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AlignError::NotEnoughData { have, need } => write!(
                f,
                "the IMU log covers {have:.1} s but the alignment stages need {need:.1} s"
            ),
            AlignError::HeadingUnobservable {
                lat,
                predicted,
                limit,
                horizontal_earth_rate,
            } => write!(
                f,
                "gyrocompassing cannot find north at latitude {:.3} deg: the horizontal Earth \
                 rate is only {:.4} deg/h, so this IMU's heading would be good to {} (1 sigma), \
                 worse than the limit {:.3} deg. Instead: align in motion with GNSS (schuler nav \
                 with GNSS aiding), or give an external heading (--heading DEG[,STD]); or raise \
                 the limit (--max-heading-std) if that accuracy will do",
                lat.to_degrees(),
                horizontal_earth_rate.to_degrees() * 3600.0,
                if predicted.is_finite() {
                    format!("{:.3} deg", predicted.to_degrees())
                } else {
                    "nothing (north is undefined at a pole)".to_string()
                },
                limit.to_degrees()
            ),
            AlignError::NoGravity => {
                write!(f, "the mean specific force is zero: not a base at rest")
            }
            AlignError::Inconsistent {
                chi2,
                dof,
                threshold,
                heading_change,
                moving,
            } => {
                if chi2.is_finite() && heading_change.is_finite() {
                    write!(
                        f,
                        "the fine stage moved the coarse attitude by {:.3} deg of heading, \
                         {:.1} standard deviations (chi-square {chi2:.1} on {dof} degrees of \
                         freedom, threshold {threshold:.1})",
                        heading_change.to_degrees(),
                        chi2.sqrt()
                    )?;
                } else {
                    write!(f, "the fine stage's filter left the finite numbers")?;
                }
                write!(
                    f,
                    ": its own stages contradict each other, so no heading is given. {}",
                    if *moving {
                        "The base moved (motion detected): align at rest, or in motion with GNSS"
                    } else {
                        "The log does not behave as a base at rest with this noise model: \
                     columns swapped or units wrong (--imu-columns, --gyro-unit), or the \
                     noise model far too optimistic (--imu-grade)"
                    }
                )
            }
        }
    }
}

impl std::error::Error for AlignError {}

/// The alignment and everything it found on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Alignment {
    /// The aligned state at the end of alignment (the base's position, zero velocity).
    pub state: NavState,
    /// Standard deviations of roll, pitch, yaw [rad].
    pub attitude_std: Vector3<f64>,
    /// Estimated gyro biases [rad/s] (zero after a coarse-only alignment).
    pub gyro_bias: Vector3<f64>,
    /// Their standard deviations [rad/s].
    pub gyro_bias_std: Vector3<f64>,
    /// Estimated accelerometer biases [m/s^2].
    pub accel_bias: Vector3<f64>,
    /// Their standard deviations [m/s^2].
    pub accel_bias_std: Vector3<f64>,
    /// The coarse stage.
    pub coarse: CoarseAlignment,
    /// Coarse attitude standard deviations, roll, pitch, yaw [rad].
    pub coarse_std: Vector3<f64>,
    /// Predicted one-sigma limits after both stages `[level N, level E, heading]` [rad].
    pub predicted_limit: Vector3<f64>,
    /// The fine stage, if run.
    pub fine: Option<FineAlignment>,
    /// Spikes replaced.
    pub spikes: Vec<Spike>,
    /// What the motion detector saw.
    pub motion: MotionReport,
    /// Per state of the fine filter: name, posterior/prior standard deviation (a
    /// state the data did not reduce below half its prior is not observable at rest).
    pub observability: Vec<(String, f64)>,
    /// Start of the data used [s].
    pub t_start: f64,
    /// End of the coarse stage [s].
    pub t_coarse: f64,
    /// End of alignment [s].
    pub t_end: f64,
    /// Run time of the pre-filter, the coarse and the fine stage [s] (wall clock).
    pub stage_seconds: [f64; 3],
}

/// Probability beyond which the fine stage's correction of the coarse attitude
/// refuses an alignment ([`coarse_consistency`]): `1 − 1e-6`, so that a consistent
/// filter on a base at rest is refused once in a million alignments, while a log that
/// is not at rest (hundreds of standard deviations) always is.
pub const CONSISTENCY_PROBABILITY: f64 = 1.0 - 1e-6;

/// The chi-square test of the fine stage against the coarse one: the fine filter
/// estimates the error of the attitude it started from (its reference-attitude
/// state, prior mean zero, prior covariance `P₀` the coarse stage's). For a
/// consistent linear filter the estimate `δ` and its error are uncorrelated, so
/// `cov δ = P₀ − P₁` (`P₁` the posterior) and `δᵀ (P₀ − P₁)⁺ δ` is chi-square with
/// the rank of `P₀ − P₁` degrees of freedom (Bar-Shalom, Li & Kirubarajan 2001,
/// §5.4: the same logic as the innovation test). Returns `(statistic, dof)`; a NaN
/// statistic when an input is not finite.
pub fn coarse_consistency(
    delta: &Vector3<f64>,
    prior: &Matrix3<f64>,
    posterior: &Matrix3<f64>,
) -> (f64, usize) {
    let inputs = delta.iter().chain(prior.iter()).chain(posterior.iter());
    if !inputs.into_iter().all(|x| x.is_finite()) {
        // A filter driven out of the numbers contradicts everything.
        return (f64::NAN, 3);
    }
    let d = (prior - posterior).symmetric_eigen();
    let largest = d.eigenvalues.max().max(0.0);
    let mut chi2 = 0.0;
    let mut dof = 0;
    for (i, &l) in d.eigenvalues.iter().enumerate() {
        // Directions the data did not inform (no variance drop) carry no test.
        if l > 1e-9 * largest && l > 0.0 {
            let x = d.eigenvectors.column(i).dot(delta);
            chi2 += x * x / l;
            dof += 1;
        }
    }
    (chi2, dof)
}

/// A state the filter reduced to less than this fraction of its prior counts as
/// observable.
pub const OBSERVABLE_RATIO: f64 = 0.5;

/// Prior covariance of the fine filter (layout [`Layout::core`] plus the reference
/// attitude) after the coarse stage: the coarse attitude errors with their
/// correlation with the biases, the base's stillness, and the bias walk over half the
/// coarse stage (the coarse means see the bias at its middle).
pub fn prior_covariance<E: EarthModel>(
    coarse: &CoarseAlignment,
    earth: &E,
    pos: &Geodetic,
    noise: &ImuNoise,
    stillness: &FineConfig,
) -> DMatrix<f64> {
    let layout = Layout::core().with_attitude_ref();
    let mut p = DMatrix::zeros(layout.n, layout.n);
    let (ppsi, ppsi_g, ppsi_a) = coarse.error_covariance(earth, pos, noise);
    let d = |v: &Vector3<f64>| Matrix3::from_diagonal(&v.component_mul(v));
    let half = 0.5 * coarse.duration;
    let pbg = d(&noise.gyro_bias) + d(&noise.gyro_bias_walk) * half;
    let pba = d(&noise.accel_bias) + d(&noise.accel_bias_walk) * half;
    let mut put = |r: usize, c: usize, m: &Matrix3<f64>| {
        p.fixed_view_mut::<3, 3>(r, c).copy_from(m);
        p.fixed_view_mut::<3, 3>(c, r).copy_from(&m.transpose());
    };
    put(
        Layout::POS,
        Layout::POS,
        &(Matrix3::identity() * stillness.position_std.powi(2)),
    );
    put(
        Layout::VEL,
        Layout::VEL,
        &(Matrix3::identity() * stillness.velocity_std.powi(2)),
    );
    put(Layout::ATT, Layout::ATT, &ppsi);
    put(Layout::ATT, Layout::GYRO_BIAS, &ppsi_g);
    put(Layout::ATT, Layout::ACCEL_BIAS, &ppsi_a);
    put(Layout::GYRO_BIAS, Layout::GYRO_BIAS, &pbg);
    put(Layout::ACCEL_BIAS, Layout::ACCEL_BIAS, &pba);
    duplicate_states(&mut p, Layout::ATT, layout.attitude_ref.unwrap_or(15), 3);
    p
}

fn mean_rates(samples: &[ImuSample]) -> (Vector3<f64>, Vector3<f64>, f64) {
    let t: f64 = samples.iter().map(|s| s.dt).sum();
    let w = samples.iter().map(|s| s.dtheta).sum::<Vector3<f64>>() / t;
    let f = samples.iter().map(|s| s.dvel).sum::<Vector3<f64>>() / t;
    (f, w, t)
}

/// Align on a base at rest at `pos` from the samples (their first sample starts the
/// coarse stage). The samples are not modified; spikes are replaced in a copy.
pub fn align<E: EarthModel>(
    earth: E,
    pos: Geodetic,
    samples: &[ImuSample],
    noise: &ImuNoise,
    cfg: &AlignConfig,
) -> Result<Alignment, AlignError> {
    let t_start = samples.first().map_or(0.0, |s| s.t - s.dt);
    let have = samples.last().map_or(0.0, |s| s.t) - t_start;
    let need = cfg.coarse + cfg.fine;
    // Half a sample's tolerance: a log of exactly `need` seconds is enough.
    let dt = samples.first().map_or(1.0, |s| s.dt);
    if samples.is_empty() || have < need - 0.5 * dt {
        return Err(AlignError::NotEnoughData { have, need });
    }
    let end = samples.partition_point(|s| s.t <= t_start + need + 0.5 * dt);
    let clock = std::time::Instant::now();
    let mut data = samples[..end].to_vec();
    let block = ((cfg.block / dt).round() as usize).max(1);
    let spikes = prefilter::reject_spikes(&mut data, block, cfg.spike_sigmas);
    let motion = prefilter::detect_motion(&data, block, &noise.arw, &noise.vrw);

    let t_pre = clock.elapsed().as_secs_f64();
    let split = data.partition_point(|s| s.t <= t_start + cfg.coarse + 0.5 * dt);
    let (f_b, w_b, t_c) = mean_rates(&data[..split]);
    if f_b.norm() == 0.0 {
        return Err(AlignError::NoGravity);
    }
    let horizontal_earth_rate = earth.rotation_rate() * pos.lat.cos();
    let refuse = |predicted: f64| AlignError::HeadingUnobservable {
        lat: pos.lat,
        predicted,
        limit: cfg.max_heading_std,
        horizontal_earth_rate,
    };
    let coarse = CoarseAlignment::from_means(&earth, &pos, f_b, w_b, t_c, cfg.heading)
        .ok_or_else(|| refuse(f64::INFINITY))?;
    // On a moving base the coarse means carry the motion's net angle and velocity
    // change over the stage, `Δθ/T` and `Δv/T` (std √2 × wander / T): counted as extra
    // white noise of the same mean variance, `N² += 2 wander² / T`.
    let mut coarse_noise = *noise;
    if motion.angular_motion || motion.vibration {
        let add = |n: &Vector3<f64>, w: &Vector3<f64>| {
            Vector3::from_fn(|i, _| (n[i] * n[i] + 2.0 * w[i] * w[i] / t_c).sqrt())
        };
        coarse_noise.arw = add(&noise.arw, &motion.attitude_wander);
        coarse_noise.vrw = add(&noise.vrw, &motion.velocity_wander);
    }
    // The limit after both stages: the coarse construction averaged over all the data.
    let limit = CoarseAlignment {
        duration: need,
        ..coarse
    };
    // The fine stage tracks the motion with the gyros: its limit is the sensors'.
    let predicted_limit = limit.predicted_std(&earth, &pos, noise);
    if cfg.heading == HeadingSource::Gyrocompass
        && (predicted_limit.z > cfg.max_heading_std || predicted_limit.z.is_nan())
    {
        return Err(refuse(predicted_limit.z));
    }
    let (ppsi, _, _) = coarse.error_covariance(&earth, &pos, &coarse_noise);
    let coarse_std = fine::euler_covariance(&coarse.q_bn, &ppsi)
        .diagonal()
        .map(|v| v.max(0.0).sqrt());

    let t_coarse = t_start + t_c;
    let t_coarse_run = clock.elapsed().as_secs_f64() - t_pre;
    let mut out = Alignment {
        state: NavState {
            t: t_coarse,
            pos,
            v_n: Vector3::zeros(),
            q_bn: coarse.q_bn,
        },
        attitude_std: coarse_std,
        gyro_bias: Vector3::zeros(),
        gyro_bias_std: noise.gyro_bias,
        accel_bias: Vector3::zeros(),
        accel_bias_std: noise.accel_bias,
        coarse,
        coarse_std,
        predicted_limit,
        fine: None,
        spikes,
        motion,
        observability: Vec::new(),
        t_start,
        t_coarse,
        t_end: t_coarse,
        stage_seconds: [t_pre, t_coarse_run, 0.0],
    };
    if cfg.fine <= 0.0 || split >= data.len() {
        return Ok(out);
    }
    // Raise the stillness noise to what the detector saw.
    let mut still = cfg.stillness;
    still.window = cfg.block;
    if motion.angular_motion {
        // The base turns: "attitude unchanged" no longer holds; leave it out (a
        // 1-rad standard deviation carries no information).
        still.attitude_std = 1.0;
    }
    if motion.angular_motion || motion.vibration {
        still.velocity_std = still.velocity_std.max(motion.velocity_wander.max());
    }
    let mut prior = prior_covariance(&coarse, &earth, &pos, &coarse_noise, &still);
    if motion.angular_motion {
        // The coarse attitude is the stage's mean; at its end the base is off it by
        // the wander.
        let w2 = motion.attitude_wander.norm_squared();
        for i in 0..3 {
            prior[(Layout::ATT + i, Layout::ATT + i)] += w2;
        }
        let r = Layout::core()
            .with_attitude_ref()
            .attitude_ref
            .unwrap_or(15);
        duplicate_states(&mut prior, Layout::ATT, r, 3);
    }
    let fine = fine::fine_align(
        earth,
        pos,
        &data[split..],
        coarse.q_bn,
        prior.clone(),
        noise,
        &still,
    );
    let p = &fine.covariance;
    let r_ref = Layout::core()
        .with_attitude_ref()
        .attitude_ref
        .unwrap_or(15);
    let delta =
        crate::rotation::rotation_vector_from_quaternion(&(fine.q_start * coarse.q_bn.inverse()));
    let (chi2, dof) = coarse_consistency(
        &delta,
        &prior.fixed_view::<3, 3>(r_ref, r_ref).into_owned(),
        &p.fixed_view::<3, 3>(r_ref, r_ref).into_owned(),
    );
    let threshold = crate::filter::kalman::chi_square_quantile(dof, CONSISTENCY_PROBABILITY);
    if chi2.is_nan() || chi2 > threshold {
        return Err(AlignError::Inconsistent {
            chi2,
            dof,
            threshold,
            heading_change: crate::rotation::wrap_pi(
                Euler::from_quaternion(&fine.q_start).yaw
                    - Euler::from_quaternion(&coarse.q_bn).yaw,
            ),
            moving: motion.angular_motion || motion.vibration,
        });
    }
    let p_psi = p.fixed_view::<3, 3>(Layout::ATT, Layout::ATT).into_owned();
    let std = |o: usize| crate::filter::kalman::std3(p, o);
    let names = Layout::core().with_attitude_ref().names();
    out.observability = names
        .into_iter()
        .enumerate()
        .take(15)
        .map(|(i, n)| {
            (
                n,
                p[(i, i)].max(0.0).sqrt() / fine.prior_std[i].max(f64::MIN_POSITIVE),
            )
        })
        .collect();
    out.state = NavState {
        t: fine.t_end,
        pos,
        v_n: Vector3::zeros(),
        q_bn: fine.q_bn,
    };
    out.attitude_std = fine::euler_covariance(&fine.q_bn, &p_psi)
        .diagonal()
        .map(|v| v.max(0.0).sqrt());
    out.gyro_bias = fine.gyro_bias;
    out.gyro_bias_std = std(Layout::GYRO_BIAS);
    out.accel_bias = fine.accel_bias;
    out.accel_bias_std = std(Layout::ACCEL_BIAS);
    out.t_end = fine.t_end;
    out.stage_seconds[2] = clock.elapsed().as_secs_f64() - t_pre - t_coarse_run;
    out.fine = Some(fine);
    Ok(out)
}
