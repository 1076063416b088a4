//! The vertical channel: free inertial (30)-(32), unstable with e-fold time
//! `τ0 = 1/(√2 ω0)` ≈ 570 s, and aided by an external height through constant-gain
//! feedback (34), whose error dynamics (37) have the matrix
//! `A = [[k1, 1], [k2 + 2ω0², 0]]` and characteristic polynomial
//! `λ² - k1 λ - (k2 + 2ω0²) = 0` (the text prints `ω0²` in the last term: a typo; the
//! matrix it writes gives `2ω0²`). Stable iff `k1 < 0` and `k2 + 2ω0² < 0`; critical
//! damping `k1² + 4(k2 + 2ω0²) = 0` leaves one time constant `τ = 2/|k1|`.
//!
//! Truth: the vehicle holds height `h` (radius `r = a + h`) at rest over a non-rotating
//! sphere, so the accelerometer reads `f = μ/r² (+ bias)`. The computer integrates
//! `h̃' = Ṽ + k1 (h̃ - h*)`, `Ṽ' = f - g(h̃) + k2 (h̃ - h*)` with `g(h̃) = μ/(a + h̃)²`
//! computed from its own height, not from `h*`, so it can drop the feedback and predict
//! with (38) when the reference fails, and reconnect when valid data return.
//! Errors: `Δh = h̃ - h`, `ΔV_h = Ṽ`. Stepped with RK4, the reference held over a step.

use super::ChannelError;
use super::detector::{DetectorConfig, FaultDetector};
use super::error::{finite, positive};
use super::expm::expm;
use super::measure::settling_time;
use super::ode::{Grid, rk4_step};
use crate::earth::Sphere;
use nalgebra::{Complex, Matrix2, Vector2};

/// A vertical-channel scenario (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalConfig {
    /// The sphere (radius, gravitational parameter; rotation is ignored here).
    pub earth: Sphere,
    /// True height above the sphere \[m\] (constant).
    pub height: f64,
    /// Initial height error Δh0 \[m\].
    pub init_height_error: f64,
    /// Initial vertical-velocity error ΔV0 [m/s].
    pub init_vel_error: f64,
    /// Vertical accelerometer bias [m/s^2].
    pub accel_bias: f64,
    /// Run length \[s\].
    pub duration: f64,
    /// Integration step and reference sample interval \[s\].
    pub dt: f64,
}

impl VerticalConfig {
    /// The textbook sphere, height 0, no errors, 30 min at dt = 0.1 s.
    pub fn textbook() -> Self {
        Self {
            earth: Sphere::textbook(false),
            height: 0.0,
            init_height_error: 0.0,
            init_vel_error: 0.0,
            accel_bias: 0.0,
            duration: 1800.0,
            dt: 0.1,
        }
    }

    /// Checks every input.
    pub fn validate(&self) -> Result<(), ChannelError> {
        positive("radius", self.earth.radius)?;
        positive("gravitational parameter", self.earth.mu)?;
        finite("height", self.height)?;
        if self.earth.radius + self.height <= 0.0 {
            return Err(ChannelError::OutOfRange {
                name: "height",
                value: self.height,
                reason: "below the centre of the sphere".to_owned(),
            });
        }
        finite("initial height error", self.init_height_error)?;
        finite("initial vertical velocity error", self.init_vel_error)?;
        finite("vertical accelerometer bias", self.accel_bias)?;
        positive("duration", self.duration)?;
        positive("step dt", self.dt)?;
        super::ode::check_steps(self.duration, self.dt)?;
        // RK4 on the free channel needs dt well below τ0 ≈ 570 s; the loop's own time
        // constants are checked against dt in `Gains::check`.
        let max_dt = self.e_fold_time() / 20.0;
        if self.dt > max_dt {
            return Err(ChannelError::StepTooCoarse {
                dt: self.dt,
                max_dt,
                reason: "the free channel's e-fold time needs 20 steps".to_owned(),
            });
        }
        Ok(())
    }

    /// `ω0² = μ / r³` at the true radius [1/s²] (32).
    pub fn w0_sq(&self) -> f64 {
        let r = self.earth.radius + self.height;
        self.earth.mu / (r * r * r)
    }

    /// e-fold time of the free channel `1/(√2 ω0)` \[s\] (32).
    pub fn e_fold_time(&self) -> f64 {
        1.0 / (2.0 * self.w0_sq()).sqrt()
    }

    /// The run's time grid.
    pub fn grid(&self) -> Grid {
        Grid::new(self.duration, self.dt)
    }

    /// Gravitation at height `h` [m/s^2] (30).
    fn gravitation(&self, h: f64) -> f64 {
        self.earth.gravitation(self.earth.radius + h)
    }

    /// Right-hand side of (34) (or (38) when `reference` is `None`) for the state
    /// `[h̃, Ṽ]`.
    fn rhs(&self, gains: Option<(Gains, f64)>, x: &Vector2<f64>) -> Vector2<f64> {
        let f = self.gravitation(self.height) + self.accel_bias;
        let mut d = Vector2::new(x[1], f - self.gravitation(x[0]));
        if let Some((g, h_ref)) = gains {
            let e = x[0] - h_ref;
            d[0] += g.k1 * e;
            d[1] += g.k2 * e;
        }
        d
    }

    /// One RK4 step of (34) with the reference held, or of (38) without.
    fn step(&self, gains: Option<(Gains, f64)>, x: &Vector2<f64>, h: f64) -> Vector2<f64> {
        rk4_step(&mut |_t, s: &Vector2<f64>| self.rhs(gains, s), 0.0, x, h)
    }

    /// One RK4 step of the prediction (38) from `x = [h̃, Ṽ]` over `h` \[s\].
    pub fn predict(&self, x: &Vector2<f64>, h: f64) -> Vector2<f64> {
        self.step(None, x, h)
    }

    /// Initial computed state `[h + Δh0, ΔV0]`.
    fn initial(&self) -> Vector2<f64> {
        Vector2::new(self.height + self.init_height_error, self.init_vel_error)
    }
}

/// Feedback gains of (34): `k1` [1/s], `k2` [1/s²].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Gain on the height equation [1/s] (< 0).
    pub k1: f64,
    /// Gain on the velocity equation [1/s²] (k2 + 2ω0² < 0).
    pub k2: f64,
}

impl Gains {
    /// Critically damped gains for time constant `tau` \[s\]: double root `-1/τ` of
    /// `λ² - k1 λ - (k2 + 2ω0²)`, i.e. `k1 = -2/τ`, `k2 = -1/τ² - 2ω0²`.
    pub fn critical(tau: f64, w0_sq: f64) -> Result<Self, ChannelError> {
        positive("time constant", tau)?;
        Ok(Self {
            k1: -2.0 / tau,
            k2: -1.0 / (tau * tau) - 2.0 * w0_sq,
        })
    }

    /// The error-dynamics matrix (37) `[[k1, 1], [k2 + 2ω0², 0]]`.
    pub fn matrix(&self, w0_sq: f64) -> Matrix2<f64> {
        Matrix2::new(self.k1, 1.0, self.k2 + 2.0 * w0_sq, 0.0)
    }

    /// Roots of `λ² - k1 λ - (k2 + 2ω0²) = 0`: `(k1 ± sqrt(k1² + 4(k2 + 2ω0²)))/2` (37).
    pub fn eigenvalues(&self, w0_sq: f64) -> [Complex<f64>; 2] {
        let disc = self.k1 * self.k1 + 4.0 * (self.k2 + 2.0 * w0_sq);
        let half = 0.5 * self.k1;
        if disc >= 0.0 {
            let r = 0.5 * disc.sqrt();
            [Complex::new(half + r, 0.0), Complex::new(half - r, 0.0)]
        } else {
            let i = 0.5 * (-disc).sqrt();
            [Complex::new(half, i), Complex::new(half, -i)]
        }
    }

    /// Time constants `-1/Re λ` of the two eigenvalues \[s\] (the slower first).
    pub fn time_constants(&self, w0_sq: f64) -> [f64; 2] {
        let [a, b] = self.eigenvalues(w0_sq);
        let (ta, tb) = (-1.0 / a.re, -1.0 / b.re);
        if ta >= tb { [ta, tb] } else { [tb, ta] }
    }

    /// Steady state `(Δh, ΔV_h)` of (37) driven by a constant reference bias `ref_bias`
    /// \[m\] (in `h*`) and accelerometer bias `accel_bias` [m/s^2]: from
    /// `0 = ΔV + k1 (Δh - ref_bias)` and `0 = 2ω0² Δh + accel_bias + k2 (Δh - ref_bias)`,
    /// `Δh = (k2 ref_bias - accel_bias) / (k2 + 2ω0²)`, `ΔV = -k1 (Δh - ref_bias)`.
    pub fn steady_state(&self, w0_sq: f64, ref_bias: f64, accel_bias: f64) -> (f64, f64) {
        let dh = (self.k2 * ref_bias - accel_bias) / (self.k2 + 2.0 * w0_sq);
        (dh, -self.k1 * (dh - ref_bias))
    }

    /// Checks finiteness, asymptotic stability of (37), and that `dt` resolves the
    /// fastest eigenvalue (|λ| dt <= 0.5).
    pub fn check(&self, w0_sq: f64, dt: f64) -> Result<(), ChannelError> {
        finite("k1", self.k1)?;
        finite("k2", self.k2)?;
        if !(self.k1 < 0.0 && self.k2 + 2.0 * w0_sq < 0.0) {
            return Err(ChannelError::UnstableGains {
                k1: self.k1,
                k2: self.k2,
                two_w0_sq: 2.0 * w0_sq,
            });
        }
        let fastest = self
            .eigenvalues(w0_sq)
            .iter()
            .map(|l| l.norm())
            .fold(0.0, f64::max);
        if fastest * dt > 0.5 {
            return Err(ChannelError::StepTooCoarse {
                dt,
                max_dt: 0.5 / fastest,
                reason: format!("the loop's fastest eigenvalue is {fastest} 1/s"),
            });
        }
        Ok(())
    }
}

/// Solution of (37) from `(Δh0, ΔV0)` at `t`: `exp(A t) x0` [m, m/s].
pub fn closed_loop_response(
    gains: &Gains,
    w0_sq: f64,
    dh0: f64,
    dv0: f64,
    t: f64,
) -> Result<(f64, f64), ChannelError> {
    let x = expm(&(gains.matrix(w0_sq) * t))? * Vector2::new(dh0, dv0);
    Ok((x[0], x[1]))
}

/// Whether the feedback (34) was on at a sample, or the loop predicted with (38).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Feedback on the reference (34).
    Aided,
    /// Free integration (38): the free channel, a dropout, or a rejected sample.
    Predict,
}

impl Mode {
    /// `"aided"` or `"predict"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Aided => "aided",
            Mode::Predict => "predict",
        }
    }
}

/// One sample of a vertical run: errors at `t` and the mode chosen for the step after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalSample {
    /// Time \[s\].
    pub t: f64,
    /// Height error `h̃ - h` \[m\].
    pub dh: f64,
    /// Vertical-velocity error [m/s].
    pub dvh: f64,
    /// Mode for the step starting at `t`.
    pub mode: Mode,
}

/// Counts of what the fault detector did over a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DetectorCounts {
    /// Samples used.
    pub accepted: usize,
    /// Samples rejected by the gate.
    pub rejected: usize,
    /// Samples missing (dropouts).
    pub missing: usize,
    /// Reconnections after a run of consistent rejected samples.
    pub reacquired: usize,
}

impl DetectorCounts {
    /// Tallies one verdict.
    pub fn count(&mut self, v: super::detector::Verdict) {
        use super::detector::Verdict as V;
        match v {
            V::Accept => self.accepted += 1,
            V::Reacquire => {
                self.accepted += 1;
                self.reacquired += 1;
            }
            V::Reject => self.rejected += 1,
            V::Missing => self.missing += 1,
        }
    }
}

/// The free vertical channel (31): prediction (38) from the initial errors, every sample `Predict`.
pub fn simulate_free(cfg: &VerticalConfig) -> Result<Vec<VerticalSample>, ChannelError> {
    cfg.validate()?;
    let grid = cfg.grid();
    let mut x = cfg.initial();
    let mut out = Vec::with_capacity(grid.steps + 1);
    for k in 0..=grid.steps {
        let t = grid.time(k);
        out.push(VerticalSample {
            t,
            dh: x[0] - cfg.height,
            dvh: x[1],
            mode: Mode::Predict,
        });
        if k < grid.steps {
            x = cfg.step(None, &x, grid.time(k + 1) - t);
        }
    }
    Ok(out)
}

/// A constant-gain aided run.
#[derive(Debug, Clone, PartialEq)]
pub struct AidedRun {
    /// One sample per grid point.
    pub samples: Vec<VerticalSample>,
    /// What the detector did.
    pub counts: DetectorCounts,
}

/// The reference-aided loop (34) with the fault detector and prediction (38), on the
/// reference heights `reference` (one per grid point, `None` = no data).
pub fn simulate_aided(
    cfg: &VerticalConfig,
    gains: Gains,
    reference: &[Option<f64>],
    detector: DetectorConfig,
) -> Result<AidedRun, ChannelError> {
    cfg.validate()?;
    gains.check(cfg.w0_sq(), cfg.dt)?;
    let grid = cfg.grid();
    if reference.len() != grid.steps + 1 {
        return Err(ChannelError::ReferenceLength {
            expected: grid.steps + 1,
            got: reference.len(),
        });
    }
    let mut det = FaultDetector::new(detector);
    let mut counts = DetectorCounts::default();
    let mut x = cfg.initial();
    let mut out = Vec::with_capacity(grid.steps + 1);
    for (k, r) in reference.iter().enumerate() {
        let t = grid.time(k);
        let verdict = det.assess(r.map(|h| x[0] - h), detector.gate);
        counts.count(verdict);
        let aided = verdict.is_aided();
        out.push(VerticalSample {
            t,
            dh: x[0] - cfg.height,
            dvh: x[1],
            mode: if aided { Mode::Aided } else { Mode::Predict },
        });
        if k < grid.steps {
            let fb = match (aided, r) {
                (true, Some(h)) => Some((gains, *h)),
                _ => None,
            };
            x = cfg.step(fb, &x, grid.time(k + 1) - t);
        }
    }
    Ok(AidedRun {
        samples: out,
        counts,
    })
}

/// A stretch of prediction inside an aided run and how the loop recovered from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outage {
    /// First predicted sample \[s\].
    pub start: f64,
    /// First aided sample after it (reconnection) \[s\].
    pub end: f64,
    /// Error relative to the steady state at reconnection \[m\].
    pub error_at_reconnect: f64,
    /// Time from reconnection until the error stays within the band until the next
    /// outage or the end of the run \[s\]; `None` if it never does.
    pub reconverge_time: Option<f64>,
}

/// Finds the outages (runs of `Predict` samples) of an aided run and measures each
/// reconvergence to `target` (the steady-state height error, e.g. the reference bias)
/// within `max(fraction * |error at reconnection|, floor)`.
pub fn outages(samples: &[VerticalSample], target: f64, fraction: f64, floor: f64) -> Vec<Outage> {
    let t: Vec<f64> = samples.iter().map(|s| s.t).collect();
    let x: Vec<f64> = samples.iter().map(|s| s.dh).collect();
    let mut spans = Vec::new();
    let mut k = 0;
    while k < samples.len() {
        if samples[k].mode == Mode::Predict {
            let start = k;
            while k < samples.len() && samples[k].mode == Mode::Predict {
                k += 1;
            }
            spans.push((start, k));
        } else {
            k += 1;
        }
    }
    let mut out = Vec::new();
    for (i, &(start, end)) in spans.iter().enumerate() {
        if end >= samples.len() {
            continue; // the run ended in prediction: no reconnection to measure
        }
        let next = spans.get(i + 1).map_or(samples.len(), |s| s.0);
        let e0 = x[end] - target;
        let band = (fraction * e0.abs()).max(floor);
        out.push(Outage {
            start: t[start],
            end: t[end],
            error_at_reconnect: e0,
            reconverge_time: settling_time(&t, &x, target, band, end, next),
        });
    }
    out
}
