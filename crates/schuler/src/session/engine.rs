//! The mechanizations a session runs, free or under the filter, and the hand-over
//! between NED and the wander frame at [`super::MechanizationConfig::auto_latitude`].
//!
//! A hand-over converts the state and the two-sample step history exactly (NED →
//! wander with wander azimuth 0; wander → NED by turning velocity, attitude and the
//! history through the azimuth), so the run continues as if uninterrupted; under the
//! filter the covariance is turned between the two computation frames
//! ([`crate::filter::Integrator::hand_over`]).

use super::config::{MechanizationChoice, MechanizationConfig, MechanizationKind};
use super::output::Handover;
use crate::earth::EarthModel;
use crate::filter::Integrator;
use crate::filter::seed18::Seed18;
use crate::nav::{ErrorFrame, LocalLevel, Mechanization, NavState, Wander};
use nalgebra::Vector3;

/// A mechanization a session can run.
pub trait Navigating<E: EarthModel>: ErrorFrame + Sized {
    /// Which one it is.
    const KIND: MechanizationKind;
    /// Start at `init`.
    fn start(earth: E, init: NavState) -> Self;
    /// The NED state, the ECEF position and the wander azimuth now.
    fn read_out(&self) -> (NavState, Vector3<f64>, f64);
    /// `sin` of the latitude now (cheap, for the hand-over's thresholds).
    fn sin_lat(&self) -> f64;
}

impl<E: EarthModel> Navigating<E> for LocalLevel<E> {
    const KIND: MechanizationKind = MechanizationKind::Ned;
    fn start(earth: E, init: NavState) -> Self {
        LocalLevel::new(earth, init)
    }
    fn read_out(&self) -> (NavState, Vector3<f64>, f64) {
        let state = self.state();
        (state, self.earth().geodetic_to_ecef(&state.pos), 0.0)
    }
    #[inline]
    fn sin_lat(&self) -> f64 {
        self.state().pos.lat.sin()
    }
}

impl<E: EarthModel> Navigating<E> for Wander<E> {
    const KIND: MechanizationKind = MechanizationKind::Wander;
    fn start(earth: E, init: NavState) -> Self {
        Wander::new(earth, init)
    }
    fn read_out(&self) -> (NavState, Vector3<f64>, f64) {
        let (state, alpha) = self.nav_state_and_azimuth();
        (state, self.ecef_position(), alpha)
    }
    #[inline]
    fn sin_lat(&self) -> f64 {
        Wander::sin_lat(self)
    }
}

/// The running navigation: a mechanization alone or under the filter.
#[derive(Debug, Clone)]
pub(crate) enum Core<E: EarthModel> {
    Ned(LocalLevel<E>),
    Wander(Wander<E>),
    FilterNed(Integrator<LocalLevel<E>, E>),
    FilterWander(Integrator<Wander<E>, E>),
    /// The 18-state filter (wander only, never handed over).
    FilterSeed18(Box<Seed18<E>>),
}

/// When `auto` hands over: above `sin_enter` to wander, below `sin_leave` to NED.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Switch {
    pub auto: bool,
    pub sin_enter: f64,
    pub sin_leave: f64,
    /// A latitude [rad] 1 µrad below the hand-over's: below it `|sin φ|` is surely
    /// below `sin_enter` (the sines differ by more than 1e-13 at any latitude, libm's
    /// `sin` errs by an ulp), so the NED run skips its per-sample sine.
    pub lat_clear: f64,
}

impl Switch {
    pub fn new(m: &MechanizationConfig) -> Self {
        Self {
            auto: m.choice == MechanizationChoice::Auto,
            sin_enter: m.auto_latitude.sin(),
            sin_leave: (m.auto_latitude - m.hysteresis).sin(),
            lat_clear: m.auto_latitude - 1e-6,
        }
    }

    /// Whether to start on the wander frame at the latitude whose `sin` is `sin_lat`.
    pub fn starts_wander(&self, choice: MechanizationChoice, sin_lat: f64) -> bool {
        match choice {
            MechanizationChoice::Ned => false,
            MechanizationChoice::Wander => true,
            MechanizationChoice::Auto => sin_lat.abs() > self.sin_enter,
        }
    }

    /// Whether the running mechanization `kind` at `sin_lat` should hand over.
    #[inline]
    pub fn due(&self, kind: MechanizationKind, sin_lat: f64) -> bool {
        self.auto
            && match kind {
                MechanizationKind::Ned => sin_lat.abs() > self.sin_enter,
                MechanizationKind::Wander => sin_lat.abs() < self.sin_leave,
            }
    }

    /// Whether `core` should hand over ([`Self::due`] at its latitude), without the
    /// sine on an NED run clear of the hand-over latitude ([`Self::lat_clear`]): the
    /// same answer at every sample.
    #[inline]
    pub fn due_for<E: EarthModel>(&self, core: &Core<E>) -> bool {
        self.auto
            && !core.ned_latitude_below(self.lat_clear)
            && self.due(core.kind(), core.sin_lat())
    }
}

impl<E: EarthModel> Core<E> {
    pub fn kind(&self) -> MechanizationKind {
        match self {
            Core::Ned(_) | Core::FilterNed(_) => MechanizationKind::Ned,
            Core::Wander(_) | Core::FilterWander(_) | Core::FilterSeed18(_) => {
                MechanizationKind::Wander
            }
        }
    }

    /// Whether this is an NED run whose `|latitude|` is below `lat` [rad].
    #[inline]
    fn ned_latitude_below(&self, lat: f64) -> bool {
        match self {
            Core::Ned(m) => m.state().pos.lat.abs() < lat,
            Core::FilterNed(i) => i.mechanization().state().pos.lat.abs() < lat,
            _ => false,
        }
    }

    pub fn sin_lat(&self) -> f64 {
        match self {
            Core::Ned(m) => m.sin_lat(),
            Core::Wander(m) => Navigating::sin_lat(m),
            Core::FilterNed(i) => i.mechanization().sin_lat(),
            Core::FilterWander(i) => Navigating::sin_lat(i.mechanization()),
            Core::FilterSeed18(i) => Navigating::sin_lat(i.mechanization()),
        }
    }

    pub fn read_out(&self) -> (NavState, Vector3<f64>, f64) {
        match self {
            Core::Ned(m) => m.read_out(),
            Core::Wander(m) => m.read_out(),
            Core::FilterNed(i) => i.mechanization().read_out(),
            Core::FilterWander(i) => i.mechanization().read_out(),
            Core::FilterSeed18(i) => i.mechanization().read_out(),
        }
    }

    /// The other mechanization continuing from this one's state (module doc).
    pub fn handed_over(self) -> (Self, Handover) {
        let core = match self {
            Core::Ned(m) => Core::Wander(Wander::from_local_level(&m)),
            Core::Wander(m) => Core::Ned(m.to_local_level()),
            Core::FilterNed(i) => Core::FilterWander(i.hand_over(Wander::from_local_level)),
            Core::FilterWander(i) => Core::FilterNed(i.hand_over(Wander::to_local_level)),
            // The configuration refuses a hand-over with the 18-state model
            // (`SessionConfig::validate`): it stays.
            Core::FilterSeed18(i) => Core::FilterSeed18(i),
        };
        let (state, ..) = core.read_out();
        let handover = Handover {
            t: state.t,
            lat: state.pos.lat,
            to: core.kind(),
        };
        (core, handover)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Geodetic, Wgs84};
    use nalgebra::UnitQuaternion;
    use std::f64::consts::FRAC_PI_2;

    /// The NED run's short cut decides as the sine does at every latitude, right up
    /// to the hand-over latitude (a sweep in 1e-9 rad steps across it, both signs,
    /// and for a hand-over latitude of 90° too).
    #[test]
    fn skipping_the_sine_decides_as_the_sine() {
        for degrees in [75.0f64, 30.0, 89.9, 90.0] {
            let config = MechanizationConfig {
                auto_latitude: degrees.to_radians(),
                ..MechanizationConfig::default()
            };
            let switch = Switch::new(&config);
            let mut shortcuts = 0;
            for k in -20_000i32..=20_000 {
                for sign in [1.0, -1.0] {
                    let lat = sign * (config.auto_latitude + f64::from(k) * 1e-9).min(FRAC_PI_2);
                    let core = Core::Ned(LocalLevel::new(
                        Wgs84,
                        NavState {
                            t: 0.0,
                            pos: Geodetic::new(lat, 0.1, 100.0),
                            v_n: Vector3::zeros(),
                            q_bn: UnitQuaternion::identity(),
                        },
                    ));
                    let by_sine = switch.due(core.kind(), core.sin_lat());
                    assert_eq!(switch.due_for(&core), by_sine, "lat {lat}");
                    shortcuts += usize::from(core.ned_latitude_below(switch.lat_clear));
                }
            }
            // The sweep reaches below the clear latitude: the short cut was taken.
            assert!(shortcuts > 0, "{degrees}");
        }
    }
}
