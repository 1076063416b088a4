//! The signal's path through the atmosphere: a satellite's elevation and azimuth from
//! the receiver, the Klobuchar ionosphere broadcast by GPS, and the Saastamoinen
//! troposphere on a standard atmosphere.
//!
//! - Klobuchar: IS-GPS-200N §20.3.3.5.2.5 and Figure 20-4, the L1 group delay from the
//!   eight broadcast coefficients (α from RINEX's `ION ALPHA`/`GPSA`, β from `ION
//!   BETA`/`GPSB`); on another frequency f the delay scales by (f_L1/f)², the
//!   ionosphere's first-order dispersion (IS-GPS-200 §20.3.3.3.3.3).
//! - Saastamoinen (1972): zenith hydrostatic delay 0.0022768·P/(1 − 0.00266·cos 2φ −
//!   0.00028·h_km) (Davis et al. 1985's form) and wet delay
//!   0.002277·(1255/T + 0.05)·e, with P, T and e from the ISA standard atmosphere
//!   (1013.25 hPa and 15 °C at sea level, −6.5 K/km to 11 km, isothermal above) and a
//!   relative humidity of 50 %; the water-vapour pressure by Magnus–Tetens.
//! - Mapping to the slant: RTCA DO-229 (MOPS, §A.4.2.4) `m(E) = 1.001/√(0.002001 +
//!   sin²E)`, one function for both parts: within 0.5 % of Niell's above 10°, and
//!   finite at the horizon (1/sin E is not, and errs by metres below 10°).

use nalgebra::Vector3;

use crate::earth::{EarthModel, Wgs84, c_ne};

/// A satellite's direction seen from a receiver: elevation above the ellipsoid's
/// tangent plane and azimuth clockwise from north [rad].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LookAngles {
    /// Elevation, −π/2 … π/2.
    pub elevation: f64,
    /// Azimuth, 0 … 2π, clockwise from north.
    pub azimuth: f64,
}

/// The look angles of a satellite at ECEF `r_sat` from a receiver at ECEF `r_rx`
/// [m] (WGS84 geodetic normal). A receiver within 1 km of the Earth's centre (an SPP's
/// first iterate) sees every satellite at the zenith.
pub fn look_angles(r_rx: &Vector3<f64>, r_sat: &Vector3<f64>) -> LookAngles {
    if r_rx.norm() < 1e3 {
        return LookAngles {
            elevation: std::f64::consts::FRAC_PI_2,
            azimuth: 0.0,
        };
    }
    let p = Wgs84.ecef_to_geodetic(r_rx);
    let los_n = c_ne(p.lat, p.lon).transpose() * (r_sat - r_rx);
    let elevation = (-los_n.z).atan2(los_n.x.hypot(los_n.y));
    let azimuth = los_n.y.atan2(los_n.x).rem_euclid(std::f64::consts::TAU);
    LookAngles { elevation, azimuth }
}

/// The GPS broadcast ionosphere coefficients (IS-GPS-200 §20.3.3.5.1.7): α₀..α₃ [s,
/// s/semicircle, s/semicircle², s/semicircle³] and β₀..β₃ [s, s/semicircle, …].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Klobuchar {
    /// Amplitude coefficients α.
    pub alpha: [f64; 4],
    /// Period coefficients β.
    pub beta: [f64; 4],
}

/// The L1 carrier frequency [Hz], Klobuchar's reference.
pub const F_L1: f64 = 1_575.42e6;

impl Klobuchar {
    /// The ionospheric group delay on L1 [s] (IS-GPS-200 Figure 20-4) for a receiver
    /// at geodetic latitude `lat` and longitude `lon` [rad], a satellite at `look`,
    /// at GPS second of week (or of day) `t_sow`. At least 5 ns·F at night.
    pub fn l1_delay_s(&self, lat: f64, lon: f64, look: LookAngles, t_sow: f64) -> f64 {
        use super::ephemeris::ICD_PI as PI;
        // Semicircles.
        let el = look.elevation / PI;
        let (phi_u, lambda_u) = (lat / PI, lon / PI);
        let psi = 0.0137 / (el + 0.11) - 0.022;
        let phi_i = (phi_u + psi * look.azimuth.cos()).clamp(-0.416, 0.416);
        let lambda_i = lambda_u + psi * look.azimuth.sin() / (phi_i * PI).cos();
        let phi_m = phi_i + 0.064 * ((lambda_i - 1.617) * PI).cos();
        let t = (4.32e4 * lambda_i + t_sow).rem_euclid(86_400.0);
        let f = 1.0 + 16.0 * (0.53 - el).powi(3);
        let poly = |c: &[f64; 4]| c[0] + phi_m * (c[1] + phi_m * (c[2] + phi_m * c[3]));
        let per = poly(&self.beta).max(72_000.0);
        let amp = poly(&self.alpha).max(0.0);
        let x = 2.0 * PI * (t - 50_400.0) / per;
        if x.abs() < 1.57 {
            let x2 = x * x;
            f * (5e-9 + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0))
        } else {
            f * 5e-9
        }
    }

    /// The ionospheric group delay [m] on carrier frequency `freq` [Hz]: the L1 delay
    /// times c·(f_L1/f)².
    pub fn delay_m(&self, lat: f64, lon: f64, look: LookAngles, t_sow: f64, freq: f64) -> f64 {
        let r = F_L1 / freq;
        self.l1_delay_s(lat, lon, look, t_sow) * super::ephemeris::C * r * r
    }
}

/// Pressure [hPa], temperature [K] and water-vapour pressure [hPa] of the standard
/// atmosphere at height `h` [m] (see the module's doc).
pub fn standard_atmosphere(h: f64) -> (f64, f64, f64) {
    const T0: f64 = 288.15;
    const LAPSE: f64 = 0.0065;
    const H_TROPOPAUSE: f64 = 11_000.0;
    // g0·M/(R·L) and g0·M/(R·T11) of the ISA.
    const EXPONENT: f64 = 5.255_88;
    const SCALE: f64 = 1.576_9e-4;
    let h_trop = h.min(H_TROPOPAUSE);
    let t = T0 - LAPSE * h_trop;
    let mut p = 1013.25 * (t / T0).powf(EXPONENT);
    if h > H_TROPOPAUSE {
        p *= (-SCALE * (h - H_TROPOPAUSE)).exp();
    }
    let tc = t - 273.15;
    let e = 0.5 * 6.1078 * (17.27 * tc / (tc + 237.3)).exp();
    (p, t, e)
}

/// Saastamoinen's zenith delays [m], hydrostatic and wet, at geodetic latitude `lat`
/// [rad] and height `h` [m] on the standard atmosphere (−500 m ≤ h; above the
/// tropopause the wet part vanishes with the vapour).
pub fn saastamoinen_zenith(lat: f64, h: f64) -> (f64, f64) {
    let h = h.max(-500.0);
    let (p, t, e) = standard_atmosphere(h);
    let hydro = 0.002_276_8 * p / (1.0 - 0.002_66 * (2.0 * lat).cos() - 0.000_28 * h / 1e3);
    let wet = 0.002_277 * (1_255.0 / t + 0.05) * e;
    (hydro, wet)
}

/// The troposphere's mapping from zenith to elevation `el` [rad] (RTCA DO-229's).
pub fn tropo_mapping(el: f64) -> f64 {
    let s = el.sin();
    1.001 / (0.002_001 + s * s).sqrt()
}

/// The tropospheric delay [m] along a line of sight at elevation `el` [rad] from
/// geodetic latitude `lat` [rad] and height `h` [m].
pub fn tropo_delay_m(lat: f64, h: f64, el: f64) -> f64 {
    let (hydro, wet) = saastamoinen_zenith(lat, h);
    (hydro + wet) * tropo_mapping(el)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Geodetic;
    use std::f64::consts::PI;

    /// RINEX brdc1820.10n's header: 2010-07-01's coefficients.
    const IONO: Klobuchar = Klobuchar {
        alpha: [0.4657e-08, 0.1490e-07, -0.5960e-07, -0.1192e-06],
        beta: [0.8192e+05, 0.8192e+05, -0.6554e+05, -0.5243e+06],
    };

    fn look(el_deg: f64, az_deg: f64) -> LookAngles {
        LookAngles {
            elevation: el_deg.to_radians(),
            azimuth: az_deg.to_radians(),
        }
    }

    #[test]
    fn look_angles_of_known_directions() {
        let rx = Geodetic::from_degrees(45.0, 10.0, 100.0);
        let r_rx = Wgs84.geodetic_to_ecef(&rx);
        let up = c_ne(rx.lat, rx.lon) * Vector3::new(0.0, 0.0, -1.0);
        let zenith = look_angles(&r_rx, &(r_rx + 2e7 * up));
        assert!((zenith.elevation - PI / 2.0).abs() < 1e-9);
        let east = c_ne(rx.lat, rx.lon) * Vector3::new(0.0, 1.0, -1.0);
        let a = look_angles(&r_rx, &(r_rx + 1e7 * east));
        assert!((a.elevation - PI / 4.0).abs() < 1e-9 && (a.azimuth - PI / 2.0).abs() < 1e-9);
        let nw = c_ne(rx.lat, rx.lon) * Vector3::new(1.0, -1.0, 0.0);
        let a = look_angles(&r_rx, &(r_rx + 1e6 * nw));
        assert!(a.elevation.abs() < 1e-9 && (a.azimuth - 1.75 * PI).abs() < 1e-9);
        let centre = look_angles(&Vector3::zeros(), &(2e7 * up));
        assert_eq!(centre.elevation, PI / 2.0);
    }

    #[test]
    fn klobuchar_night_floor_is_5_ns_times_the_obliquity() {
        // At the zenith F = 1 + 16(0.53 − 0.5)³ = 1.000432: at 02:00 local time the
        // cosine is off (|x| ≥ 1.57) and the delay is the 5-ns floor.
        let (lat, lon) = (0.0, 0.0);
        let d = IONO.l1_delay_s(lat, lon, look(90.0, 0.0), 2.0 * 3600.0);
        let f = 1.0 + 16.0 * 0.03f64.powi(3);
        assert!((d - 5e-9 * f).abs() < 1e-18, "{d}");
        // At 10° elevation, F (the obliquity factor) is near 3.
        let d = IONO.l1_delay_s(lat, lon, look(10.0, 0.0), 2.0 * 3600.0);
        assert!((d / 5e-9 - 1.0 - 16.0 * (0.53 - 10.0 / 180.0f64).powi(3)).abs() < 1e-9);
    }

    #[test]
    fn klobuchar_daytime_peak_is_the_cosines_amplitude() {
        // Local 14:00 (50400 s) at the zenith: x = 0, the delay is F·(5 ns + AMP) with
        // AMP the α polynomial in the geomagnetic latitude φm = φi + 0.064 cos(λi − 1.617).
        let (lat, lon) = (0.0, 0.0);
        let d = IONO.l1_delay_s(lat, lon, look(90.0, 0.0), 50_400.0);
        let psi = 0.0137 / (0.5 + 0.11) - 0.022;
        let phi_m = psi + 0.064 * ((-1.617) * PI).cos();
        let a = IONO.alpha;
        let amp = a[0] + a[1] * phi_m + a[2] * phi_m.powi(2) + a[3] * phi_m.powi(3);
        let f = 1.0 + 16.0 * 0.03f64.powi(3);
        assert!(
            (d - f * (5e-9 + amp)).abs() < 1e-15,
            "{d} {}",
            f * (5e-9 + amp)
        );
        // Two hours either side, the cosine's series: below the peak, above the floor.
        let before = IONO.l1_delay_s(lat, lon, look(90.0, 0.0), 43_200.0);
        assert!(before < d && before > 5e-9 * f);
        // On L2 the delay in metres is (77/60)² that on L1.
        let l1 = IONO.delay_m(lat, lon, look(30.0, 0.0), 50_400.0, F_L1);
        let l2 = IONO.delay_m(lat, lon, look(30.0, 0.0), 50_400.0, 1_227.6e6);
        assert!((l2 / l1 - (77.0f64 / 60.0).powi(2)).abs() < 1e-12);
    }

    #[test]
    fn saastamoinen_zenith_delay_is_2_3_m_at_sea_level() {
        let (hydro, wet) = saastamoinen_zenith(45f64.to_radians(), 0.0);
        // 0.0022768·1013.25 = 2.3070 m at 45°; wet 0.002277·(1255/288.15 + 0.05)·8.5
        // hPa = 0.085 m.
        assert!((hydro - 2.3070).abs() < 1e-4, "{hydro}");
        assert!((wet - 0.0855).abs() < 1e-3, "{wet}");
        // At 2 km the pressure is 795 hPa (ISA): 1.81 m hydrostatic.
        let (h2, _) = saastamoinen_zenith(45f64.to_radians(), 2_000.0);
        assert!(
            (h2 - 0.0022768 * 795.0 / (1.0 - 0.00056)).abs() < 5e-3,
            "{h2}"
        );
        // The mapping: 1 at the zenith, about 1/sin E at 30°, finite at the horizon.
        assert!((tropo_mapping(PI / 2.0) - 1.0).abs() < 1e-3);
        assert!((tropo_mapping(PI / 6.0) - 2.0).abs() < 0.01);
        assert!(tropo_mapping(0.0).is_finite() && tropo_mapping(0.0) > 20.0);
        let slant = tropo_delay_m(45f64.to_radians(), 0.0, PI / 6.0);
        assert!((slant - 2.0 * (hydro + wet)).abs() < 0.03, "{slant}");
        // Above the tropopause: little left, still finite.
        let (h20, w20) = saastamoinen_zenith(0.0, 20_000.0);
        assert!(h20 > 0.0 && h20 < 0.2 && w20 < 1e-3, "{h20} {w20}");
    }
}
