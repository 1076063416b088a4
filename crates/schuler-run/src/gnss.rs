//! `schuler gnss`: single-point positioning of a RINEX observation file with broadcast
//! ephemerides (issue 31).
//!
//! Every `--gnss-nav` file is read into one ephemeris store (the Klobuchar coefficients
//! of the first file that has them); the observation file is streamed epoch by epoch,
//! each converted to raw measurements ([`schuler_io::formats::rinex::raw::raw_epoch`])
//! and solved by [`spp::solve`] from the previous solution. Written into `--out`:
//! - `nav.txt` and `nav.csv`, schuler's navigation layouts (as `schuler nav` writes
//!   them, through [`NavWriter`]): the position, the NED velocity of the Doppler
//!   solution (the ECEF velocity rotated by `C_e^n`), 0 when the epoch has fewer than
//!   four Dopplers (the readers refuse NaN), and attitude 0 (SPP has none);
//! - `solution.pos`, RTKLIB's default layout (GPST calendar time, latitude, longitude,
//!   ellipsoidal height, Q = 5 single, satellites, standard deviations north, east,
//!   up and the signed roots of their covariances, age 0, ratio 0);
//! - `satellites.csv`: per epoch and satellite, used or excluded with the reason, the
//!   residual, elevation, azimuth and C/N0 of the signal used.
//!
//! Epochs without a solution (too few satellites, no convergence, singular geometry)
//! are counted by reason in the [`Summary`] and skipped. Nothing is printed.

use anyhow::{Result, bail};
use nalgebra::{Matrix3, Vector3};
use schuler::earth::c_ne;
use schuler::gnss::atmosphere::Klobuchar;
use schuler::gnss::spp::{self, Exclusion, SppSolution};
use schuler::gnss::{EphemerisStore, RawEpoch, SppConfig, SppError, System};
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler_io::formats::rinex::{nav::read_store, obs::ObsReader, raw::raw_epoch};
use schuler_io::line_file::LineFile;
use schuler_io::output::NavWriter;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `schuler gnss`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// RINEX observation file (2.xx, 3.0x, 4.0x; gzip or Hatanaka allowed).
    #[arg(long = "gnss-obs", value_name = "OBS")]
    pub gnss_obs: PathBuf,
    /// RINEX navigation file(s) of broadcast ephemerides (repeat for several).
    #[arg(long = "gnss-nav", value_name = "NAV", required = true)]
    pub gnss_nav: Vec<PathBuf>,
    /// Output directory (nav.txt, nav.csv, solution.pos, satellites.csv).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Elevation mask [deg].
    #[arg(
        long,
        default_value_t = 10.0,
        value_name = "DEG",
        allow_hyphen_values = true
    )]
    pub elevation_mask: f64,
    /// No Klobuchar ionosphere correction.
    #[arg(long)]
    pub no_iono: bool,
    /// No Saastamoinen troposphere correction.
    #[arg(long)]
    pub no_tropo: bool,
    /// Systems used, by RINEX letter (`G,E,C,J`); default every one with ephemerides.
    #[arg(long, value_delimiter = ',', value_name = "G,E,C")]
    pub systems: Vec<char>,
}

/// What a run did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Epochs with measurements.
    pub epochs: u64,
    /// Epochs solved.
    pub solved: u64,
    /// Epochs without a solution, counted by reason.
    pub failed: BTreeMap<String, u64>,
    /// Mean PDOP and HDOP of the solutions.
    pub mean_pdop: f64,
    /// See [`Summary::mean_pdop`].
    pub mean_hdop: f64,
    /// Satellites excluded by the fault detection, summed over epochs.
    pub fde_excluded: u64,
    /// Ephemerides read.
    pub ephemerides: usize,
    /// Where the files went.
    pub out: PathBuf,
}

/// The solver's configuration from `args`, checked against the systems of `store`.
pub fn config(args: &Args, store: &EphemerisStore) -> Result<SppConfig> {
    let c = SppConfig {
        elevation_mask: args.elevation_mask.to_radians(),
        ionosphere: !args.no_iono,
        troposphere: !args.no_tropo,
        ..SppConfig::default()
    };
    with_systems(c, &args.systems, store)
}

/// `c` using the systems of `systems` (RINEX letters; empty: every one with
/// ephemerides in `store`), checked.
pub(crate) fn with_systems(
    mut c: SppConfig,
    systems: &[char],
    store: &EphemerisStore,
) -> Result<SppConfig> {
    let with_eph: Vec<System> = store.sats().map(|s| s.system).collect();
    if systems.is_empty() {
        c.signals.retain(|(s, _)| with_eph.contains(s));
    } else {
        let mut wanted = Vec::new();
        for &l in systems {
            let Some(s) = System::from_letter(l.to_ascii_uppercase()).filter(|_| l != ' ') else {
                bail!("--systems: unknown system letter `{l}` (G, E, C, J)");
            };
            if !c.signals.iter().any(|(x, _)| *x == s) {
                bail!("--systems: system `{l}` is not supported by the single-point solution");
            }
            wanted.push(s);
        }
        c.signals.retain(|(s, _)| wanted.contains(s));
    }
    c.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(c)
}

/// Reads every navigation file into one store.
pub(crate) fn read_nav_files(paths: &[PathBuf]) -> Result<(EphemerisStore, Option<Klobuchar>)> {
    let mut store = EphemerisStore::new();
    let mut klobuchar = None;
    for p in paths {
        let (_, k, s) = read_store(p)?;
        klobuchar = klobuchar.or(k);
        for sat in s.sats().collect::<Vec<_>>() {
            store.extend(s.of(sat).iter().cloned());
        }
    }
    Ok((store, klobuchar))
}

/// The output files.
struct Outputs {
    nav: NavWriter,
    pos: LineFile,
    sats: LineFile,
    line: String,
}

/// Solves every epoch of `args.gnss_obs` and writes the files of the module's doc.
pub fn run(args: &Args) -> Result<Summary> {
    let (store, klobuchar) = read_nav_files(&args.gnss_nav)?;
    if store.is_empty() {
        bail!("no ephemeris in the navigation files");
    }
    let cfg = config(args, &store)?;
    let mut reader = ObsReader::open(&args.gnss_obs)?;
    let mut out = Outputs::create(&args.out)?;
    let mut summary = Summary {
        ephemerides: store.len(),
        out: args.out.clone(),
        ..Summary::default()
    };
    let mut prior = None;
    while let Some(epoch) = reader.next() {
        let epoch = epoch?;
        let channels = &reader.header().glonass_channels;
        let Some(raw) = raw_epoch(&epoch, channels) else {
            continue;
        };
        summary.epochs += 1;
        match spp::solve(&raw, &store, klobuchar.as_ref(), &cfg, prior) {
            Ok(sol) => {
                prior = Some(sol.r_e);
                summary.solved += 1;
                summary.mean_pdop += sol.dop.pdop;
                summary.mean_hdop += sol.dop.hdop;
                summary.fde_excluded += sol
                    .excluded
                    .iter()
                    .filter(|e| matches!(e.reason, Exclusion::Fault { .. }))
                    .count() as u64;
                out.write(&raw, &sol)?;
            }
            Err(e) => {
                if let SppError::TooFewSatellites { excluded, .. } = &e {
                    out.write_excluded(&raw, excluded)?;
                }
                *summary.failed.entry(failure_reason(&e)).or_default() += 1;
            }
        }
    }
    if summary.solved > 0 {
        summary.mean_pdop /= summary.solved as f64;
        summary.mean_hdop /= summary.solved as f64;
    }
    out.finish()?;
    Ok(summary)
}

/// The reason an epoch failed, without its numbers (so that reasons count together).
fn failure_reason(e: &SppError) -> String {
    match e {
        SppError::TooFewSatellites { .. } => "too few satellites".into(),
        SppError::NotConverged { .. } => "no convergence".into(),
        SppError::SingularGeometry => "singular geometry".into(),
        other => other.to_string(),
    }
}

/// The RTKLIB `.pos` header line of the columns.
const POS_COLUMNS: &str = "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  \
                           ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio";

/// The header of `satellites.csv`.
const SATS_HEADER: &str =
    "week,sow,sat,signal,status,reason,residual_m,elevation_deg,azimuth_deg,cn0_dbhz";

impl Outputs {
    fn create(dir: &Path) -> Result<Self> {
        let nav = NavWriter::create(dir, 0)?;
        let mut pos = LineFile::create(dir.join("solution.pos"))?;
        pos.append(
            format!(
                "% program   : schuler gnss {}\n% pos mode  : single\n% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n{POS_COLUMNS}\n",
                env!("CARGO_PKG_VERSION")
            )
            .as_bytes(),
        )?;
        let mut sats = LineFile::create(dir.join("satellites.csv"))?;
        sats.append(format!("{SATS_HEADER}\n").as_bytes())?;
        Ok(Self {
            nav,
            pos,
            sats,
            line: String::new(),
        })
    }

    fn write(&mut self, raw: &RawEpoch, sol: &SppSolution) -> Result<()> {
        let g = &sol.geodetic;
        let c_en = c_ne(g.lat, g.lon).transpose();
        let v_n = sol.v_e.map_or(Vector3::zeros(), |v| c_en * v);
        let t = sol.gps_time();
        self.nav.write(&NavState::new(
            t.sow,
            *g,
            v_n,
            Euler::from_degrees(0.0, 0.0, 0.0),
        ))?;
        // Covariance of position, north-east-down, then up.
        let p_e: Matrix3<f64> = sol.cov.fixed_view::<3, 3>(0, 0).into_owned();
        let p_n = c_en * p_e * c_en.transpose();
        let sd = |v: f64| v.abs().sqrt().copysign(v);
        let l = &mut self.line;
        l.clear();
        let _ = writeln!(
            l,
            "{} {:14.9} {:14.9} {:10.4} {:3} {:3} {:8.4} {:8.4} {:8.4} {:8.4} {:8.4} {:8.4} {:6.2} {:6.1}",
            calendar(t.week, t.sow),
            g.lat.to_degrees(),
            g.lon.to_degrees(),
            g.h,
            5,
            sol.used.len(),
            sd(p_n[(0, 0)]),
            sd(p_n[(1, 1)]),
            sd(p_n[(2, 2)]),
            sd(p_n[(0, 1)]),
            sd(-p_n[(1, 2)]),
            sd(-p_n[(2, 0)]),
            0.0,
            0.0
        );
        self.pos.append(self.line.as_bytes())?;
        self.line.clear();
        for u in &sol.used {
            let cn0 = raw.get(u.sat, u.signal).and_then(|m| m.cn0);
            row(
                &mut self.line,
                raw,
                &u.sat.to_string(),
                &u.signal.rinex(),
                "used",
                "",
                [
                    Some(u.residual),
                    Some(u.elevation.to_degrees()),
                    Some(u.azimuth.to_degrees()),
                    cn0,
                ],
            );
        }
        self.sats.append(self.line.as_bytes())?;
        self.write_excluded(raw, &sol.excluded)
    }

    fn write_excluded(&mut self, raw: &RawEpoch, excluded: &[spp::Excluded]) -> Result<()> {
        self.line.clear();
        for e in excluded {
            let (reason, el) = match e.reason {
                Exclusion::SystemNotUsed => ("system not used".to_string(), None),
                Exclusion::NoSignal => ("no signal".to_string(), None),
                Exclusion::InvalidMeasurement => ("invalid measurement".to_string(), None),
                Exclusion::NoEphemeris => ("no ephemeris".to_string(), None),
                Exclusion::Unhealthy => ("unhealthy".to_string(), None),
                Exclusion::NoGroupDelay(s) => (format!("no group delay for {}", s.rinex()), None),
                Exclusion::BelowMask { elevation } => {
                    ("below mask".to_string(), Some(elevation.to_degrees()))
                }
                Exclusion::Fault { w, .. } => (format!("fault w={w:.2}"), None),
            };
            row(
                &mut self.line,
                raw,
                &e.sat.to_string(),
                "",
                "excluded",
                &reason,
                [None, el, None, None],
            );
        }
        self.sats.append(self.line.as_bytes())?;
        Ok(())
    }

    fn finish(self) -> Result<()> {
        self.nav.finish()?;
        Ok(())
    }
}

/// Appends one `satellites.csv` row (blank for absent values).
fn row(
    l: &mut String,
    raw: &RawEpoch,
    sat: &str,
    signal: &str,
    status: &str,
    reason: &str,
    values: [Option<f64>; 4],
) {
    let _ = write!(
        l,
        "{},{:.3},{sat},{signal},{status},{reason}",
        raw.t.week, raw.t.sow
    );
    for (v, d) in values.iter().zip([3, 2, 2, 1]) {
        match v {
            Some(x) => {
                let _ = write!(l, ",{x:.d$}");
            }
            None => l.push(','),
        }
    }
    l.push('\n');
}

/// GPS week and second as RTKLIB's `yyyy/mm/dd hh:mm:ss.sss` (the civil date of a
/// day count by Hinnant's `civil_from_days`).
fn calendar(week: i64, sow: f64) -> String {
    let ms = (sow * 1000.0).round() as i64;
    // 1980-01-06 is day 3657 after 1970-01-01.
    let days = 3657 + 7 * week + ms.div_euclid(86_400_000);
    let ms_of_day = ms.rem_euclid(86_400_000);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let s = ms_of_day / 1000;
    format!(
        "{y:04}/{m:02}/{d:02} {:02}:{:02}:{:02}.{:03}",
        s / 3600,
        s / 60 % 60,
        s % 60,
        ms_of_day % 1000
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_of_gps_time() {
        // 2005-04-02 00:00 GPST is week 1316, second 518400.
        assert_eq!(calendar(1316, 518_400.0), "2005/04/02 00:00:00.000");
        assert_eq!(
            calendar(1316, 518_400.0 + 2880.004),
            "2005/04/02 00:48:00.004"
        );
    }
}
