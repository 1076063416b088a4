//! A run's result as a ROS 2 bag (MCAP, zstd chunks) that Foxglove opens beside the
//! input: at each output epoch
//! - `/schuler/odometry` (`nav_msgs/Odometry`): pose of `base_link` (FLU, REP 103) in
//!   `map`, the ENU plane tangent at the first epoch (REP 105), with the filter's
//!   position and attitude covariance turned into that frame; twist in `base_link`;
//! - `/schuler/fix` (`sensor_msgs/NavSatFix`): latitude, longitude, ellipsoidal
//!   height, the position covariance in the local ENU (type KNOWN with a filter,
//!   UNKNOWN without);
//! - with a filter, `/schuler/gyro_bias` [rad/s] and `/schuler/accel_bias` [m/s²]
//!   (`geometry_msgs/Vector3Stamped`) in `base_link` axes.
//!
//! Stamps are the epoch times (`sec` = ⌊t⌋, `nanosec` the rest rounded to 1 ns) on
//! the input bag's clock: GPS seconds of week back to UNIX time when its stamps were
//! UNIX time ([`StampClock`]), as they are otherwise; the MCAP log time is the same
//! instant in ns.

use super::BagError;
use super::clock::StampClock;
use super::messages::{
    Header, NAV_SAT_FIX, NavSatFix, ODOMETRY, Odometry, VECTOR3_STAMPED, Vector3Stamped,
    definitions,
};
use mcap::records::MessageHeader;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use schuler::session::Epoch;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// NED to ENU (and back): swap north and east, negate down.
fn ned_to_enu() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0)
}

/// FLU to FRD (and back).
fn flu_frd() -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0))
}

/// ECEF to the local ENU at latitude `lat`, longitude `lon` [rad].
fn ecef_to_enu(lat: f64, lon: f64) -> Matrix3<f64> {
    let (sp, cp, sl, cl) = (lat.sin(), lat.cos(), lon.sin(), lon.cos());
    Matrix3::new(-sl, cl, 0.0, -sp * cl, -sp * sl, cp, cp * cl, cp * sl, sp)
}

/// The stamp of time `t` [s]: `sec` = ⌊t⌋, `nanosec` the rest rounded (a rest that
/// rounds to 10⁹ carries into `sec`), and the same instant in ns; `None` for a time
/// outside the stamp's range (negative, or past 2038 as `int32` seconds).
pub fn stamp(t: f64) -> Option<(i32, u32, u64)> {
    stamp_on(&StampClock::Raw, t)
}

/// [`stamp`] of the run's time `t` [s] on `clock` (GPS seconds of week back to UNIX
/// time).
pub fn stamp_on(clock: &StampClock, t: f64) -> Option<(i32, u32, u64)> {
    if !(t.is_finite() && t.abs() < 1e15) {
        return None;
    }
    let mut sec = t.floor();
    let mut ns = ((t - sec) * 1e9).round();
    if ns >= 1e9 {
        sec += 1.0;
        ns -= 1e9;
    }
    let sec = i32::try_from(clock.unix_second(sec as i64))
        .ok()
        .filter(|s| *s >= 0)?;
    let ns = ns as u32;
    Some((sec, ns, sec as u64 * 1_000_000_000 + u64::from(ns)))
}

/// Where a run's result bag goes, and the clock of its stamps.
#[derive(Debug, Clone, PartialEq)]
pub struct OutBag {
    /// The `.mcap` file.
    pub path: PathBuf,
    /// The input bag's clock ([`StampClock::Raw`] for any other input).
    pub clock: StampClock,
}

/// The topics written, their types and definitions.
const TOPICS: [(&str, &str); 4] = [
    ("/schuler/odometry", ODOMETRY),
    ("/schuler/fix", NAV_SAT_FIX),
    ("/schuler/gyro_bias", VECTOR3_STAMPED),
    ("/schuler/accel_bias", VECTOR3_STAMPED),
];

/// Writer of a run's result bag.
pub struct ResultBag {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    clock: StampClock,
    channels: [u16; 4],
    sequence: u32,
    /// ECEF position of the ENU origin and ECEF→ENU there.
    origin: Option<(Vector3<f64>, Matrix3<f64>)>,
}

impl ResultBag {
    /// Creates the bag with the four channels.
    pub fn create(out: &OutBag) -> Result<Self, BagError> {
        let path = out.path.as_path();
        let err = |e: mcap::McapError| failed(path, e);
        let file =
            File::create(path).map_err(|e| BagError::file(path, format!("cannot create: {e}")))?;
        let mut writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("schuler ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(err)?;
        let mut channels = [0u16; 4];
        for (slot, (topic, type_name)) in channels.iter_mut().zip(TOPICS) {
            let definition = match type_name {
                ODOMETRY => definitions::odometry(),
                NAV_SAT_FIX => definitions::nav_sat_fix(),
                _ => definitions::vector3_stamped(),
            };
            let schema = writer
                .add_schema(type_name, "ros2msg", definition.as_bytes())
                .map_err(err)?;
            *slot = writer
                .add_channel(schema, topic, "cdr", &BTreeMap::new())
                .map_err(err)?;
        }
        Ok(Self {
            writer,
            path: path.to_path_buf(),
            clock: out.clock,
            channels,
            sequence: 0,
            origin: None,
        })
    }

    fn put(&mut self, channel: usize, log_time: u64, data: &[u8]) -> Result<(), BagError> {
        self.sequence += 1;
        let header = MessageHeader {
            channel_id: self.channels[channel],
            sequence: self.sequence,
            log_time,
            publish_time: log_time,
        };
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(|e| failed(&self.path, e))
    }

    /// Writes the messages of epoch `e`.
    pub fn write_epoch(&mut self, e: &Epoch) -> Result<(), BagError> {
        let t = e.state.t;
        let (sec, nanosec, log_time) = stamp_on(&self.clock, t).ok_or_else(|| {
            BagError::file(
                &self.path,
                format!("epoch t = {t} s has no ROS stamp (negative or past 2038)"),
            )
        })?;
        let header = |frame: &str| Header {
            sec,
            nanosec,
            frame_id: frame.to_owned(),
        };
        let pos = e.state.pos;
        let &mut (r0, c_e_enu0) = self
            .origin
            .get_or_insert_with(|| (e.r_e, ecef_to_enu(pos.lat, pos.lon)));
        // Local NED at the epoch to the origin's ENU.
        let m = c_e_enu0 * ecef_to_enu(pos.lat, pos.lon).transpose() * ned_to_enu();
        let c_bn = e.state.q_bn.to_rotation_matrix().into_inner();
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            m * c_bn * flu_frd(),
        ));
        let c_nb_flu = flu_frd() * c_bn.transpose();
        let mut pose_cov = [0.0; 36];
        let mut twist_cov = [0.0; 36];
        let mut fix_cov = [0.0; 9];
        if let Some(f) = &e.filter {
            let [p, v, a] = f.nav_cov;
            put_block(&mut pose_cov, 0, &(m * p * m.transpose()));
            put_block(&mut pose_cov, 3, &(m * a * m.transpose()));
            put_block(&mut twist_cov, 0, &(c_nb_flu * v * c_nb_flu.transpose()));
            let enu = ned_to_enu() * p * ned_to_enu();
            fix_cov.copy_from_slice(enu.transpose().as_slice());
        }
        let r = c_e_enu0 * (e.r_e - r0);
        let odometry = Odometry {
            header: header("map"),
            child_frame_id: "base_link".into(),
            position: [r.x, r.y, r.z],
            orientation: [q.i, q.j, q.k, q.w],
            pose_covariance: pose_cov,
            linear: (c_nb_flu * e.state.v_n).into(),
            angular: [0.0; 3],
            twist_covariance: twist_cov,
        };
        self.put(0, log_time, &odometry.encode())?;
        let fix = NavSatFix {
            header: header("base_link"),
            status: 0,
            service: 0,
            latitude: pos.lat.to_degrees(),
            longitude: wrap_degrees(pos.lon.to_degrees()),
            altitude: pos.h,
            position_covariance: fix_cov,
            position_covariance_type: if e.filter.is_some() { 3 } else { 0 },
        };
        self.put(1, log_time, &fix.encode())?;
        if let Some(f) = &e.filter {
            for (channel, v) in [(2, f.estimates.gyro_bias), (3, f.estimates.accel_bias)] {
                let msg = Vector3Stamped {
                    header: header("base_link"),
                    vector: (flu_frd() * v).into(),
                };
                self.put(channel, log_time, &msg.encode())?;
            }
        }
        Ok(())
    }

    /// Writes the summary and closes the file.
    pub fn finish(mut self) -> Result<(), BagError> {
        self.writer.finish().map_err(|e| failed(&self.path, e))?;
        Ok(())
    }
}

/// The error of a failed write to the bag at `path` (the disk full), naming it; the
/// partial file is removed, since a bag cut short of its summary is no MCAP a reader
/// opens whole. (A bag dropped on another output's failure is finished by the `mcap`
/// writer's drop: it stays a valid MCAP of the epochs written.)
fn failed(path: &Path, e: mcap::McapError) -> BagError {
    let reason = match e {
        mcap::McapError::Io(io) => io.to_string(),
        other => other.to_string(),
    };
    let removed = std::fs::remove_file(path).is_ok();
    BagError::file(
        path,
        format!(
            "cannot write: {reason}{}",
            if removed {
                " (the partial bag was removed)"
            } else {
                ""
            }
        ),
    )
}

/// A longitude [deg] in [−180, 180]; one already there unchanged (bit for bit).
fn wrap_degrees(lon: f64) -> f64 {
    if (-180.0..=180.0).contains(&lon) {
        lon
    } else {
        (lon + 180.0).rem_euclid(360.0) - 180.0
    }
}

/// Puts the 3×3 `block` on the diagonal of the row-major 6×6 `cov` at `at`.
fn put_block(cov: &mut [f64; 36], at: usize, block: &Matrix3<f64>) {
    for i in 0..3 {
        for j in 0..3 {
            cov[(at + i) * 6 + at + j] = block[(i, j)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_split_seconds_and_carry() {
        assert_eq!(
            stamp(345_600.25),
            Some((345_600, 250_000_000, 345_600_250_000_000))
        );
        assert_eq!(stamp(1.999_999_999_9), Some((2, 0, 2_000_000_000)));
        assert_eq!(stamp(-0.5), None);
        assert_eq!(stamp(f64::NAN), None);
    }

    /// At the origin with level attitude and heading north, base_link's x (forward)
    /// is ENU's y (north) and its y (left) is ENU's −x (west): a rotation of +90°
    /// about up.
    #[test]
    fn heading_north_is_a_quarter_turn_about_up() {
        let m = ned_to_enu();
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            m * Matrix3::identity() * flu_frd(),
        ));
        let expected =
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        assert!(q.angle_to(&expected) < 1e-15);
    }
}
