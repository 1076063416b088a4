//! `schuler nav`: navigation of an IMU log, free-inertial or aided (`--gnss`,
//! `--baro`, vehicle aids), optionally after an alignment at rest (`--align`), or a
//! KF-GINS configuration (`--kf-gins-config`).
//!
//! Reads the log lazily and pushes it into the library's navigation session
//! ([`schuler::session`]), which starts from the given initial state at the time tag
//! of the first processed sample; writes `nav.txt` (KF-GINS navigation-result format)
//! and `nav.csv` (with ECEF position and wander azimuth) at the requested output rate
//! ([`schuler_run::navigate`]).
//!
//! Mechanizations (`--mechanization`): `ned` (latitude/longitude, singular at the
//! poles), `wander` (the all-latitude free-azimuth mechanization of seed 003, valid
//! everywhere), or `auto` (default): NED while `|lat| <= auto_latitude`, wander above
//! it, back to NED below `auto_latitude − auto_hysteresis` (defaults 75° and 0.5°),
//! in free and aided runs alike (the filter is carried across the hand-over).

use anyhow::{Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use schuler_io::formats::{ImuFormat, ImuReader};
use schuler_run::aided::Aiding;
use schuler_run::nav::{BANK_MEMBERS, navigate_samples, parse_nav_args};
use schuler_run::nav::{Began, InitChoice, NavArgs, NavPlan, Navigated, filter_grade};
use schuler_run::navigate::{NavSettings, RunSummary, samples_of};
use std::path::Path;
use std::time::Instant;

/// A progress bar over the IMU file's bytes.
pub fn progress_bar(imu: &Path) -> ProgressBar {
    let total = std::fs::metadata(imu).map(|m| m.len()).unwrap_or(0);
    let bar = ProgressBar::with_draw_target(Some(total), indicatif::ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} navigating [{bar:40}] {percent:>3}% {bytes}/{total_bytes} eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// How the run began, on stdout: an alignment's report, or the start in motion from
/// the fixes.
fn print_start(began: &Began, aiding: Option<&Aiding>, init: InitChoice, bar: &ProgressBar) {
    let m = match began {
        Began::Given => return,
        Began::Aligned(a) => {
            bar.suspend(|| print!("{}", schuler_run::alignment::summary_text(a, &[])));
            return;
        }
        Began::InMotion(m) => m,
    };
    let fixes = aiding.map(|a| &a.fixes);
    let e = m.state.euler();
    let heading = match init {
        InitChoice::Gnss => format!(
            "heading {:.2} ± {:.2} deg (the course: forward motion along the IMU's x axis assumed)",
            e.heading_0_2pi().to_degrees(),
            m.att_std.z.to_degrees()
        ),
        _ => format!("heading unknown: a bank of {BANK_MEMBERS} filters searches it"),
    };
    let fix_t = |i: usize| {
        fixes
            .and_then(|f| f.iter().nth(i))
            .map_or(f64::NAN, |f| f.t)
    };
    println!(
        "started in motion at t = {} s from the fixes at {} and {} s: {:.2} m/s, {heading}, roll {:.2} pitch {:.2} ± {:.2} deg",
        m.state.t,
        fix_t(m.fixes.0),
        fix_t(m.fixes.1),
        m.speed,
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        m.att_std.x.to_degrees()
    );
}

/// The heading bank's choice, on stdout.
fn print_bank(navigated: &Navigated) {
    if let Some((yaw0, decided)) = navigated.bank {
        println!(
            "heading bank: kept the filter started at {:.0} deg, decided at t = {decided} s",
            yaw0.to_degrees().rem_euclid(360.0)
        );
    }
}

/// The run from an open IMU source ([`navigate_samples`]) with its start and the
/// heading bank's choice printed.
pub fn navigate_printing<I, E>(
    plan: &NavPlan,
    aiding: &mut Option<Aiding>,
    reader: &mut I,
    bar: &ProgressBar,
    mut on_sample: impl FnMut(u64),
) -> Result<RunSummary>
where
    I: Iterator<Item = Result<schuler::imu::ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let mut on_start = |b: &Began, a: Option<&Aiding>| print_start(b, a, plan.init, bar);
    let mut samples = samples_of(reader);
    let navigated = navigate_samples(plan, aiding, &mut samples, &mut on_start, &mut on_sample)?;
    print_bank(&navigated);
    Ok(navigated.summary)
}

/// The run's summary on stdout (aided or free-inertial), `secs` its wall time.
pub fn print_summary(
    plan: &NavPlan,
    aiding: Option<&Aiding>,
    summary: &RunSummary,
    secs: f64,
) -> Result<()> {
    match aiding {
        Some(a) => {
            if plan.init != InitChoice::Given {
                print_heading_settled(summary);
            }
            print_aided(&plan.settings, a, summary, secs)
        }
        None => {
            print_free(&plan.settings, summary, secs);
            Ok(())
        }
    }
}

/// `schuler nav` on an IMU log (`--kf-gins-config` is dispatched before, by
/// [`crate::commands::run_nav`]; `--bag` goes to [`schuler_run::bag_input::run`], `--log` to [`super::nav_log::run`]).
pub fn run(args: NavArgs) -> Result<()> {
    let plan = parse_nav_args(args)?;
    if plan.bag.bag.is_some() {
        return super::nav_bag::run(plan);
    }
    if plan.log.log.is_some() {
        return super::nav_log::run(plan);
    }
    let mut aiding: Option<Aiding> = plan.aiding.resolve(filter_grade(&plan).noise()?)?;
    let settings = &plan.settings;
    let started = Instant::now();
    let reader = ImuReader::open(&settings.imu, &settings.read)?;
    eprintln!(
        "{}: {}, {}, nominal rate {:.6} Hz",
        settings.imu.display(),
        match reader.format() {
            ImuFormat::Csv => "CSV",
            _ => "KF-GINS text",
        },
        reader.layout(),
        1.0 / reader.nominal_dt()
    );
    let bar = progress_bar(&settings.imu);
    let progress = reader.progress();
    let on_sample = |_| bar.set_position(progress.bytes());
    // Read and parsed on a second thread, overlapping the navigation.
    let mut reader = reader.read_ahead()?;
    let summary = navigate_printing(&plan, &mut aiding, &mut reader, &bar, on_sample)?;
    bar.set_position(progress.bytes());
    bar.finish_and_clear();
    let secs = started.elapsed().as_secs_f64();
    if aiding.is_none() {
        let report = reader.gaps();
        if !report.is_empty() {
            eprintln!("warning: {}: {report}", settings.imu.display());
        }
    }
    print_summary(&plan, aiding.as_ref(), &summary, secs)
}

/// What the filter estimated of the set-up: the vehicle mounting and the
/// calibrations, each ready as the flags for next time.
fn print_estimates(aiding: &Aiding, summary: &RunSummary) {
    if let Some((mount, [sp, sy])) = summary.nav.mounting {
        let e = schuler::rotation::Euler::from_quaternion(&mount.q_vb);
        println!(
            "mounting estimated: the vehicle frame's roll {:.3}, pitch {:.3} ± {:.3}, yaw {:.3} ± {:.3} deg relative to the IMU (use as --mounting-angles)",
            e.roll.to_degrees(),
            e.pitch.to_degrees(),
            sp.to_degrees(),
            e.yaw.to_degrees(),
            sy.to_degrees()
        );
    }
    for line in schuler_run::aided::calibration::summary_lines(
        &summary.nav.calibration,
        &aiding.filter.integration.lever_arm,
        aiding.gnss_time_shift,
    ) {
        println!("{line}");
    }
}

/// The aided run's summary on stdout (and its outage test).
fn print_aided(
    settings: &NavSettings,
    aiding: &Aiding,
    summary: &RunSummary,
    secs: f64,
) -> Result<()> {
    let c = summary.nav.counts;
    println!(
        "integrated {} samples with {} GNSS fixes in {:.2} s: {} position and {} velocity updates, {} rejected by the gate, {} outside the IMU data (see rejected.csv); mean NIS per dimension {}",
        summary.nav.samples,
        aiding.fixes.len(),
        secs,
        c.position,
        c.velocity,
        c.rejected,
        c.skipped,
        mean_nis_text(summary.nav.mean_nis_per_dof)
    );
    print_handovers(&summary.nav);
    print!("{}", summary.report_text);
    if let Some(line) = schuler_run::aided::vehicle::summary(&c) {
        println!("{line}");
    }
    print_estimates(aiding, summary);
    if let Some(test) = &aiding.outage_test {
        schuler_run::aided::report_outage_test(
            &settings.out.join("nav.txt"),
            &test.windows,
            test.truth.as_deref(),
            &settings.out,
        )?;
    }
    let tried = c.position
        + c.velocity
        + c.baro
        + c.zupt
        + c.zaru
        + c.nhc
        + c.odometer
        + c.heading
        + c.rejected;
    let nis = summary.nav.mean_nis_per_dof;
    let wrote = format!(
        "wrote {} epochs to {} (and nav.csv, std.txt, imu_err.txt, rejected.csv)",
        summary.epochs,
        settings.out.join("nav.txt").display()
    );
    if c.rejected * 2 > tried && nis > INCONSISTENT_NIS_PER_DOF {
        println!("{wrote}");
        bail!(
            "the filter disagrees with its measurements: the gate refused {} of {tried} and the \
             mean NIS per dimension is {nis:.0} (a consistent filter gives 1): its solution and \
             the standard deviations it reports are not to be trusted. The IMU data do not move \
             as the aids do: gyro or accelerometer columns swapped or dead, axes mounted \
             otherwise (--imu-axes, --imu-columns), wrong units, or a far too optimistic noise \
             model (--imu-grade)",
            c.rejected
        );
    }
    if c.rejected * 10 > tried {
        print_gate_warning(&settings.out, c.rejected, tried);
    }
    println!("{wrote}");
    Ok(())
}

/// The warning of a gate that refused many measurements: which kinds it refused and
/// their likely causes (`rejected.csv` says which).
fn print_gate_warning(out: &std::path::Path, rejected: u64, tried: u64) {
    use schuler_run::aided::refusals::{by_kind, likely_causes};
    let kinds = by_kind(out);
    let Some((kind, n)) = kinds.first() else {
        eprintln!(
            "warning: the gate refused {rejected} of {tried} measurements: a measurement \
             misread or its noise too small, or the IMU noise model too optimistic \
             (--imu-grade, --arw, --gyro-bias-std, ...)"
        );
        return;
    };
    let all: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
    eprintln!(
        "warning: the gate refused {rejected} of {tried} measurements ({}; see \
         rejected.csv); for the {n} {kind} refused: {}",
        all.join(", "),
        likely_causes(kind)
    );
}

/// The mean NIS per dimension as printed: none when no update was accepted.
fn mean_nis_text(nis: f64) -> String {
    if nis.is_finite() {
        format!("{nis:.2}")
    } else {
        "none (no update accepted)".to_owned()
    }
}

/// Mean NIS per dimension beyond which, with most measurements refused, a run is
/// reported as failed: 100 is 10 standard deviations per dimension on average, where a
/// consistent filter gives 1 and a noise model optimistic by a factor of 3 gives 9.
const INCONSISTENT_NIS_PER_DOF: f64 = 100.0;

/// When the heading of a start in motion converged (its standard deviation below 1°).
fn print_heading_settled(summary: &RunSummary) {
    let t0 = summary.nav.t_first;
    match summary.heading_settled {
        Some((t, yaw)) => println!(
            "heading converged (std below 1 deg) at t = {t} s, {:.1} s after the start: {:.3} deg",
            t - t0,
            yaw.to_degrees()
        ),
        None => println!(
            "heading did not converge below 1 deg std (turns and accelerations make it observable)"
        ),
    }
}

/// The hand-overs between mechanizations, one line each.
fn print_handovers(s: &schuler::session::Summary) {
    for h in &s.handovers {
        println!(
            "  hand-over to {} at t = {} s, lat {:.6} deg",
            h.to,
            h.t,
            h.lat.to_degrees()
        );
    }
}

/// The free-inertial run's summary on stdout.
fn print_free(settings: &NavSettings, summary: &RunSummary, secs: f64) {
    let s = &summary.nav;
    println!("mechanization: {} from the start", s.first_mechanization);
    print_handovers(s);
    let last = s.last.normalized();
    let e = last.euler();
    println!(
        "navigated {} samples, t = {} .. {} s ({:.1} s of data) in {:.2} s ({:.2} M samples/s)",
        s.samples,
        s.t_first,
        s.t_last,
        s.t_last - s.t_first,
        secs,
        s.samples as f64 / secs / 1e6
    );
    println!(
        "final: lat {:.9} deg, lon {:.9} deg, h {:.3} m, v_ned [{:.3}, {:.3}, {:.3}] m/s, roll {:.4} pitch {:.4} yaw {:.4} deg",
        last.pos.lat.to_degrees(),
        (last.pos.lon.to_degrees() + 180.0).rem_euclid(360.0) - 180.0,
        last.pos.h,
        last.v_n.x,
        last.v_n.y,
        last.v_n.z,
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        e.heading_0_2pi().to_degrees()
    );
    println!(
        "wrote {} epochs to {} and {}",
        summary.epochs,
        settings.out.join("nav.txt").display(),
        settings.out.join("nav.csv").display()
    );
}
