//! The start of a navigation run: the given state, an alignment at rest on the log's
//! first seconds, or a start in motion from the GNSS fixes; the filter's prior follows
//! the start.

use super::args::InitChoice;
use crate::aided::Aiding;
use crate::alignment::AlignOptions;
use crate::navigate::NavSettings;
use anyhow::{Context, Result, bail};
use schuler::align::Alignment;
use schuler::align::in_motion::InMotionStart;
use schuler::earth::Wgs84;
use schuler::imu::ImuSample;
use schuler::session::{Prior, Start};

/// How a run began.
#[derive(Debug)]
pub enum Began {
    /// From the given position, velocity and attitude.
    Given,
    /// After an alignment at rest (`--align`).
    Aligned(Box<Alignment>),
    /// In motion from the GNSS fixes (`--init gnss` or `gnss-any-heading`).
    InMotion(InMotionStart),
}

/// The start of a run: with `align` the alignment at rest ([`align_start`]), else the
/// given state or, with `init` in motion, the start from the fixes
/// ([`motion_start`]). Returns the start, the samples read past it (its carrier
/// first) and how it began; with aiding the filter's prior follows the start.
pub fn begin<I, E>(
    settings: &NavSettings,
    align: Option<&AlignOptions>,
    init: InitChoice,
    samples: &mut I,
    aiding: Option<&mut Aiding>,
) -> Result<(Start, Vec<ImuSample>, Began)>
where
    I: Iterator<Item = Result<ImuSample, E>> + ?Sized,
    anyhow::Error: From<E>,
{
    Ok(match (align, init) {
        (Some(opts), _) => {
            let (start, head, a) = align_start(settings, opts, samples, aiding)?;
            (start, head, Began::Aligned(Box::new(a)))
        }
        (None, InitChoice::Given) => (settings.start(), Vec::new(), Began::Given),
        (None, init) => {
            let (start, head, m) = motion_start(settings, samples, aiding, init)?;
            (start, head, Began::InMotion(m))
        }
    })
}

/// The alignment of `--align` on the log's first stages: the start it gives (the
/// aligned state at the last aligned sample, its biases as the first estimates), the
/// samples after the alignment's end (the carrier of the start first) and the
/// alignment itself. With aiding, the filter's prior becomes the alignment's
/// ([`Prior::from_alignment`]).
pub fn align_start<I, E>(
    settings: &NavSettings,
    opts: &AlignOptions,
    reader: &mut I,
    aiding: Option<&mut Aiding>,
) -> Result<(Start, Vec<ImuSample>, Alignment)>
where
    I: Iterator<Item = Result<ImuSample, E>> + ?Sized,
    anyhow::Error: From<E>,
{
    let (cfg, noise) = opts.resolve()?;
    let samples = crate::alignment::read_stage(reader, cfg.coarse + cfg.fine)?;
    let a = crate::alignment::align_on(settings.earth, settings.init_pos, &samples, &noise, &cfg)
        .with_context(|| format!("aligning {}", settings.imu.display()))?;
    if let Some(aiding) = aiding {
        let pos_std = aiding.filter.integration.init_pos_std;
        aiding.filter = Prior::from_alignment(&a, pos_std).apply_to(aiding.filter);
    }
    let carrier = samples
        .partition_point(|s| s.t <= a.t_end + 1e-9)
        .saturating_sub(1);
    Ok((Start::from_alignment(&a), samples[carrier..].to_vec(), a))
}

/// The start in motion of `--init gnss` or `gnss-any-heading` from the fixes and the
/// IMU samples up to just past the fix it starts at ([`schuler::align::in_motion`]:
/// the course's first long straight chord, or without a heading the first fix two
/// seconds into the log); the filter's prior becomes its standard deviations.
/// Returns the start, the samples from its carrier on, and the start's details.
pub fn motion_start<I, E>(
    settings: &NavSettings,
    reader: &mut I,
    aiding: Option<&mut Aiding>,
    init: InitChoice,
) -> Result<(Start, Vec<ImuSample>, InMotionStart)>
where
    I: Iterator<Item = Result<ImuSample, E>> + ?Sized,
    anyhow::Error: From<E>,
{
    use schuler::align::in_motion::{
        InMotionConfig, VELOCITY_SPAN, course_pair, start_at_fix, start_in_motion,
    };
    let name = clap::ValueEnum::to_possible_value(&init)
        .map_or_else(|| format!("{init:?}"), |v| v.get_name().to_owned());
    let Some(aiding) = aiding.filter(|a| !a.fixes.is_empty() || a.raw.is_some()) else {
        bail!("--init {name} needs GNSS fixes (--gnss FILE) or raw observations (--gnss-obs)");
    };
    // Raw observations alone: their single-point solutions.
    let all = match &aiding.raw {
        Some(raw) if aiding.fixes.is_empty() => raw.spp_fixes()?,
        _ => aiding.fixes.to_vec()?,
    };
    let (cfg, earth, fixes) = (InMotionConfig::default(), Wgs84, &all);
    // The start's failures are the fixes' (their number, order, values), not the IMU
    // file's: the messages say so.
    let context = || format!("--init {name}");
    let first = match reader.next() {
        Some(s) => s?,
        None => bail!(
            "{}: no IMU sample in the requested time window",
            settings.imu.display()
        ),
    };
    let i0 = fixes.partition_point(|f| f.t < first.t);
    let j = match init {
        InitChoice::Gnss => course_pair(&earth, fixes, &cfg).with_context(context)?.1,
        // A fix before it to difference the velocity with (the next one at least).
        _ => (i0 + fixes[i0..].partition_point(|f| f.t < first.t + VELOCITY_SPAN)).max(i0 + 1),
    };
    let Some(fix) = fixes.get(j) else {
        bail!(
            "{}: {} GNSS fix(es), none two seconds into the IMU data (t = {} s on) after \
             another",
            context(),
            fixes.len(),
            first.t
        );
    };
    let mut samples = vec![first];
    let until = fix.t + cfg.settle + cfg.level_window;
    samples.extend(crate::alignment::read_stage(
        reader,
        (until - first.t).max(0.0),
    )?);
    let m = match init {
        InitChoice::Gnss => start_in_motion(&earth, &samples, fixes, &cfg),
        _ => start_at_fix(&earth, &samples, fixes, i0, j, &cfg),
    }
    .with_context(context)?;
    let filter = &mut aiding.filter;
    *filter = Prior::from_motion(&m).apply_to(*filter);
    let head = samples[m.sample..].to_vec();
    Ok((Start::from_motion(&m), head, m))
}

/// Members of the heading bank of `--init gnss-any-heading` (every 30°).
pub const BANK_MEMBERS: usize = 12;

/// Longest the heading bank runs before it keeps its most likely member [s] (it
/// decides earlier once the data tell the headings apart).
pub const BANK_SECONDS: f64 = 600.0;
