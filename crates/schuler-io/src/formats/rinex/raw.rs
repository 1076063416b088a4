//! RINEX observation epochs as the library's raw measurements ([`RawEpoch`]).
//!
//! Each satellite's observations are grouped by signal (band digit and attribute
//! letter of the RINEX 3 code; RINEX 2 codes arrive already mapped to RINEX 3 by
//! [`super::obs::ObsReader`]): `C` → pseudorange [m], `D` → Doppler [Hz], `L` → carrier
//! phase [cycles], `S` → C/N0 [dB-Hz, as the file gives it]. The phase's loss-of-lock
//! indicator gives the lock state (RINEX 3.05 §5.3.1: bit 0 lost lock, a slip possible;
//! bit 1 half-cycle ambiguity); a phase without an indicator has no lock state. The
//! GLONASS FDMA channel is the header's (`GLONASS SLOT / FRQ #`). An epoch's time is
//! its GPS week and second (the receiver clock's reading: RINEX's clock offset, when
//! given, is left to the solution's clock bias). Events (flags 2–5) and cycle-slip
//! records (flag 6) carry no measurements: [`raw_epoch`] gives `None` for them.

use super::obs::{Epoch, ObsKind};
use schuler::gnss::{GpsTime, PhaseLock, RawEpoch, RawMeasurement, Signal};

/// The raw measurements of `epoch`, `None` for an epoch without measurements (an event
/// or cycle-slip records). `glonass_channels`: the header's `(slot, channel)` pairs.
pub fn raw_epoch(epoch: &Epoch, glonass_channels: &[(u8, i8)]) -> Option<RawEpoch> {
    if !epoch.flag.has_measurements() {
        return None;
    }
    let mut measurements: Vec<RawMeasurement> = Vec::new();
    for sat_obs in epoch.sats() {
        let sat = sat_obs.sat;
        let channel = (sat.system == schuler::gnss::System::Glonass)
            .then(|| {
                glonass_channels
                    .iter()
                    .find(|(slot, _)| *slot == sat.prn)
                    .map(|&(_, k)| k)
            })
            .flatten();
        let first = measurements.len();
        for (code, o) in sat_obs.iter() {
            if code.kind() == ObsKind::Channel {
                continue;
            }
            let Some(signal) = Signal::from_rinex(sat.system, code.as_str()) else {
                continue;
            };
            let i = match measurements[first..]
                .iter()
                .position(|m| m.signal == signal)
            {
                Some(i) => first + i,
                None => {
                    let mut m = RawMeasurement::code(sat, signal, f64::NAN);
                    m.pseudorange = None;
                    m.glonass_channel = channel;
                    measurements.push(m);
                    measurements.len() - 1
                }
            };
            let m = &mut measurements[i];
            match code.kind() {
                ObsKind::Pseudorange => m.pseudorange = Some(o.value),
                ObsKind::Doppler => m.doppler = Some(o.value),
                ObsKind::Phase => {
                    m.carrier_phase = Some(o.value);
                    m.lock = o.lli.map(|lli| PhaseLock {
                        slip: lli & 1 != 0,
                        half_cycle: lli & 2 != 0,
                        lock_time_ms: None,
                    });
                }
                ObsKind::SignalStrength => m.cn0 = Some(o.value),
                ObsKind::Channel => {}
            }
        }
    }
    Some(RawEpoch {
        t: GpsTime::new(epoch.week, epoch.sow),
        measurements,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::rinex::obs::ObsReader;
    use schuler::gnss::{Sat, System};
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data/rinex_obs")
            .join(name)
    }

    /// Station 0759's first epoch (RINEX 2.10, `L1 C1 L2 P2`): C1 and L1 on `1C`, P2
    /// and L2 on `2W`, values as written.
    #[test]
    fn gsi_0759_first_epoch() {
        let mut r = ObsReader::open(&data("07590920.05o.gz")).expect("open");
        let channels = r.header().glonass_channels.clone();
        let e = r.next().expect("an epoch").expect("read");
        let raw = raw_epoch(&e, &channels).expect("measurements");
        assert_eq!(raw.t, GpsTime::new(e.week, e.sow));
        assert_eq!(raw.sats().len(), e.len());
        let first = e.sats().next().expect("a satellite");
        let sat: Sat = first.sat;
        assert_eq!(sat.system, System::Gps);
        let l1 = raw
            .get(sat, Signal::new(System::Gps, '1', 'C'))
            .expect("1C");
        let c1 = first
            .iter()
            .find(|(c, _)| c.as_str() == "C1C")
            .expect("C1C")
            .1;
        let ph = first
            .iter()
            .find(|(c, _)| c.as_str() == "L1C")
            .expect("L1C")
            .1;
        assert_eq!(l1.pseudorange, Some(c1.value));
        assert_eq!(l1.carrier_phase, Some(ph.value));
        assert!(l1.pseudorange.expect("C1") > 1.9e7 && l1.pseudorange.expect("C1") < 2.7e7);
        let l2 = raw
            .get(sat, Signal::new(System::Gps, '2', 'W'))
            .expect("2W");
        assert!(l2.pseudorange.is_some() && l2.carrier_phase.is_some());
        assert_eq!(l2.doppler, None);
        assert_eq!(l2.cn0, None);
        // Two signals per satellite, each once.
        assert_eq!(raw.measurements.len(), 2 * e.len());
        // Events carry none.
        let event = r
            .by_ref()
            .map(|e| e.expect("read"))
            .find(|e| e.flag.is_event())
            .expect("an event");
        assert!(raw_epoch(&event, &channels).is_none());
    }

    /// Lock indicators: bit 0 a slip, bit 1 a half cycle.
    #[test]
    fn lli_bits() {
        let mut r =
            ObsReader::open(&data("ACOR00ESP_R_20213550000_01D_30S_MO.rnx.gz")).expect("open");
        let channels = r.header().glonass_channels.clone();
        let mut seen = 0;
        for e in r.by_ref().take(25) {
            let e = e.expect("read");
            let Some(raw) = raw_epoch(&e, &channels) else {
                continue;
            };
            for s in e.sats() {
                for (c, o) in s.iter().filter(|(c, _)| c.kind() == ObsKind::Phase) {
                    let sig = Signal::from_rinex(s.sat.system, c.as_str()).expect("signal");
                    let m = raw.get(s.sat, sig).expect("measurement");
                    let lock = m.lock;
                    match o.lli {
                        Some(lli) => {
                            let lock = lock.expect("lock");
                            assert_eq!(lock.slip, lli & 1 != 0);
                            assert_eq!(lock.half_cycle, lli & 2 != 0);
                            seen += 1;
                        }
                        None => assert!(lock.is_none()),
                    }
                    if s.sat.system == System::Glonass {
                        assert!(m.glonass_channel.is_some());
                    }
                }
            }
        }
        assert!(seen > 0 || channels.is_empty());
    }
}
