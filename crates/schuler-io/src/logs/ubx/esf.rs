//! The ESF class: the inertial sensors of u-blox dead-reckoning receivers (NEO-M8L/U,
//! ZED-F9R/K).
//!
//! - **ESF-RAW** (0x10 0x03): 4 reserved bytes, then blocks of `data` (U4) and `sTag`
//!   (U4, the sensor time tag); the data word holds a signed 24-bit value in bits 0–23
//!   and the data type in bits 24–31. Each sample of the IMU is one block per data
//!   type, all with the same `sTag`.
//! - **ESF-MEAS** (0x10 0x02): `timeTag` (U4, ms), flags (number of measurements in
//!   bits 11–15, calibTtagValid in bit 3), provider id, then `data` words (value in
//!   bits 0–23, type in bits 24–29), then `calibTtag` when flagged. The receivers
//!   write the gyroscope and the accelerometer in separate messages a few ms apart.
//!
//! Data types and scalings (u-blox F9 HPS / M8 interface descriptions, "ESF
//! measurement data"): 5 gyro z, 13 gyro y, 14 gyro x [deg/s · 2⁻¹²]; 16, 17, 18
//! accelerometer x, y, z [m/s² · 2⁻¹⁰]; 12 gyro temperature [°C · 10⁻²].
//!
//! **Axes.** The values are in the IMU's own frame. In the committed logs, a receiver
//! at rest reads +g on z (gpsd's NEO-M8U log: +10.0 m/s²), and on gpsd's NEO-M8L log
//! the same instants' HNR-INS, which the manual gives in the FRD vehicle frame, have
//! z ≈ −10 m/s² where ESF-MEAS z ≈ +10 and the same sign on x: the IMU frame is x
//! forward, y left, z up. The reader turns it to FRD: `(x, −y, −z)`, for rates and
//! specific forces alike (a rotation by π about x, so both stay right-handed).
//!
//! **Time.** ESF-MEAS `timeTag` counts milliseconds (32 bits). ESF-RAW `sTag` counts
//! ticks of 2⁻⁸ × 10 ms = 39.0625 µs: the interface description gives no unit; 2 556
//! ticks pass per 100 ms of the receiver's millisecond count in gpsd's NEO-M8U log
//! (ESF-RAW's leading field), 256 per 100-Hz sample. Differences are taken modulo 2²⁴,
//! which also follows a 32-bit counter while consecutive tags are < 2²³ ticks (5.4 min)
//! apart.
//!
//! **Increments.** The sensors give rates sampled at an instant; a sample's increments
//! over `(t − dt, t]` are its rates times the time since the stream's previous sample
//! (a first-order hold, exact for rates constant over the ~10-ms interval).

use super::le;
use nalgebra::Vector3;

/// Gyroscope z data type.
pub const GYRO_Z: u8 = 5;
/// Gyroscope temperature data type.
pub const GYRO_TEMP: u8 = 12;
/// Gyroscope y data type.
pub const GYRO_Y: u8 = 13;
/// Gyroscope x data type.
pub const GYRO_X: u8 = 14;
/// Accelerometer x data type.
pub const ACC_X: u8 = 16;
/// Accelerometer y data type.
pub const ACC_Y: u8 = 17;
/// Accelerometer z data type.
pub const ACC_Z: u8 = 18;

/// Gyro scaling: 2⁻¹² deg/s in rad/s.
pub const GYRO_SCALE: f64 = std::f64::consts::PI / 180.0 / 4096.0;
/// Accelerometer scaling: 2⁻¹⁰ m/s².
pub const ACC_SCALE: f64 = 1.0 / 1024.0;
/// ESF-RAW sensor time tag tick [s].
pub const STAG_TICK_S: f64 = 0.01 / 256.0;
/// Time tags are differenced modulo this.
const STAG_MODULUS: u32 = 1 << 24;

/// The signed 24-bit value of a data word.
pub fn value24(word: u32) -> i32 {
    ((word << 8) as i32) >> 8
}

/// A signed difference `new − old` of two time tags, modulo 2²⁴.
pub fn tag_delta(new: u32, old: u32) -> i64 {
    let d = new.wrapping_sub(old) % STAG_MODULUS;
    if d >= STAG_MODULUS / 2 {
        i64::from(d) - i64::from(STAG_MODULUS)
    } else {
        i64::from(d)
    }
}

/// IMU-frame (x forward, y left, z up) to FRD.
pub fn to_frd(v: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x, -v.y, -v.z)
}

/// One block of ESF-RAW or one data word of ESF-MEAS: type, value, time tag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Datum {
    /// Data type.
    pub kind: u8,
    /// Signed 24-bit value.
    pub value: i32,
    /// Time tag (ESF-RAW ticks, ESF-MEAS ms).
    pub tag: u32,
}

/// The blocks of an ESF-RAW payload (its length, 4 + 8n, checked by the caller).
pub fn raw_blocks(p: &[u8]) -> impl Iterator<Item = Datum> + '_ {
    p[4..].chunks_exact(8).map(|b| {
        let word = le::u32(b, 0);
        Datum {
            kind: (word >> 24) as u8,
            value: value24(word),
            tag: le::u32(b, 4),
        }
    })
}

/// The number of data words an ESF-MEAS payload declares, and whether a calibrated
/// time tag follows them.
pub fn meas_layout(p: &[u8]) -> (usize, bool) {
    let flags = le::u16(p, 4);
    (usize::from(flags >> 11), flags & 0x08 != 0)
}

/// The data words of an ESF-MEAS payload (its length checked by the caller against
/// [`meas_layout`]).
pub fn meas_data(p: &[u8]) -> impl Iterator<Item = Datum> + '_ {
    let tag = le::u32(p, 0);
    let (n, _) = meas_layout(p);
    p[8..8 + 4 * n].chunks_exact(4).map(move |b| {
        let word = le::u32(b, 0);
        Datum {
            kind: ((word >> 24) & 0x3F) as u8,
            value: value24(word),
            tag,
        }
    })
}

/// Gathers the data of one IMU stream into samples of rates (FRD, rad/s and m/s²)
/// with their time tags.
#[derive(Debug, Clone, Default)]
pub struct Assembler {
    /// Gyro x, y, z and its tag; None until all three are met.
    gyro: [Option<i32>; 3],
    gyro_tag: Option<u32>,
    acc: [Option<i32>; 3],
    acc_tag: Option<u32>,
}

/// One sample of rates in the IMU's frame turned to FRD, at a time tag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateSample {
    /// Time tag (the later of the gyro's and the accelerometer's).
    pub tag: u32,
    /// Angular rate, FRD [rad/s].
    pub w: Vector3<f64>,
    /// Specific force, FRD [m/s²].
    pub f: Vector3<f64>,
}

impl Assembler {
    /// Takes one datum; returns a sample when it completes one (all three gyro and
    /// all three accelerometer axes since the previous sample). A datum of a tag
    /// newer than its sensor's incomplete triple starts that triple afresh.
    pub fn push(&mut self, d: Datum) -> Option<RateSample> {
        let (slot, triple, tag) = match d.kind {
            GYRO_X => (0, &mut self.gyro, &mut self.gyro_tag),
            GYRO_Y => (1, &mut self.gyro, &mut self.gyro_tag),
            GYRO_Z => (2, &mut self.gyro, &mut self.gyro_tag),
            ACC_X => (0, &mut self.acc, &mut self.acc_tag),
            ACC_Y => (1, &mut self.acc, &mut self.acc_tag),
            ACC_Z => (2, &mut self.acc, &mut self.acc_tag),
            _ => return None,
        };
        if *tag != Some(d.tag) {
            *triple = [None; 3];
            *tag = Some(d.tag);
        }
        triple[slot] = Some(d.value);
        let (Some(gx), Some(gy), Some(gz)) = (self.gyro[0], self.gyro[1], self.gyro[2]) else {
            return None;
        };
        let (Some(ax), Some(ay), Some(az)) = (self.acc[0], self.acc[1], self.acc[2]) else {
            return None;
        };
        let (gt, at) = (self.gyro_tag?, self.acc_tag?);
        let tag = if tag_delta(gt, at) >= 0 { gt } else { at };
        self.gyro = [None; 3];
        self.acc = [None; 3];
        let v = |x: i32, y: i32, z: i32, s: f64| {
            to_frd(Vector3::new(f64::from(x), f64::from(y), f64::from(z)) * s)
        };
        Some(RateSample {
            tag,
            w: v(gx, gy, gz, GYRO_SCALE),
            f: v(ax, ay, az, ACC_SCALE),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_24_bit_values() {
        assert_eq!(value24(0x10_00_00_1A), 26);
        assert_eq!(value24(0x12_FF_F6_8B), -2421);
        assert_eq!(value24(0x00_80_00_00), -8_388_608);
        assert_eq!(value24(0x00_7F_FF_FF), 8_388_607);
    }

    #[test]
    fn tag_differences_wrap() {
        assert_eq!(tag_delta(10, 0xFF_FF_F6), 20);
        assert_eq!(tag_delta(0x0100_0005, 0x00FF_FFFF), 6);
        assert_eq!(tag_delta(100, 356), -256);
    }

    #[test]
    fn a_sample_needs_all_six_axes_and_turns_to_frd() {
        let mut a = Assembler::default();
        let d = |kind, value, tag| Datum { kind, value, tag };
        assert_eq!(a.push(d(GYRO_X, 4096, 7)), None);
        assert_eq!(a.push(d(GYRO_Y, 4096, 7)), None);
        assert_eq!(a.push(d(GYRO_TEMP, 3000, 7)), None);
        assert_eq!(a.push(d(GYRO_Z, -4096, 7)), None);
        assert_eq!(a.push(d(ACC_X, 1024, 9)), None);
        assert_eq!(a.push(d(ACC_Y, 0, 9)), None);
        let s = a.push(d(ACC_Z, 10_240, 9)).unwrap();
        assert_eq!(s.tag, 9);
        let r = 1f64.to_radians();
        assert_eq!(s.w, Vector3::new(r, -r, r));
        assert_eq!(s.f, Vector3::new(1.0, 0.0, -10.0));
        // A triple left incomplete is dropped when a newer tag arrives.
        assert_eq!(a.push(d(GYRO_X, 1, 11)), None);
        assert_eq!(a.push(d(GYRO_X, 1, 12)), None);
        assert_eq!(a.gyro, [Some(1), None, None]);
    }
}
