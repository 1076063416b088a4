//! The textbook's single-channel INS or SINS (`schuler channel`) run three ways: the
//! nonlinear ideal and perturbed systems (6)/(9) or (7)/(26), the linear error model
//! (13)/(28), and the closed form (18)-(23) where the inputs are constant.
//!
//! Writes `errors.csv` (`t,dr,dv,alpha,dr_linear,dv_linear,alpha_linear,dr_closed,
//! dv_closed,alpha_closed`, SI: s, m, m/s, rad; `_closed` empty without a closed form),
//! `summary.json` (inputs in SI, measured Schuler period, largest differences, peaks)
//! and the plots `dr.svg` (km), `dv.svg` (m/s), `alpha.svg` (arcsec), like the text's
//! figures 4-15. Every value with a unit goes through `schuler::units`.

use crate::options::{
    SphereArgs, acceleration, angle, angular_rate, in_domain, is_positive, length, opt_in_domain,
    ratio, time, velocity,
};
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use schuler::channel::ChannelError;
use schuler::channel::linear::ErrorState;
use schuler::channel::models::{Alignment, SensorErrors, System};
use schuler::channel::profile::{BodyAngleProfile, SpeedProfile};
use schuler::channel::run::{ChannelConfig, ChannelRun, simulate};
use schuler::domain::Domain;
use schuler::units::{ARCSEC, DEG};
use schuler_report::plot::{LineStyle, Plot, time_axis};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// `AT:ANGLE[:DURATION]`, e.g. `1h:180deg` or `1h:180deg:20s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnSpec {
    /// Start \[s\].
    pub at: f64,
    /// Angle \[rad\].
    pub angle: f64,
    /// Duration \[s\], if given.
    pub duration: Option<f64>,
}

fn turn_spec(s: &str) -> Result<TurnSpec, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if !(2..=3).contains(&parts.len()) {
        return Err(format!(
            "expected AT:ANGLE[:DURATION] (e.g. 1h:180deg), got {s:?}"
        ));
    }
    Ok(TurnSpec {
        at: time(parts[0]).map_err(|e| format!("AT: {e}"))?,
        angle: angle(parts[1]).map_err(|e| format!("ANGLE: {e}"))?,
        duration: parts
            .get(2)
            .map(|d| time(d).map_err(|e| format!("DURATION: {e}")))
            .transpose()?,
    })
}

/// A speed change `AT:DV:DURATION` along the track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelSpec {
    /// Start \[s\].
    pub at: f64,
    /// Speed change \[m/s\].
    pub delta_v: f64,
    /// Duration \[s\].
    pub duration: f64,
}

fn accel_spec(s: &str) -> Result<AccelSpec, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected AT:DV:DURATION (e.g. 10min:100m/s:50s), got {s:?}"
        ));
    }
    Ok(AccelSpec {
        at: time(parts[0]).map_err(|e| format!("AT: {e}"))?,
        delta_v: velocity(parts[1]).map_err(|e| format!("DV: {e}"))?,
        duration: time(parts[2]).map_err(|e| format!("DURATION: {e}"))?,
    })
}

/// Default turn rate when a `--turn` gives no duration: 30 deg/s on average (peak 60).
const DEFAULT_TURN_RATE: f64 = 30.0 * DEG;

/// The textbook's Earth rate, used by a bare `--earth-rate`.
const EARTH_RATE_TEXT: &str = "7.2921158553e-5rad/s";

/// The system modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SystemChoice {
    /// Platform (gimballed) INS, (6) and (9).
    Ins,
    /// Strapdown INS, (7) and (26).
    Sins,
}

/// Arguments of `schuler channel`. Values carry units (`1e-3m/s^2`, `0.01deg/h`,
/// `20arcsec`, `4h`); errors are set one at a time, as in the text's figures, or together.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Platform INS or strapdown SINS.
    #[arg(long, value_enum, default_value = "ins")]
    pub system: SystemChoice,
    /// INS: bias of the platform accelerometer (e.g. 1e-3m/s^2).
    #[arg(long, value_parser = acceleration, allow_hyphen_values = true, value_name = "ACCEL")]
    pub accel_bias: Option<f64>,
    /// SINS: bias of the accelerometer on the body vertical p1.
    #[arg(long, value_parser = acceleration, allow_hyphen_values = true, value_name = "ACCEL")]
    pub accel_bias_p1: Option<f64>,
    /// SINS: bias of the accelerometer on the body axis p2.
    #[arg(long, value_parser = acceleration, allow_hyphen_values = true, value_name = "ACCEL")]
    pub accel_bias_p2: Option<f64>,
    /// Gyro drift: platform drift (INS) or gyro bias on p3 (SINS), e.g. 0.01deg/h.
    #[arg(long, value_parser = angular_rate, allow_hyphen_values = true, value_name = "RATE")]
    pub gyro_drift: Option<f64>,
    /// Gyro scale-factor error (1e-5, 10ppm).
    #[arg(long, value_parser = ratio, allow_hyphen_values = true, value_name = "RATIO")]
    pub gyro_scale: Option<f64>,
    /// Initial vertical error alpha0 (e.g. 20arcsec).
    #[arg(long, value_parser = angle, allow_hyphen_values = true, value_name = "ANGLE", conflicts_with = "level")]
    pub init_tilt: Option<f64>,
    /// Initial velocity error (e.g. 1m/s).
    #[arg(long, value_parser = velocity, allow_hyphen_values = true, value_name = "SPEED")]
    pub init_vel_error: Option<f64>,
    /// Initial position error (e.g. 100m).
    #[arg(long, value_parser = length, allow_hyphen_values = true, value_name = "LENGTH")]
    pub init_pos_error: Option<f64>,
    /// Level at t = 0 with the biased sensors, so alpha0 comes out of the model (24).
    #[arg(long)]
    pub level: bool,
    /// Rotate the Earth: bare flag for 7.2921158553e-5 rad/s, or a rate.
    #[arg(long, value_parser = angular_rate, num_args = 0..=1, default_missing_value = EARTH_RATE_TEXT, value_name = "RATE")]
    pub earth_rate: Option<f64>,
    /// SINS: turn the body by ANGLE starting at AT, over DURATION (default |ANGLE| at
    /// 30 deg/s); repeatable, e.g. --turn 1h:180deg.
    #[arg(long, value_parser = turn_spec, allow_hyphen_values = true, value_name = "AT:ANGLE[:DURATION]")]
    pub turn: Vec<TurnSpec>,
    /// SINS: rotate the body continuously at RATE (e.g. 6deg/s = 1 rev/min).
    #[arg(long, value_parser = angular_rate, allow_hyphen_values = true, value_name = "RATE")]
    pub rotate: Option<f64>,
    /// Constant speed along the equator (e.g. 250m/s); default at rest.
    #[arg(long, value_parser = velocity, allow_hyphen_values = true, value_name = "SPEED")]
    pub speed: Option<f64>,
    /// Change speed by DV starting at AT over DURATION (smooth acceleration profile);
    /// repeatable, e.g. --accelerate 10min:100m/s:50s.
    #[arg(long, value_parser = accel_spec, allow_hyphen_values = true, value_name = "AT:DV:DURATION")]
    pub accelerate: Vec<AccelSpec>,
    /// Run length.
    #[arg(long, value_parser = time, allow_hyphen_values = true, default_value = "4h", value_name = "TIME")]
    pub duration: f64,
    /// Integration step (RK4); default 1 s, or the largest 1/n s that resolves the turns
    /// (10 steps each) and the rotation (0.1 rad per step).
    #[arg(long, value_parser = time, allow_hyphen_values = true, value_name = "TIME")]
    pub dt: Option<f64>,
    /// The textbook sphere.
    #[command(flatten)]
    pub sphere: SphereArgs,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// A position error [m] of the channel: within the Earth's quadrant.
const POSITION_ERROR: Domain = Domain {
    quantity: "position error",
    min: -1e7,
    max: 1e7,
    unit: "m",
    scale: 1.0,
    why: "at most the Earth's quadrant",
};

/// Every physical flag in its domain ([`schuler::domain`]): a drift of 1e20 rad/s or
/// an Earth turning at 1e9 deg/h has no channel to model.
fn check_domains(args: &Args) -> Result<()> {
    use schuler::domain as d;
    let flags: [(&str, &Domain, Option<f64>); 11] = [
        (
            "--accel-bias",
            &d::SPECIFIC_FORCE_COMPONENT,
            args.accel_bias,
        ),
        (
            "--accel-bias-p1",
            &d::SPECIFIC_FORCE_COMPONENT,
            args.accel_bias_p1,
        ),
        (
            "--accel-bias-p2",
            &d::SPECIFIC_FORCE_COMPONENT,
            args.accel_bias_p2,
        ),
        ("--gyro-drift", &d::ANGULAR_RATE_COMPONENT, args.gyro_drift),
        ("--gyro-scale", &d::SCALE_FACTOR, args.gyro_scale),
        ("--init-tilt", &d::PITCH, args.init_tilt),
        ("--init-vel-error", &d::SPEED, args.init_vel_error),
        ("--init-pos-error", &POSITION_ERROR, args.init_pos_error),
        ("--earth-rate", &d::ANGULAR_RATE_COMPONENT, args.earth_rate),
        ("--rotate", &d::ANGULAR_RATE_COMPONENT, args.rotate),
        ("--speed", &d::SPEED, args.speed),
    ];
    for (flag, domain, value) in flags {
        opt_in_domain(flag, domain, value)?;
    }
    for a in &args.accelerate {
        in_domain("--accelerate", &d::SPEED, a.delta_v)?;
    }
    Ok(())
}

/// Builds the library scenario from the flags, naming the flag on any inconsistency.
pub fn config(args: &Args) -> Result<ChannelConfig> {
    check_domains(args)?;
    let system = match args.system {
        SystemChoice::Ins => System::Ins,
        SystemChoice::Sins => System::Sins,
    };
    if system == System::Ins {
        for (set, flag) in [
            (args.accel_bias_p1.is_some(), "--accel-bias-p1"),
            (args.accel_bias_p2.is_some(), "--accel-bias-p2"),
            (!args.turn.is_empty(), "--turn"),
            (args.rotate.is_some(), "--rotate"),
        ] {
            if set {
                bail!(
                    "{flag} applies to --system sins: the platform INS keeps its accelerometer on a level platform, whatever the body does (6)"
                );
            }
        }
    } else if args.accel_bias.is_some() {
        bail!(
            "--accel-bias is the platform accelerometer's bias (--system ins); for --system sins give --accel-bias-p1 and/or --accel-bias-p2"
        );
    }
    let earth = args.sphere.sphere(args.earth_rate.unwrap_or(0.0))?;
    let mut body = BodyAngleProfile::fixed(0.0).with_rate(args.rotate.unwrap_or(0.0));
    for t in &args.turn {
        let duration = t
            .duration
            .unwrap_or_else(|| (t.angle.abs() / DEFAULT_TURN_RATE).max(1.0));
        if !is_positive(duration) {
            bail!("--turn: the duration must be positive, got {duration} s");
        }
        body = body.with_turn(t.at, duration, t.angle);
    }
    let mut speed = SpeedProfile::constant(args.speed.unwrap_or(0.0));
    for a in &args.accelerate {
        if !is_positive(a.duration) {
            bail!(
                "--accelerate: the duration must be positive, got {} s",
                a.duration
            );
        }
        speed = speed.with_change(a.at, a.duration, a.delta_v);
    }
    let mut cfg = ChannelConfig {
        system,
        earth,
        speed,
        body,
        sensors: SensorErrors {
            accel_bias: args.accel_bias.unwrap_or(0.0),
            accel_bias_p1: args.accel_bias_p1.unwrap_or(0.0),
            accel_bias_p2: args.accel_bias_p2.unwrap_or(0.0),
            drift: args.gyro_drift.unwrap_or(0.0),
            gyro_scale: args.gyro_scale.unwrap_or(0.0),
        },
        alignment: if args.level {
            Alignment::Level
        } else {
            Alignment::Tilt(args.init_tilt.unwrap_or(0.0))
        },
        init_vel_error: args.init_vel_error.unwrap_or(0.0),
        init_pos_error: args.init_pos_error.unwrap_or(0.0),
        duration: args.duration,
        dt: 1.0,
        record_interval: 1.0,
    };
    let (max_dt, _) = cfg.max_step();
    cfg.dt = match args.dt {
        Some(dt) if !is_positive(dt) => bail!("--dt must be positive, got {dt} s"),
        Some(dt) => dt,
        // The largest step that divides 1 s and resolves the motion, so rows fall on
        // whole seconds.
        None => 1.0 / (1.0 / max_dt.min(1.0)).ceil(),
    };
    cfg.record_interval = cfg.dt.max(1.0);
    Ok(cfg)
}

/// Adds the flag that a library error is about.
pub fn explain(e: ChannelError) -> anyhow::Error {
    let flag = match &e {
        ChannelError::StepTooCoarse { .. } => Some("--dt"),
        ChannelError::CannotLevel { .. } => Some("--level"),
        ChannelError::NonFinite { name, .. }
        | ChannelError::NotPositive { name, .. }
        | ChannelError::OutOfRange { name, .. } => match *name {
            "step dt" => Some("--dt"),
            "duration" => Some("--duration"),
            "radius" => Some("--radius"),
            "gravitational parameter" => Some("--g"),
            "earth rate" => Some("--earth-rate"),
            "speed" => Some("--speed"),
            _ => None,
        },
        _ => None,
    };
    match flag {
        Some(f) => anyhow::anyhow!("{f}: {e}"),
        None => anyhow::anyhow!("invalid scenario: {e}"),
    }
}

/// Runs `args`'s channel and writes `errors.csv`, `summary.json` and the plots into
/// `args.out` (created if needed); returns the configuration, the run and the summary.
pub fn run_and_write(args: &Args) -> Result<(ChannelConfig, ChannelRun, Value)> {
    let cfg = config(args)?;
    let result = simulate(&cfg).map_err(explain)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating --out directory {}", args.out.display()))?;
    write_errors_csv(&args.out.join("errors.csv"), &result)?;
    let summary = summary(&cfg, &result);
    let text = serde_json::to_string_pretty(&summary).context("encoding summary.json")?;
    schuler_io::line_file::write_whole(&args.out.join("summary.json"), text + "\n")?;
    write_plots(&args.out, &cfg, &result)?;
    Ok((cfg, result, summary))
}

/// Writes `errors.csv`.
fn write_errors_csv(path: &Path, run: &ChannelRun) -> Result<()> {
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    let mut line = String::with_capacity(256);
    writeln!(
        w,
        "t,dr,dv,alpha,dr_linear,dv_linear,alpha_linear,dr_closed,dv_closed,alpha_closed"
    )?;
    for r in &run.rows {
        line.clear();
        let _ = write!(
            line,
            "{},{:e},{:e},{:e},{:e},{:e},{:e}",
            r.t,
            r.nonlinear.dr,
            r.nonlinear.dv,
            r.nonlinear.alpha,
            r.linear.dr,
            r.linear.dv,
            r.linear.alpha
        );
        match r.closed {
            Some(c) => {
                let _ = write!(line, ",{:e},{:e},{:e}", c.dr, c.dv, c.alpha);
            }
            None => line.push_str(",,,"),
        }
        writeln!(w, "{line}")?;
    }
    w.finish()
}

fn triple(e: &ErrorState) -> Value {
    json!({ "dr_m": e.dr, "dv_m_s": e.dv, "alpha_rad": e.alpha })
}

fn ratio_of(a: &ErrorState, b: &ErrorState) -> Value {
    let r = |x: f64, y: f64| if y > 0.0 { json!(x / y) } else { Value::Null };
    json!({ "dr": r(a.dr, b.dr), "dv": r(a.dv, b.dv), "alpha": r(a.alpha, b.alpha) })
}

/// The summary: inputs in SI, the measured Schuler period and trend, differences, peaks.
pub fn summary(cfg: &ChannelConfig, run: &ChannelRun) -> Value {
    let g = cfg.earth.gravitation(cfg.earth.radius);
    let theory = std::f64::consts::TAU * (cfg.earth.radius / g).sqrt();
    let fit = run.measured_oscillation();
    let measured = fit.map(|f| f.period);
    let slope_theory = run
        .constant_errors
        .map(|c| -run.model.g * c.drift / run.model.schuler_frequency().powi(2));
    json!({
        "command": "channel",
        "system": match cfg.system { System::Ins => "ins", System::Sins => "sins" },
        "inputs": {
            "radius_m": cfg.earth.radius,
            "g_m_s2": g,
            "earth_rate_rad_s": cfg.earth.rotation_rate,
            "accel_bias_m_s2": cfg.sensors.accel_bias,
            "accel_bias_p1_m_s2": cfg.sensors.accel_bias_p1,
            "accel_bias_p2_m_s2": cfg.sensors.accel_bias_p2,
            "gyro_drift_rad_s": cfg.sensors.drift,
            "gyro_scale": cfg.sensors.gyro_scale,
            "init_tilt_rad": match cfg.alignment { Alignment::Tilt(a) => json!(a), Alignment::Level => Value::Null },
            "level": matches!(cfg.alignment, Alignment::Level),
            "init_vel_error_m_s": cfg.init_vel_error,
            "init_pos_error_m": cfg.init_pos_error,
            "speed_m_s": cfg.speed.initial,
            "rotate_rad_s": cfg.body.rate,
            "turns": cfg.body.turns.iter().map(|t| json!({"at_s": t.start, "angle_rad": t.angle, "duration_s": t.duration})).collect::<Vec<_>>(),
            "duration_s": cfg.duration,
            "dt_s": cfg.dt,
        },
        "alpha0_rad": { "nonlinear": run.alpha0_nonlinear, "linear": run.alpha0_linear },
        "linear_model_g_m_s2": run.model.g,
        "schuler_period_s": {
            "theory": theory,
            "theory_linear_model": run.model.schuler_period(),
            "measured": measured,
            "relative_error": measured.map(|m| m / theory - 1.0),
        },
        "position_slope_m_s": {
            "measured": run.measured_position_slope(),
            "theory": slope_theory,
        },
        "closed_form": run.constant_errors.map(|_| "(18)-(19)"),
        "max_abs_diff": {
            "nonlinear_minus_linear": triple(&run.max_nonlinear_minus_linear),
            "linear_minus_closed": run.max_linear_minus_closed.as_ref().map(triple),
        },
        "relative_to_peak": {
            "nonlinear_minus_linear": ratio_of(&run.max_nonlinear_minus_linear, &run.peak_linear),
            "linear_minus_closed": run.max_linear_minus_closed.as_ref().zip(run.peak_closed.as_ref()).map(|(d, p)| ratio_of(d, p)),
        },
        "peak": {
            "nonlinear": triple(&run.peak_nonlinear),
            "linear": triple(&run.peak_linear),
            "closed": run.peak_closed.as_ref().map(triple),
        },
        "files": ["errors.csv", "summary.json", "dr.svg", "dv.svg", "alpha.svg"],
    })
}

/// Writes `dr.svg`, `dv.svg`, `alpha.svg`.
fn write_plots(dir: &Path, cfg: &ChannelConfig, run: &ChannelRun) -> Result<()> {
    let (tscale, tlabel) = time_axis(cfg.duration);
    let t: Vec<f64> = run.rows.iter().map(|r| r.t / tscale).collect();
    let sys = match cfg.system {
        System::Ins => "INS",
        System::Sins => "SINS",
    };
    type Pick = fn(&ErrorState) -> f64;
    let panels: [(&str, &str, &str, f64, Pick); 3] = [
        ("dr.svg", "Position error", "dr [km]", 1e3, |e| e.dr),
        ("dv.svg", "Velocity error", "dV [m/s]", 1.0, |e| e.dv),
        (
            "alpha.svg",
            "Vertical error",
            "alpha [arcsec]",
            ARCSEC,
            |e| e.alpha,
        ),
    ];
    for (file, title, ylabel, unit, pick) in panels {
        let nl: Vec<f64> = run.rows.iter().map(|r| pick(&r.nonlinear) / unit).collect();
        let lin: Vec<f64> = run.rows.iter().map(|r| pick(&r.linear) / unit).collect();
        let mut plot = Plot::new(&format!("Single-channel {sys}: {title}"), tlabel, ylabel)
            .line("nonlinear (9)/(26)", &t, &nl, LineStyle::Solid)
            .line("linear (13)/(28)", &t, &lin, LineStyle::Dashed);
        if run.constant_errors.is_some() {
            let closed: Vec<Option<f64>> = run
                .rows
                .iter()
                .map(|r| r.closed.map(|c| pick(&c) / unit))
                .collect();
            plot = plot.line_opt("closed form (18)-(19)", &t, &closed, LineStyle::Dotted);
        }
        plot.write(&dir.join(file))?;
    }
    Ok(())
}
