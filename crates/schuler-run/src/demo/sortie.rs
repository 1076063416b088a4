//! The demo's sortie: the seed's helicopter flight test above the Arctic circle
//! (`examples/polar_flight.toml`), and the shortened `--quick` version of it.

use anyhow::{Context, Result};
use schuler::sim::run::ScenarioSpec;
use schuler::sim::scenario::{Quantity, SegmentSpec, WaypointSpec};
use schuler::sim::sensor_spec::GnssOutlierSpec;

/// The full sortie as written (also a `schuler simulate` config).
pub const POLAR_FLIGHT: &str = include_str!("../../../../examples/polar_flight.toml");

/// The sortie and the timeline its processing follows.
#[derive(Debug, Clone)]
pub struct Sortie {
    /// The scenario.
    pub spec: ScenarioSpec,
    /// Coarse alignment length [s] (the seed: 0–190 s).
    pub coarse: f64,
    /// Fine alignment length [s] (the seed: 190–860 s).
    pub fine: f64,
    /// End of the time on the pad [s].
    pub takeoff: f64,
    /// GNSS outages [s].
    pub outages: Vec<(f64, f64)>,
}

fn text(s: &str) -> Quantity {
    Quantity::Text(s.to_string())
}

impl Sortie {
    /// The seed's timeline: 15 min on the pad, 45 min of flight, 1 kHz.
    pub fn full() -> Result<Self> {
        let spec: ScenarioSpec =
            toml::from_str(POLAR_FLIGHT).context("examples/polar_flight.toml")?;
        Ok(Self {
            spec,
            coarse: 190.0,
            fine: 670.0,
            takeoff: 900.0,
            outages: vec![(2400.0, 2520.0)],
        })
    }

    /// The same aircraft, sensors and processing, shortened for tests: 200 Hz, 5 min
    /// on the pad (coarse 60 s, fine 200 s), about 7 minutes of flight over two legs
    /// with a 60-s outage on the second.
    pub fn quick() -> Result<Self> {
        let mut s = Self::full()?;
        s.spec.imu.rate_hz = 200.0;
        s.coarse = 60.0;
        s.fine = 200.0;
        s.takeoff = 300.0;
        s.outages = vec![(620.0, 680.0)];
        if let Some(SegmentSpec::Hold { duration }) = s.spec.motion.first_mut() {
            *duration = text("300 s");
        }
        for seg in &mut s.spec.motion {
            if let SegmentSpec::Route { waypoints, .. } = seg {
                let wp = |lat: &str, lon: &str, h: &str| WaypointSpec {
                    position: [text(lat), text(lon), text(h)],
                    speed: None,
                    time: None,
                };
                *waypoints = vec![
                    wp("70.09 deg", "25.05 deg", "400 m"),
                    wp("70.10 deg", "25.40 deg", "300 m"),
                ];
            }
        }
        if let Some(g) = s.spec.gnss.as_mut() {
            g.outages = s
                .outages
                .iter()
                .map(|(a, b)| [text(&format!("{a} s")), text(&format!("{b} s"))])
                .collect();
            for o in &mut g.outliers {
                *o = GnssOutlierSpec {
                    at: text("500 s"),
                    ..o.clone()
                };
            }
        }
        Ok(s)
    }

    /// Start of the data [s].
    pub fn t0(&self) -> f64 {
        self.spec.start.as_ref().map_or(0.0, |s| s.time)
    }

    /// End of the coarse stage [s].
    pub fn coarse_end(&self) -> f64 {
        self.t0() + self.coarse
    }

    /// End of alignment, start of navigation [s].
    pub fn nav_start(&self) -> f64 {
        self.coarse_end() + self.fine
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two sorties keep the seed's order of events: alignment ends on the pad, the
    /// outage falls in flight.
    #[test]
    fn timelines_are_consistent() {
        for s in [
            Sortie::full().expect("full"),
            Sortie::quick().expect("quick"),
        ] {
            assert!(s.nav_start() < s.takeoff);
            for (a, b) in &s.outages {
                assert!(s.takeoff < *a && a < b);
            }
            let pad = match &s.spec.motion[0] {
                SegmentSpec::Hold { duration } => duration
                    .si("pad", schuler::units::Dimension::Time)
                    .expect("time"),
                other => panic!("the sortie starts with {other:?}"),
            };
            assert_eq!(pad, s.takeoff);
        }
    }
}
