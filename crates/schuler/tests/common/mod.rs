//! Helpers shared by the library's scenario tests: the repository's example scenarios,
//! a simulation kept in memory (exact increments and truth at every sample) and the
//! GNSS fixes simulated from it.

#![allow(dead_code)] // each test crate uses its own subset

use nalgebra::Vector3;
use schuler::earth::{EarthModel, Wgs84};
use schuler::filter::integration::GnssFix;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{BaroReading, GnssModel, GnssSimulator};
use schuler::sim::run::{ScenarioSpec, SimSink, simulate};
use schuler::sim::scenario::{Quantity, SegmentSpec};

/// `examples/drive.toml`: a car drive near 45° N with a tactical IMU at 200 Hz.
pub const EXAMPLE_DRIVE: &str = include_str!("../../../../examples/drive.toml");

/// `examples/polar_flight.toml`: the demo's helicopter sortie at 70° N with a
/// navigation-grade FOG IMU at 1 kHz.
pub const EXAMPLE_SORTIE: &str = include_str!("../../../../examples/polar_flight.toml");

/// A scenario from its TOML text.
pub fn scenario(text: &str) -> ScenarioSpec {
    toml::from_str(text).expect("scenario")
}

/// `spec` with its `hold` segments lasting `durations` in turn (e.g. `"30 s"`);
/// the holds past the list are kept.
pub fn with_holds(mut spec: ScenarioSpec, durations: &[&str]) -> ScenarioSpec {
    let holds = spec.motion.iter_mut().filter_map(|seg| match seg {
        SegmentSpec::Hold { duration } => Some(duration),
        _ => None,
    });
    for (duration, new) in holds.zip(durations) {
        *duration = Quantity::Text((*new).to_string());
    }
    spec
}

/// The exact increments, the truth at every sample's end, and at each whole second
/// the truth with the body's rate relative to the Earth `w_eb_b` (for
/// [`GnssSimulator::fix_w_eb`], defined at the poles too).
#[derive(Default)]
pub struct Data {
    pub exact: Vec<ImuSample>,
    pub truth: Vec<NavState>,
    pub gnss_epochs: Vec<(NavState, Vector3<f64>)>,
}

impl SimSink for Data {
    fn imu(
        &mut self,
        exact: &ImuSample,
        _m: &ImuSample,
        truth: &NavState,
        kin: &Kinematics,
    ) -> std::io::Result<()> {
        self.exact.push(*exact);
        self.truth.push(*truth);
        if (truth.t - truth.t.round()).abs() < 1e-6 {
            let w_ie_n = Wgs84.w_ie_n(truth.pos.lat);
            let w_eb = kin.w_ib_b - truth.q_bn.inverse() * w_ie_n;
            self.gnss_epochs.push((*truth, w_eb));
        }
        Ok(())
    }
    fn gnss(&mut self, _f: &schuler::sim::receivers::GnssFix) -> std::io::Result<()> {
        Ok(())
    }
    fn baro(&mut self, _b: &BaroReading) -> std::io::Result<()> {
        Ok(())
    }
}

/// `spec` simulated in memory.
pub fn simulated(spec: &ScenarioSpec) -> Data {
    let mut d = Data::default();
    simulate(spec, &mut d).expect("simulate");
    d
}

/// The GNSS fixes of `model` with noise seed `seed` at the whole seconds of `d` from
/// t = 1 s on, each with its velocity; and how many carry an injected outlier.
pub fn gnss_fixes(d: &Data, model: GnssModel, seed: u64) -> (Vec<GnssFix>, usize) {
    let mut sim = GnssSimulator::new(model, seed);
    let mut injected = 0;
    let fixes = d
        .gnss_epochs
        .iter()
        .filter(|(s, _)| s.t >= 1.0)
        .filter_map(|(s, w)| sim.fix_w_eb(&Wgs84, s, w))
        .map(|f| {
            injected += usize::from(f.outlier);
            GnssFix {
                t: f.t,
                pos: f.pos,
                pos_std: f.pos_std,
                vel: Some((f.v_n, f.vel_std)),
            }
        })
        .collect();
    (fixes, injected)
}
