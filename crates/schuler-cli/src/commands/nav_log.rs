//! `schuler nav --log`: a device log as the run's input ([`schuler_run::log_input`]):
//! the streams chosen told on stderr, and the device's own solution compared with
//! ours after the run ([`schuler_run::log_reference`]).

use super::nav::{navigate_printing, print_summary};
use anyhow::{Result, bail};
use indicatif::ProgressBar;
use schuler_run::log_input::{LogPlan, plan_log};
use schuler_run::log_reference::{ReferenceComparison, compare_reference};
use schuler_run::nav::{NavPlan, filter_grade};
use std::time::Instant;

/// The chosen streams and what they hold, on stderr.
fn describe(p: &LogPlan) {
    let path = p.path.display();
    eprintln!(
        "{path}: {}; IMU from {} ({} samples, {:.3} Hz); GNSS {}; barometer {}; {} fixes ({} with velocity), {} barometer readings",
        p.format.name(),
        p.imu.1,
        p.imu_samples,
        p.imu_rate,
        p.gnss.as_deref().unwrap_or("none"),
        p.baro.as_deref().unwrap_or("none"),
        p.aids.fixes.len(),
        p.aids.fixes.iter().filter(|f| f.vel.is_some()).count(),
        p.aids.baro.len()
    );
    if let Some(shift) = p.baro_shift {
        eprintln!("{path}: barometer heights shifted by {shift:.3} m to the first fix's height");
    }
}

/// The device's solution against ours, on stdout.
fn print_reference(c: &ReferenceComparison) {
    let (np, p) = c.position;
    let (nv, v) = c.velocity;
    let (na, a) = c.attitude;
    println!(
        "against the device's own solution ({}, {} samples; schuler minus device, RMS): \
         position N/E/D {:.3} {:.3} {:.3} m ({np} samples), velocity {:.3} {:.3} {:.3} m/s \
         ({nv}), roll/pitch/yaw {:.3} {:.3} {:.3} deg ({na}); written to {}",
        c.stream,
        c.compared,
        p[0],
        p[1],
        p[2],
        v[0],
        v[1],
        v[2],
        a[0],
        a[1],
        a[2],
        c.file.display()
    );
}

/// `schuler nav --log` (a log that is no ROS bag; bags go to `--bag`'s run).
pub fn run(mut plan: NavPlan) -> Result<()> {
    let Some(path) = plan.log.log.clone() else {
        bail!("--log is missing");
    };
    let started = Instant::now();
    let format = schuler_io::logs::detect(&path)?;
    let log = plan_log(&path, format, &plan.log)?;
    describe(&log);
    if let Some(week) = log.week() {
        let given = plan.settings.week;
        if given != 0 && given != week {
            bail!("--week {given}: the log's clock is in GPS week {week}");
        }
        plan.settings.week = week;
    }
    plan.aiding.bag = Some(log.aids.clone());
    let mut aiding = plan.aiding.resolve(filter_grade(&plan).noise()?)?;
    let mut samples = log.imu_samples(&plan)?;
    let bar = ProgressBar::hidden();
    let summary = navigate_printing(&plan, &mut aiding, &mut samples, &bar, |_| {})?;
    let secs = started.elapsed().as_secs_f64();
    print_summary(&plan, aiding.as_ref(), &summary, secs)?;
    if let Some(c) = compare_reference(&log, &plan.settings.out)? {
        print_reference(&c);
    }
    Ok(())
}
