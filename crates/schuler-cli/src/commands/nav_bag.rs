//! `schuler nav --bag`: a ROS 1 or ROS 2 bag as the run's input
//! ([`schuler_run::bag_input`]), what it holds and the noise its covariances give told
//! on stderr.

use super::nav::{navigate_printing, print_summary};
use anyhow::{Result, bail};
use indicatif::ProgressBar;
use schuler_io::bag::input::{BagPlan, Kind, Mounting};
use schuler_run::bag_input::{plan_bag, read_options};
use schuler_run::nav::{NavPlan, filter_grade};
use std::time::Instant;

/// The chosen topics, the clock and what was found, on stderr.
fn describe(p: &BagPlan) {
    eprintln!(
        "{}: {}",
        p.path.display(),
        schuler_io::bag::clock::describe(&p.clock)
    );
    for kind in Kind::ALL {
        if let Some(t) = p.topic(kind) {
            eprintln!("{}: {} from {t}", p.path.display(), kind.type_name());
        }
    }
    eprintln!(
        "{}: nominal IMU rate {:.6} Hz; {} GNSS fixes ({} NO_FIX skipped, {} with velocity), {} barometer, {} odometer readings",
        p.path.display(),
        1.0 / p.nominal_dt,
        p.aids.fixes.len(),
        p.aids.no_fix,
        p.aids.fixes.iter().filter(|f| f.vel.is_some()).count(),
        p.aids.baro.len(),
        p.aids.odometer.len()
    );
    describe_mounting(p);
    if p.aids.unmatched_velocities > 0 {
        eprintln!(
            "warning: {}: {} velocity messages have no fix at the same stamp and are not used",
            p.path.display(),
            p.aids.unmatched_velocities
        );
    }
}

/// Where the IMU's axes came from, as the `--imu-rotation` that gives the same.
fn describe_mounting(p: &BagPlan) {
    let path = p.path.display();
    let e = schuler::rotation::Euler::from_dcm(&p.c_vs);
    let as_flag = format!(
        "--imu-rotation {:.6},{:.6},{:.6}",
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        e.yaw.to_degrees()
    );
    match &p.mounting {
        Mounting::Tf {
            imu_frame,
            base_frame,
        } => eprintln!(
            "{path}: IMU mounting from /tf_static: {imu_frame} in {base_frame} (FLU), as {as_flag}"
        ),
        Mounting::Given {
            tf_ignored: Some(base),
        } => eprintln!(
            "warning: {path}: the IMU's axes given by hand ({as_flag}) override /tf_static's mounting in {base}"
        ),
        Mounting::Given { tf_ignored: None } => {}
        Mounting::Flu { imu_frame } => eprintln!(
            "{path}: IMU axes FLU (REP 103): /tf_static does not place its frame {}",
            imu_frame.as_deref().unwrap_or("(none)")
        ),
    }
}

/// The barometer's and the odometer's noise from the messages' variances, where they
/// give them and neither a flag nor a file of the same kind does (as the IMU's
/// covariances give ARW and VRW); printed.
fn noise_of_variances(plan: &mut NavPlan, bag: &BagPlan) {
    let a = &mut plan.aiding;
    let path = bag.path.display();
    if let Some(std) = bag.aids.baro_std
        && a.baro.is_none()
        && a.baro_std.is_none()
    {
        a.baro_std = Some(std.to_string());
        eprintln!(
            "{path}: barometer noise from its pressure variances: {std} m (--baro-std overrides)"
        );
    }
    if let Some(std) = bag.aids.odometer_std
        && a.odometer.is_none()
        && a.odometer_std.is_none()
    {
        a.odometer_std = Some(std.to_string());
        eprintln!(
            "{path}: odometer noise from its twist covariances: {std} m/s (--odometer-std overrides)"
        );
    }
}

/// `schuler nav --bag`.
pub fn run(mut plan: NavPlan) -> Result<()> {
    let args = plan.bag.clone();
    let Some(path) = &args.bag else {
        bail!("--bag is missing");
    };
    let started = Instant::now();
    let options = read_options(&plan, &args, plan.axes_given)?;
    let bag = plan_bag(path, &options)?;
    describe(&bag);
    noise_of_variances(&mut plan, &bag);
    if let Some(week) = bag.clock.week() {
        let given = plan.settings.week;
        if given != 0 && given != week {
            bail!("--week {given}: the bag's UNIX stamps are in GPS week {week}");
        }
        plan.settings.week = week;
    }
    if let Some(out) = plan.settings.out_bag.as_mut() {
        out.clock = bag.clock;
    }
    plan.aiding.bag = Some(bag.aids.clone());
    let mut noise = filter_grade(&plan).noise()?;
    if let Some((arw, vrw)) = bag.imu_noise {
        // The flags override the covariances (applied in resolve).
        noise.arw = arw;
        noise.vrw = vrw;
        eprintln!(
            "{}: IMU noise from its covariances: ARW {:.4} deg/sqrt(h), VRW {:.4} m/s/sqrt(h) (largest axis; --arw, --vrw override)",
            path.display(),
            arw.max().to_degrees() * 60.0,
            vrw.max() * 60.0
        );
    }
    let mut aiding = plan.aiding.resolve(noise)?;
    let mut samples = bag.imu_samples()?;
    let bar = ProgressBar::hidden();
    let summary = navigate_printing(&plan, &mut aiding, &mut samples, &bar, |_| {})?;
    let secs = started.elapsed().as_secs_f64();
    let gaps = samples.gaps();
    if !gaps.is_empty() {
        eprintln!(
            "warning: {}: topic {}: {gaps}",
            path.display(),
            samples.topic()
        );
    }
    print_summary(&plan, aiding.as_ref(), &summary, secs)
}
