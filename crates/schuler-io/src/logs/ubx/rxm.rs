//! RXM-RAWX (0x02 0x15): the receiver's raw measurements of one epoch, as a
//! [`RawEpoch`].
//!
//! Layout (u-blox M8 protocol 15+ and F9 interface descriptions): `rcvTow` (R8, s),
//! `week` (U2), `leapS` (I1), `numMeas` (U1), `recStat` (X1), `version` (U1), 2
//! reserved bytes, then 32 bytes per measurement: `prMes` (R8, m), `cpMes` (R8,
//! cycles), `doMes` (R4, Hz), `gnssId`, `svId`, `sigId`, `freqId` (U1 each), `locktime`
//! (U2, ms), `cno` (U1, dB-Hz), `prStdev` (0.01 m · 2ⁿ, n in bits 0–3), `cpStdev`
//! (0.004 cycles · n), `doStdev` (0.002 Hz · 2ⁿ), `trkStat` (bit 0 pseudorange valid,
//! 1 carrier phase valid, 2 half cycle resolved, 3 half cycle subtracted from phase).
//!
//! Doppler: u-blox gives "positive sign for approaching satellites", as RINEX does and
//! as [`schuler::gnss::RawMeasurement::doppler`] is defined: taken unchanged (the
//! committed log's two epochs confirm it: each satellite's pseudorange change over
//! the 4.125 s between them is −λ·D plus the receiver clock's drift, the same for all).
//!
//! Satellites (`gnssId`, `svId`): 0 GPS, 1 SBAS (PRN 120–158 → `S20`–`S58`), 2
//! Galileo, 3 BeiDou, 5 QZSS (svId 1–10 → `J01`–`J10`), 6 GLONASS (slot; 255 = unknown,
//! left out), 7 NavIC. GLONASS's frequency channel is `freqId − 7`.
//!
//! Signals (`sigId`, the F9 interface description's table; M8 receivers write 0,
//! their L1/E1/B1I signal): GPS 0 L1C/A `1C`, 3 L2 CL `2L`, 4 L2 CM `2S`, 6 L5 I `5I`,
//! 7 L5 Q `5Q`; SBAS 0 `1C`; Galileo 0 E1 C `1C`, 1 E1 B `1B`, 3 E5a I `5I`, 4 E5a Q
//! `5Q`, 5 E5b I `7I`, 6 E5b Q `7Q`, 8 E6 B `6B`, 9 E6 C `6C`, 10 E6 A `6A`; BeiDou 0, 1
//! B1I D1/D2 `2I`, 2, 3 B2I `7I`, 4, 10 B3I `6I`, 5 B1C pilot `1P`, 6 B1C data `1D`, 7
//! B2a pilot `5P`, 8 B2a data `5D`; QZSS 0 L1C/A `1C`, 1 L1S `1Z`, 4 L2 CM `2S`, 5 L2 CL
//! `2L`, 8 L5 I `5I`, 9 L5 Q `5Q`; GLONASS 0 L1OF `1C`, 2 L2OF `2C`; NavIC 0 L5 A `5A`.
//! A measurement of an unknown system or signal is counted and left out.
//!
//! Lock: `locktime` restarting (smaller than the previous epoch's for the same
//! satellite and signal, or the signal new) marks a slip; `half_cycle` is set while
//! `trkStat` bit 2 is clear.

use super::le;
use schuler::gnss::{GpsTime, PhaseLock, RawEpoch, RawMeasurement, Sat, Signal, System};
use std::collections::BTreeMap;

/// The fixed part of a RAWX payload [bytes].
pub const RAWX_HEADER: usize = 16;
/// One measurement block [bytes].
pub const RAWX_BLOCK: usize = 32;

/// The satellite of a `gnssId`, `svId` pair.
pub fn sat(gnss_id: u8, sv_id: u8) -> Option<Sat> {
    let (system, prn) = match gnss_id {
        0 => (System::Gps, sv_id),
        1 => (System::Sbas, sv_id.checked_sub(100)?),
        2 => (System::Galileo, sv_id),
        3 => (System::BeiDou, sv_id),
        5 => (System::Qzss, sv_id),
        6 if sv_id != 255 => (System::Glonass, sv_id),
        7 => (System::Navic, sv_id),
        _ => return None,
    };
    (prn > 0).then(|| Sat::new(system, prn))
}

/// The signal of `sigId` in system `system` (table in the module's doc).
pub fn signal(system: System, sig_id: u8) -> Option<Signal> {
    use System::*;
    let (band, attr) = match (system, sig_id) {
        (Gps, 0) | (Sbas, 0) | (Qzss, 0) | (Glonass, 0) | (Galileo, 0) => ('1', 'C'),
        (Gps, 3) | (Qzss, 5) => ('2', 'L'),
        (Gps, 4) | (Qzss, 4) => ('2', 'S'),
        (Gps, 6) | (Qzss, 8) | (Galileo, 3) => ('5', 'I'),
        (Gps, 7) | (Qzss, 9) | (Galileo, 4) => ('5', 'Q'),
        (Qzss, 1) => ('1', 'Z'),
        (Galileo, 1) => ('1', 'B'),
        (Galileo, 5) | (BeiDou, 2) | (BeiDou, 3) => ('7', 'I'),
        (Galileo, 6) => ('7', 'Q'),
        (Galileo, 8) => ('6', 'B'),
        (Galileo, 9) => ('6', 'C'),
        (Galileo, 10) => ('6', 'A'),
        (BeiDou, 0) | (BeiDou, 1) => ('2', 'I'),
        (BeiDou, 4) | (BeiDou, 10) => ('6', 'I'),
        (BeiDou, 5) => ('1', 'P'),
        (BeiDou, 6) => ('1', 'D'),
        (BeiDou, 7) => ('5', 'P'),
        (BeiDou, 8) => ('5', 'D'),
        (Glonass, 2) => ('2', 'C'),
        (Navic, 0) => ('5', 'A'),
        _ => return None,
    };
    Some(Signal::new(system, band, attr))
}

/// The header fields of a RAWX payload.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawxHeader {
    /// Receiver time of week [s].
    pub rcv_tow: f64,
    /// GPS week.
    pub week: u16,
    /// GPS − UTC leap seconds.
    pub leap_s: i8,
    /// Measurements that follow.
    pub num_meas: u8,
    /// Receiver status: bit 0 leap seconds known, bit 1 clock reset.
    pub rec_stat: u8,
}

/// The header of a RAWX payload of at least [`RAWX_HEADER`] bytes.
pub fn header(p: &[u8]) -> RawxHeader {
    RawxHeader {
        rcv_tow: le::f64(p, 0),
        week: le::u16(p, 8),
        leap_s: p[10] as i8,
        num_meas: p[11],
        rec_stat: p[12],
    }
}

/// One RAWX measurement block as written (for the dump and the tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawxBlock {
    /// `prMes` [m].
    pub pr: f64,
    /// `cpMes` [cycles].
    pub cp: f64,
    /// `doMes` [Hz].
    pub doppler: f32,
    /// `gnssId`.
    pub gnss_id: u8,
    /// `svId`.
    pub sv_id: u8,
    /// `sigId`.
    pub sig_id: u8,
    /// `freqId`.
    pub freq_id: u8,
    /// `locktime` [ms].
    pub locktime: u16,
    /// `cno` [dB-Hz].
    pub cno: u8,
    /// `prStdev`, `cpStdev`, `doStdev` (low four bits each).
    pub stdev: [u8; 3],
    /// `trkStat`.
    pub trk_stat: u8,
}

/// The `i`-th measurement block of a RAWX payload whose length the caller checked.
pub fn block(p: &[u8], i: usize) -> RawxBlock {
    let b = &p[RAWX_HEADER + RAWX_BLOCK * i..RAWX_HEADER + RAWX_BLOCK * (i + 1)];
    RawxBlock {
        pr: le::f64(b, 0),
        cp: le::f64(b, 8),
        doppler: f32::from_bits(le::u32(b, 16)),
        gnss_id: b[20],
        sv_id: b[21],
        sig_id: b[22],
        freq_id: b[23],
        locktime: le::u16(b, 24),
        cno: b[26],
        stdev: [b[27] & 0x0F, b[28] & 0x0F, b[29] & 0x0F],
        trk_stat: b[30],
    }
}

/// Turns RAWX payloads into [`RawEpoch`]s, remembering each signal's lock time to tell
/// slips.
#[derive(Debug, Clone, Default)]
pub struct RawxDecoder {
    lock: BTreeMap<(Sat, Signal), u16>,
    /// Measurements left out (unknown system or signal, GLONASS slot unknown).
    pub skipped: u64,
}

impl RawxDecoder {
    /// The epoch of a RAWX payload whose length the caller checked.
    pub fn epoch(&mut self, p: &[u8]) -> RawEpoch {
        let h = header(p);
        let mut measurements = Vec::with_capacity(usize::from(h.num_meas));
        let mut lock = BTreeMap::new();
        for i in 0..usize::from(h.num_meas) {
            let b = block(p, i);
            let Some(sat) = sat(b.gnss_id, b.sv_id) else {
                self.skipped += 1;
                continue;
            };
            let Some(signal) = signal(sat.system, b.sig_id) else {
                self.skipped += 1;
                continue;
            };
            let pr_valid = b.trk_stat & 0x01 != 0;
            let cp_valid = b.trk_stat & 0x02 != 0;
            let previous = self.lock.get(&(sat, signal)).copied();
            lock.insert((sat, signal), b.locktime);
            let slip = previous.is_none_or(|prev| b.locktime < prev);
            measurements.push(RawMeasurement {
                sat,
                signal,
                glonass_channel: (sat.system == System::Glonass).then(|| b.freq_id as i8 - 7),
                pseudorange: pr_valid.then_some(b.pr),
                doppler: Some(f64::from(b.doppler)),
                carrier_phase: cp_valid.then_some(b.cp),
                cn0: Some(f64::from(b.cno)),
                lock: Some(PhaseLock {
                    slip: cp_valid && slip,
                    half_cycle: b.trk_stat & 0x04 == 0,
                    lock_time_ms: Some(u32::from(b.locktime)),
                }),
                pseudorange_std: pr_valid.then(|| 0.01 * f64::from(1u32 << b.stdev[0])),
                doppler_std: Some(0.002 * f64::from(1u32 << b.stdev[2])),
                carrier_phase_std: cp_valid.then(|| 0.004 * f64::from(b.stdev[1])),
            });
        }
        self.lock = lock;
        RawEpoch {
            t: GpsTime::new(i64::from(h.week), h.rcv_tow),
            measurements,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn satellites_and_signals() {
        assert_eq!(sat(0, 5).unwrap().to_string(), "G05");
        assert_eq!(sat(1, 120).unwrap().to_string(), "S20");
        assert_eq!(sat(5, 1).unwrap().to_string(), "J01");
        assert_eq!(sat(6, 255), None);
        assert_eq!(sat(4, 1), None); // IMES
        assert_eq!(signal(System::Gps, 0).unwrap().rinex(), "1C");
        assert_eq!(signal(System::Gps, 3).unwrap().rinex(), "2L");
        assert_eq!(signal(System::Galileo, 6).unwrap().rinex(), "7Q");
        assert_eq!(signal(System::BeiDou, 1).unwrap().rinex(), "2I");
        assert_eq!(signal(System::Glonass, 2).unwrap().rinex(), "2C");
        assert_eq!(signal(System::Gps, 1), None);
    }

    fn payload(blocks: &[(u8, u8, u16, u8)]) -> Vec<u8> {
        let mut p = vec![0u8; RAWX_HEADER];
        p[0..8].copy_from_slice(&1000.5f64.to_le_bytes());
        p[8..10].copy_from_slice(&2049u16.to_le_bytes());
        p[11] = blocks.len() as u8;
        for &(g, s, lock, trk) in blocks {
            let mut b = [0u8; RAWX_BLOCK];
            b[0..8].copy_from_slice(&2.1e7f64.to_le_bytes());
            b[8..16].copy_from_slice(&1.1e8f64.to_le_bytes());
            b[16..20].copy_from_slice(&(-1234.5f32).to_le_bytes());
            b[20] = g;
            b[21] = s;
            b[23] = 3;
            b[24..26].copy_from_slice(&lock.to_le_bytes());
            b[26] = 44;
            b[27] = 5;
            b[28] = 3;
            b[29] = 4;
            b[30] = trk;
            p.extend_from_slice(&b);
        }
        p
    }

    #[test]
    fn measurements_validity_and_slips() {
        let mut d = RawxDecoder::default();
        let e = d.epoch(&payload(&[
            (0, 5, 500, 0x07),
            (6, 3, 500, 0x01),
            (4, 1, 0, 1),
        ]));
        assert_eq!(e.t, GpsTime::new(2049, 1000.5));
        assert_eq!(e.measurements.len(), 2);
        assert_eq!(d.skipped, 1);
        let g = &e.measurements[0];
        assert_eq!(g.pseudorange, Some(2.1e7));
        assert_eq!(g.carrier_phase, Some(1.1e8));
        assert_eq!(g.doppler, Some(-1234.5));
        assert_eq!(g.pseudorange_std, Some(0.32));
        assert_eq!(g.carrier_phase_std, Some(0.012));
        assert_eq!(g.doppler_std, Some(0.032));
        assert!(g.lock.unwrap().slip); // first seen
        assert!(!g.lock.unwrap().half_cycle);
        let r = &e.measurements[1];
        assert_eq!(r.glonass_channel, Some(-4));
        assert_eq!(r.carrier_phase, None);
        // Lock time growing: no slip; restarting: a slip.
        let e = d.epoch(&payload(&[(0, 5, 1500, 0x07)]));
        assert!(!e.measurements[0].lock.unwrap().slip);
        let e = d.epoch(&payload(&[(0, 5, 20, 0x03)]));
        let l = e.measurements[0].lock.unwrap();
        assert!(l.slip && l.half_cycle);
    }
}
