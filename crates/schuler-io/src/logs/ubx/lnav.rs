//! RXM-SFRBX (0x02 0x13) GPS L1 C/A subframes 1–3 decoded into an [`Ephemeris`]
//! (IS-GPS-200N §20.3.3.3 and §20.3.3.4, Tables 20-I, 20-III; the bit positions of
//! Figure 20-1).
//!
//! An SFRBX payload is `gnssId`, `svId`, `sigId`, `freqId`, `numWords`, `chn`,
//! `version`, a reserved byte, then `numWords` 32-bit words. For GPS L1 C/A the ten
//! words of a 300-bit subframe each hold one 30-bit navigation word in bits 29–0: its
//! 24 data bits in bits 29–6 (already corrected for the D30* polarity by the receiver:
//! the TLM preamble reads 0x8B), parity in bits 5–0. The reader concatenates the data
//! bits (240 per subframe) and takes the fields at their positions in that string.
//!
//! A satellite's subframes 1, 2 and 3 are kept until all three carry the same issue
//! of data (IODC's 8 low bits = IODE of subframe 2 = IODE of subframe 3, §20.3.4.4);
//! then one ephemeris is emitted, once per (IODC, IODE, toe). The 10-bit week of
//! subframe 1 is resolved to the full GPS week nearest the receiver's (from RXM-RAWX
//! or NAV-PVT); toe and toc are placed within half a week of the subframe's
//! transmission time (HOW time of week). Angles in semicircles are turned to radians
//! with [`ICD_PI`], as receivers do.

use super::le;
use schuler::gnss::{Ephemeris, GpsTime, ICD_PI, Kepler, NavMessage, Sat, System};
use std::collections::BTreeMap;

/// The LNAV TLM preamble.
const PREAMBLE: u32 = 0x8B;
/// GPS's nominal URA in metres by index (IS-GPS-200 §20.3.3.3.1.3, the upper bound of
/// each interval, as RINEX writers give it); index 15 is "no accuracy prediction".
const URA_M: [f64; 15] = [
    2.4, 3.4, 4.85, 6.85, 9.65, 13.65, 24.0, 48.0, 96.0, 192.0, 384.0, 768.0, 1536.0, 3072.0,
    6144.0,
];

/// The data bits of one subframe: ten 24-bit words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Subframe([u32; 10]);

impl Subframe {
    /// `len` ≤ 32 bits at 0-based bit `pos` of the 240-bit data string, unsigned.
    fn bits(&self, pos: usize, len: usize) -> u32 {
        let mut v: u64 = 0;
        for k in pos..pos + len {
            let bit = (self.0[k / 24] >> (23 - k % 24)) & 1;
            v = (v << 1) | u64::from(bit);
        }
        v as u32
    }

    /// As [`Subframe::bits`], two's complement.
    fn signed(&self, pos: usize, len: usize) -> i32 {
        let v = self.bits(pos, len);
        ((v << (32 - len)) as i32) >> (32 - len)
    }

    /// Two fields of `a` then `b` bits at `pa`, `pb` joined (MSBs first), unsigned.
    fn joined(&self, pa: usize, a: usize, pb: usize, b: usize) -> u32 {
        (self.bits(pa, a) << b) | self.bits(pb, b)
    }

    /// The subframe id (HOW bits 20–22).
    pub fn id(&self) -> u32 {
        self.bits(43, 3)
    }

    /// The HOW time of week [s] (of the next subframe's start).
    pub fn how_tow_s(&self) -> f64 {
        f64::from(self.bits(24, 17)) * 6.0
    }
}

/// The subframe of a GPS L1 C/A SFRBX payload (satellite, subframe), `None` for other
/// systems or signals, or a word count other than ten, or a preamble other than 0x8B.
pub fn gps_subframe(p: &[u8]) -> Option<(u8, Subframe)> {
    if p.len() < 8 + 40 || p[0] != 0 || p[4] != 10 || p[2] != 0 {
        return None;
    }
    let mut w = [0u32; 10];
    for (i, x) in w.iter_mut().enumerate() {
        *x = (le::u32(p, 8 + 4 * i) >> 6) & 0xFF_FFFF;
    }
    let sf = Subframe(w);
    (sf.bits(0, 8) == PREAMBLE && (1..=5).contains(&sf.id())).then_some((p[1], sf))
}

/// A satellite's latest subframes 1–3.
#[derive(Debug, Clone, Default)]
struct Set {
    sf: [Option<Subframe>; 3],
    /// (IODC, IODE, toe) of the last ephemeris emitted.
    emitted: Option<(u32, u32, u32)>,
}

/// Collects subframes per GPS satellite and emits ephemerides.
#[derive(Debug, Clone, Default)]
pub struct Collector {
    sets: BTreeMap<u8, Set>,
}

impl Collector {
    /// Takes subframe `sf` of GPS satellite `prn`; returns the ephemeris it completes
    /// when the satellite's subframes 1–3 now agree on their issue of data and differ
    /// from the last one emitted. `week` is the receiver's full GPS week, if known.
    pub fn push(&mut self, prn: u8, sf: Subframe, week: Option<u32>) -> Option<Ephemeris> {
        let id = sf.id() as usize;
        if !(1..=3).contains(&id) || !(1..=32).contains(&prn) {
            return None;
        }
        let set = self.sets.entry(prn).or_default();
        set.sf[id - 1] = Some(sf);
        let [Some(s1), Some(s2), Some(s3)] = set.sf else {
            return None;
        };
        let iodc = s1.joined(70, 2, 168, 8);
        let iode2 = s2.bits(48, 8);
        let iode3 = s3.bits(216, 8);
        if iodc & 0xFF != iode2 || iode2 != iode3 {
            return None;
        }
        let toe_raw = s2.bits(216, 16);
        if set.emitted == Some((iodc, iode2, toe_raw)) {
            return None;
        }
        let eph = ephemeris(Sat::new(System::Gps, prn), &s1, &s2, &s3, week?)?;
        set.emitted = Some((iodc, iode2, toe_raw));
        Some(eph)
    }
}

/// The fit interval [s] of a fit-interval flag and IODC (IS-GPS-200 §20.3.4.4,
/// Table 20-XII): 4 h when the flag is clear; otherwise 6 h, or longer for the IODC
/// ranges of extended operations.
fn fit_interval_s(flag: u32, iodc: u32) -> f64 {
    let hours = if flag == 0 {
        4.0
    } else {
        match iodc {
            240..=247 => 8.0,
            248..=255 | 496 => 14.0,
            497..=503 | 1021..=1023 => 26.0,
            _ => 6.0,
        }
    };
    hours * 3600.0
}

/// `sow` of the week nearest `near`.
fn near(near: GpsTime, sow: f64) -> GpsTime {
    let t = GpsTime::new(near.week, sow);
    let weeks = (t.diff_s(near) / 604_800.0).round();
    t.add_s(-weeks * 604_800.0)
}

/// The ephemeris of three subframes that share their issue of data.
fn ephemeris(
    sat: Sat,
    s1: &Subframe,
    s2: &Subframe,
    s3: &Subframe,
    rx_week: u32,
) -> Option<Ephemeris> {
    let sc = |v: i32, e: i32| f64::from(v) * 2f64.powi(e) * ICD_PI;
    // Subframe 1: week (mod 1024) resolved to the receiver's.
    let wn10 = i64::from(s1.bits(48, 10));
    let rx = i64::from(rx_week);
    let mut ahead = (wn10 - rx).rem_euclid(1024);
    if ahead > 512 {
        ahead -= 1024;
    }
    let week = rx + ahead;
    let tx = GpsTime::new(week, s1.how_tow_s());
    let ura = s1.bits(60, 4) as usize;
    let iodc = s1.joined(70, 2, 168, 8);
    let toc = near(tx, f64::from(s1.bits(176, 16)) * 16.0);
    let toe_sow = f64::from(s2.bits(216, 16)) * 16.0;
    let sqrt_a = f64::from(s2.joined(184, 8, 192, 24)) * 2f64.powi(-19);
    let e = f64::from(s2.joined(136, 8, 144, 24)) * 2f64.powi(-33);
    if sqrt_a <= 0.0 {
        return None;
    }
    let joined_signed = |s: &Subframe, pa, pb| s.joined(pa, 8, pb, 24) as i32;
    Some(Ephemeris {
        sat,
        message: NavMessage::Lnav,
        toc,
        af0: f64::from(s1.signed(216, 22)) * 2f64.powi(-31),
        af1: f64::from(s1.signed(200, 16)) * 2f64.powi(-43),
        af2: f64::from(s1.signed(192, 8)) * 2f64.powi(-55),
        toe: near(tx, toe_sow),
        kepler: Kepler {
            sqrt_a,
            e,
            i0: sc(joined_signed(s3, 112, 120), -31),
            omega0: sc(joined_signed(s3, 64, 72), -31),
            omega: sc(joined_signed(s3, 160, 168), -31),
            m0: sc(joined_signed(s2, 88, 96), -31),
            delta_n: sc(s2.signed(72, 16), -43),
            i_dot: sc(s3.signed(224, 14), -43),
            omega_dot: sc(s3.signed(192, 24), -43),
            cuc: f64::from(s2.signed(120, 16)) * 2f64.powi(-29),
            cus: f64::from(s2.signed(168, 16)) * 2f64.powi(-29),
            crc: f64::from(s3.signed(144, 16)) * 2f64.powi(-5),
            crs: f64::from(s2.signed(56, 16)) * 2f64.powi(-5),
            cic: f64::from(s3.signed(48, 16)) * 2f64.powi(-29),
            cis: f64::from(s3.signed(96, 16)) * 2f64.powi(-29),
            toe_sow,
        },
        iode: s2.bits(48, 8),
        iodc,
        health: s1.bits(64, 6),
        data_source: 0,
        accuracy_m: URA_M.get(ura).copied().unwrap_or(-1.0),
        group_delays: [f64::from(s1.signed(160, 8)) * 2f64.powi(-31), 0.0],
        fit_interval_s: fit_interval_s(s2.bits(232, 1), iodc),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A subframe with `fields` (position, length, value) set in its data bits.
    fn subframe(id: u32, fields: &[(usize, usize, u32)]) -> Subframe {
        let mut s = Subframe([0; 10]);
        let mut set = |pos: usize, len: usize, v: u32| {
            for k in 0..len {
                let bit = (v >> (len - 1 - k)) & 1;
                let p = pos + k;
                s.0[p / 24] |= bit << (23 - p % 24);
            }
        };
        set(0, 8, PREAMBLE);
        set(24, 17, 1000);
        set(43, 3, id);
        for &(p, l, v) in fields {
            set(p, l, v);
        }
        s
    }

    #[test]
    fn fields_across_words_and_signs() {
        let s = subframe(2, &[(88, 8, 0xFF), (96, 24, 0xFF_FFFF), (56, 16, 0x8000)]);
        assert_eq!(s.id(), 2);
        assert_eq!(s.how_tow_s(), 6000.0);
        assert_eq!(s.joined(88, 8, 96, 24) as i32, -1);
        assert_eq!(s.signed(56, 16), -32768);
    }

    #[test]
    fn a_set_is_emitted_once_when_its_issues_of_data_agree() {
        // IODC 0x145: IODE must be 0x45. √A = 5153.6 (2^19 units), toe 7200 s.
        let sqrt_a = (5153.6f64 * 2f64.powi(19)).round() as u64;
        let s1 = subframe(
            1,
            &[
                (48, 10, 1025 % 1024),
                (70, 2, 1),
                (168, 8, 0x45),
                (176, 16, 450),
            ],
        );
        let s2 = subframe(
            2,
            &[
                (48, 8, 0x45),
                (184, 8, (sqrt_a >> 24) as u32),
                (192, 24, (sqrt_a & 0xFF_FFFF) as u32),
                (216, 16, 450),
            ],
        );
        let s3_old = subframe(3, &[(216, 8, 0x44)]);
        let s3 = subframe(3, &[(216, 8, 0x45)]);
        let mut c = Collector::default();
        assert!(c.push(7, s1, Some(2049)).is_none());
        assert!(c.push(7, s2, Some(2049)).is_none());
        assert!(c.push(7, s3_old, Some(2049)).is_none(), "IODE mismatch");
        let e = c.push(7, s3, Some(2049)).expect("complete set");
        assert_eq!(e.sat, Sat::new(System::Gps, 7));
        assert_eq!((e.iodc, e.iode), (0x145, 0x45));
        // Week 1025 mod 1024 = 1 resolved to the receiver's 2049.
        assert_eq!(e.toe, GpsTime::new(2049, 7200.0));
        assert_eq!(e.toc, GpsTime::new(2049, 7200.0));
        assert!((e.kepler.sqrt_a - 5153.6).abs() < 2f64.powi(-19));
        assert_eq!(e.fit_interval_s, 4.0 * 3600.0);
        assert!(c.push(7, s3, Some(2049)).is_none(), "emitted once");
    }
}
