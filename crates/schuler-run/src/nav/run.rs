//! A navigation run from an open IMU source: the start, then the samples pushed through
//! the session on the chosen Earth model (or the heading bank first) and the outputs
//! written.

use super::args::InitChoice;
use super::plan::NavPlan;
use super::start::{BANK_MEMBERS, BANK_SECONDS, Began, begin};
use crate::aided::Aiding;
use crate::navigate::{NavSettings, RunSummary, navigate};
use crate::options::EarthChoice;
use anyhow::Result;
use schuler::earth::{Sphere, Wgs84, Wgs84Series};
use schuler::imu::ImuSample;
use schuler::session::Start;

/// What a run gave: its summary and, with the heading bank, the kept member's initial
/// heading [rad] and the time the bank decided [s].
pub struct Navigated {
    /// The run's summary.
    pub summary: RunSummary,
    /// The heading bank's choice (`--init gnss-any-heading`).
    pub bank: Option<(f64, f64)>,
}

/// What a run starts from: the settings, the aiding, the start, and whether the
/// heading is searched by the bank.
struct Begin<'a> {
    settings: &'a NavSettings,
    aiding: Option<&'a Aiding>,
    start: Start,
    any_heading: bool,
}

impl Begin<'_> {
    /// Navigate on the settings' Earth model: from the start, or through the heading
    /// bank.
    fn navigate<I, E>(&self, samples: I, on_sample: impl FnMut(u64)) -> Result<Navigated>
    where
        I: Iterator<Item = Result<ImuSample, E>>,
        E: std::error::Error + Send + Sync + 'static,
    {
        match self.settings.earth {
            EarthChoice::Wgs84 => self.navigate_on(Wgs84, samples, on_sample),
            EarthChoice::Wgs84Series => self.navigate_on(Wgs84Series, samples, on_sample),
            EarthChoice::Sphere | EarthChoice::SphereFixed => {
                let rotating = self.settings.earth == EarthChoice::Sphere;
                self.navigate_on(Sphere::textbook(rotating), samples, on_sample)
            }
        }
    }

    /// [`Begin::navigate`] on `earth`.
    fn navigate_on<M: schuler::earth::EarthModel, I, E>(
        &self,
        earth: M,
        samples: I,
        on_sample: impl FnMut(u64),
    ) -> Result<Navigated>
    where
        I: Iterator<Item = Result<ImuSample, E>>,
        E: std::error::Error + Send + Sync + 'static,
    {
        let (settings, start) = (self.settings, self.start);
        match (self.aiding, self.any_heading) {
            (Some(a), true) => {
                let (summary, yaw0, decided) = crate::navigate::navigate_any_heading(
                    earth,
                    settings,
                    a,
                    start,
                    BANK_MEMBERS,
                    BANK_SECONDS,
                    samples,
                    on_sample,
                )?;
                Ok(Navigated {
                    summary,
                    bank: Some((yaw0, decided)),
                })
            }
            _ => Ok(Navigated {
                summary: navigate(earth, settings, self.aiding, start, samples, on_sample)?,
                bank: None,
            }),
        }
    }
}

/// The run from an open IMU source: the start (given, aligned at rest, or from the
/// fixes in motion; an alignment's `align.json` written), told to `on_start` as soon as
/// it is known, then the samples navigated and written; `on_sample` as in
/// [`navigate`].
pub fn navigate_samples<I, E>(
    plan: &NavPlan,
    aiding: &mut Option<Aiding>,
    reader: &mut I,
    on_start: impl FnOnce(&Began, Option<&Aiding>),
    on_sample: impl FnMut(u64),
) -> Result<Navigated>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let settings = &plan.settings;
    let align = plan.align.then_some(&plan.alignment);
    let (start, head, began) = begin(settings, align, plan.init, reader, aiding.as_mut())?;
    on_start(&began, aiding.as_ref());
    if let Began::Aligned(a) = &began {
        crate::alignment::write_outputs(&settings.out, a)?;
    }
    let samples = head.into_iter().map(Ok).chain(reader);
    let begin = Begin {
        settings,
        aiding: aiding.as_ref(),
        start,
        any_heading: plan.init == InitChoice::GnssAnyHeading,
    };
    begin.navigate(samples, on_sample)
}
