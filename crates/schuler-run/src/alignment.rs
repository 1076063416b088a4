//! Alignment shared by `schuler align` and `schuler nav --align`: the options as
//! written, reading the stage's samples, running the library's alignment on the
//! chosen Earth model, and its report, `align.json` and convergence files.

use crate::earth::AnyEarth;
use crate::imu_input::ImuInputOptions;
use crate::options::{EarthChoice, GradeChoice, Triple};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use schuler::align::{AlignConfig, AlignError, Alignment, HeadingSource, MotionReport, align};
use schuler::earth::Geodetic;
use schuler::filter::ImuNoise;
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::units::{DEG_PER_H, Dimension, MGAL, parse_as_or_si};
use schuler_report::plot::{LineStyle, Plot};
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The alignment options shared by `align` and `nav --align`, as written.
#[derive(clap::Args, Debug, Default, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlignOptions {
    /// Coarse stage length (e.g. `190s`, `3 min`; default 190 s).
    #[arg(long, value_name = "TIME", allow_hyphen_values = true)]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub coarse: Option<String>,
    /// Fine stage length (default 670 s; `0` for coarse only).
    #[arg(long, value_name = "TIME", allow_hyphen_values = true)]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub fine: Option<String>,
    /// Averaging block: spike test window, motion detector block and fine-filter
    /// measurement window (default 1 s; the averaging filter's band is 1/block).
    #[arg(long, value_name = "TIME", allow_hyphen_values = true)]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub block: Option<String>,
    /// Noise model the filters assume (default: navigation for alignment, tactical
    /// with --gnss).
    #[arg(long, value_enum)]
    pub imu_grade: Option<GradeChoice>,
    /// External heading instead of gyrocompassing: `DEG` or `DEG,STD_DEG` (default std
    /// 1 deg).
    #[arg(long, value_name = "DEG[,STD]", allow_hyphen_values = true)]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub heading: Option<String>,
    /// Refuse gyrocompassing when the predicted heading std exceeds this (default
    /// 1 deg).
    #[arg(long, value_name = "DEG")]
    pub max_heading_std: Option<f64>,
}

impl AlignOptions {
    /// `self` with missing fields taken from `other`.
    pub fn or(self, other: AlignOptions) -> AlignOptions {
        AlignOptions {
            coarse: self.coarse.or(other.coarse),
            fine: self.fine.or(other.fine),
            block: self.block.or(other.block),
            imu_grade: self.imu_grade.or(other.imu_grade),
            heading: self.heading.or(other.heading),
            max_heading_std: self.max_heading_std.or(other.max_heading_std),
        }
    }

    /// The checked configuration and noise model.
    pub fn resolve(&self) -> Result<(AlignConfig, ImuNoise)> {
        let mut cfg = AlignConfig::default();
        let time =
            |flag: &str, v: &Option<String>, default: f64, allow_zero: bool| -> Result<f64> {
                let Some(s) = v else { return Ok(default) };
                let t = parse_as_or_si(s, Dimension::Time)
                    .with_context(|| format!("--{flag} {s:?}: expected a time such as 190s"))?;
                if !(t.is_finite() && (t > 0.0 || (allow_zero && t == 0.0))) {
                    bail!("--{flag} must be a positive time, got {s:?}");
                }
                Ok(t)
            };
        cfg.coarse = time("coarse", &self.coarse, cfg.coarse, false)?;
        cfg.fine = time("fine", &self.fine, cfg.fine, true)?;
        cfg.block = time("block", &self.block, cfg.block, false)?;
        cfg.stillness.window = cfg.block;
        if cfg.block > cfg.coarse {
            bail!(
                "--block ({} s) is longer than the coarse stage ({} s)",
                cfg.block,
                cfg.coarse
            );
        }
        if let Some(m) = self.max_heading_std {
            if !(m.is_finite() && m > 0.0) {
                bail!("--max-heading-std must be a positive number of degrees, got {m}");
            }
            cfg.max_heading_std = m.to_radians();
        }
        if let Some(h) = &self.heading {
            let parts: Vec<&str> = h.split(',').map(str::trim).collect();
            let num = |p: &str| p.parse::<f64>().ok().filter(|x| x.is_finite());
            let (yaw, std) = match parts.as_slice() {
                [y] => (num(y), Some(1.0)),
                [y, s] => (num(y), num(s)),
                _ => (None, None),
            };
            let (Some(yaw), Some(std)) = (yaw, std) else {
                bail!("--heading {h:?}: expected DEG or DEG,STD_DEG");
            };
            if std <= 0.0 {
                bail!("--heading {h:?}: the standard deviation must be positive");
            }
            cfg.heading = HeadingSource::External {
                yaw: yaw.to_radians(),
                std: std.to_radians(),
            };
        }
        Ok((cfg, self.imu_grade.unwrap_or_default().noise()?))
    }
}

/// Read the samples from `start` up to `start + seconds` (and one more, which the
/// caller may use to continue). Samples are read lazily and reading stops there.
pub fn read_stage<I, E>(samples: &mut I, seconds: f64) -> Result<Vec<ImuSample>>
where
    I: Iterator<Item = Result<ImuSample, E>> + ?Sized,
    anyhow::Error: From<E>,
{
    let mut out: Vec<ImuSample> = Vec::new();
    for s in &mut *samples {
        let s = s?;
        let t0 = out.first().map_or(s.t - s.dt, |f| f.t - f.dt);
        let done = s.t > t0 + seconds + 0.5 * s.dt;
        out.push(s);
        if done {
            break;
        }
    }
    Ok(out)
}

/// Run the alignment on `samples` for the chosen Earth model.
pub fn align_on(
    earth: EarthChoice,
    pos: Geodetic,
    samples: &[ImuSample],
    noise: &ImuNoise,
    cfg: &AlignConfig,
) -> Result<Alignment> {
    let r = align(AnyEarth::of(earth), pos, samples, noise, cfg);
    r.map_err(|e| match e {
        AlignError::NotEnoughData { .. } => anyhow::anyhow!(
            "{e}: shorten the stages with --coarse and --fine (their sum at most the log's \
             span), or give a longer log"
        ),
        other => anyhow::Error::new(other),
    })
}

fn deg3(v: &Vector3<f64>) -> [f64; 3] {
    v.map(f64::to_degrees).into()
}

/// One row of the attitude table: the stage ending at `t` [s], its roll, pitch and
/// heading (0..360) [deg] and their standard deviations `sd` [deg].
fn stage_row(s: &mut String, name: &str, t: f64, e: &Euler, sd: &Vector3<f64>) {
    let _ = writeln!(
        s,
        "{name:6} | {t:9.2} | {:9.5} ± {:8.5} | {:9.5} ± {:8.5} | {:9.4} ± {:7.4}",
        e.roll.to_degrees(),
        sd.x,
        e.pitch.to_degrees(),
        sd.y,
        e.heading_0_2pi().to_degrees(),
        sd.z
    );
}

/// The sensor biases the fine stage left unobservable at rest (their estimates stay
/// at the prior), as `gyro bias x` etc. Sensor errors only: the attitude's prior is
/// already the coarse stage's bias-limited result, so its ratio says nothing about
/// observability.
fn unobservable_biases(a: &Alignment) -> Vec<String> {
    a.observability
        .iter()
        .filter(|(n, r)| *r >= schuler::align::OBSERVABLE_RATIO && n.starts_with('b'))
        .map(|(n, _)| {
            let axis = n.chars().last().unwrap_or('?');
            let sensor = if n.starts_with("bg") { "gyro" } else { "accel" };
            format!("{sensor} bias {axis}")
        })
        .collect()
}

/// The fine stage's gyro [deg/h] and accelerometer [mGal] bias estimates with their
/// standard deviations, and which of them stayed unobservable.
fn write_biases(s: &mut String, a: &Alignment) {
    let bg = a.gyro_bias / DEG_PER_H;
    let bgs = a.gyro_bias_std / DEG_PER_H;
    let ba = a.accel_bias / MGAL;
    let bas = a.accel_bias_std / MGAL;
    let _ = writeln!(
        s,
        "gyro bias  [deg/h]: {:+.5} ± {:.5}, {:+.5} ± {:.5}, {:+.5} ± {:.5}",
        bg.x, bgs.x, bg.y, bgs.y, bg.z, bgs.z
    );
    let _ = writeln!(
        s,
        "accel bias [mGal]:  {:+.1} ± {:.1}, {:+.1} ± {:.1}, {:+.1} ± {:.1}",
        ba.x, bas.x, ba.y, bas.y, ba.z, bas.z
    );
    let unobservable = unobservable_biases(a);
    let _ = writeln!(
        s,
        "not observable at rest (standard deviation near its prior; the estimate moves \
         only with the states it is correlated with): {}",
        if unobservable.is_empty() {
            "none".to_string()
        } else {
            unobservable.join(", ")
        }
    );
}

/// What the pre-filter's motion detector found, and that the stillness noise was
/// raised to match.
fn write_motion(s: &mut String, m: &MotionReport) {
    if !(m.angular_motion || m.vibration) {
        let _ = writeln!(s, "motion: none beyond the sensor noise");
        return;
    }
    let _ = writeln!(
        s,
        "motion detected: {}{}; the filter's stillness noise was raised to match",
        if m.angular_motion {
            format!(
                "angular motion (gyro block scatter {:.2e} rad/s vs noise {:.2e})",
                m.gyro_block_scatter.max(),
                m.gyro_block_noise.max()
            )
        } else {
            String::new()
        },
        if m.vibration {
            format!(
                "{}vibration (accel scatter {:.3} m/s^2 vs noise {:.3})",
                if m.angular_motion { ", " } else { "" },
                m.accel_sample_scatter.max(),
                m.accel_sample_noise.max()
            )
        } else {
            String::new()
        }
    );
}

/// The report printed on stdout.
pub fn summary_text(a: &Alignment, timing: &[(&str, f64)]) -> String {
    let mut s = String::new();
    let lim = a.predicted_limit.map(f64::to_degrees);
    let _ = writeln!(
        s,
        "predicted accuracy after both stages (1 sigma): level {:.5} / {:.5} deg, heading {:.4} deg",
        lim.x, lim.y, lim.z
    );
    let _ = writeln!(
        s,
        "stage  | t_end [s] | roll ± std [deg]      | pitch ± std [deg]     | yaw ± std [deg]"
    );
    let coarse = Euler::from_quaternion(&a.coarse.q_bn);
    stage_row(
        &mut s,
        "coarse",
        a.t_coarse,
        &coarse,
        &a.coarse_std.map(f64::to_degrees),
    );
    if a.fine.is_some() {
        let sd = a.attitude_std.map(f64::to_degrees);
        stage_row(&mut s, "fine", a.t_end, &a.state.euler(), &sd);
        write_biases(&mut s, a);
    }
    let _ = writeln!(s, "spikes rejected: {}", a.spikes.len());
    for sp in a.spikes.iter().take(5) {
        let _ = writeln!(
            s,
            "  t = {} s, channel {}, {:.0} sigma",
            sp.t, sp.channel, sp.sigmas
        );
    }
    write_motion(&mut s, &a.motion);
    let times: Vec<String> = timing
        .iter()
        .map(|(n, t)| format!("{n} {:.3} s", t))
        .collect();
    if !times.is_empty() {
        let _ = writeln!(s, "run time: {}", times.join(", "));
    }
    s
}

/// `align.json`: the keys plus the coarse stage, predicted limits and
/// observability (no run times, so the file is the same for the same input).
pub fn to_json(a: &Alignment) -> serde_json::Value {
    let e = a.state.euler();
    let c = schuler::rotation::Euler::from_quaternion(&a.coarse.q_bn);
    serde_json::json!({
        "roll_deg": e.roll.to_degrees(),
        "pitch_deg": e.pitch.to_degrees(),
        "yaw_deg": e.heading_0_2pi().to_degrees(),
        "roll_std_deg": a.attitude_std.x.to_degrees(),
        "pitch_std_deg": a.attitude_std.y.to_degrees(),
        "yaw_std_deg": a.attitude_std.z.to_degrees(),
        "gyro_bias_dph": <[f64; 3]>::from(a.gyro_bias / DEG_PER_H),
        "gyro_bias_std_dph": <[f64; 3]>::from(a.gyro_bias_std / DEG_PER_H),
        "accel_bias_mgal": <[f64; 3]>::from(a.accel_bias / MGAL),
        "accel_bias_std_mgal": <[f64; 3]>::from(a.accel_bias_std / MGAL),
        "t_start": a.t_start,
        "t_coarse": a.t_coarse,
        "t_end": a.t_end,
        "lat_deg": a.state.pos.lat.to_degrees(),
        "lon_deg": a.state.pos.lon.to_degrees(),
        "h_m": a.state.pos.h,
        "coarse": {
            "roll_deg": c.roll.to_degrees(),
            "pitch_deg": c.pitch.to_degrees(),
            "yaw_deg": c.heading_0_2pi().to_degrees(),
            "std_deg": deg3(&a.coarse_std),
        },
        "predicted_limit_deg": {
            "level_north": a.predicted_limit.x.to_degrees(),
            "level_east": a.predicted_limit.y.to_degrees(),
            "heading": a.predicted_limit.z.to_degrees(),
        },
        "observability": a.observability.iter().map(|(n, r)| serde_json::json!({
            "state": n,
            "posterior_over_prior_std": r,
            "observable": *r < schuler::align::OBSERVABLE_RATIO,
        })).collect::<Vec<_>>(),
        "spikes": a.spikes.iter().map(|s| serde_json::json!({
            "t": s.t, "channel": s.channel, "sigmas": s.sigmas
        })).collect::<Vec<_>>(),
        "motion": {
            "angular_motion": a.motion.angular_motion,
            "vibration": a.motion.vibration,
            "gyro_block_scatter_rad_s": <[f64; 3]>::from(a.motion.gyro_block_scatter),
            "accel_sample_scatter_m_s2": <[f64; 3]>::from(a.motion.accel_sample_scatter),
        },
    })
}

/// Columns of `align_convergence.csv` ([`convergence_row`]).
pub const CONVERGENCE_COLUMNS: [&str; 10] = [
    "t",
    "roll_std_deg",
    "pitch_std_deg",
    "yaw_std_deg",
    "gyro_bias_std_x_dph",
    "gyro_bias_std_y_dph",
    "gyro_bias_std_z_dph",
    "accel_bias_std_x_mgal",
    "accel_bias_std_y_mgal",
    "accel_bias_std_z_mgal",
];

/// One row of `align_convergence.csv`: time [s], the attitude standard deviations
/// [deg], the gyro bias ones [deg/h] and the accelerometer bias ones [mGal].
pub fn convergence_row(c: &schuler::align::fine::Convergence) -> [f64; 10] {
    let a = c.attitude_std.map(f64::to_degrees);
    let g = c.gyro_bias_std / DEG_PER_H;
    let b = c.accel_bias_std / MGAL;
    [c.t, a.x, a.y, a.z, g.x, g.y, g.z, b.x, b.y, b.z]
}

/// Write `align.json`, `align_convergence.csv` and `align_convergence.svg` into `dir`.
pub fn write_outputs(dir: &Path, a: &Alignment) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json = serde_json::to_string_pretty(&to_json(a))?;
    let path = dir.join("align.json");
    schuler_io::line_file::write_whole(&path, json + "\n")?;
    let Some(fine) = &a.fine else { return Ok(()) };
    let mut csv = CONVERGENCE_COLUMNS.join(",") + "\n";
    for c in &fine.convergence {
        let row = convergence_row(c).map(|x| x.to_string());
        let _ = writeln!(csv, "{}", row.join(","));
    }
    let path = dir.join("align_convergence.csv");
    schuler_io::line_file::write_whole(&path, csv)?;
    let t: Vec<f64> = fine.convergence.iter().map(|c| c.t - a.t_start).collect();
    let col = |i: usize| -> Vec<f64> {
        fine.convergence
            .iter()
            .map(|c| (c.attitude_std[i].to_degrees() * 3600.0).log10())
            .collect()
    };
    Plot::new(
        "Fine alignment: attitude standard deviation",
        "t since start [s]",
        "log10(std [arcsec])",
    )
    .line("roll", &t, &col(0), LineStyle::Solid)
    .line("pitch", &t, &col(1), LineStyle::Dashed)
    .line("yaw", &t, &col(2), LineStyle::Dotted)
    .write(&dir.join("align_convergence.svg"))
}
/// Arguments of `schuler align`.
#[derive(clap::Args, Debug)]
pub struct AlignArgs {
    /// IMU log recorded at rest (KF-GINS text or CSV).
    #[arg(long, value_name = "FILE")]
    pub imu: PathBuf,
    /// Position of the base: latitude [deg], longitude [deg], height [m].
    #[arg(long, value_name = "LAT,LON,H", allow_hyphen_values = true)]
    pub pos: Triple,
    /// Alignment options.
    #[command(flatten)]
    pub options: AlignOptions,
    /// Start time [s, the log's clock] (default: the first sample).
    #[arg(long, value_name = "SOW")]
    pub start: Option<f64>,
    /// Output directory for align.json, align_convergence.csv and .svg.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Earth model.
    #[arg(long, value_enum, default_value = "wgs84")]
    pub earth: EarthChoice,
    /// How to read the IMU log: format, layout, columns, units, clock, axes.
    #[command(flatten)]
    pub input: ImuInputOptions,
}

/// `schuler align`'s own options beside its two groups, as data (each optional here,
/// so that each is read alone; the required ones are checked after).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AlignOwn {
    imu: Option<PathBuf>,
    pos: Option<Triple>,
    start: Option<f64>,
    out: Option<PathBuf>,
    #[serde(default)]
    earth: EarthChoice,
}

impl AlignArgs {
    /// The arguments described by flat options, each the name of a flag with
    /// underscores (Python's keyword arguments; see [`crate::flat_options`]).
    pub fn from_options(options: toml::Table) -> Result<Self> {
        use crate::flat_options::{keys_of, partition, read_group, unknown_option};
        let (align_keys, input_keys) = (keys_of::<AlignOptions>(), ImuInputOptions::keys());
        let (groups, own) = partition(options, &[&align_keys, &input_keys]);
        let known = keys_of::<AlignArgs>();
        if let Some(k) = own.keys().find(|k| !known.contains(k)) {
            return Err(unknown_option(k, &known));
        }
        let [options, input] = <[toml::Table; 2]>::try_from(groups)
            .map_err(|_| anyhow::anyhow!("two option groups"))?;
        let own: AlignOwn = read_group(own)?;
        let required = |name: &str| anyhow::anyhow!("option `{name}` is required");
        Ok(Self {
            imu: own.imu.ok_or_else(|| required("imu"))?,
            pos: own.pos.ok_or_else(|| required("pos"))?,
            options: read_group(options)?,
            start: own.start,
            out: own.out,
            earth: own.earth,
            input: read_group(input)?,
        })
    }
}

/// The checked configuration, noise model and base position of `args`.
pub fn setup(args: &AlignArgs) -> Result<(AlignConfig, ImuNoise, Geodetic)> {
    let (cfg, noise) = args.options.resolve()?;
    let Triple([lat, lon, h]) = args.pos;
    if !(-90.0..=90.0).contains(&lat) {
        bail!("--pos: latitude {lat} deg is outside [-90, 90]");
    }
    Ok((cfg, noise, Geodetic::from_degrees(lat, lon, h)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    #[command(no_binary_name = true)]
    struct Flags {
        #[command(flatten)]
        args: AlignArgs,
    }

    #[test]
    fn options_by_name_give_the_arguments_of_their_flags() {
        let flags = [
            "--imu=a.txt",
            "--pos=45,7,200",
            "--coarse=60 s",
            "--imu-grade=navigation",
            "--gyro-unit=deg/s",
        ];
        let a = Flags::try_parse_from(flags).expect("flags").args;
        let options = "imu = 'a.txt'\npos = [45, 7, 200]\ncoarse = '60 s'\nimu_grade = 'navigation'\ngyro_unit = 'deg/s'";
        let b = AlignArgs::from_options(options.parse().expect("toml")).expect("options");
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        let e = AlignArgs::from_options("imu = 'a.txt'".parse().expect("toml")).unwrap_err();
        assert_eq!(e.to_string(), "option `pos` is required");
        let e = AlignArgs::from_options(
            "imu = 'a'\npos = [0, 0, 0]\nblocks = '1 s'"
                .parse()
                .expect("toml"),
        );
        assert_eq!(
            e.unwrap_err().to_string(),
            "unknown option `blocks` (did you mean `block`?)"
        );
    }
}
