//! The NAV class: the receiver's own navigation solution.
//!
//! - **NAV-PVT** (0x01 0x07, 92 bytes; 84 before protocol 15): GPS time of week of
//!   the navigation epoch `iTOW` [ms], UTC date and time, fix type and flags, longitude
//!   and latitude [1e-7 deg], height above the ellipsoid [mm], velocity north, east,
//!   down [mm/s], accuracy estimates `hAcc`, `vAcc` [mm] and `sAcc` [mm/s], vehicle
//!   heading [1e-5 deg].
//! - **NAV-ATT** (0x01 0x05, 32 bytes): vehicle roll, pitch and heading [1e-5 deg] of
//!   the receiver's sensor fusion (F9R, M8L/U), body frame x forward, y right, z down.
//!
//! u-blox calls `hAcc`/`vAcc`/`sAcc` accuracy *estimates* without naming a confidence
//! level; they are taken as 1-σ per axis (σN = σE = hAcc), as the ROS u-blox driver
//! does: a conservative reading of a horizontal (radial) figure.

use super::le;
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::rotation::Euler;

/// The fields of one NAV-PVT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavPvt {
    /// GPS time of week of the navigation epoch [ms].
    pub itow_ms: u32,
    /// UTC date and time (year, month, day, hour, minute, second) and whether the
    /// date and the time are valid (`valid` bits 0 and 1).
    pub utc: (u16, u8, u8, u8, u8, u8),
    /// `valid` bits 0 (date) and 1 (time) both set.
    pub utc_valid: bool,
    /// 0 no fix, 1 dead reckoning only, 2 2-D, 3 3-D, 4 GNSS + dead reckoning, 5
    /// time only.
    pub fix_type: u8,
    /// `flags`: bit 0 gnssFixOK, bit 5 headVehValid, bits 6–7 carrier solution.
    pub flags: u8,
    /// Satellites used.
    pub num_sv: u8,
    /// Position (WGS 84, height above the ellipsoid).
    pub pos: Geodetic,
    /// Velocity north, east, down [m/s].
    pub v_n: Vector3<f64>,
    /// Horizontal, vertical position and speed accuracy estimates [m], [m], [m/s].
    pub h_acc: f64,
    /// See `h_acc`.
    pub v_acc: f64,
    /// See `h_acc`.
    pub s_acc: f64,
    /// Heading of vehicle [rad] when the message carries it (92-byte form).
    pub head_veh: Option<f64>,
}

/// The shortest NAV-PVT payload read (protocol 14's 84 bytes).
pub const NAV_PVT_MIN_LEN: usize = 84;
/// The NAV-ATT payload length.
pub const NAV_ATT_LEN: usize = 32;

/// 1e-7 degree in radians.
const DEG_1E7: f64 = std::f64::consts::PI / 180.0 * 1e-7;
/// 1e-5 degree in radians.
const DEG_1E5: f64 = std::f64::consts::PI / 180.0 * 1e-5;

impl NavPvt {
    /// Decodes a payload of at least [`NAV_PVT_MIN_LEN`] bytes (checked by the caller).
    pub fn decode(p: &[u8]) -> Self {
        let mm = |off| f64::from(le::i32(p, off)) / 1e3;
        let head_veh = (p.len() >= 92).then(|| f64::from(le::i32(p, 84)) * DEG_1E5);
        Self {
            itow_ms: le::u32(p, 0),
            utc: (le::u16(p, 4), p[6], p[7], p[8], p[9], p[10]),
            utc_valid: p[11] & 0x03 == 0x03,
            fix_type: p[20],
            flags: p[21],
            num_sv: p[23],
            pos: Geodetic {
                lat: f64::from(le::i32(p, 28)) * DEG_1E7,
                lon: f64::from(le::i32(p, 24)) * DEG_1E7,
                h: mm(32),
            },
            v_n: Vector3::new(mm(48), mm(52), mm(56)),
            h_acc: f64::from(le::u32(p, 40)) / 1e3,
            v_acc: f64::from(le::u32(p, 44)) / 1e3,
            s_acc: f64::from(le::u32(p, 68)) / 1e3,
            head_veh,
        }
    }

    /// Whether it is a fix a filter may take: `gnssFixOK` with a 3-D or GNSS + dead
    /// reckoning fix.
    pub fn is_fix(&self) -> bool {
        self.flags & 0x01 != 0 && matches!(self.fix_type, 3 | 4)
    }

    /// The fix at time `t` [s] on the reader's clock.
    pub fn fix(&self, t: f64) -> GnssFix {
        GnssFix {
            t,
            pos: self.pos,
            pos_std: Vector3::new(self.h_acc, self.h_acc, self.v_acc),
            vel: Some((self.v_n, Vector3::repeat(self.s_acc))),
        }
    }

    /// The GPS week of the epoch from its UTC date and `iTOW`, when the date and time
    /// are valid: GPS time − UTC is a few tens of seconds, so the week is the nearest
    /// integer to (UTC seconds since 1980-01-06 − iTOW) / 604 800.
    pub fn gps_week(&self) -> Option<u32> {
        if !self.utc_valid {
            return None;
        }
        let (y, mo, d, h, mi, s) = self.utc;
        let date = chrono::NaiveDate::from_ymd_opt(i32::from(y), u32::from(mo), u32::from(d))?;
        let epoch = chrono::NaiveDate::from_ymd_opt(1980, 1, 6)?;
        let days = (date - epoch).num_days() as f64;
        let utc_s = days * 86_400.0 + f64::from(h) * 3600.0 + f64::from(mi) * 60.0 + f64::from(s);
        let week = ((utc_s - f64::from(self.itow_ms) * 1e-3) / 604_800.0).round();
        (week >= 0.0).then_some(week as u32)
    }
}

/// The fields of one NAV-ATT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavAtt {
    /// GPS time of week [ms].
    pub itow_ms: u32,
    /// Roll, pitch, heading of the vehicle (FRD to NED) [rad], yaw in (−π, π].
    pub att: Euler,
    /// Their accuracy estimates [rad].
    pub acc: Vector3<f64>,
}

impl NavAtt {
    /// Decodes a payload of [`NAV_ATT_LEN`] bytes (checked by the caller).
    pub fn decode(p: &[u8]) -> Self {
        let ang = |off| f64::from(le::i32(p, off)) * DEG_1E5;
        let acc = |off| f64::from(le::u32(p, off)) * DEG_1E5;
        let mut yaw = ang(16);
        if yaw > std::f64::consts::PI {
            yaw -= 2.0 * std::f64::consts::PI;
        }
        Self {
            itow_ms: le::u32(p, 0),
            att: Euler {
                roll: ang(8),
                pitch: ang(12),
                yaw,
            },
            acc: Vector3::new(acc(20), acc(24), acc(28)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nav_pvt_fields_and_week() {
        let mut p = vec![0u8; 92];
        p[0..4].copy_from_slice(&231_471_125u32.to_le_bytes());
        p[4..6].copy_from_slice(&2019u16.to_le_bytes());
        p[6..11].copy_from_slice(&[4, 16, 16, 17, 33]);
        p[11] = 0x07;
        p[20] = 3;
        p[21] = 0x01;
        p[24..28].copy_from_slice(&(-138_668_837i32).to_le_bytes());
        p[28..32].copy_from_slice(&287_341_829i32.to_le_bytes());
        p[32..36].copy_from_slice(&49_891i32.to_le_bytes());
        p[40..44].copy_from_slice(&102u32.to_le_bytes());
        p[48..52].copy_from_slice(&(-1_500i32).to_le_bytes());
        let n = NavPvt::decode(&p);
        assert!(n.is_fix());
        assert!((n.pos.lat.to_degrees() - 28.734_182_9).abs() < 1e-12);
        assert!((n.pos.lon.to_degrees() + 13.866_883_7).abs() < 1e-12);
        assert_eq!(n.pos.h, 49.891);
        assert_eq!(n.v_n.x, -1.5);
        assert_eq!(n.h_acc, 0.102);
        // 2019-04-16 16:17:33 UTC is Tuesday of GPS week 2049 (second 231 471 after
        // 18 leap seconds: 2 days + 16:17:51).
        assert_eq!(n.gps_week(), Some(2049));
    }
}
