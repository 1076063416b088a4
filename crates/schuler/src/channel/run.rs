//! One single-channel scenario run three ways on one time grid: the nonlinear ideal and
//! perturbed computers ([`super::models`]), the linear error model (13)/(28) with the
//! same inputs, and, where the inputs are constant, the closed form (18)/(19).
//!
//! The linear model's coupling `g` is the vertical specific force `f_x1(0)` of (5):
//! the text's `g` for its non-rotating Earth at rest, and `g - (V + aω)²/a` with Earth
//! rate or speed, the term (11) drops (`aλ'² < 0.04 m/s²`). Keeping it makes the linear
//! model's Schuler frequency that of the nonlinear run. Its initial vertical is the typed
//! α0, or after leveling the linear leveling (24) `α0 = (Δf_z2 + f_x2(0)) / g`.
//! Both ODEs are stepped with RK4 ([`super::ode`]).

use super::ChannelError;
use super::closed::{ConstantErrors, response};
use super::error::{finite, positive};
use super::linear::{ErrorModel, ErrorState, sins_accel_error};
use super::measure::{SinusoidFit, fit_sinusoid, peak_abs};
use super::models::{Alignment, Nonlinear, SensorErrors, System, Truth};
use super::ode::{Grid, rk4_step};
use super::profile::{BodyAngleProfile, SpeedProfile};
use crate::earth::Sphere;
use nalgebra::Vector3;

/// A single-channel scenario: system, Earth, motion, errors, time grid.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelConfig {
    /// Platform INS or SINS.
    pub system: System,
    /// The sphere (radius, gravitation, rotation rate; [`Sphere::textbook`]).
    pub earth: Sphere,
    /// Speed along the equator.
    pub speed: SpeedProfile,
    /// Body angle D(t) (SINS only).
    pub body: BodyAngleProfile,
    /// Instrument errors.
    pub sensors: SensorErrors,
    /// Initial vertical: typed α0 or leveling.
    pub alignment: Alignment,
    /// Initial velocity error ΔV0 [m/s].
    pub init_vel_error: f64,
    /// Initial position error Δr0 \[m\].
    pub init_pos_error: f64,
    /// Run length \[s\].
    pub duration: f64,
    /// Integration step \[s\].
    pub dt: f64,
    /// Interval between recorded rows \[s\] (rounded to whole steps; at least one step).
    pub record_interval: f64,
}

impl ChannelConfig {
    /// The text's setting: non-rotating sphere a = 6371 km, g = 9.81 m/s², at rest, no
    /// errors, 4 h, dt = 1 s, a row every 10 s.
    pub fn textbook(system: System) -> Self {
        Self {
            system,
            earth: Sphere::textbook(false),
            speed: SpeedProfile::constant(0.0),
            body: BodyAngleProfile::fixed(0.0),
            sensors: SensorErrors::default(),
            alignment: Alignment::Tilt(0.0),
            init_vel_error: 0.0,
            init_pos_error: 0.0,
            duration: 4.0 * 3600.0,
            dt: 1.0,
            record_interval: 10.0,
        }
    }

    /// Largest step that resolves the run's fastest motion with RK4: a hundredth of the
    /// Schuler period, a tenth of every turn and speed change, 0.1 rad of rotation.
    pub fn max_step(&self) -> (f64, String) {
        let model = ErrorModel::new(self.earth.radius, self.earth.gravitation(self.earth.radius));
        let mut best = (
            model.schuler_period() / 100.0,
            "a hundredth of the Schuler period".to_owned(),
        );
        let mut consider = |dt: f64, why: String| {
            if dt < best.0 {
                best = (dt, why);
            }
        };
        for c in &self.speed.changes {
            consider(
                c.duration / 10.0,
                format!(
                    "the {} s speed change at {} s needs 10 steps",
                    c.duration, c.start
                ),
            );
        }
        if self.system == System::Sins {
            for c in &self.body.turns {
                consider(
                    c.duration / 10.0,
                    format!("the {} s turn at {} s needs 10 steps", c.duration, c.start),
                );
            }
            if self.body.rate != 0.0 {
                consider(
                    0.1 / self.body.rate.abs(),
                    "rotation must advance at most 0.1 rad per step".to_owned(),
                );
            }
        }
        best
    }

    /// End of the last turn (SINS) or speed change \[s\]; 0 if there is none.
    pub fn last_change_end(&self) -> f64 {
        let speed = self.speed.changes.iter().map(|c| c.start + c.duration);
        let turns = self
            .body
            .turns
            .iter()
            .filter(|_| self.system == System::Sins)
            .map(|c| c.start + c.duration);
        speed.chain(turns).fold(0.0, f64::max)
    }

    /// The vehicle stays on the sphere: the specific force `f_x1 = μ/a² − (V/a + ω)² a`
    /// (5) is positive at the start and after every speed change (the speed is
    /// monotone in between). An Earth turning at the Schuler frequency `sqrt(g/a)` or
    /// faster, or a speed at orbital velocity, flings it off: the linear model's
    /// `ω0 = sqrt(f/a)` (13) is then no longer real and the closed forms are NaN.
    fn held_down(&self) -> Result<(), ChannelError> {
        let truth = self.truth();
        let ends = self.speed.changes.iter().map(|c| c.start + c.duration);
        let Some(t) = std::iter::once(0.0).chain(ends).find(|&t| {
            let f = truth.specific_force(t).0;
            f.is_nan() || f <= 0.0
        }) else {
            return Ok(());
        };
        let (a, w) = (self.earth.radius, self.earth.rotation_rate);
        let schuler = (self.earth.mu / a.powi(3)).sqrt();
        let name = if w.abs() >= schuler {
            "earth rate"
        } else {
            "speed"
        };
        Err(ChannelError::OutOfRange {
            name,
            value: if name == "speed" {
                self.speed.speed(t)
            } else {
                w
            },
            reason: format!(
                "at t = {t} s gravity no longer holds the vehicle on the sphere: the Earth \
                 rate must stay below the Schuler frequency sqrt(g/a) = {schuler:e} rad/s and \
                 the inertial speed V + a w below the orbital speed sqrt(g a) = {:.0} m/s",
                (self.earth.mu / a).sqrt()
            ),
        })
    }

    /// Checks every input (finite, positive where needed, step fine enough).
    pub fn validate(&self) -> Result<(), ChannelError> {
        positive("radius", self.earth.radius)?;
        positive("gravitational parameter", self.earth.mu)?;
        finite("earth rate", self.earth.rotation_rate)?;
        self.speed.validate()?;
        self.held_down()?;
        self.body.validate()?;
        let s = &self.sensors;
        finite("accelerometer bias", s.accel_bias)?;
        finite("accelerometer bias p1", s.accel_bias_p1)?;
        finite("accelerometer bias p2", s.accel_bias_p2)?;
        finite("gyro drift", s.drift)?;
        finite("gyro scale-factor error", s.gyro_scale)?;
        if let Alignment::Tilt(a) = self.alignment {
            finite("initial tilt", a)?;
        }
        finite("initial velocity error", self.init_vel_error)?;
        finite("initial position error", self.init_pos_error)?;
        positive("duration", self.duration)?;
        positive("step dt", self.dt)?;
        positive("record interval", self.record_interval)?;
        super::ode::check_steps(self.duration, self.dt)?;
        let (max_dt, reason) = self.max_step();
        if self.dt > max_dt * (1.0 + 1e-12) {
            return Err(ChannelError::StepTooCoarse {
                dt: self.dt,
                max_dt,
                reason,
            });
        }
        Ok(())
    }

    /// The true motion of this scenario.
    pub fn truth(&self) -> Truth {
        Truth {
            earth: self.earth,
            speed: self.speed.clone(),
            body: self.body.clone(),
        }
    }

    /// The linear model (13) with `g = f_x1(0)` (5).
    pub fn linear_model(&self) -> ErrorModel {
        ErrorModel::new(self.earth.radius, self.truth().specific_force(0.0).0)
    }

    /// The linear model's forcing `(Δf, ν)` at `t`: (13) for the INS, (28) for the SINS
    /// (`Δf = -Δf_p1 sin D + Δf_p2 cos D`, `ν = -(ν_p3 + θ ω_p3)`).
    pub fn linear_forcing(&self, truth: &Truth, t: f64) -> (f64, f64) {
        let s = &self.sensors;
        match self.system {
            System::Ins => (s.accel_bias, s.drift + s.gyro_scale * truth.frame_rate(t)),
            System::Sins => (
                sins_accel_error(s.accel_bias_p1, s.accel_bias_p2, truth.body.angle(t)),
                -(s.drift + s.gyro_scale * truth.gyro_rate(t)),
            ),
        }
    }

    /// Initial vertical error of the linear model: typed α0, or leveling (24).
    pub fn linear_initial_vertical(&self) -> f64 {
        match self.alignment {
            Alignment::Tilt(a) => a,
            Alignment::Level => {
                let truth = self.truth();
                let (f1, f2) = truth.specific_force(0.0);
                (self.linear_forcing(&truth, 0.0).0 + f2) / f1
            }
        }
    }

    /// The constant inputs of (18)/(19) if the forcing is constant over the run.
    pub fn constant_errors(&self) -> Option<ConstantErrors> {
        let s = &self.sensors;
        let speed_const = self.speed.is_constant();
        let constant = match self.system {
            System::Ins => s.gyro_scale == 0.0 || speed_const,
            System::Sins => self.body.is_constant() && (s.gyro_scale == 0.0 || speed_const),
        };
        if !constant {
            return None;
        }
        let (accel_bias, drift) = self.linear_forcing(&self.truth(), 0.0);
        Some(ConstantErrors {
            accel_bias,
            drift,
            alpha0: self.linear_initial_vertical(),
            dv0: self.init_vel_error,
            dr0: self.init_pos_error,
        })
    }
}

/// One recorded row of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelRow {
    /// Time \[s\].
    pub t: f64,
    /// Nonlinear run: perturbed minus ideal (9)/(26).
    pub nonlinear: ErrorState,
    /// Kinematic error β = α - Δλ of the nonlinear run \[rad\] (8).
    pub beta: f64,
    /// Linear error model (13)/(28).
    pub linear: ErrorState,
    /// Closed form (18)/(19), when the inputs are constant.
    pub closed: Option<ErrorState>,
}

/// A finished run: recorded rows and statistics over every step.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelRun {
    /// Recorded rows (every `record_interval`, plus the last step).
    pub rows: Vec<ChannelRow>,
    /// The linear model used (its `g` is f_x1(0)).
    pub model: ErrorModel,
    /// Initial vertical error of the nonlinear perturbed computer \[rad\].
    pub alpha0_nonlinear: f64,
    /// Initial vertical error of the linear model and closed form \[rad\].
    pub alpha0_linear: f64,
    /// Inputs of the closed form, when it exists.
    pub constant_errors: Option<ConstantErrors>,
    /// Largest |nonlinear - linear| over every step, per component.
    pub max_nonlinear_minus_linear: ErrorState,
    /// Largest |linear - closed| over every step, per component (when the closed form exists).
    pub max_linear_minus_closed: Option<ErrorState>,
    /// Largest |nonlinear| over every step, per component.
    pub peak_nonlinear: ErrorState,
    /// Largest |linear| over every step, per component.
    pub peak_linear: ErrorState,
    /// Largest |closed| over every step, per component.
    pub peak_closed: Option<ErrorState>,
    /// End of the last turn or speed change \[s\] (0 if none): the inputs are constant after it.
    pub settled_from: f64,
}

/// Component-wise running maximum of absolute values.
fn max_abs(acc: &mut ErrorState, e: &ErrorState) {
    acc.dr = acc.dr.max(e.dr.abs());
    acc.dv = acc.dv.max(e.dv.abs());
    acc.alpha = acc.alpha.max(e.alpha.abs());
}

/// Runs a scenario: nonlinear, linear and closed form side by side on one grid.
pub fn simulate(cfg: &ChannelConfig) -> Result<ChannelRun, ChannelError> {
    cfg.validate()?;
    let truth = cfg.truth();
    let nl = Nonlinear {
        system: cfg.system,
        truth: truth.clone(),
        sensors: cfg.sensors,
    };
    let model = cfg.linear_model();
    let mut x = nl.initial_state(cfg.alignment, cfg.init_vel_error, cfg.init_pos_error)?;
    let alpha0_nonlinear = nl.initial_vertical(cfg.alignment)?;
    let alpha0_linear = cfg.linear_initial_vertical();
    let mut y: Vector3<f64> = ErrorState {
        dr: cfg.init_pos_error,
        dv: cfg.init_vel_error,
        alpha: alpha0_linear,
    }
    .to_state(model.radius);
    let constant_errors = cfg.constant_errors();

    let grid = Grid::new(cfg.duration, cfg.dt);
    let every = ((cfg.record_interval / cfg.dt).round() as usize).max(1);
    let mut rows = Vec::with_capacity(grid.steps / every + 2);
    let mut f_nl = |t: f64, s: &nalgebra::Vector6<f64>| nl.derivative(t, s);
    let mut f_lin = |t: f64, s: &Vector3<f64>| {
        let (accel, drift) = cfg.linear_forcing(&truth, t);
        model.derivative(s, accel, drift)
    };

    let mut max_nl_lin = ErrorState::default();
    let mut max_lin_closed = ErrorState::default();
    let mut peak_nl = ErrorState::default();
    let mut peak_lin = ErrorState::default();
    let mut peak_closed = ErrorState::default();
    for k in 0..=grid.steps {
        let t = grid.time(k);
        let e_nl = nl.errors(&x);
        let e_lin = ErrorState::from_state(&y, model.radius);
        let e_closed = constant_errors.map(|c| response(&model, &c, t));
        max_abs(&mut max_nl_lin, &e_nl.minus(&e_lin));
        max_abs(&mut peak_nl, &e_nl);
        max_abs(&mut peak_lin, &e_lin);
        if let Some(c) = &e_closed {
            max_abs(&mut max_lin_closed, &e_lin.minus(c));
            max_abs(&mut peak_closed, c);
        }
        if k % every == 0 || k == grid.steps {
            rows.push(ChannelRow {
                t,
                nonlinear: e_nl,
                beta: nl.kinematic_error(&x),
                linear: e_lin,
                closed: e_closed,
            });
        }
        if k < grid.steps {
            let h = grid.time(k + 1) - t;
            x = rk4_step(&mut f_nl, t, &x, h);
            y = rk4_step(&mut f_lin, t, &y, h);
        }
    }
    Ok(ChannelRun {
        rows,
        model,
        alpha0_nonlinear,
        alpha0_linear,
        constant_errors,
        max_nonlinear_minus_linear: max_nl_lin,
        max_linear_minus_closed: constant_errors.map(|_| max_lin_closed),
        peak_nonlinear: peak_nl,
        peak_linear: peak_lin,
        peak_closed: constant_errors.map(|_| peak_closed),
        settled_from: cfg.last_change_end(),
    })
}

impl ChannelRun {
    /// Rows used for measuring: those after the last turn or speed change when at least
    /// one Schuler period follows it (the inputs are constant there), else all rows.
    fn fit_rows(&self) -> &[ChannelRow] {
        let period = self.model.schuler_period();
        let end = self.rows.last().map_or(0.0, |r| r.t);
        if self.settled_from > 0.0 && end - self.settled_from >= period {
            let k = self.rows.partition_point(|r| r.t < self.settled_from);
            &self.rows[k..]
        } else {
            &self.rows
        }
    }

    /// Fit of `c0 + c1 t + A cos(wt + φ)` to one nonlinear component over [`Self::fit_rows`].
    fn fit(&self, pick: impl Fn(&ErrorState) -> f64) -> Option<SinusoidFit> {
        let w0 = self.model.schuler_frequency();
        let rows = self.fit_rows();
        let t: Vec<f64> = rows.iter().map(|r| r.t).collect();
        let x: Vec<f64> = rows.iter().map(|r| pick(&r.nonlinear)).collect();
        fit_sinusoid(&t, &x, w0 / 4.0, w0 * 4.0)
    }

    /// The Schuler oscillation measured from the nonlinear velocity error: a fit of
    /// `c0 + c1 t + A cos(wt + φ)` with w searched over [ω0/4, 4ω0] (see
    /// [`fit_sinusoid`]), over the rows after the last turn or speed change if a Schuler
    /// period follows it; `None` when ΔV does not oscillate (e.g. a position error only).
    pub fn measured_oscillation(&self) -> Option<SinusoidFit> {
        self.fit(|e| e.dv)
    }

    /// The trend of the nonlinear position error [m/s]: slope of the same fit applied to Δr
    /// (the `-gν/ω0² t = -aν t` term of (19)); `None` when Δr does not oscillate.
    pub fn measured_position_slope(&self) -> Option<f64> {
        self.fit(|e| e.dr).map(|f| f.slope)
    }

    /// Largest |nonlinear| over the recorded rows, per component.
    pub fn recorded_peak(&self) -> ErrorState {
        ErrorState {
            dr: peak_abs(self.rows.iter().map(|r| r.nonlinear.dr)),
            dv: peak_abs(self.rows.iter().map(|r| r.nonlinear.dv)),
            alpha: peak_abs(self.rows.iter().map(|r| r.nonlinear.alpha)),
        }
    }
}
