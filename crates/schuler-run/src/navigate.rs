//! The run shared by `schuler nav` and its KF-GINS mode: a library [`Session`]
//! configured from the settings (and the aiding, if any), fed from the IMU reader,
//! its output written by [`crate::drive`]. With aiding the run also writes
//! `rejected.csv`, the smoothed trajectory on request and the consistency report.

use crate::aided::feed::AidFeed;
use crate::aided::report::{ReportData, RunFacts};
use crate::aided::spilled::Spilled;
use crate::aided::{Aiding, OutputNames};
use crate::drive::{Driven, FilterFiles, Outputs, drive, write_smoothed};
pub use crate::drive::{Samples, samples_of};
use crate::earth::AnyEarth;
use crate::options::EarthChoice;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic};
use schuler::filter::Layout;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler::session::{
    Aid, Chosen, Finished, HeadingBank, MechanizationConfig, Session, SessionConfig, SessionError,
    Snapshot, Start, Summary,
};
use schuler_io::formats::ImuReadOptions;
use schuler_io::output::NavWriter;
use std::path::{Path, PathBuf};

/// Everything a run needs besides its aiding, validated.
#[derive(Debug, Clone)]
pub struct NavSettings {
    /// IMU log.
    pub imu: PathBuf,
    /// Reader options.
    pub read: ImuReadOptions,
    /// Initial position (at the first processed sample's time).
    pub init_pos: Geodetic,
    /// Initial NED velocity [m/s].
    pub init_vel: Vector3<f64>,
    /// Initial attitude.
    pub init_att: Euler,
    /// Output rate [Hz], `None`: every sample.
    pub output_rate: Option<f64>,
    /// Output directory.
    pub out: PathBuf,
    /// Earth model.
    pub earth: EarthChoice,
    /// GPS week for nav.txt.
    pub week: u32,
    /// The mechanization and its hand-over latitudes.
    pub mechanization: MechanizationConfig,
    /// The result bag to write (`--out-bag`), if any.
    pub out_bag: Option<schuler_io::bag::output::OutBag>,
}

impl NavSettings {
    /// The start the settings give (no sensor error known).
    pub fn start(&self) -> Start {
        Start::at(NavState::new(
            0.0,
            self.init_pos,
            self.init_vel,
            self.init_att,
        ))
    }

    /// The session's configuration, with the filter of `aiding` if any; the
    /// filter's snapshots only where the report uses them (its HTML or a truth's
    /// NEES), so that a run without keeps nothing per epoch.
    pub fn session_config(&self, aiding: Option<&Aiding>) -> SessionConfig {
        let defaults = SessionConfig::default();
        let snapshots = aiding
            .is_some_and(|a| a.names.diagnostics && (a.report.html || a.report.truth.is_some()));
        SessionConfig {
            mechanization: self.mechanization,
            output_rate: self.output_rate,
            filter: aiding.map(|a| a.filter),
            snapshot_rate: if snapshots {
                defaults.snapshot_rate
            } else {
                0.0
            },
            ..defaults
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// The session's summary.
    pub nav: Summary,
    /// Epochs written.
    pub epochs: u64,
    /// The consistency summary to print (aided runs).
    pub report_text: String,
    /// The first output epoch whose heading standard deviation was below 1°: its time
    /// [s] and heading [rad].
    pub heading_settled: Option<(f64, f64)>,
}

/// The session from `start` with the settings' configuration (aided: with the
/// truth); configuration errors name the flag.
fn new_session<E: EarthModel>(
    earth: E,
    settings: &NavSettings,
    aiding: Option<&Aiding>,
    start: Start,
) -> Result<Session<E>> {
    let mut session =
        Session::new(earth, settings.session_config(aiding), start).map_err(named_flag)?;
    if let Some(r) = aiding.and_then(|a| a.raw.as_ref()) {
        session = session.with_tight(r.tight.clone()).map_err(named_flag)?;
    }
    if let Some(rows) = aiding.and_then(|a| a.report.truth.as_ref()?.held.clone()) {
        session = session.with_truth(rows);
    }
    Ok(session)
}

/// The session from `start` with the settings' configuration (aided: with the truth
/// and every aid pushed); configuration errors name the flag.
pub fn open_session<E: EarthModel>(
    earth: E,
    settings: &NavSettings,
    aiding: Option<&Aiding>,
    start: Start,
) -> Result<Session<E>> {
    let mut session = new_session(earth, settings, aiding, start)?;
    if let Some(a) = aiding {
        if a.report.truth.as_ref().is_some_and(|t| t.held.is_none()) {
            session = session.with_truth(a.report.truth_records()?);
        }
        for aid in aids(a) {
            session.push(aid)?;
        }
        if let Some(r) = &a.raw {
            for aid in r.read_aids()? {
                session.push(aid)?;
            }
        }
    }
    Ok(session)
}

/// The session (its aids to be fed in step with the samples, [`AidFeed`]) and the
/// outputs it writes into `settings.out`: the navigation result and, aided, the
/// filter's files.
fn open<'a, E: EarthModel>(
    earth: E,
    settings: &NavSettings,
    aiding: Option<&'a Aiding>,
    start: Start,
) -> Result<(Session<E>, AidFeed<'a>, Outputs)> {
    let mut session = new_session(earth, settings, aiding, start)?;
    let feed = match aiding {
        Some(a) => AidFeed::open(a, &mut session)?,
        None => AidFeed::none(),
    };
    Ok((session, feed, outputs(&earth, settings, aiding)?))
}

/// The outputs a run writes into `settings.out`: the navigation result and, aided,
/// the filter's files.
fn outputs<E: EarthModel>(
    earth: &E,
    settings: &NavSettings,
    aiding: Option<&Aiding>,
) -> Result<Outputs> {
    let out = &settings.out;
    let names = aiding.map_or(OutputNames::SCHULER, |a| a.names);
    let writer = NavWriter::create_named(out, names.nav, settings.week, earth, names.nav_csv)?;
    let files = match aiding {
        Some(a) => Some(FilterFiles::create(
            out,
            a.names.std,
            a.names.imu_err,
            names.diagnostics,
        )?),
        None => None,
    };
    let mut outputs = Outputs::new(writer, files);
    if !names.start_epoch {
        outputs = outputs.without_start_epoch();
    }
    if let Some(out_bag) = &settings.out_bag {
        outputs.bag = Some(schuler_io::bag::output::ResultBag::create(out_bag)?);
    }
    Ok(outputs)
}

/// The facts of an aided run, with summary `s`, that the report states.
fn run_facts<'a>(
    settings: &'a NavSettings,
    a: &'a Aiding,
    nav_file: &'a Path,
    s: &Summary,
) -> RunFacts<'a> {
    RunFacts {
        imu: &settings.imu,
        nav_file,
        mechanization: s.first_mechanization,
        layout: s.layout.unwrap_or_else(Layout::core),
        states: s.states.unwrap_or(Layout::core().n),
        samples: s.samples,
        t_first: s.t_first,
        t_last: s.t_last,
        counts: s.counts,
        gate_resets: s.gate_resets as usize,
        fixes: &a.fixes,
    }
}

/// The end of an aided run: the filter's files closed (`rejected.csv`) and the
/// smoothed trajectory written, then the read error that stopped the run if any, else
/// the consistency report; returns the text to print.
fn finish_aided<E: EarthModel>(
    earth: &E,
    settings: &NavSettings,
    a: &Aiding,
    files: FilterFiles,
    finished: &mut Finished,
    snapshots: &Spilled<Snapshot>,
    failure: Option<anyhow::Error>,
) -> Result<String> {
    let out = &settings.out;
    let log = files.finish(out)?;
    if let Some(smoothed) = finished.smoothed.take() {
        write_smoothed(earth, &out.join("smoothed"), settings.week, smoothed)?;
    }
    if let Some(e) = failure {
        return Err(e);
    }
    let Some(log) = log else {
        return Ok(String::new());
    };
    let nav_file = out.join(a.names.nav);
    crate::aided::report::write(
        out,
        a.report.html,
        &ReportData {
            facts: run_facts(settings, a, &nav_file, &finished.summary),
            innovations: &log.rows,
            samples: snapshots,
            settings: &a.report,
        },
    )
}

/// Navigate `samples` (the first carries `start`) on the Earth model `earth` with the
/// settings and, if given, the aiding; write everything into `settings.out`. On a
/// read error all that was computed is written before the error is returned.
/// `on_sample` is called every 65,536 samples with their count ([`drive`]).
pub fn navigate(
    earth: EarthChoice,
    settings: &NavSettings,
    aiding: Option<&Aiding>,
    start: Start,
    samples: &mut Samples<'_>,
    on_sample: &mut dyn FnMut(u64),
) -> Result<RunSummary> {
    let earth = AnyEarth::of(earth);
    let (session, feed, outputs) = open(earth, settings, aiding, start)?;
    let driven = drive(session, feed, samples, outputs, &settings.out, on_sample)?;
    conclude(&earth, settings, aiding, driven)
}

/// The end of a run driven through [`drive`] (`None`: no sample at all): the aided
/// run's files and report, the read error that stopped it if any, the summary.
fn conclude<E: EarthModel>(
    earth: &E,
    settings: &NavSettings,
    aiding: Option<&Aiding>,
    driven: Option<Driven>,
) -> Result<RunSummary> {
    let Some(driven) = driven else {
        bail!(
            "{}: no IMU sample in the requested time window",
            settings.imu.display()
        );
    };
    let Driven {
        mut finished,
        failure,
        epochs,
        filter,
        heading_settled,
        snapshots,
    } = driven;
    let report_text = match (aiding, filter) {
        (Some(a), Some(files)) => finish_aided(
            earth,
            settings,
            a,
            files,
            &mut finished,
            &snapshots,
            failure,
        )?,
        _ => match failure {
            Some(e) => return Err(e),
            None => String::new(),
        },
    };
    if let Some(a) = aiding {
        check_clocks(settings, a, &finished.summary)?;
    }
    Ok(RunSummary {
        nav: finished.summary,
        epochs,
        report_text,
        heading_settled,
    })
}

/// The IMU's and the GNSS fixes' time spans against each other, after the run: no
/// fix inside the IMU's span is an error (nothing aided the run: two clocks apart, a
/// UNIX-time GNSS log against an IMU clock starting at 0) that shows both spans and
/// the offset aligning their starts; fixes partly outside it a warning.
fn check_clocks(settings: &NavSettings, a: &Aiding, s: &Summary) -> Result<()> {
    let (Some(first), Some(last)) = (a.fixes.first(), a.fixes.last()) else {
        return Ok(());
    };
    let inside = a
        .fixes
        .iter()
        .filter(|f| f.t >= s.t_first && f.t <= s.t_last)
        .count();
    a.fixes.status()?;
    let spans = format!(
        "the IMU samples span t = {} .. {} s ({}), the GNSS fixes t = {} .. {} s",
        s.t_first,
        s.t_last,
        settings.imu.display(),
        first.t,
        last.t
    );
    if inside == 0 {
        bail!(
            "{spans}: no fix falls inside the IMU's span, so nothing aided the run (its \
             free-inertial result is in {}). Two clocks apart? An offset of {:+} s on the \
             GNSS stamps (or {:+} s on the IMU's) aligns their starts (--gnss-time-offset, \
             --imu-time-offset)",
            settings.out.display(),
            s.t_first - first.t,
            first.t - s.t_first
        );
    }
    if inside < a.fixes.len() {
        eprintln!(
            "warning: {spans}: {} of {} fixes fall outside the IMU's span and are not used",
            a.fixes.len() - inside,
            a.fixes.len()
        );
    }
    Ok(())
}

/// As [`navigate`] with the heading unknown: a bank of `members` sessions from every
/// `360°/members` of heading runs on the samples ([`schuler::session::HeadingBank`])
/// until the most likely leads every member more than a sector away from it by
/// [`BANK_MARGIN`] in log-likelihood (checked once a second), or `decide_after`
/// seconds past the first sample; the most likely goes on. Returns the summary, the
/// kept member's initial heading [rad], and the time the bank decided [s].
pub fn navigate_any_heading(
    earth: EarthChoice,
    settings: &NavSettings,
    aiding: &Aiding,
    start: Start,
    (members, decide_after): (usize, f64),
    samples: &mut Samples<'_>,
    on_sample: &mut dyn FnMut(u64),
) -> Result<(RunSummary, f64, f64)> {
    let earth = AnyEarth::of(earth);
    let bank = (members, decide_after);
    let (chosen, decided) = decide_heading(earth, settings, aiding, start, bank, samples)?;
    let mut out = outputs(&earth, settings, Some(aiding))?;
    for e in chosen.events {
        out.event(e)?;
    }
    let driven = drive(
        chosen.session,
        AidFeed::none(),
        samples,
        out,
        &settings.out,
        on_sample,
    )?;
    let summary = conclude(&earth, settings, Some(aiding), driven)?;
    Ok((summary, chosen.yaw0, decided))
}

/// The heading bank of [`navigate_any_heading`] run on `samples` (as many as it
/// needs) with `members` sessions until it decides or `decide_after` seconds past
/// the first sample: the member kept, and the time of the last sample pushed [s].
pub fn decide_heading<E: EarthModel, I, Fail>(
    earth: E,
    settings: &NavSettings,
    aiding: &Aiding,
    start: Start,
    (members, decide_after): (usize, f64),
    samples: &mut I,
) -> Result<(Chosen<E>, f64)>
where
    I: Iterator<Item = Result<ImuSample, Fail>> + ?Sized,
    anyhow::Error: From<Fail>,
{
    let config = settings.session_config(Some(aiding));
    let mut bank = HeadingBank::new(earth, config, start, members)
        .map_err(named_flag)?
        .with_truth(&aiding.report.truth_records()?);
    if aiding.raw.is_some() {
        bail!(
            "--init gnss-any-heading takes its heading from GNSS fixes (--gnss); raw \
             observations (--gnss-obs) cannot start it yet: give --init-att"
        );
    }
    for aid in aids(aiding) {
        bank.push(aid)?;
    }
    let (mut t0, mut checked, mut decided) = (None, f64::NEG_INFINITY, f64::NAN);
    for s in &mut *samples {
        let s = s?;
        bank.push_imu(s)?;
        decided = s.t;
        let since = s.t - *t0.get_or_insert(s.t);
        if since >= decide_after {
            break;
        }
        if since - checked >= 1.0 {
            checked = since;
            if bank.separated(BANK_MARGIN) {
                break;
            }
        }
    }
    Ok((bank.decide(), decided))
}

/// Log-likelihood lead [nats] at which the heading bank decides: a likelihood ratio of
/// e^20 ≈ 5e8 against every heading more than a sector away.
pub const BANK_MARGIN: f64 = 20.0;

/// Every aid of a run, as pushed: GNSS fixes, barometer readings, vehicle readings.
fn aids(a: &Aiding) -> impl Iterator<Item = Aid> + '_ {
    let fixes = a.fixes.iter().map(Aid::Gnss);
    let baro = a.baro.iter().map(|&(t, h)| Aid::Baro { t, h });
    fixes.chain(baro).chain(a.vehicle.aids())
}

/// The flag of `nav` that sets a session configuration field.
fn flag_of(field: &str) -> &'static str {
    const FLAGS: [(&str, &str); 41] = [
        ("mechanization.auto_latitude", "--auto-latitude"),
        ("filter.error_model", "--error-model"),
        ("mechanization.hysteresis", "--auto-hysteresis"),
        ("output_rate", "--output-rate"),
        ("filter.integration.noise.arw", "--arw"),
        ("filter.integration.noise.vrw", "--vrw"),
        ("filter.integration.noise.gyro_bias", "--gyro-bias-std"),
        ("filter.integration.noise.accel_bias", "--accel-bias-std"),
        (
            "filter.integration.noise.gyro_bias_walk",
            "--gyro-bias-instability",
        ),
        (
            "filter.integration.noise.accel_bias_walk",
            "--accel-bias-instability",
        ),
        ("filter.integration.noise.gyro_scale", "--gyro-scale-std"),
        ("filter.integration.noise.accel_scale", "--accel-scale-std"),
        ("filter.integration.noise.gyro_bias_tau", "--bias-corr-time"),
        (
            "filter.integration.noise.accel_bias_tau",
            "--bias-corr-time",
        ),
        ("filter.integration.lever_arm", "--lever-arm"),
        ("filter.integration.gate", "--gate"),
        (
            "filter.integration.propagation_interval",
            "--propagation-interval",
        ),
        ("filter.integration.init_pos_std", "--init-pos-std"),
        ("filter.integration.init_vel_std", "--init-vel-std"),
        ("filter.integration.init_att_std", "--init-att-std"),
        ("filter.integration.baro", "--baro-bias-std"),
        ("filter.baro_std", "--baro-std"),
        ("filter.vehicle.rest.std", "--zupt-std"),
        ("filter.vehicle.rest.interval", "--zupt-interval"),
        ("filter.vehicle.rest.zaru_std", "--zaru-std"),
        ("filter.vehicle.nhc.std", "--nhc-std"),
        ("filter.vehicle.odometer_std", "--odometer-std"),
        ("filter.vehicle.odometer_scale_std", "--odometer-scale-std"),
        ("filter.vehicle.mounting_std", "--estimate-mounting"),
        ("filter.vehicle.mount.lever", "--vehicle-lever-arm"),
        ("filter.vehicle.mount.q_vb", "--mounting-angles"),
        (
            "filter.integration.init_sensor_std",
            "the initial sensor-error standard deviations",
        ),
        ("start.state.pos.lat", "--init-pos"),
        ("start.state.pos.lon", "--init-pos"),
        ("start.state.pos.h", "--init-pos"),
        ("start.state.v_n", "--init-vel"),
        ("start.state.q_bn", "--init-att"),
        ("start.estimates.gyro_bias", "the initial gyro bias"),
        (
            "start.estimates.accel_bias",
            "the initial accelerometer bias",
        ),
        (
            "start.estimates.gyro_scale",
            "the initial gyro scale factor",
        ),
        (
            "start.estimates.accel_scale",
            "the initial accelerometer scale factor",
        ),
    ];
    FLAGS
        .iter()
        .find(|(f, _)| *f == field)
        .map_or("the configuration", |(_, flag)| flag)
}

/// A session error with its configuration field named as the flag that sets it.
fn named_flag(e: SessionError) -> anyhow::Error {
    match e {
        SessionError::Config(c) => {
            anyhow::anyhow!("{} ({}): {}", flag_of(c.field), c.field, c.reason)
        }
        other => anyhow::Error::new(other),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use schuler::session::{FilterConfig, SessionConfig};

    /// A value the session refuses comes back under the flag that sets it.
    #[test]
    fn configuration_errors_name_the_flag() {
        let noise = crate::options::GradeChoice::Tactical
            .noise()
            .expect("preset");
        let mut filter = FilterConfig::new(schuler::filter::IntegrationConfig::new(noise));
        filter.integration.init_vel_std.y = -1.0;
        let cfg = SessionConfig {
            filter: Some(filter),
            ..SessionConfig::default()
        };
        let e = named_flag(cfg.validate().expect_err("negative std").into()).to_string();
        assert!(
            e.starts_with(
                "--init-vel-std (filter.integration.init_vel_std): velocity standard \
                 deviation -1 m/s is outside (0, 12000] m/s"
            ),
            "{e}"
        );
    }
}
