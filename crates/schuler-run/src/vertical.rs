//! The vertical channel (`schuler vertical`). `--mode free` integrates the free inertial
//! channel (30)-(32) from initial errors and measures its e-fold time; `--mode aided`
//! runs the reference-aided loop (34) with gains k1, k2 (or critically damped from a time
//! constant) on a simulated reference height with noise, bias, outliers and dropouts,
//! with the fault detector switching to prediction (38) and back, and a Kalman-filter
//! variant with time-varying gains on the same reference samples.
//!
//! Writes `vertical.csv` (`t,dh,dvh,mode`, SI, mode = aided or predict), in aided mode
//! also `vertical_kf.csv` (`t,dh,dvh,mode,k1,k2,sigma_h`) and `reference.csv`
//! (`t,dh_ref`: reference minus true height, empty in dropouts), `summary.json`
//! (eigenvalues, e-fold time, settling and reconvergence times, detector counts) and the
//! plots `dh.svg`, `dvh.svg`.

use crate::options::{SphereArgs, acceleration, is_positive, length, time, velocity};
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use schuler::channel::ChannelError;
use schuler::channel::closed::vertical_free_response;
use schuler::channel::detector::DetectorConfig;
use schuler::channel::kalman::{KalmanRun, KalmanTuning, simulate_kalman};
use schuler::channel::measure::{e_fold_time, peak_abs, settling_time};
use schuler::channel::reference::{Dropout, Outlier, ReferenceConfig};
use schuler::channel::vertical::{
    AidedRun, Gains, Mode, Outage, VerticalConfig, VerticalSample, closed_loop_response, outages,
    simulate_aided, simulate_free,
};
use schuler::units::{self, Dimension};
use schuler_report::plot::{LineStyle, Plot, time_axis};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Free inertial channel or reference-aided loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeChoice {
    /// Free inertial vertical channel (30)-(32).
    Free,
    /// Reference-aided loop (34) with fault detection and prediction (38).
    Aided,
}

/// `AT:SIZE`, e.g. `600s:200m`.
fn outlier_spec(s: &str) -> Result<Outlier, String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("expected AT:SIZE (e.g. 600s:200m), got {s:?}"))?;
    Ok(Outlier {
        t: time(a).map_err(|e| format!("AT: {e}"))?,
        size: length(b).map_err(|e| format!("SIZE: {e}"))?,
    })
}

/// `FROM:DURATION`, e.g. `1000s:300s`.
fn dropout_spec(s: &str) -> Result<Dropout, String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("expected FROM:DURATION (e.g. 1000s:300s), got {s:?}"))?;
    Ok(Dropout {
        start: time(a).map_err(|e| format!("FROM: {e}"))?,
        duration: time(b).map_err(|e| format!("DURATION: {e}"))?,
    })
}

fn probability(s: &str) -> Result<f64, String> {
    let p = units::parse_as_or_si(s, Dimension::Dimensionless).map_err(|e| e.to_string())?;
    if (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(format!("a probability is in [0, 1], got {p}"))
    }
}

fn noise_density(s: &str) -> Result<f64, String> {
    units::parse_as(s, Dimension::VelocityRandomWalk).map_err(|e| e.to_string())
}

/// Arguments of `schuler vertical`. Values carry units (`100m`, `0.1m/s`, `20s`); the
/// gains k1 [1/s] and k2 [1/s^2] are plain numbers.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Free inertial channel or reference-aided loop.
    #[arg(long, value_enum, default_value = "aided")]
    pub mode: ModeChoice,
    /// Initial height error.
    #[arg(long, value_parser = length, allow_hyphen_values = true, default_value = "0m", value_name = "LENGTH")]
    pub init_height_error: f64,
    /// Initial vertical-velocity error.
    #[arg(long, value_parser = velocity, allow_hyphen_values = true, default_value = "0m/s", value_name = "SPEED")]
    pub init_vel_error: f64,
    /// Vertical accelerometer bias.
    #[arg(long, value_parser = acceleration, allow_hyphen_values = true, default_value = "0m/s^2", value_name = "ACCEL")]
    pub accel_bias: f64,
    /// Feedback gain k1 of (34) [1/s] (negative); give with --k2.
    #[arg(
        long,
        allow_hyphen_values = true,
        requires = "k2",
        conflicts_with = "time_constant",
        value_name = "1/s"
    )]
    pub k1: Option<f64>,
    /// Feedback gain k2 of (34) [1/s^2] (k2 + 2 w0^2 negative); give with --k1.
    #[arg(
        long,
        allow_hyphen_values = true,
        requires = "k1",
        conflicts_with = "time_constant",
        value_name = "1/s^2"
    )]
    pub k2: Option<f64>,
    /// Time constant of a critically damped loop (default 20s when no gains are given).
    #[arg(long, value_parser = time, allow_hyphen_values = true, value_name = "TIME")]
    pub time_constant: Option<f64>,
    /// Reference-height noise standard deviation per sample.
    #[arg(long, value_parser = length, default_value = "0m", value_name = "LENGTH")]
    pub ref_noise: f64,
    /// Reference-height bias.
    #[arg(long, value_parser = length, allow_hyphen_values = true, default_value = "0m", value_name = "LENGTH")]
    pub ref_bias: f64,
    /// An outlier of SIZE in the reference sample at AT; repeatable (e.g. 600s:200m).
    #[arg(long, value_parser = outlier_spec, allow_hyphen_values = true, value_name = "AT:SIZE")]
    pub ref_outlier: Vec<Outlier>,
    /// Probability that any reference sample is an outlier (random sign).
    #[arg(long, value_parser = probability, default_value = "0", value_name = "P")]
    pub ref_outlier_prob: f64,
    /// Size of random outliers.
    #[arg(long, value_parser = length, default_value = "200m", value_name = "LENGTH")]
    pub ref_outlier_size: f64,
    /// No reference from FROM for DURATION; repeatable (e.g. 1000s:300s).
    #[arg(long, value_parser = dropout_spec, value_name = "FROM:DURATION")]
    pub ref_dropout: Vec<Dropout>,
    /// Fault-detector gate on |prediction - reference| for the constant-gain loop.
    #[arg(long, value_parser = length, default_value = "50m", value_name = "LENGTH")]
    pub gate: f64,
    /// Consecutive consistent rejected samples that reconnect the loop.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub reacquire: usize,
    /// Accept every reference sample (to see what an outlier does).
    #[arg(long)]
    pub no_fault_detector: bool,
    /// Kalman variant: accelerometer noise density assumed (e.g. 1e-3m/s^2/sqrt(Hz)).
    #[arg(long, value_parser = noise_density, default_value = "1e-3m/s^2/sqrt(Hz)", value_name = "DENSITY")]
    pub kf_accel_noise: f64,
    /// Seed of the reference noise and random outliers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// True height above the sphere.
    #[arg(long, value_parser = length, allow_hyphen_values = true, default_value = "0m", value_name = "LENGTH")]
    pub height: f64,
    /// Run length.
    #[arg(long, value_parser = time, allow_hyphen_values = true, default_value = "30min", value_name = "TIME")]
    pub duration: f64,
    /// Integration step and reference sample interval.
    #[arg(long, value_parser = time, allow_hyphen_values = true, default_value = "0.1s", value_name = "TIME")]
    pub dt: f64,
    /// The textbook sphere.
    #[command(flatten)]
    pub sphere: SphereArgs,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// The flag behind a library parameter name.
fn flag_for(name: &str) -> Option<&'static str> {
    Some(match name {
        "height" => "--height",
        "initial height error" => "--init-height-error",
        "initial vertical velocity error" => "--init-vel-error",
        "vertical accelerometer bias" => "--accel-bias",
        "duration" => "--duration",
        "step dt" => "--dt",
        "time constant" => "--time-constant",
        "k1" => "--k1",
        "k2" => "--k2",
        "Kalman accelerometer noise" => "--kf-accel-noise",
        "Kalman reference sigma" => "--ref-noise",
        "reference noise" => "--ref-noise",
        "outlier probability" => "--ref-outlier-prob",
        "dropout duration" => "--ref-dropout",
        _ => return None,
    })
}

/// Adds the flag that a library error is about.
fn explain(e: ChannelError) -> anyhow::Error {
    let flag = match &e {
        ChannelError::StepTooCoarse { .. } => Some("--dt"),
        ChannelError::UnstableGains { .. } => Some("--k1/--k2"),
        ChannelError::NonFinite { name, .. }
        | ChannelError::NotPositive { name, .. }
        | ChannelError::OutOfRange { name, .. } => flag_for(name),
        _ => None,
    };
    match flag {
        Some(f) => anyhow::anyhow!("{f}: {e}"),
        None => anyhow::anyhow!("invalid scenario: {e}"),
    }
}

/// Runs `args`'s vertical channel (free or aided) and writes its files and
/// `summary.json` into `args.out` (created if needed); returns the summary.
pub fn run_and_write(args: &Args) -> Result<Value> {
    if args.ref_noise < 0.0 || args.ref_noise.is_nan() {
        bail!("--ref-noise must be >= 0, got {} m", args.ref_noise);
    }
    if !is_positive(args.gate) {
        bail!("--gate must be positive, got {} m", args.gate);
    }
    let n = args.reacquire as u64;
    crate::options::in_count("--reacquire", &schuler::domain::IN_A_ROW, n)?;
    let cfg = VerticalConfig {
        earth: args.sphere.sphere(0.0)?,
        height: args.height,
        init_height_error: args.init_height_error,
        init_vel_error: args.init_vel_error,
        accel_bias: args.accel_bias,
        duration: args.duration,
        dt: args.dt,
    };
    cfg.validate().map_err(explain)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating --out directory {}", args.out.display()))?;
    let summary = match args.mode {
        ModeChoice::Free => {
            let aided_flags = !args.ref_outlier.is_empty()
                || !args.ref_dropout.is_empty()
                || args.k1.is_some()
                || args.time_constant.is_some();
            if aided_flags {
                bail!(
                    "--k1/--k2/--time-constant/--ref-outlier/--ref-dropout apply to --mode aided"
                );
            }
            run_free(&cfg, &args.out)?
        }
        ModeChoice::Aided => run_aided(&cfg, args)?,
    };
    let text = serde_json::to_string_pretty(&summary).context("encoding summary.json")?;
    schuler_io::line_file::write_whole(&args.out.join("summary.json"), text + "\n")?;
    Ok(summary)
}

/// Writes `vertical.csv`.
fn write_samples(path: &Path, samples: &[VerticalSample]) -> Result<()> {
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    writeln!(w, "t,dh,dvh,mode")?;
    for s in samples {
        writeln!(w, "{},{:e},{:e},{}", s.t, s.dh, s.dvh, s.mode.as_str())?;
    }
    w.finish()
}

fn eigen_json(l: &[nalgebra::Complex<f64>]) -> Value {
    Value::Array(l.iter().map(|c| json!({"re": c.re, "im": c.im})).collect())
}

fn run_free(cfg: &VerticalConfig, out: &Path) -> Result<Value> {
    let samples = simulate_free(cfg).map_err(explain)?;
    write_samples(&out.join("vertical.csv"), &samples)?;
    let w0 = cfg.w0_sq().sqrt();
    let theory = cfg.e_fold_time();
    let dh: Vec<f64> = samples.iter().map(|s| s.dh).collect();
    let lag = ((60.0 / cfg.dt).round() as usize).max(1);
    let measured = e_fold_time(&dh, cfg.dt, lag);
    let closed: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| {
            vertical_free_response(
                w0,
                cfg.init_height_error,
                cfg.init_vel_error,
                cfg.accel_bias,
                s.t,
            )
        })
        .collect();
    let max_diff = samples
        .iter()
        .zip(&closed)
        .fold(0.0f64, |m, (s, c)| m.max((s.dh - c.0).abs()));
    let (tscale, tlabel) = time_axis(cfg.duration);
    let t: Vec<f64> = samples.iter().map(|s| s.t / tscale).collect();
    let c_dh: Vec<f64> = closed.iter().map(|c| c.0).collect();
    let c_dv: Vec<f64> = closed.iter().map(|c| c.1).collect();
    let dv: Vec<f64> = samples.iter().map(|s| s.dvh).collect();
    Plot::new("Free vertical channel: height error", tlabel, "dh [m]")
        .line("nonlinear (31)", &t, &dh, LineStyle::Solid)
        .line("closed form (32)", &t, &c_dh, LineStyle::Dashed)
        .write(&out.join("dh.svg"))?;
    Plot::new(
        "Free vertical channel: vertical-velocity error",
        tlabel,
        "dVh [m/s]",
    )
    .line("nonlinear (31)", &t, &dv, LineStyle::Solid)
    .line("closed form (32)", &t, &c_dv, LineStyle::Dashed)
    .write(&out.join("dvh.svg"))?;
    let k = std::f64::consts::SQRT_2 * w0;
    Ok(json!({
        "command": "vertical",
        "mode": "free",
        "inputs": inputs_json(cfg),
        "w0_rad_s": w0,
        "eigenvalues": eigen_json(&[nalgebra::Complex::new(k, 0.0), nalgebra::Complex::new(-k, 0.0)]),
        "e_fold_time_s": {
            "theory": theory,
            "measured": measured,
            "relative_error": measured.map(|m| m / theory - 1.0),
        },
        "max_abs_diff_nonlinear_minus_closed_m": max_diff,
        "peak_abs_dh_m": peak_abs(dh.iter().copied()),
        "files": ["vertical.csv", "summary.json", "dh.svg", "dvh.svg"],
    }))
}

fn inputs_json(cfg: &VerticalConfig) -> Value {
    json!({
        "radius_m": cfg.earth.radius,
        "g_m_s2": cfg.earth.gravitation(cfg.earth.radius),
        "height_m": cfg.height,
        "init_height_error_m": cfg.init_height_error,
        "init_vel_error_m_s": cfg.init_vel_error,
        "accel_bias_m_s2": cfg.accel_bias,
        "duration_s": cfg.duration,
        "dt_s": cfg.dt,
    })
}

/// The loop's gains: `--k1`/`--k2` as given, or critically damped for
/// `--time-constant` (default 20 s); checked stable (37) and resolved by the step.
fn aided_gains(cfg: &VerticalConfig, args: &Args) -> Result<Gains> {
    let w0_sq = cfg.w0_sq();
    let gains = match (args.k1, args.k2, args.time_constant) {
        (Some(k1), Some(k2), _) => Gains { k1, k2 },
        (_, _, tau) => Gains::critical(tau.unwrap_or(20.0), w0_sq).map_err(explain)?,
    };
    gains.check(w0_sq, cfg.dt).map_err(explain)?;
    Ok(gains)
}

/// The simulated reference height's errors: noise, bias, outliers and dropouts.
fn reference_config(args: &Args) -> ReferenceConfig {
    ReferenceConfig {
        noise: args.ref_noise,
        bias: args.ref_bias,
        outliers: args.ref_outlier.clone(),
        outlier_probability: args.ref_outlier_prob,
        outlier_size: args.ref_outlier_size,
        dropouts: args.ref_dropout.clone(),
        seed: args.seed,
    }
}

/// The Kalman variant's tuning: its accelerometer noise, the reference sigma (at least
/// 0.1 m) and initial sigmas from the initial errors (at least 10 m and 1 m/s).
fn kalman_tuning(args: &Args) -> KalmanTuning {
    KalmanTuning {
        accel_noise: args.kf_accel_noise,
        ref_sigma: args.ref_noise.max(0.1),
        sigma_h0: args.init_height_error.abs().max(10.0),
        sigma_v0: args.init_vel_error.abs().max(1.0),
        gate_sigmas: 5.0,
    }
}

/// The aided mode's two runs on the same reference samples, with their settings.
struct AidedRuns {
    /// The constant-gain loop's gains.
    gains: Gains,
    /// The fault detector's settings.
    detector: DetectorConfig,
    /// The Kalman variant's tuning.
    tuning: KalmanTuning,
    /// The constant-gain loop (34) with prediction (38).
    loop_run: AidedRun,
    /// The Kalman variant.
    kf: KalmanRun,
}

/// Noise floor of the settling band [m]: a critically damped loop of time constant
/// `tau` passes white reference noise (variance σ² per sample of length dt) through an
/// equivalent noise bandwidth of 1.25/τ, so its height error has σ_f = σ sqrt(1.25 dt/τ);
/// five of those (at least 1 mm).
fn noise_floor(ref_noise: f64, dt: f64, tau: f64) -> f64 {
    (5.0 * ref_noise * (1.25 * dt / tau).sqrt()).max(1e-3)
}

/// Fraction of the initial error that bounds the settling band.
const SETTLING_FRACTION: f64 = 0.05;

/// How the loop settles and recovers: steady state of (37), the settling band and
/// times, and the outages of the loop and of the filter.
struct AidedAnalysis {
    /// The loop's time constants [s], slowest first.
    taus: [f64; 2],
    /// Steady-state height and vertical-velocity errors [m, m/s] forced by the
    /// reference and accelerometer biases.
    steady: (f64, f64),
    /// Half-width of the settling band [m].
    band: f64,
    /// Settling time measured on the loop's run and on the noise-free solution [s].
    settling: (Option<f64>, Option<f64>),
    /// The loop's prediction intervals and its reconvergence after each.
    outages: Vec<Outage>,
    /// The filter's final equivalent gains.
    kf_final: Option<Gains>,
    /// The filter's prediction intervals and its reconvergence after each.
    kf_outages: Vec<Outage>,
}

/// Settling time of the loop's height error into `band` around `steady` before its
/// first prediction, measured and on the noise-free solution exp(A t) (x0 - x_ss) of
/// (37) from the initial errors less the steady state `(e0, v0)`.
fn settling_times(
    samples: &[VerticalSample],
    gains: &Gains,
    w0_sq: f64,
    steady: f64,
    band: f64,
    (e0, v0): (f64, f64),
) -> (Option<f64>, Option<f64>) {
    let t: Vec<f64> = samples.iter().map(|s| s.t).collect();
    let dh: Vec<f64> = samples.iter().map(|s| s.dh).collect();
    let first_predict = samples
        .iter()
        .position(|s| s.mode == Mode::Predict)
        .unwrap_or(dh.len());
    let measured = settling_time(&t, &dh, steady, band, 0, first_predict);
    let theory_curve: Vec<f64> = t
        .iter()
        .map(|&ti| {
            closed_loop_response(gains, w0_sq, e0, v0, ti)
                .map(|(h, _)| h)
                .unwrap_or(f64::NAN)
        })
        .collect();
    (
        measured,
        settling_time(&t, &theory_curve, 0.0, band, 0, t.len()),
    )
}

/// The filter's final equivalent gains (of its last aided sample) and its outages,
/// each measured against the steady state of those gains (the reference bias and the
/// loop's `tau` without them).
fn kalman_outages(
    cfg: &VerticalConfig,
    args: &Args,
    kf: &KalmanRun,
    tau: f64,
) -> (Option<Gains>, Vec<Outage>) {
    let w0_sq = cfg.w0_sq();
    let kf_final = kf
        .samples
        .iter()
        .rev()
        .find(|s| s.mode == Mode::Aided)
        .map(|s| Gains { k1: s.k1, k2: s.k2 });
    let as_loop: Vec<VerticalSample> = kf
        .samples
        .iter()
        .map(|s| VerticalSample {
            t: s.t,
            dh: s.dh,
            dvh: s.dvh,
            mode: s.mode,
        })
        .collect();
    let (target, tau) = kf_final.map_or((args.ref_bias, tau), |g| {
        (
            g.steady_state(w0_sq, args.ref_bias, cfg.accel_bias).0,
            g.time_constants(w0_sq)[0],
        )
    });
    let floor = noise_floor(args.ref_noise, cfg.dt, tau);
    (
        kf_final,
        outages(&as_loop, target, SETTLING_FRACTION, floor),
    )
}

/// Steady state, settling and outages of both runs.
fn analyse(cfg: &VerticalConfig, args: &Args, runs: &AidedRuns) -> AidedAnalysis {
    let w0_sq = cfg.w0_sq();
    let (steady, steady_v) = runs
        .gains
        .steady_state(w0_sq, args.ref_bias, cfg.accel_bias);
    let taus = runs.gains.time_constants(w0_sq);
    let floor = noise_floor(args.ref_noise, cfg.dt, taus[0]);
    let e0 = cfg.init_height_error - steady;
    let v0 = cfg.init_vel_error - steady_v;
    let band = (SETTLING_FRACTION * e0.abs()).max(floor);
    let samples = &runs.loop_run.samples;
    let settling = settling_times(samples, &runs.gains, w0_sq, steady, band, (e0, v0));
    let (kf_final, kf_outages) = kalman_outages(cfg, args, &runs.kf, taus[0]);
    AidedAnalysis {
        taus,
        steady: (steady, steady_v),
        band,
        settling,
        outages: outages(samples, steady, SETTLING_FRACTION, floor),
        kf_final,
        kf_outages,
    }
}

/// The outages longer than 1.5 steps, with reconvergence times also in units of the
/// loop's time constant `tau`.
fn outage_json(v: &[Outage], dt: f64, tau: f64) -> Value {
    Value::Array(
        v.iter()
            .filter(|o| o.end - o.start > dt * 1.5)
            .map(|o| {
                json!({
                    "start_s": o.start,
                    "reconnect_s": o.end,
                    "error_at_reconnect_m": o.error_at_reconnect,
                    "reconverge_time_s": o.reconverge_time,
                    "reconverge_time_constants": o.reconverge_time.map(|r| r / tau),
                })
            })
            .collect(),
    )
}

/// The reference's settings as given.
fn reference_json(args: &Args) -> Value {
    json!({
        "noise_m": args.ref_noise,
        "bias_m": args.ref_bias,
        "outliers": args.ref_outlier.iter().map(|o| json!({"t_s": o.t, "size_m": o.size})).collect::<Vec<_>>(),
        "outlier_probability": args.ref_outlier_prob,
        "outlier_size_m": args.ref_outlier_size,
        "dropouts": args.ref_dropout.iter().map(|d| json!({"start_s": d.start, "duration_s": d.duration})).collect::<Vec<_>>(),
        "seed": args.seed,
    })
}

/// The Kalman variant's tuning, final gains, detector counts and outages.
fn kalman_json(cfg: &VerticalConfig, runs: &AidedRuns, a: &AidedAnalysis) -> Value {
    let (tuning, kf) = (&runs.tuning, &runs.kf);
    json!({
        "accel_noise_m_s_sqrt_s": tuning.accel_noise,
        "ref_sigma_m": tuning.ref_sigma,
        "gate_sigmas": tuning.gate_sigmas,
        "final_gains": a.kf_final.map(|g| json!({"k1_1_s": g.k1, "k2_1_s2": g.k2})),
        "accepted": kf.counts.accepted,
        "rejected": kf.counts.rejected,
        "missing": kf.counts.missing,
        "reacquired": kf.counts.reacquired,
        "outages": outage_json(&a.kf_outages, cfg.dt, a.taus[0]),
    })
}

/// `summary.json` of the aided mode.
fn aided_summary(cfg: &VerticalConfig, args: &Args, runs: &AidedRuns, a: &AidedAnalysis) -> Value {
    let w0_sq = cfg.w0_sq();
    let (gains, detector, loop_run) = (&runs.gains, &runs.detector, &runs.loop_run);
    json!({
        "command": "vertical",
        "mode": "aided",
        "inputs": inputs_json(cfg),
        "reference": reference_json(args),
        "w0_rad_s": w0_sq.sqrt(),
        "free_e_fold_time_s": cfg.e_fold_time(),
        "gains": { "k1_1_s": gains.k1, "k2_1_s2": gains.k2 },
        "eigenvalues": eigen_json(&gains.eigenvalues(w0_sq)),
        "time_constants_s": a.taus,
        "steady_state_dh_m": a.steady.0,
        "steady_state_dvh_m_s": a.steady.1,
        "settling": {
            "band_m": a.band,
            "measured_s": a.settling.0,
            "theory_s": a.settling.1,
        },
        "outages": outage_json(&a.outages, cfg.dt, a.taus[0]),
        "detector": {
            "enabled": detector.enabled,
            "gate_m": detector.gate,
            "reacquire": detector.reacquire,
            "accepted": loop_run.counts.accepted,
            "rejected": loop_run.counts.rejected,
            "missing": loop_run.counts.missing,
            "reacquired": loop_run.counts.reacquired,
        },
        "kalman": kalman_json(cfg, runs, a),
        "rms_dh_minus_reference_bias_m": {
            "loop": rms(loop_run.samples.iter().map(|s| s.dh - args.ref_bias)),
            "kalman": rms(runs.kf.samples.iter().map(|s| s.dh - args.ref_bias)),
        },
        "files": ["vertical.csv", "vertical_kf.csv", "reference.csv", "summary.json", "dh.svg", "dvh.svg"],
    })
}

/// `--mode aided`: the constant-gain loop and the Kalman variant on one simulated
/// reference; writes their CSVs, the reference and the plots, and returns the summary.
fn run_aided(cfg: &VerticalConfig, args: &Args) -> Result<Value> {
    let gains = aided_gains(cfg, args)?;
    let grid = cfg.grid();
    let reference = reference_config(args)
        .generate(cfg.height, &grid)
        .map_err(explain)?;
    let detector = DetectorConfig {
        enabled: !args.no_fault_detector,
        gate: args.gate,
        reacquire: args.reacquire,
    };
    let loop_run = simulate_aided(cfg, gains, &reference, detector).map_err(explain)?;
    let tuning = kalman_tuning(args);
    // The filter gates on its own innovation sigma (`gate_sigmas`), not on `--gate`.
    let kf = simulate_kalman(cfg, tuning, &reference, detector).map_err(explain)?;
    write_samples(&args.out.join("vertical.csv"), &loop_run.samples)?;
    write_kf(&args.out.join("vertical_kf.csv"), &kf)?;
    write_reference(
        &args.out.join("reference.csv"),
        &grid,
        &reference,
        cfg.height,
    )?;
    let runs = AidedRuns {
        gains,
        detector,
        tuning,
        loop_run,
        kf,
    };
    let analysis = analyse(cfg, args, &runs);
    write_aided_plots(&args.out, cfg, &runs.loop_run, &runs.kf)?;
    Ok(aided_summary(cfg, args, &runs, &analysis))
}

/// Root mean square of `xs` (0 for none).
fn rms(xs: impl Iterator<Item = f64>) -> f64 {
    let (n, s) = xs.fold((0usize, 0.0), |(n, s), x| (n + 1, s + x * x));
    if n == 0 { 0.0 } else { (s / n as f64).sqrt() }
}

fn write_kf(path: &Path, kf: &KalmanRun) -> Result<()> {
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    writeln!(w, "t,dh,dvh,mode,k1,k2,sigma_h")?;
    for s in &kf.samples {
        writeln!(
            w,
            "{},{:e},{:e},{},{:e},{:e},{:e}",
            s.t,
            s.dh,
            s.dvh,
            s.mode.as_str(),
            s.k1,
            s.k2,
            s.sigma_h
        )?;
    }
    w.finish()
}

fn write_reference(
    path: &Path,
    grid: &schuler::channel::ode::Grid,
    reference: &[Option<f64>],
    height: f64,
) -> Result<()> {
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    writeln!(w, "t,dh_ref")?;
    let mut line = String::new();
    for (k, r) in reference.iter().enumerate() {
        line.clear();
        let _ = write!(line, "{},", grid.time(k));
        if let Some(h) = r {
            let _ = write!(line, "{:e}", h - height);
        }
        writeln!(w, "{line}")?;
    }
    w.finish()
}

/// Prediction intervals [t0, t1) of a run, in plot time units.
fn predict_spans(samples: &[VerticalSample], scale: f64) -> Vec<(f64, f64)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, s) in samples.iter().enumerate() {
        match (s.mode, start) {
            (Mode::Predict, None) => start = Some(s.t),
            (Mode::Aided, Some(t0)) => {
                spans.push((t0 / scale, s.t / scale));
                start = None;
            }
            _ => {}
        }
        if i + 1 == samples.len()
            && let Some(t0) = start
        {
            spans.push((t0 / scale, s.t / scale));
        }
    }
    spans
}

fn write_aided_plots(
    dir: &Path,
    cfg: &VerticalConfig,
    run: &AidedRun,
    kf: &KalmanRun,
) -> Result<()> {
    let (tscale, tlabel) = time_axis(cfg.duration);
    let t: Vec<f64> = run.samples.iter().map(|s| s.t / tscale).collect();
    let spans = predict_spans(&run.samples, tscale);
    for (file, title, ylabel, pick_loop, pick_kf) in [
        (
            "dh.svg",
            "Aided vertical channel: height error",
            "dh [m]",
            (|s: &VerticalSample| s.dh) as fn(&VerticalSample) -> f64,
            (|s: &schuler::channel::kalman::KalmanSample| s.dh)
                as fn(&schuler::channel::kalman::KalmanSample) -> f64,
        ),
        (
            "dvh.svg",
            "Aided vertical channel: vertical-velocity error",
            "dVh [m/s]",
            |s: &VerticalSample| s.dvh,
            |s: &schuler::channel::kalman::KalmanSample| s.dvh,
        ),
    ] {
        let a: Vec<f64> = run.samples.iter().map(pick_loop).collect();
        let b: Vec<f64> = kf.samples.iter().map(pick_kf).collect();
        Plot::new(title, tlabel, ylabel)
            .line("constant-gain loop (34)", &t, &a, LineStyle::Solid)
            .line("Kalman filter", &t, &b, LineStyle::Dashed)
            .shade("loop predicting (38)", spans.iter().copied())
            .write(&dir.join(file))?;
    }
    Ok(())
}
