//! Lecture 22's systems on one trajectory (`schuler platform --config FILE`)
//! with the same instrument error magnitudes — the strapdown INS, the platform INS in
//! its geographic, orthodromic and free-azimuth mechanizations, the analytic INS and
//! the gyro-free six-accelerometer INS ([`schuler::lab::platform`]).
//!
//! The config is a scenario's `[start]` and `[[motion]]` (as for `schuler simulate`)
//! plus the run's settings, `[errors]`, `[gyro_free]` and optionally a scenario's
//! `[imu]` (the simulator's error model, applied with `seed` to the SINS's, the
//! platforms' and the analytic INS's instruments alike); see `examples/platform.toml`.
//! Writes `errors.csv` (`t` and, per system, `SYS_north,SYS_east,SYS_down` [m],
//! `SYS_vn,SYS_ve,SYS_vd` [m/s], `SYS_att_n,SYS_att_e,SYS_att_d` [rad]), one plot per
//! error quantity with every system (`north.svg`, `east.svg`, `horizontal.svg`,
//! `height.svg`, `v_north.svg`, `v_east.svg`, `v_down.svg`, `tilt_north.svg`,
//! `tilt_east.svg`, `heading.svg`), the table of errors at 1 h (or at the end of a
//! shorter run) as `table.csv` and `table.md`, and `summary.json`.

use crate::options::in_domain;
use anyhow::{Context, Result, bail};
use nalgebra::{Vector3, Vector6};
use schuler::earth::{EarthModel, Sphere, Wgs84};
use schuler::imu::model::ImuModel;
use schuler::lab::platform::compare::{CompareConfig, Comparison, NavError, SystemKind, compare};
use schuler::lab::platform::{AccelerometerArray, InstrumentErrors, VerticalChannel};
use schuler::sim::run::EarthSpec;
use schuler::sim::scenario::{MotionSpec, Quantity, SegmentSpec, StartSpec};
use schuler::sim::sensor_spec::ImuSpec;
use schuler::units::{ARCSEC, Dimension};
use schuler_report::plot::{LineStyle, Plot, time_axis};
use serde::Deserialize;
use serde_json::json;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `schuler platform`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Comparison config TOML (start, motion, errors, gyro_free; see
    /// examples/platform.toml).
    #[arg(long, value_name = "FILE")]
    pub config: PathBuf,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Vertical channel handling, as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
enum VerticalSpec {
    /// Free inertial.
    Free,
    /// Held at the true height.
    #[default]
    TrueHeight,
}

/// Gyro-free accelerometer layout, as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
enum LayoutSpec {
    /// Face centres of a cube (Chen, Lee & DeBra).
    #[default]
    Cube,
    /// A triad and three offset accelerometers (unstable under rotation).
    TriadAndOffsets,
}

/// `[errors]`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ErrorsSpec {
    accel_bias: Option<[Quantity; 3]>,
    gyro_drift: Option<[Quantity; 3]>,
}

/// `[gyro_free]`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct GyroFreeSpec {
    #[serde(default)]
    layout: LayoutSpec,
    baseline: Option<Quantity>,
    accel_bias: Option<[Quantity; 6]>,
}

/// The whole config file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigSpec {
    #[serde(default)]
    earth: EarthSpec,
    duration: Option<Quantity>,
    step: Option<Quantity>,
    imu_rate_hz: Option<f64>,
    output_interval: Option<Quantity>,
    #[serde(default = "yes")]
    leveled: bool,
    #[serde(default)]
    vertical: VerticalSpec,
    systems: Option<Vec<String>>,
    start: StartSpec,
    motion: Vec<SegmentSpec>,
    #[serde(default)]
    errors: ErrorsSpec,
    #[serde(default)]
    gyro_free: GyroFreeSpec,
    /// The simulator's IMU model (as in a scenario) on top of `[errors]`.
    imu: Option<ImuSpec>,
    #[serde(default)]
    seed: u64,
}

fn yes() -> bool {
    true
}

fn si(q: &Quantity, key: &str, dim: Dimension) -> Result<f64> {
    Ok(q.si(key, dim)?)
}

fn vec3(q: &Option<[Quantity; 3]>, key: &str, dim: Dimension) -> Result<Vector3<f64>> {
    let mut v = Vector3::zeros();
    if let Some(q) = q {
        for i in 0..3 {
            v[i] = si(&q[i], &format!("{key}[{i}]"), dim)?;
        }
    }
    Ok(v)
}

/// [`vec3`] with each axis in `domain`.
fn vec3_in(
    q: &Option<[Quantity; 3]>,
    key: &str,
    dim: Dimension,
    domain: &schuler::domain::Domain,
) -> Result<Vector3<f64>> {
    let v = vec3(q, key, dim)?;
    for (i, x) in v.iter().enumerate() {
        in_domain(&format!("{key}[{i}]"), domain, *x)?;
    }
    Ok(v)
}

fn system_by_name(name: &str, index: usize) -> Result<SystemKind> {
    SystemKind::ALL
        .into_iter()
        .find(|s| s.name() == name)
        .with_context(|| {
            let names: Vec<&str> = SystemKind::ALL.iter().map(|s| s.name()).collect();
            format!("systems[{index}]: unknown system {name:?}; expected one of {names:?}")
        })
}

/// A parsed config: the run's settings and the motion, before the Earth is chosen.
pub struct Config {
    earth: EarthSpec,
    duration: Option<f64>,
    motion: MotionSpec,
    compare: CompareConfig,
}

/// Reads and checks a config; errors name the key.
pub fn load(path: &Path) -> Result<Config> {
    let text = schuler_io::formats::read_config_text(path)?;
    let spec: ConfigSpec =
        toml::from_str(&text).with_context(|| format!("in {}", path.display()))?;
    parse(spec).with_context(|| format!("in {}", path.display()))
}

/// `x`, which must be finite and positive (the error names `key`).
fn positive(x: f64, key: &str) -> Result<f64> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        bail!("{key}: must be positive, got {x}")
    }
}

/// The positive value of `key` in SI (`default` when not given).
fn positive_or(q: &Option<Quantity>, key: &str, dim: Dimension, default: f64) -> Result<f64> {
    match q {
        Some(q) => positive(si(q, key, dim)?, key),
        None => Ok(default),
    }
}

/// The SINS's IMU rate [Hz] and the simulator's sensor model: `[imu]`'s rate and
/// model, or `imu_rate_hz` (default 100 Hz) and none; not both.
fn imu_settings(spec: &ConfigSpec) -> Result<(f64, Option<ImuModel>)> {
    Ok(match (&spec.imu, spec.imu_rate_hz) {
        (Some(_), Some(_)) => {
            bail!("imu_rate_hz: give the SINS rate once, as imu.rate_hz when [imu] is present")
        }
        (Some(imu), None) => (imu.rate_hz, Some(imu.model()?)),
        (None, rate) => (positive(rate.unwrap_or(100.0), "imu_rate_hz")?, None),
    })
}

/// The gyro-free INS's accelerometer array (`[gyro_free]`: layout, baseline, default
/// 0.5 m) and its six biases (default: the triad's `accel_bias` magnitudes with
/// alternating signs: independent instruments, and equal signs would cancel in the
/// cube's differences).
fn gyro_free(
    spec: &GyroFreeSpec,
    accel_bias: Vector3<f64>,
) -> Result<(AccelerometerArray, Vector6<f64>)> {
    let rho = positive_or(&spec.baseline, "gyro_free.baseline", Dimension::Length, 0.5)?;
    let array = match spec.layout {
        LayoutSpec::Cube => AccelerometerArray::cube(rho),
        LayoutSpec::TriadAndOffsets => AccelerometerArray::triad_and_offsets(rho),
    }
    .context("gyro_free.layout")?;
    let b = accel_bias;
    let biases = match &spec.accel_bias {
        Some(q) => {
            let mut v = Vector6::zeros();
            for k in 0..6 {
                v[k] = si(
                    &q[k],
                    &format!("gyro_free.accel_bias[{k}]"),
                    Dimension::Acceleration,
                )?;
            }
            v
        }
        None => Vector6::new(b.x, -b.y, b.z, -b.x, b.y, -b.z),
    };
    Ok((array, biases))
}

/// The systems compared: those `systems` names (at least one), or all.
fn systems(names: &Option<Vec<String>>) -> Result<Vec<SystemKind>> {
    match names {
        Some(names) if names.is_empty() => bail!("systems: empty; name at least one system"),
        Some(names) => names
            .iter()
            .enumerate()
            .map(|(i, n)| system_by_name(n, i))
            .collect(),
        None => Ok(SystemKind::ALL.to_vec()),
    }
}

/// The checked config of `spec`; errors name the key.
fn parse(spec: ConfigSpec) -> Result<Config> {
    let duration = spec
        .duration
        .as_ref()
        .map(|q| si(q, "duration", Dimension::Time).and_then(|x| positive(x, "duration")))
        .transpose()?;
    let step = positive_or(&spec.step, "step", Dimension::Time, 0.1)?;
    let (imu_rate, sensor_model) = imu_settings(&spec)?;
    let output_interval = positive_or(
        &spec.output_interval,
        "output_interval",
        Dimension::Time,
        10.0,
    )?;
    let errors = InstrumentErrors {
        accel_bias: vec3_in(
            &spec.errors.accel_bias,
            "errors.accel_bias",
            Dimension::Acceleration,
            &schuler::domain::SPECIFIC_FORCE_COMPONENT,
        )?,
        gyro_drift: vec3_in(
            &spec.errors.gyro_drift,
            "errors.gyro_drift",
            Dimension::AngularRate,
            &schuler::domain::ANGULAR_RATE_COMPONENT,
        )?,
    };
    let (array, gyro_free_biases) = gyro_free(&spec.gyro_free, errors.accel_bias)?;
    let systems = systems(&spec.systems)?;
    Ok(Config {
        earth: spec.earth,
        duration,
        motion: MotionSpec {
            start: spec.start,
            motion: spec.motion,
        },
        compare: CompareConfig {
            errors,
            sensor_model,
            seed: spec.seed,
            gyro_free_array: array,
            gyro_free_biases,
            leveled: spec.leveled,
            vertical: match spec.vertical {
                VerticalSpec::Free => VerticalChannel::Free,
                VerticalSpec::TrueHeight => VerticalChannel::TrueHeight,
            },
            step,
            imu_rate,
            output_interval,
            systems,
        },
    })
}

/// Runs the comparison on the config's Earth.
fn run_on<E: EarthModel>(earth: E, cfg: &Config) -> Result<Comparison> {
    let traj = cfg.motion.build(earth)?;
    let (t0, end) = (traj.start(), traj.end());
    let t1 = match cfg.duration {
        Some(d) if t0 + d > end + 1e-9 => bail!(
            "duration: {d} s is longer than the motion ({:.3} s); add a [[motion]] hold",
            end - t0
        ),
        Some(d) => t0 + d,
        None => end,
    };
    Ok(compare(earth, &traj, t0, t1, &cfg.compare)?)
}

/// One plotted quantity: file, title, axis label with unit, and how to read it.
struct Panel {
    file: &'static str,
    title: &'static str,
    label: &'static str,
    pick: fn(&NavError) -> f64,
}

const QUANTITIES: [Panel; 10] = [
    Panel {
        file: "north.svg",
        title: "North position error",
        label: "dN [m]",
        pick: |e| e.pos_ned.x,
    },
    Panel {
        file: "east.svg",
        title: "East position error",
        label: "dE [m]",
        pick: |e| e.pos_ned.y,
    },
    Panel {
        file: "horizontal.svg",
        title: "Horizontal position error",
        label: "dS [m]",
        pick: NavError::horizontal,
    },
    Panel {
        file: "height.svg",
        title: "Height error",
        label: "dh [m]",
        pick: |e| -e.pos_ned.z,
    },
    Panel {
        file: "v_north.svg",
        title: "North velocity error",
        label: "dV_N [m/s]",
        pick: |e| e.v_ned.x,
    },
    Panel {
        file: "v_east.svg",
        title: "East velocity error",
        label: "dV_E [m/s]",
        pick: |e| e.v_ned.y,
    },
    Panel {
        file: "v_down.svg",
        title: "Down velocity error",
        label: "dV_D [m/s]",
        pick: |e| e.v_ned.z,
    },
    Panel {
        file: "tilt_north.svg",
        title: "Attitude error about north",
        label: "psi_N [arcsec]",
        pick: |e| e.attitude.x / ARCSEC,
    },
    Panel {
        file: "tilt_east.svg",
        title: "Attitude error about east",
        label: "psi_E [arcsec]",
        pick: |e| e.attitude.y / ARCSEC,
    },
    Panel {
        file: "heading.svg",
        title: "Heading error (about down)",
        label: "psi_D [arcsec]",
        pick: |e| e.attitude.z / ARCSEC,
    },
];

/// Runs `args`'s systems on one trajectory and writes `errors.csv`, the plots, the
/// tables and `summary.json` into `args.out` (created if needed); returns the table
/// (Markdown) at the table's epoch.
pub fn run_and_write(args: &Args) -> Result<String> {
    let cfg = load(&args.config)?;
    let result = match cfg.earth {
        EarthSpec::Wgs84 => run_on(Wgs84, &cfg),
        EarthSpec::Sphere => run_on(Sphere::textbook(true), &cfg),
        EarthSpec::SphereFixed => run_on(Sphere::textbook(false), &cfg),
    }
    .with_context(|| format!("in {}", args.config.display()))?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating --out directory {}", args.out.display()))?;
    write_errors_csv(&args.out.join("errors.csv"), &result)?;
    write_plots(&args.out, &result)?;
    let k = table_epoch(&result);
    let table = table_markdown(&result, k);
    write_file(&args.out.join("table.md"), &table)?;
    write_file(&args.out.join("table.csv"), &table_csv(&result, k))?;
    let summary = summary(&cfg, &result, k);
    let text = serde_json::to_string_pretty(&summary).context("encoding summary.json")?;
    write_file(&args.out.join("summary.json"), &(text + "\n"))?;
    Ok(table)
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    schuler_io::line_file::write_whole(path, text)
}

/// The epoch of the table: 1 h after the start, or the last one of a shorter run.
fn table_epoch(c: &Comparison) -> usize {
    let t1h = c.times[0] + 3600.0;
    c.times
        .iter()
        .position(|&t| t >= t1h - 1e-6)
        .unwrap_or(c.times.len() - 1)
}

/// Writes `errors.csv`.
fn write_errors_csv(path: &Path, c: &Comparison) -> Result<()> {
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    let mut line = String::from("t");
    for s in &c.systems {
        for q in [
            "north", "east", "down", "vn", "ve", "vd", "att_n", "att_e", "att_d",
        ] {
            let _ = write!(line, ",{}_{q}", s.name());
        }
    }
    writeln!(w, "{line}")?;
    for (k, t) in c.times.iter().enumerate() {
        line.clear();
        let _ = write!(line, "{t}");
        for e in &c.errors {
            let e = &e[k];
            for x in e
                .pos_ned
                .iter()
                .chain(e.v_ned.iter())
                .chain(e.attitude.iter())
            {
                let _ = write!(line, ",{x:e}");
            }
        }
        writeln!(w, "{line}")?;
    }
    w.finish()
}

/// Writes one plot per quantity. One system whose error peaks more than 20 times
/// above every other's (the gyro-free INS, usually) is drawn only until it passes 1.5
/// times the next peak, and labelled with that time, so the others keep the scale.
fn write_plots(dir: &Path, c: &Comparison) -> Result<()> {
    let (tscale, tlabel) = time_axis(c.times[c.times.len() - 1] - c.times[0]);
    let t: Vec<f64> = c.times.iter().map(|x| (x - c.times[0]) / tscale).collect();
    let styles = [LineStyle::Solid, LineStyle::Dashed, LineStyle::Dotted];
    for q in &QUANTITIES {
        let values: Vec<Vec<f64>> = c
            .errors
            .iter()
            .map(|e| e.iter().map(q.pick).collect())
            .collect();
        let peak = |v: &Vec<f64>| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let peaks: Vec<f64> = values.iter().map(peak).collect();
        let mut sorted = peaks.clone();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        // The largest sorts last, NaN after everything (total order): an outlier too.
        let outlier = n >= 2
            && sorted[n - 2] > 0.0
            && (sorted[n - 1].is_nan() || sorted[n - 1] > 20.0 * sorted[n - 2]);
        let limit = if outlier {
            1.5 * sorted[n - 2]
        } else {
            f64::INFINITY
        };
        let mut plot = Plot::new(q.title, tlabel, q.label);
        for (s, v) in values.iter().enumerate() {
            let name = c.systems[s].name();
            // Beyond the limit, or not finite.
            let off = v
                .iter()
                .position(|x| x.abs().partial_cmp(&limit) != Some(std::cmp::Ordering::Less));
            let label = match off {
                Some(k) => format!(
                    "{name} (off scale after {:.3} {})",
                    t[k],
                    &tlabel[3..tlabel.len() - 1]
                ),
                None => name.to_owned(),
            };
            let shown: Vec<f64> = match off {
                Some(k) => v[..k].to_vec(),
                None => v.clone(),
            };
            plot = plot.line(&label, &t, &shown, styles[s % styles.len()]);
        }
        plot.write(&dir.join(q.file))?;
    }
    Ok(())
}

/// A table column: header with unit, and the value.
type Column = (&'static str, fn(&NavError) -> f64);

fn table_columns() -> [Column; 9] {
    [
        ("horizontal [m]", NavError::horizontal),
        ("north [m]", |e| e.pos_ned.x),
        ("east [m]", |e| e.pos_ned.y),
        ("height [m]", |e| -e.pos_ned.z),
        ("v_N [m/s]", |e| e.v_ned.x),
        ("v_E [m/s]", |e| e.v_ned.y),
        ("tilt_N [arcsec]", |e| e.attitude.x / ARCSEC),
        ("tilt_E [arcsec]", |e| e.attitude.y / ARCSEC),
        ("heading [arcsec]", |e| e.attitude.z / ARCSEC),
    ]
}

fn table_markdown(c: &Comparison, k: usize) -> String {
    let mut s = format!(
        "Errors at t = {} s ({:.3} h after the start)\n\n| system |",
        c.times[k],
        (c.times[k] - c.times[0]) / 3600.0
    );
    let cols = table_columns();
    for (h, _) in &cols {
        let _ = write!(s, " {h} |");
    }
    s.push_str("\n|---|");
    for _ in &cols {
        s.push_str("---:|");
    }
    s.push('\n');
    for (i, sys) in c.systems.iter().enumerate() {
        let _ = write!(s, "| {} |", sys.name());
        for (_, f) in &cols {
            let _ = write!(s, " {} |", number(f(&c.errors[i][k])));
        }
        s.push('\n');
    }
    s
}

/// Four significant digits, fixed for moderate magnitudes, exponent otherwise.
fn number(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

fn table_csv(c: &Comparison, k: usize) -> String {
    let mut s = String::from("t,system,horizontal,north,east,height,vn,ve,tilt_n,tilt_e,heading\n");
    for (i, sys) in c.systems.iter().enumerate() {
        let e = &c.errors[i][k];
        let _ = write!(s, "{},{}", c.times[k], sys.name());
        for x in [
            e.horizontal(),
            e.pos_ned.x,
            e.pos_ned.y,
            -e.pos_ned.z,
            e.v_ned.x,
            e.v_ned.y,
            e.attitude.x,
            e.attitude.y,
            e.attitude.z,
        ] {
            let _ = write!(s, ",{x:e}");
        }
        s.push('\n');
    }
    s
}

fn summary(cfg: &Config, c: &Comparison, k: usize) -> serde_json::Value {
    let cc = &cfg.compare;
    let v3 = |v: &Vector3<f64>| json!([v.x, v.y, v.z]);
    let files: Vec<&str> = ["errors.csv", "table.md", "table.csv", "summary.json"]
        .into_iter()
        .chain(QUANTITIES.iter().map(|q| q.file))
        .collect();
    json!({
        "command": "platform",
        "inputs": {
            "earth": format!("{:?}", cfg.earth),
            "accel_bias_m_s2": v3(&cc.errors.accel_bias),
            "gyro_drift_rad_s": v3(&cc.errors.gyro_drift),
            "imu_model": cc.sensor_model.is_some(),
            "seed": cc.seed,
            "gyro_free_accel_bias_m_s2": cc.gyro_free_biases.iter().collect::<Vec<_>>(),
            "gyro_free_positions_m": cc.gyro_free_array.positions.iter().map(v3).collect::<Vec<_>>(),
            "gyro_free_axes": cc.gyro_free_array.axes.iter().map(|u| v3(&u.into_inner())).collect::<Vec<_>>(),
            "leveled": cc.leveled,
            "vertical": format!("{:?}", cc.vertical),
            "step_s": cc.step,
            "imu_rate_hz": cc.imu_rate,
            "output_interval_s": cc.output_interval,
            "t0_s": c.times[0],
            "t1_s": c.times[c.times.len() - 1],
        },
        "table_t_s": c.times[k],
        "table": c.systems.iter().enumerate().map(|(i, s)| {
            let e = &c.errors[i][k];
            json!({
                "system": s.name(),
                "horizontal_m": e.horizontal(),
                "pos_ned_m": v3(&e.pos_ned),
                "v_ned_m_s": v3(&e.v_ned),
                "attitude_ned_rad": v3(&e.attitude),
            })
        }).collect::<Vec<_>>(),
        "files": files,
    })
}
