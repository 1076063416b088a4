//! One run's navigation: `schuler nav`'s own option parsing, aiding resolution and
//! session set-up ([`crate::nav`], [`crate::navigate::open_session`]) on the
//! simulated streams in memory, with the simulated truth as the report's truth so that
//! the filter's snapshots carry NEES.

use super::config::{CampaignConfig, Streams};
use super::record::Recorded;
use crate::aided::GivenReadings;
use crate::earth::AnyEarth;
use crate::nav::{InitChoice, NavConfig, plan_of, resolve_aiding};
use crate::navigate::{NavSettings, open_session};
use anyhow::{Context, Result, bail};
use schuler::analysis::errors::NavRecord;
use schuler::earth::EarthModel;
use schuler::session::Finished;

/// What navigating one run gave.
#[derive(Debug)]
pub struct Navigated {
    /// The output epochs.
    pub epochs: Vec<NavRecord>,
    /// The session's end: summary and snapshots (with NEES).
    pub finished: Finished,
}

/// The options that start a run at the simulated truth of its first sample (the
/// carrier of the start), in nav's units (degrees), over the campaign's own.
pub(crate) fn start_options(nav_options: &toml::Table, first: &NavRecord) -> toml::Table {
    let (p, v, a) = (&first.pos, &first.v_n, &first.att);
    let triple = |x: [f64; 3]| toml::Value::Array(x.map(toml::Value::Float).to_vec());
    let mut options = nav_options.clone();
    options.extend([
        (
            "imu".to_owned(),
            toml::Value::String("<simulated>".to_owned()),
        ),
        (
            "init_pos".to_owned(),
            triple([p.lat.to_degrees(), p.lon.to_degrees(), p.h]),
        ),
        ("init_vel".to_owned(), triple([v.x, v.y, v.z])),
        (
            "init_att".to_owned(),
            triple([
                a.roll.to_degrees(),
                a.pitch.to_degrees(),
                a.yaw.to_degrees(),
            ]),
        ),
    ]);
    options
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
    let plan = plan_of(NavConfig::from_options(start_options(
        &c.nav_options,
        first,
    ))?)?;
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
    run_on(AnyEarth::of(settings.earth), settings, a, data)
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
