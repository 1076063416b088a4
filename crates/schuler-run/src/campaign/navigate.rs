//! One run's navigation: `schuler nav`'s own option parsing, aiding resolution and
//! session set-up ([`crate::nav`], [`crate::navigate::open_session`]) on the
//! simulated streams in memory, with the simulated truth as the report's truth so that
//! the filter's snapshots carry NEES.

use super::config::{CampaignConfig, Streams};
use super::record::Recorded;
use crate::aided::GivenReadings;
use crate::nav::{InitChoice, NavArgs, parse_nav_args, resolve_aiding};
use crate::navigate::{NavSettings, open_session};
use crate::options::EarthChoice;
use anyhow::{Context, Result, bail};
use clap::Parser;
use schuler::analysis::errors::NavRecord;
use schuler::earth::{EarthModel, Sphere, Wgs84, Wgs84Series};
use schuler::session::Finished;

/// `schuler nav`'s options as a parser of a flag list.
#[derive(Parser, Debug)]
#[command(name = "navigate", no_binary_name = true)]
struct NavFlags {
    #[command(flatten)]
    args: NavArgs,
}

/// `schuler nav`'s arguments from `flags` (`--key=value` or `--key value`); a refusal
/// is clap's error (the Python package makes it a `TypeError`).
pub fn nav_args(flags: &[String]) -> Result<NavArgs> {
    Ok(NavFlags::try_parse_from(flags)?.args)
}

/// [`nav_args`] with a refusal as clap's message on one line, without its usage hint.
fn nav_args_one_line(flags: &[String]) -> Result<NavArgs> {
    NavFlags::try_parse_from(flags)
        .map(|f| f.args)
        .map_err(|e| {
            let text = e.render().to_string();
            let message: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.starts_with("For more information") && !l.starts_with("Usage:"))
                .filter(|l| !l.is_empty())
                .collect();
            anyhow::anyhow!("{}", message.join(" ").trim_start_matches("error: "))
        })
}

/// What navigating one run gave.
#[derive(Debug)]
pub struct Navigated {
    /// The output epochs.
    pub epochs: Vec<NavRecord>,
    /// The session's end: summary and snapshots (with NEES).
    pub finished: Finished,
}

/// The flags that start a run at the simulated truth of its first sample (the carrier
/// of the start), in nav's units (degrees), after the campaign's own.
fn start_flags(nav_flags: &[String], first: &NavRecord) -> Vec<String> {
    let (p, v, a) = (&first.pos, &first.v_n, &first.att);
    let mut flags = nav_flags.to_vec();
    flags.extend([
        "--imu=<simulated>".to_string(),
        format!(
            "--init-pos={:?},{:?},{:?}",
            p.lat.to_degrees(),
            p.lon.to_degrees(),
            p.h
        ),
        format!("--init-vel={:?},{:?},{:?}", v.x, v.y, v.z),
        format!(
            "--init-att={:?},{:?},{:?}",
            a.roll.to_degrees(),
            a.pitch.to_degrees(),
            a.yaw.to_degrees()
        ),
    ]);
    flags
}

/// The readings of `data` the streams choose, as nav's given readings.
fn given(data: &Recorded, streams: Streams, with_gnss: bool, with_baro: bool) -> GivenReadings {
    let fixes = (streams.gnss && with_gnss).then(|| {
        let keep_vel = streams.gnss_velocity;
        data.fixes
            .iter()
            .map(|f| schuler::filter::GnssFix {
                // A receiver simulated without `velocity_std` reports none.
                vel: f
                    .vel
                    .filter(|(_, std)| keep_vel && std.iter().all(|&s| s > 0.0)),
                ..*f
            })
            .collect()
    });
    let baro = (streams.baro && with_baro).then(|| data.baro.clone());
    GivenReadings {
        fixes,
        baro,
        ..Default::default()
    }
}

/// Navigates `data` with the campaign's options, from the truth at its first sample.
pub fn navigate(c: &CampaignConfig, data: &Recorded) -> Result<Navigated> {
    let first = data
        .truth
        .first()
        .context("the simulation gave no IMU sample")?;
    let plan = parse_nav_args(nav_args_one_line(&start_flags(&c.nav_flags, first))?)?;
    if plan.align || plan.init != InitChoice::Given {
        bail!(
            "a campaign starts at the simulated truth: `align` and `init` are not \
             available in [navigate] yet"
        );
    }
    let s = &c.scenario;
    let readings = given(data, c.streams, s.gnss.is_some(), s.baro.is_some());
    let mut aiding = resolve_aiding(&plan.alignment, &plan.aiding, readings)?;
    if let Some(a) = aiding.as_mut() {
        a.report.html = false;
        a.report.truth = Some(crate::aided::report::Truth {
            path: "<simulated truth>".into(),
            held: Some(data.truth.clone()),
        });
        a.names.diagnostics = true;
    }
    let settings = &plan.settings;
    let a = aiding.as_ref();
    match settings.earth {
        EarthChoice::Wgs84 => run_on(Wgs84, settings, a, data),
        EarthChoice::Wgs84Series => run_on(Wgs84Series, settings, a, data),
        EarthChoice::Sphere => run_on(Sphere::textbook(true), settings, a, data),
        EarthChoice::SphereFixed => run_on(Sphere::textbook(false), settings, a, data),
    }
}

/// The session of `settings` on `earth`, every sample of `data` pushed.
fn run_on<E: EarthModel>(
    earth: E,
    settings: &NavSettings,
    aiding: Option<&crate::aided::Aiding>,
    data: &Recorded,
) -> Result<Navigated> {
    let mut session = open_session(earth, settings, aiding, settings.start())?;
    let mut epochs = Vec::new();
    for s in &data.imu {
        session.push_imu(*s)?;
        epochs.extend(session.epochs().map(|e| NavRecord::from(&e.state)));
        session.events().for_each(drop);
    }
    session.end_of_input();
    epochs.extend(session.epochs().map(|e| NavRecord::from(&e.state)));
    let finished = session.finish()?;
    Ok(Navigated { epochs, finished })
}
