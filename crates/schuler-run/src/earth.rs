//! The Earth model a run chose, as one type: the library's session, filter and
//! writers are generic over [`EarthModel`], and each model they are used with is
//! compiled again (at the test profile's opt-level 3, in every crate that starts a
//! run). [`AnyEarth`] is the choice made at run time and forwards every method to the
//! chosen model, so a run is compiled once for all models and computes the same
//! numbers, bit for bit, as on the model itself.

use crate::options::EarthChoice;
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, LocalEarth, Radii, Sphere, Wgs84, Wgs84Series};

/// One of the Earth models a run can choose ([`EarthChoice`]).
#[derive(Clone, Copy, PartialEq)]
pub enum AnyEarth {
    /// WGS84 with its normal gravity (TR8350.2).
    Wgs84(Wgs84),
    /// WGS84 with KF-GINS's GRS80 normal gravity series.
    Wgs84Series(Wgs84Series),
    /// The textbook's sphere, rotating or not.
    Sphere(Sphere),
}

impl AnyEarth {
    /// The model `choice` names (the sphere is the textbook's, rotating unless
    /// [`EarthChoice::SphereFixed`]).
    pub fn of(choice: EarthChoice) -> Self {
        match choice {
            EarthChoice::Wgs84 => Self::Wgs84(Wgs84),
            EarthChoice::Wgs84Series => Self::Wgs84Series(Wgs84Series),
            EarthChoice::Sphere => Self::Sphere(Sphere::textbook(true)),
            EarthChoice::SphereFixed => Self::Sphere(Sphere::textbook(false)),
        }
    }
}

/// `$body` with `$e` bound to the chosen model.
macro_rules! each {
    ($earth:expr, $e:ident => $body:expr) => {
        match $earth {
            AnyEarth::Wgs84($e) => $body,
            AnyEarth::Wgs84Series($e) => $body,
            AnyEarth::Sphere($e) => $body,
        }
    };
}

/// As the chosen model's own `Debug` (a model's name may be written out).
impl std::fmt::Debug for AnyEarth {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        each!(self, e => std::fmt::Debug::fmt(e, f))
    }
}

/// Every method, the provided ones too, forwarded: the models override some of them
/// with their own closed forms.
impl EarthModel for AnyEarth {
    #[inline]
    fn semi_major_axis(&self) -> f64 {
        each!(self, e => EarthModel::semi_major_axis(e))
    }
    #[inline]
    fn eccentricity_squared(&self) -> f64 {
        each!(self, e => EarthModel::eccentricity_squared(e))
    }
    #[inline]
    fn rotation_rate(&self) -> f64 {
        each!(self, e => EarthModel::rotation_rate(e))
    }
    #[inline]
    fn gravity_n(&self, lat: f64, h: f64) -> Vector3<f64> {
        each!(self, e => EarthModel::gravity_n(e, lat, h))
    }
    #[inline]
    fn radii(&self, lat: f64) -> Radii {
        each!(self, e => EarthModel::radii(e, lat))
    }
    #[inline]
    fn local(&self, lat: f64, h: f64) -> LocalEarth {
        each!(self, e => EarthModel::local(e, lat, h))
    }
    #[inline]
    fn local_from_sin_cos(&self, sin_lat: f64, cos_lat: f64, h: f64) -> LocalEarth {
        each!(self, e => EarthModel::local_from_sin_cos(e, sin_lat, cos_lat, h))
    }
    #[inline]
    fn w_ie_n(&self, lat: f64) -> Vector3<f64> {
        each!(self, e => EarthModel::w_ie_n(e, lat))
    }
    fn geodetic_to_ecef(&self, p: &Geodetic) -> Vector3<f64> {
        each!(self, e => EarthModel::geodetic_to_ecef(e, p))
    }
    fn ecef_to_geodetic(&self, r_e: &Vector3<f64>) -> Geodetic {
        each!(self, e => EarthModel::ecef_to_geodetic(e, r_e))
    }
}
