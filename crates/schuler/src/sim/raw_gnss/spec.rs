//! The scenario's `[gnss.raw]` block as written, and its resolution into
//! [`RawGnssModel`] with every value checked (errors name the key).
//!
//! ```toml
//! [gnss.raw]
//! nav = "../tests/data/orbits/brdc1820.10n.gz"  # or constellation = "gps-nominal"
//! week = 1590                 # GPS week; the scenario's time is its second of week
//! rate_hz = 1
//! systems = ["G"]
//! signals = ["1C"]            # C1C pseudorange, D1C Doppler, S1C C/N0
//! elevation_mask = "10 deg"
//! clock_bias = "100 us"       # at the first epoch
//! clock_drift = "50 ppb"
//! clock_h0 = 2e-19            # white frequency noise (TCXO)
//! clock_h_2 = 2e-20           # random-walk frequency noise
//! ionosphere = true           # Klobuchar's delay…
//! ionosphere_error = "20 %"   # …made 20 % larger than the model the receiver uses
//! troposphere = true
//! troposphere_error = "0 %"
//! code_std = ["0.3 m", "0.3 m"]   # σ² = a² + b²/sin²(el)
//! rate_std = "0.05 m/s"           # the pseudorange rate's σ at the zenith
//! cn0 = [30, 50]                  # dB-Hz at the horizon and the zenith
//! [gnss.raw.multipath]
//! sigma = "0.5 m"
//! tau = "30 s"
//! [[gnss.raw.window]]
//! t0 = "352900 s"
//! t1 = "352960 s"
//! satellites = 3              # or a list: ["G05", "G12"]
//! [[gnss.raw.fault]]
//! sat = "G05"
//! t0 = "353000 s"
//! t1 = "353020 s"
//! step = "50 m"
//! ```
//!
//! Times of windows and faults are scenario times, as `gnss.outages` are; a window
//! or fault holds from t0 up to, not including, t1.

use serde::{Deserialize, Serialize};

use super::clock::{ClockModel, TCXO_H_2, TCXO_H0};
use super::{Fault, GaussMarkov, Keep, RawGnssModel, Window};
use crate::gnss::atmosphere::Klobuchar;
use crate::gnss::{EphemerisStore, Sat, Signal, System};
use crate::sim::scenario::{Quantity, ScenarioError};
use crate::units::Dimension;

/// The most windows or faults a scenario may give.
pub const MAX_EVENTS: usize = 1000;
/// The most epochs per second.
pub const MAX_RATE_HZ: f64 = 100.0;

/// Where the satellites come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
pub enum Constellation {
    /// [`super::constellation::nominal_gps`].
    #[serde(rename = "gps-nominal")]
    GpsNominal,
}

/// The satellites a window keeps: a number or a list.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum KeepSpec {
    /// The N highest.
    Count(i64),
    /// These satellites (`"G05"`).
    List(Vec<String>),
}

/// A window as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WindowSpec {
    /// Start (scenario time).
    pub t0: Quantity,
    /// End.
    pub t1: Quantity,
    /// What is seen.
    pub satellites: KeepSpec,
}

/// A fault as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// The satellite (`"G05"`).
    pub sat: String,
    /// Start (scenario time).
    pub t0: Quantity,
    /// End.
    pub t1: Quantity,
    /// The step (length).
    pub step: Quantity,
}

/// The multipath-like error as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MultipathSpec {
    /// Standard deviation (length).
    pub sigma: Quantity,
    /// Correlation time.
    pub tau: Quantity,
}

/// The ephemerides and ionosphere a run uses, read by the application layer from
/// `nav` (the library reads no file) or made from `constellation`.
#[derive(Debug, Clone, Default)]
pub struct NavData {
    /// The ephemerides.
    pub store: EphemerisStore,
    /// The broadcast ionosphere, if any.
    pub klobuchar: Option<Klobuchar>,
    /// The file they were read from, for the application layer to copy beside the
    /// observations (`None` when made here).
    pub file: Option<std::path::PathBuf>,
}

impl PartialEq for NavData {
    /// Loaded data are not part of the description: any two compare equal.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// `[gnss.raw]` as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawGnssSpec {
    /// A RINEX navigation file, relative to the scenario's folder.
    pub nav: Option<String>,
    /// A nominal constellation instead of `nav`.
    pub constellation: Option<Constellation>,
    /// The GPS week of the scenario's time.
    pub week: i64,
    /// Epochs per second (default 1).
    pub rate_hz: Option<f64>,
    /// Systems (RINEX letters; default `["G"]`).
    pub systems: Option<Vec<String>>,
    /// Signals (RINEX band and attribute, `"1C"`; default `["1C"]`).
    pub signals: Option<Vec<String>>,
    /// Elevation mask (default 10 deg).
    pub elevation_mask: Option<Quantity>,
    /// Clock bias at the first epoch (default 0 s).
    pub clock_bias: Option<Quantity>,
    /// Clock drift (default 0).
    pub clock_drift: Option<Quantity>,
    /// White frequency noise h₀ (default a TCXO's 2e-19).
    pub clock_h0: Option<f64>,
    /// Random-walk frequency noise h₋₂ (default a TCXO's 2e-20).
    pub clock_h_2: Option<f64>,
    /// Klobuchar ionosphere in the measurements (default true).
    pub ionosphere: Option<bool>,
    /// The ionosphere's error as a fraction of Klobuchar's (default 0).
    pub ionosphere_error: Option<Quantity>,
    /// Saastamoinen troposphere in the measurements (default true).
    pub troposphere: Option<bool>,
    /// The troposphere's error as a fraction (default 0).
    pub troposphere_error: Option<Quantity>,
    /// Code noise `[a, b]`: σ² = a² + b²/sin²(el) (default 0.3 m, 0.3 m).
    pub code_std: Option<[Quantity; 2]>,
    /// Pseudorange-rate noise at the zenith (default 0.05 m/s).
    pub rate_std: Option<Quantity>,
    /// C/N0 at the horizon and zenith [dB-Hz] (default 30, 50).
    pub cn0: Option<[f64; 2]>,
    /// Multipath-like error (default none).
    pub multipath: Option<MultipathSpec>,
    /// Windows of fewer satellites.
    #[serde(default)]
    pub window: Vec<WindowSpec>,
    /// Step faults.
    #[serde(default)]
    pub fault: Vec<FaultSpec>,
    /// The navigation data, loaded (not part of the description).
    #[serde(skip)]
    pub data: Option<NavData>,
}

/// A value in `[lo, hi]`, or an error naming `key`.
fn bounded(key: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<f64, ScenarioError> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(ScenarioError::Value {
            key: key.into(),
            message: format!("{v} is out of range: {what}"),
        })
    }
}

/// An optional quantity's SI value in `[lo, hi]` (`default` when absent).
fn quantity(
    q: &Option<Quantity>,
    key: &str,
    dim: Dimension,
    default: f64,
    (lo, hi, what): (f64, f64, &str),
) -> Result<f64, ScenarioError> {
    match q {
        None => Ok(default),
        Some(q) => bounded(key, q.si(key, dim)?, lo, hi, what),
    }
}

fn error(key: &str, message: String) -> ScenarioError {
    ScenarioError::Value {
        key: key.into(),
        message,
    }
}

/// A satellite named as RINEX writes it.
fn sat(key: &str, s: &str) -> Result<Sat, ScenarioError> {
    Sat::parse(s).ok_or_else(|| error(key, format!("{s:?} is not a satellite (write \"G05\")")))
}

impl RawGnssSpec {
    /// The SI model, every value checked.
    pub fn model(&self) -> Result<RawGnssModel, ScenarioError> {
        let k = |name: &str| format!("gnss.raw.{name}");
        match (&self.nav, &self.constellation) {
            (Some(_), Some(_)) => {
                return Err(error(
                    &k("nav"),
                    "give nav or constellation, not both".into(),
                ));
            }
            (None, None) => {
                return Err(error(
                    &k("nav"),
                    "missing: give a RINEX navigation file (nav = \"…\") or constellation = \"gps-nominal\"".into(),
                ));
            }
            _ => {}
        }
        bounded(
            &k("week"),
            self.week as f64,
            0.0,
            10_000.0,
            "a GPS week, 0 to 10000",
        )?;
        let rate = bounded(
            &k("rate_hz"),
            self.rate_hz.unwrap_or(1.0),
            1e-3,
            MAX_RATE_HZ,
            "0.001 to 100 Hz",
        )?;
        let systems: Vec<System> = match &self.systems {
            None => vec![System::Gps],
            Some(v) => v
                .iter()
                .map(|s| {
                    let mut c = s.chars();
                    match (c.next().and_then(System::from_letter), c.next()) {
                        (Some(sys), None) if s != " " => Ok(sys),
                        _ => Err(error(
                            &k("systems"),
                            format!("{s:?} is not a RINEX system letter"),
                        )),
                    }
                })
                .collect::<Result<_, _>>()?,
        };
        if systems.is_empty() {
            return Err(error(&k("systems"), "give at least one system".into()));
        }
        if self.constellation.is_some() && systems.iter().any(|&s| s != System::Gps) {
            return Err(error(
                &k("systems"),
                "the nominal constellation is GPS only".into(),
            ));
        }
        let codes = self.signals.clone().unwrap_or_else(|| vec!["1C".into()]);
        if codes.is_empty() || codes.len() > 8 {
            return Err(error(&k("signals"), "give 1 to 8 signals".into()));
        }
        let mut signals = Vec::new();
        for &system in &systems {
            for code in &codes {
                let s = Signal::from_rinex(system, code)
                    .filter(|s| s.frequency(None).is_some() && s.group_delay_band().is_some())
                    .ok_or_else(|| {
                        error(
                            &k("signals"),
                            format!(
                                "{code:?} is not a signal of {} with a broadcast group delay (write \"1C\")",
                                system.letter()
                            ),
                        )
                    })?;
                signals.push(s);
            }
        }
        let deg = std::f64::consts::PI / 180.0;
        let elevation_mask = quantity(
            &self.elevation_mask,
            &k("elevation_mask"),
            Dimension::Angle,
            10.0 * deg,
            (0.0, 89.0 * deg, "0 to 89 deg"),
        )?;
        let clock = ClockModel {
            bias: quantity(
                &self.clock_bias,
                &k("clock_bias"),
                Dimension::Time,
                0.0,
                (-1.0, 1.0, "within ±1 s"),
            )?,
            drift: quantity(
                &self.clock_drift,
                &k("clock_drift"),
                Dimension::Dimensionless,
                0.0,
                (-1e-4, 1e-4, "within ±100 ppm"),
            )?,
            h0: bounded(
                &k("clock_h0"),
                self.clock_h0.unwrap_or(TCXO_H0),
                0.0,
                1e-15,
                "0 to 1e-15 s",
            )?,
            h_2: bounded(
                &k("clock_h_2"),
                self.clock_h_2.unwrap_or(TCXO_H_2),
                0.0,
                1e-15,
                "0 to 1e-15 /s",
            )?,
        };
        let scale =
            |on: Option<bool>, err: &Option<Quantity>, name: &str| -> Result<f64, ScenarioError> {
                let e = quantity(
                    err,
                    &k(name),
                    Dimension::Dimensionless,
                    0.0,
                    (-1.0, 10.0, "-100 % to 1000 %"),
                )?;
                Ok(if on.unwrap_or(true) { 1.0 + e } else { 0.0 })
            };
        let len = |q: &Quantity, key: &str| {
            bounded(key, q.si(key, Dimension::Length)?, 0.0, 1e4, "0 to 10 km")
        };
        let code_std = match &self.code_std {
            None => [0.3, 0.3],
            Some([a, b]) => [len(a, &k("code_std[0]"))?, len(b, &k("code_std[1]"))?],
        };
        let rate_std = quantity(
            &self.rate_std,
            &k("rate_std"),
            Dimension::Velocity,
            0.05,
            (0.0, 1e3, "0 to 1000 m/s"),
        )?;
        let cn0 = self.cn0.unwrap_or([30.0, 50.0]);
        bounded(&k("cn0[0]"), cn0[0], 0.0, 99.0, "0 to 99 dB-Hz")?;
        bounded(
            &k("cn0[1]"),
            cn0[1],
            cn0[0],
            99.0,
            "from the horizon's value to 99 dB-Hz",
        )?;
        let multipath = match &self.multipath {
            None => None,
            Some(m) => Some(GaussMarkov {
                sigma: len(&m.sigma, &k("multipath.sigma"))?,
                tau: bounded(
                    &k("multipath.tau"),
                    m.tau.si(&k("multipath.tau"), Dimension::Time)?,
                    1e-3,
                    1e6,
                    "1 ms to 1e6 s",
                )?,
            }),
        };
        if self.window.len() > MAX_EVENTS || self.fault.len() > MAX_EVENTS {
            return Err(error(
                &k("window"),
                format!("at most {MAX_EVENTS} windows and {MAX_EVENTS} faults"),
            ));
        }
        let interval =
            |t0: &Quantity, t1: &Quantity, key: &str| -> Result<(f64, f64), ScenarioError> {
                let (a, b) = (
                    t0.si(&format!("{key}.t0"), Dimension::Time)?,
                    t1.si(&format!("{key}.t1"), Dimension::Time)?,
                );
                if b <= a {
                    return Err(error(
                        &format!("{key}.t1"),
                        format!("ends ({b} s) before it starts ({a} s)"),
                    ));
                }
                Ok((a, b))
            };
        let windows = self
            .window
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let key = k(&format!("window[{i}]"));
                let (start, end) = interval(&w.t0, &w.t1, &key)?;
                let sk = format!("{key}.satellites");
                let keep = match &w.satellites {
                    KeepSpec::Count(n) => {
                        Keep::Highest(
                            bounded(&sk, *n as f64, 0.0, 64.0, "0 to 64 satellites")? as usize
                        )
                    }
                    KeepSpec::List(list) => {
                        if list.len() > 64 {
                            return Err(error(&sk, "at most 64 satellites".into()));
                        }
                        Keep::Listed(list.iter().map(|s| sat(&sk, s)).collect::<Result<_, _>>()?)
                    }
                };
                Ok(Window { start, end, keep })
            })
            .collect::<Result<_, ScenarioError>>()?;
        let faults = self
            .fault
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let key = k(&format!("fault[{i}]"));
                let (start, end) = interval(&f.t0, &f.t1, &key)?;
                let sk = format!("{key}.step");
                Ok(Fault {
                    sat: sat(&format!("{key}.sat"), &f.sat)?,
                    start,
                    end,
                    step_m: bounded(
                        &sk,
                        f.step.si(&sk, Dimension::Length)?,
                        -1e5,
                        1e5,
                        "within ±100 km",
                    )?,
                })
            })
            .collect::<Result<_, ScenarioError>>()?;
        Ok(RawGnssModel {
            week: self.week,
            signals,
            interval: 1.0 / rate,
            elevation_mask,
            clock,
            iono_scale: scale(self.ionosphere, &self.ionosphere_error, "ionosphere_error")?,
            tropo_scale: scale(
                self.troposphere,
                &self.troposphere_error,
                "troposphere_error",
            )?,
            code_std,
            rate_std,
            multipath,
            cn0,
            windows,
            faults,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(extra: &str) -> Result<RawGnssModel, String> {
        let text = format!("constellation = \"gps-nominal\"\nweek = 1590\n{extra}");
        let s: RawGnssSpec = toml::from_str(&text).map_err(|e| e.to_string())?;
        s.model().map_err(|e| e.to_string())
    }

    #[test]
    fn defaults_and_a_full_block() {
        let m = spec("").unwrap();
        assert_eq!(m.interval, 1.0);
        assert_eq!(m.signals, vec![Signal::new(System::Gps, '1', 'C')]);
        assert_eq!((m.iono_scale, m.tropo_scale), (1.0, 1.0));
        let m = spec(
            "ionosphere_error = \"20 %\"\ntroposphere = false\nclock_bias = \"100 us\"\nclock_drift = \"50 ppb\"\n\
             [multipath]\nsigma = \"0.5 m\"\ntau = \"30 s\"\n\
             [[window]]\nt0 = \"10 s\"\nt1 = \"70 s\"\nsatellites = 3\n\
             [[window]]\nt0 = \"70 s\"\nt1 = \"100 s\"\nsatellites = [\"G05\", \"G12\"]\n\
             [[fault]]\nsat = \"G05\"\nt0 = \"5 s\"\nt1 = \"25 s\"\nstep = \"50 m\"\n",
        )
        .unwrap();
        assert!((m.iono_scale - 1.2).abs() < 1e-15 && m.tropo_scale == 0.0);
        assert!((m.clock.bias - 1e-4).abs() < 1e-18 && (m.clock.drift - 5e-8).abs() < 1e-20);
        assert_eq!(m.windows[0].keep, Keep::Highest(3));
        assert_eq!(
            m.windows[1].keep,
            Keep::Listed(vec![Sat::new(System::Gps, 5), Sat::new(System::Gps, 12)])
        );
        assert_eq!(m.faults[0].step_m, 50.0);
        assert_eq!(
            m.multipath,
            Some(GaussMarkov {
                sigma: 0.5,
                tau: 30.0
            })
        );
    }

    #[test]
    fn absurd_values_are_refused_by_their_key() {
        for (extra, key) in [
            ("rate_hz = 1e6", "gnss.raw.rate_hz"),
            ("clock_bias = \"5 s\"", "gnss.raw.clock_bias"),
            ("clock_h0 = -1.0", "gnss.raw.clock_h0"),
            ("signals = [\"9Z\"]", "gnss.raw.signals"),
            ("systems = [\"E\"]", "gnss.raw.systems"),
            ("cn0 = [50, 30]", "gnss.raw.cn0[1]"),
            ("elevation_mask = \"95 deg\"", "gnss.raw.elevation_mask"),
            (
                "[[window]]\nt0 = \"5 s\"\nt1 = \"1 s\"\nsatellites = 3",
                "gnss.raw.window[0].t1",
            ),
            (
                "[[window]]\nt0 = \"1 s\"\nt1 = \"5 s\"\nsatellites = 300",
                "gnss.raw.window[0].satellites",
            ),
            (
                "[[fault]]\nsat = \"X5\"\nt0 = \"1 s\"\nt1 = \"5 s\"\nstep = \"1 m\"",
                "gnss.raw.fault[0].sat",
            ),
            (
                "[[fault]]\nsat = \"G05\"\nt0 = \"1 s\"\nt1 = \"5 s\"\nstep = \"1e9 m\"",
                "gnss.raw.fault[0].step",
            ),
            (
                "[multipath]\nsigma = \"1 m\"\ntau = \"0 s\"",
                "gnss.raw.multipath.tau",
            ),
        ] {
            let e = spec(extra).unwrap_err();
            assert!(e.starts_with(key), "{extra}: {e}");
        }
        let e = toml::from_str::<RawGnssSpec>("week = 1590\n")
            .unwrap()
            .model()
            .unwrap_err();
        assert!(e.to_string().starts_with("gnss.raw.nav: missing"), "{e}");
        let e = toml::from_str::<RawGnssSpec>("week = 1\nnoise = 1\n").unwrap_err();
        assert!(e.to_string().contains("unknown field `noise`"), "{e}");
    }
}
