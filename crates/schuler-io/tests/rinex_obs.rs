//! The RINEX observation reader on public stations' files (tests/data/rinex_obs, see
//! its README): values checked against the files' text, and each Hatanaka-compressed
//! file read to the same epochs as its uncompressed twin.

use schuler::gnss::{Sat, System};
use schuler_io::formats::rinex::obs::{Epoch, EpochFlag, ObsCode, ObsReader, TimeSystem, Version};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/rinex_obs")
        .join(name)
}

fn read(name: &str) -> (ObsReader<Box<dyn std::io::BufRead + Send>>, Vec<Epoch>) {
    let mut r = ObsReader::open(&data(name)).expect("header");
    let mut out = Vec::new();
    for e in r.by_ref() {
        out.push(e.expect("epoch"));
    }
    (r, out)
}

fn code(s: &str) -> ObsCode {
    ObsCode::new(s).expect("code")
}

#[test]
fn gsi_station_0759_rinex_2_10() {
    let (r, epochs) = read("07590920.05o.gz");
    let h = r.header();
    assert_eq!(
        h.version,
        Version {
            major: 2,
            minor: 10
        }
    );
    assert_eq!(h.marker_name, "0759");
    let p = h.approx_position.expect("position");
    assert_eq!((p.x, p.y, p.z), (-3976219.5082, 3382372.5671, 3652512.9849));
    assert_eq!(h.rinex2_codes, ["L1", "C1", "L2", "P2"]);
    assert_eq!((h.interval, h.time_system), (Some(30.0), TimeSystem::Gps));
    // 120 epochs of data, and three flag 4 events where teqc spliced files (their
    // time blank, one COMMENT record each: `RINEX FILE SPLICE; ...`).
    let events: Vec<&Epoch> = epochs.iter().filter(|e| e.flag.is_event()).collect();
    assert_eq!((epochs.len(), events.len()), (123, 3));
    assert!(
        events
            .iter()
            .all(|e| e.flag == EpochFlag::HeaderRecords && !e.time_given)
    );
    assert!(events[0].records[0].starts_with("RINEX FILE SPLICE"));
    // Its receiver's clock is not steered: 00:48:00.004.
    let spliced = epochs
        .iter()
        .find(|e| e.time.to_string().starts_with("2005-04-02 00:48"))
        .expect("00:48");
    assert_eq!(spliced.sow, 518_400.0 + 48.0 * 60.0 + 0.004);
    let e = &epochs[0];
    // 2005-04-02 is the Saturday of GPS week 1316.
    assert_eq!(
        (e.week, e.sow, e.flag, e.len()),
        (1316, 518_400.0, EpochFlag::Ok, 8)
    );
    assert_eq!(e.time.to_string(), "2005-04-02 00:00:00");
    // `  55923622.160    24767686.375    43647388.2424   24767684.8224`
    let g03 = e.sat(Sat::new(System::Gps, 3)).expect("G03");
    assert_eq!(g03.get(code("L1C")).expect("L1").value, 55_923_622.160);
    assert_eq!(g03.get(code("C1C")).expect("C1").value, 24_767_686.375);
    let l2 = g03.get(code("L2W")).expect("L2");
    assert_eq!((l2.value, l2.lli, l2.ssi), (43_647_388.242, Some(4), None));
    assert_eq!(g03.get(code("C2W")).expect("P2").value, 24_767_684.822);
    let g28 = e.sat(Sat::new(System::Gps, 28)).expect("G28");
    assert_eq!(g28.get(code("L1C")).expect("L1").value, -5_448_227.324);
    let data: Vec<&Epoch> = epochs.iter().filter(|e| !e.flag.is_event()).collect();
    assert!(
        data.windows(2)
            .all(|w| (w[1].week, w[1].sow) > (w[0].week, w[0].sow))
    );
    assert!(epochs.iter().all(|e| e.clock_offset.is_none()));
}

#[test]
fn epn_station_acor_rinex_3_04() {
    let (r, epochs) = read("ACOR00ESP_R_20213550000_01D_30S_MO.rnx.gz");
    let h = r.header();
    assert_eq!(h.version, Version { major: 3, minor: 4 });
    assert_eq!(h.marker_name, "ACOR");
    assert_eq!(h.antenna_delta.expect("delta").height, 3.046);
    assert_eq!(h.codes_of(System::Galileo).len(), 15);
    assert_eq!(h.codes_of(System::BeiDou)[0], code("C2I"));
    assert_eq!(h.leap_seconds, Some(18));
    assert_eq!(h.glonass_channels.len(), 22);
    assert_eq!(h.glonass_channels[1], (2, -4));
    assert_eq!(epochs.len(), 25);
    let e = &epochs[0];
    // 2021-12-21, a Tuesday: day 2 of GPS week 2189.
    assert_eq!((e.week, e.sow, e.len()), (2189, 172_800.0, 38));
    // `G01  24600158.420   129274705.78406        38.300 ...`
    let g01 = e.sat(Sat::new(System::Gps, 1)).expect("G01");
    assert_eq!(g01.get(code("C1C")).expect("C1C").value, 24_600_158.420);
    let l1 = g01.get(code("L1C")).expect("L1C");
    assert_eq!(
        (l1.value, l1.lli, l1.ssi),
        (129_274_705.784, Some(0), Some(6))
    );
    assert_eq!(g01.get(code("S1C")).expect("S1C").value, 38.3);
    // G16 lacks its L2S triple: `G16  21389146.080   112400729.55108        50.950` + blanks.
    let g16 = e.sat(Sat::new(System::Gps, 16)).expect("G16");
    assert_eq!(g16.get(code("C2S")), None);
    assert_eq!(g16.get(code("C2W")).expect("C2W").value, 21_389_145.280);
    assert_eq!(
        e.sats().filter(|s| s.sat.system == System::BeiDou).count(),
        14
    );
    assert_eq!(epochs[24].sow - epochs[0].sow, 24.0 * 30.0);
}

/// Each compressed file reads to the same header and epochs as its twin.
#[test]
fn hatanaka_files_read_as_their_uncompressed_twins() {
    for (plain, compact, count) in [
        ("AJAC3550.21o.gz", "AJAC3550.21d.gz", 2),
        ("wsra0010.21o.gz", "wsra0010.21d.gz", 0),
        (
            "ACOR00ESP_R_20213550000_01D_30S_MO.rnx.gz",
            "ACOR00ESP_R_20213550000_01D_30S_MO.crx.gz",
            25,
        ),
        ("VLNS0010.22o.gz", "VLNS0010.22d.gz", 3),
    ] {
        let (rp, ep) = read(plain);
        let (rc, ec) = read(compact);
        assert!(
            !ep.is_empty() && (count == 0 || ep.len() == count),
            "{plain}: {}",
            ep.len()
        );
        assert_eq!(ep, ec, "{compact}");
        let mut hc = rc.header().clone();
        assert_eq!(
            hc.crinex.map(|v| v.major),
            Some(if rp.header().version.major == 2 { 1 } else { 3 })
        );
        hc.crinex = None;
        assert_eq!(rp.header(), &hc, "{compact}");
    }
}

#[test]
fn clock_offsets_and_mixed_rinex_2() {
    // VLNS writes a (zero) receiver clock offset on every epoch line.
    let (_, epochs) = read("VLNS0010.22d.gz");
    assert!(epochs.iter().all(|e| e.clock_offset == Some(0.0)));
    // AJAC: RINEX 2.11 with 22 types (five lines a satellite), GPS, GLONASS, Galileo
    // and SBAS: ` 131857102.133 6 102745756.54245  25091572.300` for G07.
    let (r, epochs) = read("AJAC3550.21d.gz");
    assert_eq!(r.header().rinex2_codes.len(), 22);
    let e = &epochs[0];
    assert_eq!(e.len(), 26);
    let g07 = e.sat(Sat::new(System::Gps, 7)).expect("G07");
    let l2 = g07.get(code("L2W")).expect("L2");
    assert_eq!(
        (l2.value, l2.lli, l2.ssi),
        (102_745_756.542, Some(4), Some(5))
    );
    assert_eq!(g07.get(code("C1C")).expect("C1").value, 25_091_572.3);
    assert_eq!(g07.get(code("D1C")).expect("D1").value, -411.138);
    assert!(e.sat(Sat::new(System::Sbas, 36)).is_some());
    assert!(e.sat(Sat::new(System::Galileo, 33)).is_some());
}
