//! A navigation run from an open IMU source: the start, then the samples pushed through
//! the session on the chosen Earth model (or the heading bank first) and the outputs
//! written.

use super::args::InitChoice;
use super::plan::NavPlan;
use super::start::{BANK_MEMBERS, BANK_SECONDS, Began, begin};
use crate::aided::Aiding;
use crate::navigate::{NavSettings, RunSummary, Samples, navigate, navigate_any_heading};
use anyhow::Result;
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
    fn navigate(
        &self,
        samples: &mut Samples<'_>,
        on_sample: &mut dyn FnMut(u64),
    ) -> Result<Navigated> {
        let (settings, start, earth) = (self.settings, self.start, self.settings.earth);
        match (self.aiding, self.any_heading) {
            (Some(a), true) => {
                let bank = (BANK_MEMBERS, BANK_SECONDS);
                let (summary, yaw0, decided) =
                    navigate_any_heading(earth, settings, a, start, bank, samples, on_sample)?;
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
pub fn navigate_samples(
    plan: &NavPlan,
    aiding: &mut Option<Aiding>,
    reader: &mut Samples<'_>,
    on_start: &mut dyn FnMut(&Began, Option<&Aiding>),
    on_sample: &mut dyn FnMut(u64),
) -> Result<Navigated> {
    let settings = &plan.settings;
    let align = plan.align.then_some(&plan.alignment);
    let (start, head, began) = begin(settings, align, plan.init, reader, aiding.as_mut())?;
    on_start(&began, aiding.as_ref());
    if let Began::Aligned(a) = &began {
        crate::alignment::write_outputs(&settings.out, a)?;
    }
    let mut samples = head.into_iter().map(Ok).chain(reader);
    let begin = Begin {
        settings,
        aiding: aiding.as_ref(),
        start,
        any_heading: plan.init == InitChoice::GnssAnyHeading,
    };
    begin.navigate(&mut samples, on_sample)
}
