//! Earth models: the WGS84 ellipsoid with normal gravity (TR8350.2's closed form, or
//! the GRS80 series KF-GINS uses: [`Wgs84Series`]), and the textbook's sphere.
//!
//! Both are ellipsoids of revolution (the sphere has zero eccentricity), so the
//! geometry — radii of curvature, geodetic <-> ECEF, Earth rate and transport rate in
//! NED — is provided once by [`EarthModel`] from the semi-major axis and eccentricity;
//! each model supplies its own gravity and rotation rate.
//!
//! References: NIMA TR8350.2 (3rd ed., 2000) for WGS84 constants and normal gravity
//! (Somigliana's formula, eq. 4-1, with the height series eq. 4-3); Titterton & Weston
//! (2004) ch. 3 for radii and transport rate; Bowring (1976, 1985) for ECEF -> geodetic.

use nalgebra::{Matrix3, Vector3};

mod series;
pub use series::Wgs84Series;

/// Geodetic position: latitude and longitude [rad], ellipsoidal height [m].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Geodetic {
    /// Geodetic latitude [rad], [-pi/2, pi/2].
    pub lat: f64,
    /// Longitude [rad], east positive.
    pub lon: f64,
    /// Height above the ellipsoid [m].
    pub h: f64,
}

impl Geodetic {
    /// Position from latitude, longitude [rad] and height [m].
    pub const fn new(lat: f64, lon: f64, h: f64) -> Self {
        Self { lat, lon, h }
    }

    /// Position from latitude, longitude [deg] and height [m].
    pub fn from_degrees(lat_deg: f64, lon_deg: f64, h: f64) -> Self {
        Self::new(lat_deg.to_radians(), lon_deg.to_radians(), h)
    }
}

/// Principal radii of curvature at a latitude [m].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Radii {
    /// Meridian radius `R_M = a (1 - e^2) / (1 - e^2 sin^2 lat)^(3/2)`.
    pub meridian: f64,
    /// Prime-vertical radius `R_N = a / sqrt(1 - e^2 sin^2 lat)`.
    pub prime_vertical: f64,
}

/// An Earth model: ellipsoid geometry, rotation and gravity.
///
/// Implementations are small `Copy` values so mechanizations can be generic over them
/// at no run-time cost.
pub trait EarthModel: Copy + std::fmt::Debug + Send + Sync {
    /// Semi-major axis `a` [m].
    fn semi_major_axis(&self) -> f64;
    /// First eccentricity squared `e^2` (0 for a sphere).
    fn eccentricity_squared(&self) -> f64;
    /// Rotation rate about the polar axis [rad/s] (0 for a non-rotating model).
    fn rotation_rate(&self) -> f64;
    /// Gravity (gravitation plus centrifugal) in NED at a position [m/s^2].
    fn gravity_n(&self, lat: f64, h: f64) -> Vector3<f64>;

    /// Radii of curvature at latitude `lat` [rad].
    #[inline]
    fn radii(&self, lat: f64) -> Radii {
        radii_from_sin(
            self.semi_major_axis(),
            self.eccentricity_squared(),
            lat.sin(),
        )
    }

    /// Everything a mechanization needs at one position, with one `sin_cos` of latitude.
    #[inline]
    fn local(&self, lat: f64, h: f64) -> LocalEarth {
        let (sin_lat, cos_lat) = lat.sin_cos();
        LocalEarth {
            sin_lat,
            cos_lat,
            h,
            radii: radii_from_sin(self.semi_major_axis(), self.eccentricity_squared(), sin_lat),
            g_n: self.gravity_n(lat, h),
            rotation_rate: self.rotation_rate(),
        }
    }

    /// [`EarthModel::local`] from `sin lat`, `cos lat` (`cos ≥ 0`) and height `h` [m],
    /// for callers that hold the sine and cosine rather than the latitude: the wander
    /// mechanization (from the polar axis in its frame, seed 003) and the simulator.
    ///
    /// The provided method goes through `atan2` and [`EarthModel::local`], valid for
    /// any model; [`Wgs84`] and [`Sphere`] override it with their closed forms in
    /// `sin lat`, `cos lat` (the detour through `atan2` and back cost the wander
    /// mechanization a fifth of a step: 1.21x NED's step time with it).
    #[inline]
    fn local_from_sin_cos(&self, sin_lat: f64, cos_lat: f64, h: f64) -> LocalEarth {
        self.local(sin_lat.atan2(cos_lat), h)
    }

    /// Earth rate in NED at latitude `lat`: `w_ie_n = [W cos lat, 0, -W sin lat]`.
    #[inline]
    fn w_ie_n(&self, lat: f64) -> Vector3<f64> {
        let (s, c) = lat.sin_cos();
        let w = self.rotation_rate();
        Vector3::new(w * c, 0.0, -w * s)
    }

    /// ECEF position of a geodetic position [m].
    fn geodetic_to_ecef(&self, p: &Geodetic) -> Vector3<f64> {
        let e2 = self.eccentricity_squared();
        let rn = self.radii(p.lat).prime_vertical;
        let (sl, cl) = p.lat.sin_cos();
        let (so, co) = p.lon.sin_cos();
        Vector3::new(
            (rn + p.h) * cl * co,
            (rn + p.h) * cl * so,
            (rn * (1.0 - e2) + p.h) * sl,
        )
    }

    /// Geodetic position of an ECEF position, by Bowring's iteration on the reduced
    /// latitude (three passes: converged to 1e-15 rad for heights from -1e5 to 1e7 m;
    /// exact at the poles and on the equator). Undefined only at the Earth's centre.
    fn ecef_to_geodetic(&self, r_e: &Vector3<f64>) -> Geodetic {
        let a = self.semi_major_axis();
        let e2 = self.eccentricity_squared();
        let b = a * (1.0 - e2).sqrt();
        let ep2 = e2 / (1.0 - e2);
        let p = r_e.x.hypot(r_e.y);
        let z = r_e.z;
        let lon = r_e.y.atan2(r_e.x);
        // Reduced latitude start, then Bowring's update of the geodetic latitude.
        let mut beta = (a * z).atan2(b * p);
        let mut lat = 0.0;
        for _ in 0..3 {
            let (sb, cb) = beta.sin_cos();
            lat = (z + ep2 * b * sb * sb * sb).atan2(p - e2 * a * cb * cb * cb);
            beta = ((1.0 - e2).sqrt() * lat.sin()).atan2(lat.cos());
        }
        let (sl, cl) = lat.sin_cos();
        // h = p cos(lat) + z sin(lat) - a sqrt(1 - e^2 sin^2 lat): valid at the poles too.
        let h = p * cl + z * sl - a * (1.0 - e2 * sl * sl).sqrt();
        Geodetic { lat, lon, h }
    }
}

/// Radii of curvature from `a`, `e^2` and `sin(lat)`.
#[inline]
pub fn radii_from_sin(a: f64, e2: f64, sin_lat: f64) -> Radii {
    let w2 = 1.0 - e2 * sin_lat * sin_lat;
    let w = w2.sqrt();
    Radii {
        meridian: a * (1.0 - e2) / (w2 * w),
        prime_vertical: a / w,
    }
}

/// An Earth model evaluated at one position: trigonometry of latitude, radii, gravity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalEarth {
    /// sin(lat).
    pub sin_lat: f64,
    /// cos(lat).
    pub cos_lat: f64,
    /// Height [m].
    pub h: f64,
    /// Radii of curvature.
    pub radii: Radii,
    /// Gravity in NED [m/s^2].
    pub g_n: Vector3<f64>,
    /// Earth's rotation rate [rad/s].
    pub rotation_rate: f64,
}

impl LocalEarth {
    /// Earth rate in NED: `w_ie_n = [W cos lat, 0, -W sin lat]`.
    #[inline]
    pub fn w_ie_n(&self) -> Vector3<f64> {
        let w = self.rotation_rate;
        Vector3::new(w * self.cos_lat, 0.0, -w * self.sin_lat)
    }

    /// Transport rate in NED for velocity `v_n` (T&W eq. 3.76):
    /// `w_en_n = [vE/(R_N+h), -vN/(R_M+h), -vE tan(lat)/(R_N+h)]`.
    #[inline]
    pub fn w_en_n(&self, v_n: &Vector3<f64>) -> Vector3<f64> {
        let rn_h = self.radii.prime_vertical + self.h;
        let rm_h = self.radii.meridian + self.h;
        let ve_rn = v_n.y / rn_h;
        Vector3::new(ve_rn, -v_n.x / rm_h, -ve_rn * self.sin_lat / self.cos_lat)
    }
}

/// DCM from NED at a geodetic position to ECEF: columns are north, east, down in ECEF.
pub fn c_ne(lat: f64, lon: f64) -> Matrix3<f64> {
    let (sl, cl) = lat.sin_cos();
    let (so, co) = lon.sin_cos();
    Matrix3::new(
        -sl * co,
        -so,
        -cl * co,
        -sl * so,
        co,
        -cl * so,
        cl,
        0.0,
        -sl,
    )
}

/// Rotation from the NED frame at `from` to the NED frame at `to`,
/// `C_ne(to)ᵀ C_ne(from)` ([`c_ne`]; rows `to`'s north, east, down, columns `from`'s),
/// written with the latitude and longitude differences `δφ = φ − φ_t`, `δλ = λ − λ_t`
/// (`φ, λ` of `from`, `φ_t, λ_t` of `to`) and `k = 1 − cos δλ = 2 sin²(δλ/2)`:
///
/// ```text
/// | cos δφ − sin φ_t sin φ k    sin φ_t sin δλ   −sin δφ − sin φ_t cos φ k |
/// | −sin φ sin δλ               cos δλ           −cos φ sin δλ             |
/// | sin δφ − cos φ_t sin φ k    cos φ_t sin δλ   cos δφ − cos φ_t cos φ k  |
/// ```
///
/// so that it is exactly the identity at the same position and free of the
/// cancellation of the product near it. Valid at any latitudes, ±90° included.
pub fn c_ned_to_ned(from: &Geodetic, to: &Geodetic) -> Matrix3<f64> {
    let (s, c) = from.lat.sin_cos();
    let (st, ct) = to.lat.sin_cos();
    let (sd, cd) = (from.lat - to.lat).sin_cos();
    let dl = from.lon - to.lon;
    let half = (0.5 * dl).sin();
    let k = 2.0 * half * half;
    let sl = dl.sin();
    Matrix3::new(
        cd - st * s * k,
        st * sl,
        -sd - st * c * k,
        -s * sl,
        dl.cos(),
        -c * sl,
        sd - ct * s * k,
        ct * sl,
        cd - ct * c * k,
    )
}

/// WGS84 with its normal gravity field (NIMA TR8350.2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wgs84;

impl Wgs84 {
    /// Semi-major axis [m].
    pub const A: f64 = 6_378_137.0;
    /// Flattening.
    pub const F: f64 = 1.0 / 298.257_223_563;
    /// Earth's rotation rate [rad/s].
    pub const OMEGA: f64 = 7.292_115e-5;
    /// Earth's gravitational constant GM [m^3/s^2].
    pub const GM: f64 = 3.986_004_418e14;
    /// Normal gravity at the equator [m/s^2] (TR8350.2 table 3.4).
    pub const GAMMA_E: f64 = 9.780_325_335_9;
    /// Normal gravity at the poles [m/s^2].
    pub const GAMMA_P: f64 = 9.832_184_937_8;
    /// Somigliana's constant k = (b gamma_p)/(a gamma_e) - 1.
    pub const K: f64 = 0.001_931_852_652_41;
    /// m = omega^2 a^2 b / GM.
    pub const M: f64 = 0.003_449_786_506_84;
    /// First eccentricity squared e^2 = f (2 - f).
    pub const E2: f64 = Self::F * (2.0 - Self::F);

    /// Normal gravity magnitude on and above the ellipsoid [m/s^2]: Somigliana
    /// (TR8350.2 eq. 4-1) with the second-order height series (eq. 4-3). Its direction is
    /// the ellipsoid normal (down); the normal field's small deflection off the
    /// ellipsoid (< 1e-6 rad below 10 km) is neglected, as in KF-GINS and pyins.
    pub fn normal_gravity(lat: f64, h: f64) -> f64 {
        let s2 = lat.sin().powi(2);
        Self::somigliana(s2, (1.0 - Self::E2 * s2).sqrt(), h)
    }

    /// [`Wgs84::normal_gravity`] from `sin^2 lat` and `w = sqrt(1 - e^2 sin^2 lat)`:
    /// `gamma_e (1 + k sin^2 lat) / w` (eq. 4-1) times the height factor (eq. 4-3).
    #[inline]
    fn somigliana(sin2_lat: f64, w: f64, h: f64) -> f64 {
        Self::GAMMA_E * (1.0 + Self::K * sin2_lat) / w * Self::height_factor(sin2_lat, h)
    }

    /// TR8350.2 eq. 4-3: `gamma_h / gamma = 1 - 2/a (1 + f + m - 2 f sin^2 lat) h + 3 h^2/a^2`.
    #[inline]
    fn height_factor(sin2_lat: f64, h: f64) -> f64 {
        let a = Self::A;
        1.0 - 2.0 / a * (1.0 + Self::F + Self::M - 2.0 * Self::F * sin2_lat) * h
            + 3.0 * h * h / (a * a)
    }
}

impl EarthModel for Wgs84 {
    fn semi_major_axis(&self) -> f64 {
        Self::A
    }
    fn eccentricity_squared(&self) -> f64 {
        Self::E2
    }
    fn rotation_rate(&self) -> f64 {
        Self::OMEGA
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
    /// Radii ([`radii_from_sin`]) and Somigliana's normal gravity in `sin lat`,
    /// sharing one square root.
    #[inline]
    fn local_from_sin_cos(&self, s: f64, c: f64, h: f64) -> LocalEarth {
        Self::local_with(s, c, h, |s2, w| Self::somigliana(s2, w, h))
    }
}

impl Wgs84 {
    /// [`EarthModel::local_from_sin_cos`] on the WGS84 ellipsoid with the normal
    /// gravity `gamma(sin² lat, w)` (`w = sqrt(1 − e² sin² lat)`, shared with the
    /// radii), for the models of this ellipsoid.
    #[inline(always)]
    fn local_with(s: f64, c: f64, h: f64, gamma: impl FnOnce(f64, f64) -> f64) -> LocalEarth {
        let s2 = s * s;
        let w2 = 1.0 - Self::E2 * s2;
        let w = w2.sqrt();
        LocalEarth {
            sin_lat: s,
            cos_lat: c,
            h,
            radii: Radii {
                meridian: Self::A * (1.0 - Self::E2) / (w2 * w),
                prime_vertical: Self::A / w,
            },
            g_n: Vector3::new(0.0, 0.0, gamma(s2, w)),
            rotation_rate: Self::OMEGA,
        }
    }
}

/// The textbook's Earth: a homogeneous sphere of radius `a` with central gravitation
/// `mu / r^2`, optionally rotating (SEEDS.md, single-channel models and (30)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Radius [m].
    pub radius: f64,
    /// Gravitational constant mu [m^3/s^2].
    pub mu: f64,
    /// Rotation rate [rad/s]; 0 for the non-rotating textbook Earth.
    pub rotation_rate: f64,
}

impl Sphere {
    /// Textbook radius a = 6371 km.
    pub const TEXTBOOK_RADIUS: f64 = 6_371_000.0;
    /// Textbook surface gravity g = 9.81 m/s^2.
    pub const TEXTBOOK_G: f64 = 9.81;
    /// Earth rate of the textbook (SEEDS.md reference numbers) [rad/s].
    pub const TEXTBOOK_OMEGA: f64 = 7.292_115_855_3e-5;

    /// Sphere of radius `radius` [m] whose gravitation at the surface is `g` [m/s^2].
    pub fn with_surface_gravity(radius: f64, g: f64, rotation_rate: f64) -> Self {
        Self {
            radius,
            mu: g * radius * radius,
            rotation_rate,
        }
    }

    /// The textbook's sphere: a = 6371 km, g = 9.81 m/s^2, rotating at 7.2921158553e-5
    /// rad/s when `rotating`.
    pub fn textbook(rotating: bool) -> Self {
        let w = if rotating { Self::TEXTBOOK_OMEGA } else { 0.0 };
        Self::with_surface_gravity(Self::TEXTBOOK_RADIUS, Self::TEXTBOOK_G, w)
    }

    /// Gravitation `mu / r^2` at radius `r` [m/s^2].
    pub fn gravitation(&self, r: f64) -> f64 {
        self.mu / (r * r)
    }

    /// Gravity in NED from `sin lat`, `cos lat` and height (see `gravity_n`).
    #[inline]
    fn gravity_sin_cos(&self, s: f64, c: f64, h: f64) -> Vector3<f64> {
        let r = self.radius + h;
        let w2r = self.rotation_rate * self.rotation_rate * r;
        Vector3::new(-w2r * s * c, 0.0, self.gravitation(r) - w2r * c * c)
    }

    /// Schuler angular frequency at the surface, `w0 = sqrt(g / a)` [rad/s].
    pub fn schuler_frequency(&self) -> f64 {
        (self.gravitation(self.radius) / self.radius).sqrt()
    }
}

impl EarthModel for Sphere {
    fn semi_major_axis(&self) -> f64 {
        self.radius
    }
    fn eccentricity_squared(&self) -> f64 {
        0.0
    }
    fn rotation_rate(&self) -> f64 {
        self.rotation_rate
    }
    /// Central gravitation down plus the centrifugal term `-W x (W x r)` in NED:
    /// `[-W^2 r sin(lat) cos(lat), 0, mu/r^2 - W^2 r cos^2(lat)]`.
    #[inline]
    fn gravity_n(&self, lat: f64, h: f64) -> Vector3<f64> {
        let (s, c) = lat.sin_cos();
        self.gravity_sin_cos(s, c, h)
    }
    /// Radius `a` both ways; gravity as `gravity_n`.
    #[inline]
    fn local_from_sin_cos(&self, s: f64, c: f64, h: f64) -> LocalEarth {
        LocalEarth {
            sin_lat: s,
            cos_lat: c,
            h,
            radii: Radii {
                meridian: self.radius,
                prime_vertical: self.radius,
            },
            g_n: self.gravity_sin_cos(s, c, h),
            rotation_rate: self.rotation_rate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// The closed form of `c_ned_to_ned` is the product of the two frames (to 1e-15)
    /// wherever they are, across the antimeridian, at and past the poles, and the
    /// identity bit for bit at one position.
    #[test]
    fn ned_to_ned_is_the_product_of_the_two_frames() {
        let pairs = [
            ((45.0, 7.0), (45.001, 7.002)),
            ((-30.0, 179.9), (-30.2, -179.8)),
            ((89.9997, 25.0), (89.9997, -155.0)),
            ((90.0, 0.0), (89.0, 120.0)),
            ((-90.0, 10.0), (-89.5, -100.0)),
            ((90.0003, 25.0), (89.9999, 200.0)),
            ((10.0, 20.0), (-60.0, 300.0)),
        ];
        for ((la, lo), (lb, lob)) in pairs {
            let (a, b) = (
                Geodetic::from_degrees(la, lo, 0.0),
                Geodetic::from_degrees(lb, lob, 0.0),
            );
            let product = c_ne(b.lat, b.lon).transpose() * c_ne(a.lat, a.lon);
            let c = c_ned_to_ned(&a, &b);
            assert!((c - product).abs().max() < 1e-15, "{a:?} {b:?}");
            assert_eq!(c_ned_to_ned(&a, &a), Matrix3::identity());
        }
    }

    /// TR8350.2 table 3.4: normal gravity at the equator and the poles; Somigliana's
    /// formula reproduces its own endpoints to the printed digits (1e-10 m/s^2).
    #[test]
    fn normal_gravity_at_equator_and_pole() {
        assert_relative_eq!(
            Wgs84::normal_gravity(0.0, 0.0),
            9.780_325_335_9,
            epsilon = 1e-10
        );
        assert_relative_eq!(
            Wgs84::normal_gravity(FRAC_PI_2, 0.0),
            9.832_184_937_8,
            epsilon = 1e-9
        );
        // At 45 deg, eq. 4-1 evaluated separately in Python (s^2 = 0.5): 9.806197769373.
        assert_relative_eq!(
            Wgs84::normal_gravity(FRAC_PI_2 / 2.0, 0.0),
            9.806_197_769_373,
            epsilon = 1e-12
        );
    }

    /// The closed forms of `local_from_sin_cos` agree with the generic route through
    /// `atan2` and `gravity_n` (poles and equator included) for both models, and so does
    /// the provided method.
    #[test]
    fn local_from_sin_cos_matches_local() {
        #[derive(Debug, Clone, Copy)]
        struct Generic(Wgs84);
        impl EarthModel for Generic {
            fn semi_major_axis(&self) -> f64 {
                self.0.semi_major_axis()
            }
            fn eccentricity_squared(&self) -> f64 {
                self.0.eccentricity_squared()
            }
            fn rotation_rate(&self) -> f64 {
                self.0.rotation_rate()
            }
            fn gravity_n(&self, lat: f64, h: f64) -> Vector3<f64> {
                self.0.gravity_n(lat, h)
            }
        }
        fn check<E: EarthModel>(e: &E) {
            for &(lat, h) in &[
                (0.0, 0.0),
                (0.5, 1200.0),
                (-1.3, -80.0),
                (FRAC_PI_2, 3000.0),
                (-FRAC_PI_2, 0.0),
            ] {
                let (s, c) = lat.sin_cos();
                let ours = e.local_from_sin_cos(s, c.abs(), h);
                // The generic route: radii from sin lat, gravity from gravity_n.
                let theirs = LocalEarth {
                    sin_lat: s,
                    cos_lat: c,
                    h,
                    radii: e.radii(lat),
                    g_n: e.gravity_n(lat, h),
                    rotation_rate: e.rotation_rate(),
                };
                assert_relative_eq!(ours.sin_lat, theirs.sin_lat, epsilon = 1e-15);
                assert_relative_eq!(ours.cos_lat, theirs.cos_lat, epsilon = 1e-15);
                assert_relative_eq!(
                    ours.radii.meridian,
                    theirs.radii.meridian,
                    max_relative = 1e-15
                );
                assert_relative_eq!(
                    ours.radii.prime_vertical,
                    theirs.radii.prime_vertical,
                    max_relative = 1e-15
                );
                assert_relative_eq!(ours.g_n, theirs.g_n, epsilon = 1e-14);
                assert_eq!(ours.rotation_rate, theirs.rotation_rate);
            }
        }
        check(&Wgs84);
        check(&Sphere::textbook(true));
        check(&Generic(Wgs84));
    }

    /// Free-air gradient: about -3.086e-6 s^-2 at mid latitudes (textbook value,
    /// 0.3086 mGal/m); the series is accurate to the 3rd digit here.
    #[test]
    fn normal_gravity_height_gradient() {
        let lat = 45f64.to_radians();
        let grad = (Wgs84::normal_gravity(lat, 1000.0) - Wgs84::normal_gravity(lat, 0.0)) / 1000.0;
        assert_relative_eq!(grad, -3.086e-6, max_relative = 2e-3);
    }

    /// Radii of curvature at the equator and poles: R_M(0) = a(1-e^2) = b^2/a,
    /// R_N(0) = a, R_M(90) = R_N(90) = a^2/b.
    #[test]
    fn radii_at_equator_and_pole() {
        let a = Wgs84::A;
        let b = a * (1.0 - Wgs84::F);
        let r0 = Wgs84.radii(0.0);
        assert_relative_eq!(r0.meridian, b * b / a, max_relative = 1e-15);
        assert_relative_eq!(r0.prime_vertical, a, max_relative = 1e-15);
        let r90 = Wgs84.radii(FRAC_PI_2);
        assert_relative_eq!(r90.meridian, a * a / b, max_relative = 1e-15);
        assert_relative_eq!(r90.prime_vertical, a * a / b, max_relative = 1e-15);
    }

    /// ECEF of well-known points: the equator/prime meridian and the pole.
    #[test]
    fn ecef_known_points() {
        let b = Wgs84::A * (1.0 - Wgs84::F);
        let e = Wgs84.geodetic_to_ecef(&Geodetic::new(0.0, 0.0, 100.0));
        assert_relative_eq!(e, Vector3::new(Wgs84::A + 100.0, 0.0, 0.0), epsilon = 1e-9);
        let p = Wgs84.geodetic_to_ecef(&Geodetic::new(FRAC_PI_2, 0.3, -50.0));
        assert_relative_eq!(p, Vector3::new(0.0, 0.0, b - 50.0), epsilon = 1e-8);
        let g = Wgs84.ecef_to_geodetic(&Vector3::new(0.0, 0.0, -(b + 7.0)));
        assert_relative_eq!(g.lat, -FRAC_PI_2, epsilon = 1e-15);
        assert_relative_eq!(g.h, 7.0, epsilon = 1e-8);
    }

    /// ECEF against PROJ 9.5.1 (pyproj 3.7.2, EPSG:4979 -> EPSG:4978), printed to 1 um.
    #[test]
    fn ecef_matches_proj() {
        let cases = [
            (
                (45.0712345678, 7.6812345678, 245.0),
                (4471675.131795, 603102.934995, 4493116.176273),
            ),
            (
                (-33.3, -123.4, 8848.0),
                (-2941590.572639, -4461156.268218, -3486673.189554),
            ),
            (
                (89.99, 179.9, -100.0),
                (-1116.920635, 1.949396, 6356652.216775),
            ),
        ];
        for ((lat, lon, h), (x, y, z)) in cases {
            let p = Geodetic::from_degrees(lat, lon, h);
            let r = Wgs84.geodetic_to_ecef(&p);
            assert_relative_eq!(r, Vector3::new(x, y, z), epsilon = 1e-6);
            let back = Wgs84.ecef_to_geodetic(&Vector3::new(x, y, z));
            // The 1e-6 m printed rounding is 1.6e-13 rad of latitude, and 1e-6/p rad of
            // longitude at distance p from the polar axis (1e-9 rad at 89.99 deg).
            let p_axis = x.hypot(y);
            assert_relative_eq!(back.lat, p.lat, epsilon = 3e-13);
            assert_relative_eq!(back.lon, p.lon, epsilon = 2e-6 / p_axis);
            assert_relative_eq!(back.h, h, epsilon = 2e-6);
        }
    }

    /// The Sphere's gravity is mu/r^2 down when it does not rotate, and its
    /// centrifugal term is perpendicular to the polar axis when it does.
    #[test]
    fn sphere_gravity() {
        let s = Sphere::textbook(false);
        assert_relative_eq!(
            s.gravity_n(0.3, 0.0),
            Vector3::new(0.0, 0.0, 9.81),
            epsilon = 1e-14
        );
        let rot = Sphere::textbook(true);
        let lat = 0.7;
        let g_n = rot.gravity_n(lat, 0.0);
        let g_e = c_ne(lat, 0.0) * g_n;
        // Remove gravitation (radially inward); the remainder is W^2 r cos(lat) away
        // from the axis: along +x at longitude 0.
        let up = Vector3::new(lat.cos(), 0.0, lat.sin());
        let centrifugal = g_e + up * 9.81;
        let w2r = Sphere::TEXTBOOK_OMEGA.powi(2) * Sphere::TEXTBOOK_RADIUS;
        assert_relative_eq!(
            centrifugal,
            Vector3::new(w2r * lat.cos(), 0.0, 0.0),
            epsilon = 1e-15
        );
        // The textbook's Schuler period 2 pi sqrt(a/g) = 84.4 min (SEEDS.md).
        let period_min = std::f64::consts::TAU / s.schuler_frequency() / 60.0;
        assert!((period_min - 84.4).abs() < 0.05, "{period_min}");
    }

    /// The shared-sqrt `Wgs84::local` agrees with the separate radii and gravity, and
    /// `LocalEarth::w_en_n` with the textbook transport rate written out here.
    #[test]
    fn local_matches_separate_functions() {
        for &(lat, h) in &[(0.3, 120.0), (-1.2, 9000.0), (1.5, 0.0)] {
            let l = Wgs84.local(lat, h);
            assert_eq!(l.radii, Wgs84.radii(lat));
            assert_relative_eq!(l.g_n, Wgs84.gravity_n(lat, h), max_relative = 4e-16);
            assert_relative_eq!(l.w_ie_n(), Wgs84.w_ie_n(lat), max_relative = 1e-16);
            let v = Vector3::new(100.0, -50.0, 3.0);
            let expected = Vector3::new(
                v.y / (l.radii.prime_vertical + h),
                -v.x / (l.radii.meridian + h),
                -v.y * lat.tan() / (l.radii.prime_vertical + h),
            );
            assert_relative_eq!(l.w_en_n(&v), expected, max_relative = 1e-14);
        }
    }

    /// c_ne columns are north, east, down: down points to -ECEF position on the sphere.
    #[test]
    fn c_ne_is_orthonormal_and_down_is_inward() {
        let c = c_ne(0.4, -2.0);
        assert_relative_eq!(c * c.transpose(), Matrix3::identity(), epsilon = 1e-15);
        let r = Sphere::textbook(false).geodetic_to_ecef(&Geodetic::new(0.4, -2.0, 0.0));
        assert_relative_eq!(c.column(2).into_owned(), -r.normalize(), epsilon = 1e-15);
    }

    proptest! {
        /// Round trip geodetic -> ECEF -> geodetic from 10 km below to 10,000 km above
        /// the ellipsoid, poles included. 1e-9 m is a few ulps of 6.4e6 m.
        #[test]
        fn ecef_round_trip(lat in -FRAC_PI_2..=FRAC_PI_2, lon in -PI..PI, h in -1e4..1e7f64) {
            for model in [&Wgs84 as &dyn AsEarth, &Sphere::textbook(true)] {
                let p = Geodetic::new(lat, lon, h);
                let r = model.ecef(&p);
                let back = model.geo(&r);
                let r2 = model.ecef(&back);
                prop_assert!((r2 - r).norm() < 2e-8 * (1.0 + h.abs() / 1e6), "{:?} {:?}", p, back);
                prop_assert!((back.h - h).abs() < 2e-8 * (1.0 + h.abs() / 1e6));
            }
        }
    }

    /// Object-safe shim so the property test can loop over both models.
    trait AsEarth {
        fn ecef(&self, p: &Geodetic) -> Vector3<f64>;
        fn geo(&self, r: &Vector3<f64>) -> Geodetic;
    }
    impl<E: EarthModel> AsEarth for E {
        fn ecef(&self, p: &Geodetic) -> Vector3<f64> {
            self.geodetic_to_ecef(p)
        }
        fn geo(&self, r: &Vector3<f64>) -> Geodetic {
            self.ecef_to_geodetic(r)
        }
    }
}
