//! `schuler align`: initial alignment of an IMU log recorded at rest (coarse
//! gyrocompassing, then the Kalman filter on invariants), with a report, `align.json`,
//! the convergence history as CSV and an SVG plot. The same settings serve
//! `schuler nav --align` ([`schuler_run::alignment`]).

use anyhow::{Context, Result, bail};
use schuler::align::AlignConfig;
use schuler::earth::Geodetic;
use schuler::filter::ImuNoise;
use schuler_io::formats::ImuReader;
use schuler_run::alignment::{AlignOptions, align_on, read_stage, summary_text, write_outputs};
use schuler_run::imu_input::ImuInputOptions;
use schuler_run::options::{EarthChoice, Triple};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `schuler align`.
#[derive(clap::Args, Debug)]
pub struct Args {
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

/// The checked configuration, noise model and base position of `args`.
pub fn setup(args: &Args) -> Result<(AlignConfig, ImuNoise, Geodetic)> {
    let (cfg, noise) = args.options.resolve()?;
    let Triple([lat, lon, h]) = args.pos;
    if !(-90.0..=90.0).contains(&lat) {
        bail!("--pos: latitude {lat} deg is outside [-90, 90]");
    }
    Ok((cfg, noise, Geodetic::from_degrees(lat, lon, h)))
}

/// `schuler align`.
pub fn run(args: Args) -> Result<()> {
    let (cfg, noise, pos) = setup(&args)?;
    let read = args.input.read_options(args.start, None)?;
    let started = Instant::now();
    let mut reader = ImuReader::open(&args.imu, &read)?;
    let samples = read_stage(&mut reader, cfg.coarse + cfg.fine)?;
    let t_read = started.elapsed().as_secs_f64();
    let a = align_on(args.earth, pos, &samples, &noise, &cfg)
        .with_context(|| format!("aligning {}", args.imu.display()))?;
    let [pre, coarse, fine] = a.stage_seconds;
    print!(
        "{}",
        summary_text(
            &a,
            &[
                ("reading", t_read),
                ("pre-filter", pre),
                ("coarse", coarse),
                ("fine", fine)
            ]
        )
    );
    if let Some(dir) = &args.out {
        write_outputs(dir, &a)?;
        println!("wrote {}", dir.join("align.json").display());
    }
    Ok(())
}
