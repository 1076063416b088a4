//! [`Wgs84Series`]: the WGS84 ellipsoid with normal gravity from the GRS80 series in
//! `sin² lat` and a second-order height term, the gravity KF-GINS navigates with.
//!
//! On the ellipsoid (Moritz, "Geodetic Reference System 1980", Bulletin Géodésique
//! 54(3), 1980; J. Geodesy 74, 2000, the series for normal gravity):
//!
//! `γ₀ = γₐ (1 + 0.0052790414 sin²φ + 0.0000232718 sin⁴φ + 0.0000001262 sin⁶φ
//!            + 0.0000000007 sin⁸φ)`, with `γₐ = 9.7803267715 m/s²`;
//!
//! above it (the free-air expansion to second order in the rounded form of the
//! geodesy literature, e.g. the "Normal gravity formula" article after Torge's
//! *Geodesy*, in m/s² with `h` in metres):
//!
//! `γ = γ₀ − (3.0877e-6 − 4.3e-9 sin²φ) h + 0.72e-12 h²`.
//!
//! Against TR8350.2's closed form ([`super::Wgs84`]) it is 1.4e-6 m/s² higher at 30°
//! (GRS80's `GM` against WGS84's, and the rounding of the height term): enough to
//! move a free vertical channel by metres in half an hour, which is why a drop-in for
//! KF-GINS offers it.

use super::{EarthModel, LocalEarth, Wgs84};
use nalgebra::Vector3;

/// The WGS84 ellipsoid and rotation rate of [`Wgs84`], with the GRS80 normal gravity
/// series (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wgs84Series;

impl Wgs84Series {
    /// GRS80 normal gravity at the equator [m/s²].
    pub const GAMMA_A: f64 = 9.780_326_771_5;
    /// The series' coefficients of `sin²φ, sin⁴φ, sin⁶φ, sin⁸φ` (Moritz 1980).
    pub const SERIES: [f64; 4] = [
        0.005_279_041_4,
        0.000_023_271_8,
        0.000_000_126_2,
        0.000_000_000_7,
    ];

    /// Normal gravity magnitude [m/s²] at latitude `lat` [rad] and height `h` [m]
    /// (module doc).
    pub fn normal_gravity(lat: f64, h: f64) -> f64 {
        let s = lat.sin();
        Self::from_sin2(s * s, h)
    }

    /// [`Wgs84Series::normal_gravity`] from `sin² lat`.
    #[inline]
    fn from_sin2(s2: f64, h: f64) -> f64 {
        let s4 = s2 * s2;
        let [c2, c4, c6, c8] = Self::SERIES;
        let on_ellipsoid = Self::GAMMA_A * (1.0 + c2 * s2 + c4 * s4 + c6 * s2 * s4 + c8 * s4 * s4);
        on_ellipsoid - (3.0877e-6 - 4.3e-9 * s2) * h + 0.72e-12 * h * h
    }
}

impl EarthModel for Wgs84Series {
    fn semi_major_axis(&self) -> f64 {
        Wgs84::A
    }
    fn eccentricity_squared(&self) -> f64 {
        Wgs84::E2
    }
    fn rotation_rate(&self) -> f64 {
        Wgs84::OMEGA
    }
    #[inline]
    fn gravity_n(&self, lat: f64, h: f64) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, Self::normal_gravity(lat, h))
    }
    /// As the provided method, through [`EarthModel::local_from_sin_cos`].
    #[inline]
    fn local(&self, lat: f64, h: f64) -> LocalEarth {
        let (s, c) = lat.sin_cos();
        self.local_from_sin_cos(s, c, h)
    }
    /// [`Wgs84`]'s radii with the series' gravity.
    #[inline]
    fn local_from_sin_cos(&self, s: f64, c: f64, h: f64) -> LocalEarth {
        Wgs84::local_with(s, c, h, |s2, _| Self::from_sin2(s2, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the ellipsoid the series is GRS80's Somigliana closed form
    /// `γₑ (1 + k sin²φ) / sqrt(1 − e² sin²φ)` with GRS80's printed constants
    /// (γₑ = 9.7803267715, γₚ = 9.8321863685 m/s², k = 0.001931851353,
    /// e² = 0.00669438002290): the series is truncated after sin⁸φ and its
    /// coefficients are printed to 1e-10, so they agree to a few 1e-10 m/s².
    #[test]
    fn the_series_is_grs80_somigliana_on_the_ellipsoid() {
        let (ge, k, e2) = (9.780_326_771_5, 0.001_931_851_353, 0.006_694_380_022_90);
        for i in 0..=90 {
            let lat = f64::from(i).to_radians();
            let s2 = lat.sin().powi(2);
            let closed = ge * (1.0 + k * s2) / (1.0 - e2 * s2).sqrt();
            let d = Wgs84Series::normal_gravity(lat, 0.0) - closed;
            assert!(d.abs() < 5e-10, "{i} deg: {d:e}");
        }
        let pole = Wgs84Series::normal_gravity(std::f64::consts::FRAC_PI_2, 0.0);
        assert!((pole - 9.832_186_368_5).abs() < 5e-10, "{pole}");
    }

    /// Above the ellipsoid the height term is GRS80's own expansion,
    /// `−(3.087691e-6 − 4.398e-9 sin²φ) h + 0.72e-12 h²` (Moritz 1980), but for the
    /// rounding of its two coefficients (9e-12 and 9.8e-11 sin²φ per metre): within
    /// 1.1e-10·h m/s² (1.1e-7 at 1 km). And the
    /// series stays within 1.5e-6 m/s² of TR8350.2's closed form ([`Wgs84`]) from the
    /// equator to the poles and up to 10 km (the GM of GRS80 against WGS84's: 0.14
    /// mGal at the equator).
    #[test]
    fn the_height_term_and_the_tr8350_closed_form() {
        for i in 0..=18 {
            let lat = f64::from(5 * i).to_radians();
            let s2 = lat.sin().powi(2);
            for h in [0.0, 245.0, 1000.0, 10_000.0] {
                let grs80 = Wgs84Series::normal_gravity(lat, 0.0)
                    - (3.087_691e-6 - 4.398e-9 * s2) * h
                    + 0.72e-12 * h * h;
                let ours = Wgs84Series::normal_gravity(lat, h);
                assert!((ours - grs80).abs() <= 1.1e-10 * h + 1e-15, "{i} {h}");
                let tr8350 = Wgs84::normal_gravity(lat, h);
                assert!(
                    (ours - tr8350).abs() < 1.5e-6,
                    "{i} {h}: {:e}",
                    ours - tr8350
                );
            }
        }
        // The figure: 1.4e-6 m/s^2 apart at 30 deg on the ellipsoid.
        let d30 = Wgs84Series::normal_gravity(30f64.to_radians(), 0.0)
            - Wgs84::normal_gravity(30f64.to_radians(), 0.0);
        assert!((d30 - 1.4e-6).abs() < 0.1e-6, "{d30:e}");
    }

    /// `local` and `local_from_sin_cos` give the series' gravity and WGS84's radii.
    #[test]
    fn local_has_wgs84_radii_and_the_series_gravity() {
        let lat = 0.7;
        let l = Wgs84Series.local(lat, 300.0);
        let w = Wgs84.local(lat, 300.0);
        assert_eq!(l.radii.meridian, w.radii.meridian);
        assert_eq!(l.radii.prime_vertical, w.radii.prime_vertical);
        assert_eq!(l.g_n.z, Wgs84Series::normal_gravity(lat, 300.0));
        assert_eq!(Wgs84Series.gravity_n(lat, 300.0), l.g_n);
    }
}
