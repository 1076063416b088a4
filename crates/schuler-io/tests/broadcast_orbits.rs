//! Broadcast orbits and clocks against precise orbits of the same day (issue 31: 3D
//! RMS ≤ 2 m; clocks ≤ 5 ns RMS once each epoch's common offset is removed).
//!
//! Data (tests/data/orbits/README.md): GPS on 2010-07-01 (IGS's merged broadcast file
//! brdc1820.10n against the IGS final orbit igs15904.sp3), and GPS, Galileo, BeiDou and
//! QZSS on 2020-06-25 (station MOJN's mixed RINEX 3.05 navigation file against IAC's
//! multi-GNSS final orbit, hourly).
//!
//! What is compared: at every SP3 epoch, every satellite with a position and clock in
//! the SP3 and a healthy broadcast ephemeris within its window ([`EphemerisStore`]'s
//! rule). The precise orbit is that of the centre of mass; the broadcast orbit refers
//! to an antenna phase centre, which lies towards the Earth. The bounds are checked on
//! the positions as they are (the RMS includes those offsets). For 2010 the comparison
//! is also printed with the SP3 moved by the IGS05 z-offsets (RTKLIB's data/igs05.atx,
//! the offsets in force that day; the Block IIA's 0.279 m along x, which needs the yaw
//! attitude, left out): it is no better (1.90 m against 1.87 m), because the broadcast
//! orbits refer to offsets of their own. The mean radial differences this test prints
//! show them: without offsets, about −1.0 m for the Block IIA, 0 for IIR-B and IIR-M,
//! −1.6 m for IIR-A, −1.0 to −1.2 m for IIF and III in 2020; −0.8 m for Galileo, −1.1
//! to −1.3 m for BDS-3 (nearly all of its 1.2-m RMS).
//!
//! Clocks: the SP3 clocks and the broadcast polynomials both leave out the periodic
//! relativistic term. The SP3 clocks refer to an ionosphere-free combination of two
//! signals (GPS P1/P2, Galileo E1/E5a, BeiDou B1I/B3I as IAC's header says); the
//! broadcast clocks to their own: GPS's to P1/P2, Galileo F/NAV's to E1/E5a (so F/NAV
//! ephemerides are used for Galileo), BeiDou's to B3I, moved to B1I/B3I by
//! −f₁²/(f₁² − f₃²)·TGD1. What remains common to a system at an epoch (the products'
//! reference clock) is removed by subtracting the epoch's mean over the system, with
//! BeiDou's two generations as two systems (their broadcast clocks differ by a bias:
//! with one mean, BDS-3's RMS grows from 2.0 to 5.3 ns).
//!
//! Which ephemeris: the store's rule (nearest healthy toe for GPS and QZSS, latest for
//! Galileo and BeiDou). The 2020 file keeps Galileo's records at whole-hour toes only
//! (README), so Galileo sets are used up to their 4-h limit, where they err by 2–6 m
//! (a full file refreshes them every 10 min).
//!
//! Bounds: GPS, Galileo and BDS-3 ≤ 2 m 3D RMS and ≤ 5 ns clock RMS (the issue's
//! figures); BeiDou-2 (IGSO/MEO and the GEO C05, metres off in their broadcast orbits
//! along and across track) and QZSS (three satellites; QZS-1 with a mean radial
//! difference of −3.2 m) are printed and only bounded against gross errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schuler::gnss::{Band, Ephemeris, EphemerisStore, GpsTime, NavMessage, Sat, System};
use schuler_io::formats::rinex::nav::read_store;
use schuler_io::formats::sp3::Sp3Reader;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/orbits")
        .join(name)
}

/// IGS05 z-offsets [m] of GPS's antennas in force on 2010-07-01 (igs05.atx, PRN →
/// `NORTH / EAST / UP` of G01, the same for G02), PRN 1–32.
const IGS05_Z_2010_07_01: [f64; 32] = [
    0.700, 0.614, 2.619, 2.279, 0.700, 2.676, 0.700, 2.405, 2.340, 2.389, 0.971, 0.700, 1.203,
    1.178, 0.700, 1.307, 0.645, 1.133, 0.668, 1.154, 1.300, 0.792, 0.602, 2.455, 1.407, 2.307,
    2.472, 0.911, 0.700, 2.466, 0.750, 2.575,
];

/// Errors of one group of satellites.
#[derive(Default)]
struct Stats {
    /// Sums of squared 3D, radial, along-track and cross-track differences [m²].
    sq: [f64; 4],
    /// Points compared.
    n: usize,
    /// Clock residuals [s] after each epoch's mean over the system.
    clock: Vec<f64>,
    /// Per satellite: points and sums of the radial, along and cross differences.
    per_sat: BTreeMap<Sat, (usize, [f64; 3])>,
}

impl Stats {
    fn rms(&self, k: usize) -> f64 {
        (self.sq[k] / self.n as f64).sqrt()
    }
    fn clock_rms(&self) -> f64 {
        (self.clock.iter().map(|c| c * c).sum::<f64>() / self.clock.len() as f64).sqrt()
    }
}

/// The broadcast clock of `eph` at `t` on the SP3's ionosphere-free combination.
fn broadcast_clock(eph: &Ephemeris, t: GpsTime) -> f64 {
    let (poly, _) = eph.clock_polynomial(t);
    match eph.sat.system {
        System::BeiDou => {
            let (f1, f3) = (Band::B1I.frequency(), Band::B3I.frequency());
            poly - f1 * f1 / (f1 * f1 - f3 * f3) * eph.group_delays[0]
        }
        _ => poly,
    }
}

/// The group a satellite's errors are counted in: a system, with BeiDou's two
/// generations apart (BDS-2: C01–C18; BDS-3: C19 on) and BDS-2's GEOs apart.
fn class(sat: Sat) -> &'static str {
    match sat.system {
        System::Gps => "GPS",
        System::Galileo => "Galileo",
        System::BeiDou if sat.prn <= 5 => "BDS-2 GEO",
        System::BeiDou if sat.prn <= 18 => "BDS-2 IGSO+MEO",
        System::BeiDou => "BDS-3",
        System::Qzss => "QZSS",
        _ => "other",
    }
}

/// Every satellite of `sp3` with a broadcast ephemeris in `nav` (as `select` picks
/// it), at every epoch: the statistics per [`class`].
fn compare(
    nav: &str,
    sp3: &str,
    z_offset: impl Fn(Sat) -> f64,
    select: impl Fn(&EphemerisStore, Sat, GpsTime) -> Option<Ephemeris>,
) -> BTreeMap<&'static str, Stats> {
    let (_, _, store) = read_store(&data(nav)).expect("nav");
    let mut stats: BTreeMap<&'static str, Stats> = BTreeMap::new();
    for epoch in Sp3Reader::open(&data(sp3)).expect("sp3") {
        let epoch = epoch.expect("epoch");
        // Per system, BeiDou's generations apart (their clocks differ by a bias).
        let mut clocks: BTreeMap<(System, bool), Vec<(Sat, f64)>> = BTreeMap::new();
        for s in &epoch.sats {
            let (Some(com), Some(clock)) = (s.r_e, s.clock_s) else {
                continue;
            };
            let Some(eph) = select(&store, s.sat, epoch.t) else {
                continue;
            };
            let p = eph.orbit_at(epoch.t);
            let radial = com.normalize();
            let d = p.r_e - (com - z_offset(s.sat) * radial);
            let cross = com.cross(&p.v_e).normalize();
            let along = cross.cross(&radial);
            let rac = [d.dot(&radial), d.dot(&along), d.dot(&cross)];
            let st = stats.entry(class(s.sat)).or_default();
            for (acc, c) in st.sq.iter_mut().zip([d.norm(), rac[0], rac[1], rac[2]]) {
                *acc += c * c;
            }
            st.n += 1;
            let (n, sums) = st.per_sat.entry(s.sat).or_default();
            *n += 1;
            for (acc, c) in sums.iter_mut().zip(rac) {
                *acc += c;
            }
            let c = broadcast_clock(&eph, epoch.t) - clock;
            let bds3 = s.sat.system == System::BeiDou && s.sat.prn > 18;
            clocks
                .entry((s.sat.system, bds3))
                .or_default()
                .push((s.sat, c));
        }
        for c in clocks.values().filter(|c| c.len() >= 2) {
            let mean = c.iter().map(|(_, x)| x).sum::<f64>() / c.len() as f64;
            for (sat, x) in c {
                stats.entry(class(*sat)).or_default().clock.push(x - mean);
            }
        }
    }
    for (group, st) in &stats {
        eprintln!(
            "{nav} {group}: {} satellites, {} points: 3D RMS {:.2} m (radial {:.2}, along {:.2}, \
             cross {:.2}); clock RMS {:.2} ns",
            st.per_sat.len(),
            st.n,
            st.rms(0),
            st.rms(1),
            st.rms(2),
            st.rms(3),
            st.clock_rms() * 1e9
        );
        for (sat, (n, v)) in &st.per_sat {
            let m = |k: usize| v[k] / *n as f64;
            eprintln!(
                "  {sat}: {n} points, mean radial {:+.2} along {:+.2} cross {:+.2} m",
                m(0),
                m(1),
                m(2)
            );
        }
    }
    stats
}

#[test]
fn gps_2010_broadcast_against_igs_final() {
    let nearest = |store: &EphemerisStore, sat, t| store.select(sat, t).cloned();
    let stats = compare("brdc1820.10n.gz", "igs15904.sp3.gz", |_| 0.0, nearest);
    let gps = &stats["GPS"];
    // G01 (SVN49) and G25 (a Block IIF launched that May) broadcast health 63 and 1
    // all day and are never used: 30 of the SP3's 32.
    assert_eq!(gps.per_sat.len(), 30);
    assert!(gps.n > 2800, "{}", gps.n);
    assert!(gps.rms(0) <= 2.0, "3D RMS {}", gps.rms(0));
    assert!(gps.clock_rms() <= 5e-9, "clock RMS {}", gps.clock_rms());
    // With IGS05's antenna offsets, for the record.
    let igs05 = |s: Sat| IGS05_Z_2010_07_01[usize::from(s.prn) - 1];
    let with = compare("brdc1820.10n.gz", "igs15904.sp3.gz", igs05, nearest);
    assert!(with["GPS"].rms(0) <= 2.0, "{}", with["GPS"].rms(0));
}

#[test]
fn multi_gnss_2020_broadcast_against_iac_final() {
    let stats = compare(
        "MOJN00DNK_R_20201770000_01D_MN_subset.rnx.gz",
        "Sta21114_hourly_noR.sp3.gz",
        |_| 0.0,
        |store, sat, t| match sat.system {
            System::Galileo => store.select_message(sat, t, NavMessage::Fnav).cloned(),
            _ => store.select(sat, t).cloned(),
        },
    );
    for (group, sats) in [("GPS", 30), ("Galileo", 20), ("BDS-3", 15)] {
        let st = &stats[group];
        assert!(st.per_sat.len() >= sats, "{group}: {}", st.per_sat.len());
        assert!(st.rms(0) <= 2.0, "{group}: 3D RMS {}", st.rms(0));
        assert!(
            st.clock_rms() <= 5e-9,
            "{group}: clock RMS {}",
            st.clock_rms()
        );
    }
    // Gross-error bounds only (a wrong GEO frame or a wrong constant errs by km).
    for (group, bound) in [("BDS-2 GEO", 25.0), ("BDS-2 IGSO+MEO", 5.0), ("QZSS", 4.0)] {
        let st = &stats[group];
        assert!(st.rms(0) <= bound, "{group}: 3D RMS {}", st.rms(0));
    }
}
