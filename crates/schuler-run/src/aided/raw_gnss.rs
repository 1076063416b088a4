//! Raw GNSS for tight coupling (`nav --gnss-obs OBS --gnss-nav NAV...`): the
//! navigation files read into one ephemeris store, the observation file streamed as
//! range epochs ([`RangeEpoch::from_raw`]), each an [`Aid::Ranges`] of the session at
//! its receive time (GPS seconds of week, continued past a week rollover, plus
//! `--gnss-time-offset`).
//!
//! The file is streamed twice, as every aid kind of the feed is ([`super::feed`]):
//! once to check it before anything is written, once in step with the IMU. A read
//! error ends the stream and is kept ([`RawGnss::take_error`]) for the caller to
//! report.

use anyhow::{Result, bail};
use schuler::filter::{GnssFix, TightConfig};
use schuler::gnss::{EphemerisStore, RangeEpoch, RangeModel, SppConfig, spp};
use schuler::session::Aid;
use schuler_io::formats::rinex::{obs::ObsReader, raw::raw_epoch};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// One week [s].
const WEEK_S: f64 = 604_800.0;

/// A run's raw GNSS: the observations, the ephemerides, tight coupling's settings.
#[derive(Debug, Clone)]
pub struct RawGnss {
    /// The RINEX observation file.
    pub obs: PathBuf,
    /// Every ephemeris of the navigation files.
    pub store: Arc<EphemerisStore>,
    /// Tight coupling's settings (model, clock, systems).
    pub tight: TightConfig,
    /// Added to every epoch's time [s].
    pub time_offset: f64,
    /// The read error that ended the last stream of [`RawGnss::aids`].
    error: Arc<Mutex<Option<String>>>,
}

impl RawGnss {
    /// Reads the navigation files `navs` for the observations `obs`, with elevation
    /// mask `mask_deg` and the systems of `systems` (RINEX letters; empty: every one
    /// with ephemerides).
    pub fn open(
        obs: &Path,
        navs: &[PathBuf],
        mask_deg: f64,
        systems: &[char],
        time_offset: f64,
    ) -> Result<Self> {
        if navs.is_empty() {
            bail!("--gnss-obs needs the broadcast ephemerides: give --gnss-nav NAV");
        }
        if !(mask_deg.is_finite() && (-10.0..=90.0).contains(&mask_deg)) {
            bail!("--elevation-mask must be within -10 and 90 deg, got {mask_deg}");
        }
        let (store, klobuchar) = crate::gnss::read_nav_files(navs)?;
        if store.is_empty() {
            bail!("no ephemeris in the --gnss-nav files");
        }
        let config = SppConfig {
            elevation_mask: mask_deg.to_radians(),
            ..SppConfig::default()
        };
        let config = crate::gnss::with_systems(config, systems, &store)?;
        Ok(Self {
            obs: obs.to_path_buf(),
            store: Arc::new(store),
            tight: TightConfig::new(RangeModel { klobuchar, config }),
            time_offset,
            error: Arc::default(),
        })
    }

    /// The epochs as aids, in file order; a read error ends them and is kept for
    /// [`RawGnss::take_error`].
    pub fn aids(&self) -> Box<dyn Iterator<Item = Aid> + '_> {
        let keep = |e: schuler_io::formats::InputError| {
            if let Ok(mut slot) = self.error.lock() {
                *slot = Some(e.to_string());
            }
        };
        let mut reader = match ObsReader::open(&self.obs) {
            Ok(r) => r,
            Err(e) => {
                keep(e);
                return Box::new(std::iter::empty());
            }
        };
        let mut week0 = None;
        Box::new(std::iter::from_fn(move || {
            loop {
                let epoch = match reader.next()? {
                    Ok(e) => e,
                    Err(e) => {
                        keep(e);
                        return None;
                    }
                };
                let Some(raw) = raw_epoch(&epoch, &reader.header().glonass_channels) else {
                    continue;
                };
                let w0 = *week0.get_or_insert(raw.t.week);
                let t = raw.t.sow + WEEK_S * (raw.t.week - w0) as f64 + self.time_offset;
                let e = RangeEpoch::from_raw(&raw, &self.store, &self.tight.model.config, t);
                return Some(Aid::Ranges(Box::new(e)));
            }
        }))
    }

    /// The read error that ended the last stream, taken.
    pub fn take_error(&self) -> Option<anyhow::Error> {
        let mut slot = self.error.lock().ok()?;
        slot.take().map(anyhow::Error::msg)
    }

    /// The single-point solution of every epoch that has one (position and Doppler
    /// velocity, [`spp::solve`] with the run's mask, systems and atmosphere), as
    /// fixes at GPS time on the run's clock: what `--init gnss` starts from when the
    /// run has raw observations and no fixes.
    pub fn spp_fixes(&self) -> Result<Vec<GnssFix>> {
        let mut reader = ObsReader::open(&self.obs)?;
        let (mut fixes, mut prior, mut week0) = (Vec::new(), None, None);
        let model = &self.tight.model;
        while let Some(epoch) = reader.next() {
            let epoch = epoch?;
            let Some(raw) = raw_epoch(&epoch, &reader.header().glonass_channels) else {
                continue;
            };
            let w0 = *week0.get_or_insert(raw.t.week);
            if let Ok(sol) = spp::solve(
                &raw,
                &self.store,
                model.klobuchar.as_ref(),
                &model.config,
                prior,
            ) {
                prior = Some(sol.r_e);
                let t = sol.gps_time();
                let t = t.sow + WEEK_S * (t.week - w0) as f64 + self.time_offset;
                fixes.push(GnssFix::from_spp(&sol, t));
            }
        }
        Ok(fixes)
    }

    /// Every epoch as an aid, or the first read error.
    pub fn read_aids(&self) -> Result<Vec<Aid>> {
        let aids: Vec<Aid> = self.aids().collect();
        match self.take_error() {
            Some(e) => Err(e),
            None => Ok(aids),
        }
    }
}
