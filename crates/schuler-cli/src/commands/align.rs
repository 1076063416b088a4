//! `schuler align`: initial alignment of an IMU log recorded at rest (coarse
//! gyrocompassing, then the Kalman filter on invariants), with a report, `align.json`,
//! the convergence history as CSV and an SVG plot. The same settings serve
//! `schuler nav --align` ([`schuler_run::alignment`]).

use anyhow::{Context, Result};
use schuler_io::formats::ImuReader;
use schuler_run::alignment::{AlignArgs, align_on, read_stage, setup, summary_text, write_outputs};
use std::time::Instant;

/// `schuler align`.
pub fn run(args: AlignArgs) -> Result<()> {
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
