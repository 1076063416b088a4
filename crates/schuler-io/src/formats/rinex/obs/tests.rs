//! The observation reader on texts written here: every record layout, event and error.

use super::*;
use proptest::prelude::*;
use schuler::gnss::System;

const PATH: &str = "t.obs";

/// A header line: `content` in columns 1–60, `label` after.
fn h(content: &str, label: &str) -> String {
    format!("{content:<60}{label}\n")
}

/// RINEX 2 observation fields: 16 columns each (F14.3, LLI, SSI), five a line.
fn v2_obs(values: &[Option<(f64, char, char)>]) -> String {
    let mut out = String::new();
    for chunk in values.chunks(5) {
        let mut line = String::new();
        for v in chunk {
            match v {
                Some((x, lli, ssi)) => line += &format!("{x:14.3}{lli}{ssi}"),
                None => line += &" ".repeat(16),
            }
        }
        out += line.trim_end();
        out.push('\n');
    }
    out
}

fn v2_header(types: &str) -> String {
    h(
        "     2.11           OBSERVATION DATA    M (MIXED)",
        "RINEX VERSION / TYPE",
    ) + &h("TEST", "MARKER NAME")
        + &h(types, "# / TYPES OF OBSERV")
        + &h("    18", "LEAP SECONDS")
        + &h(
            "  2021    12    21     0     0    0.0000000     GPS",
            "TIME OF FIRST OBS",
        )
        + &h("", "END OF HEADER")
}

fn read_all(text: &str) -> Result<Vec<Epoch>, InputError> {
    ObsReader::new(text.as_bytes(), Path::new(PATH))?.collect()
}

fn code(s: &str) -> ObsCode {
    ObsCode::new(s).expect("code")
}

/// Fourteen satellites (a continuation line), a clock offset, six types (two lines
/// per satellite), a blank field and indicators.
fn v2_epoch(second: u32, flag: u8) -> String {
    let sats: Vec<String> = (1..=13)
        .map(|p| format!("G{p:02}"))
        .chain(["R07".into()])
        .collect();
    let mut text = format!(
        " 21 12 21  0  0{:>11.7}  {flag} 14{}{:>12.9}\n",
        f64::from(second),
        sats[..12].concat(),
        -0.000123456
    );
    text += &format!("{}{}\n", " ".repeat(32), sats[12..].concat());
    for (i, _) in sats.iter().enumerate() {
        let x = 20_000_000.0 + 1000.0 * i as f64 + f64::from(second);
        text += &v2_obs(&[
            Some((x, ' ', '7')),
            Some((x * 5.25, '1', '6')),
            None,
            Some((-411.138, ' ', ' ')),
            Some((45.25, ' ', ' ')),
            Some((x + 2.5, ' ', ' ')),
        ]);
    }
    text
}

#[test]
fn rinex2_epochs_with_continuations_clock_and_indicators() {
    let text = v2_header("     6    C1    L1    L2    D1    S1    P2")
        + &v2_epoch(0, 0)
        + &v2_epoch(30, 1);
    let epochs = read_all(&text).unwrap();
    assert_eq!(epochs.len(), 2);
    let e = &epochs[0];
    assert_eq!(
        (e.len(), e.flag, e.clock_offset),
        (14, EpochFlag::Ok, Some(-0.000123456))
    );
    assert_eq!((e.week, e.sow), (2189, 2.0 * 86400.0));
    let g13 = e.sat(Sat::new(System::Gps, 13)).unwrap();
    assert_eq!(g13.get(code("C1C")).unwrap().value, 20_012_000.0);
    let l1 = g13.get(code("L1C")).unwrap();
    assert_eq!(
        (l1.value, l1.lli, l1.ssi),
        (20_012_000.0 * 5.25, Some(1), Some(6))
    );
    assert_eq!(g13.get(code("L2W")), None, "a blank field is missing");
    assert_eq!(g13.get(code("D1C")).unwrap().value, -411.138);
    assert_eq!(g13.get(code("C2W")).unwrap().value, 20_012_002.5);
    assert_eq!(g13.obs.len(), 5);
    let r07 = e.sat(Sat::new(System::Glonass, 7)).unwrap();
    assert_eq!(r07.get(code("C2P")).unwrap().value, 20_013_002.5);
    assert_eq!(
        r07.first(ObsKind::Pseudorange, 1, "PC").unwrap().0,
        code("C1C")
    );
    assert_eq!(epochs[1].flag, EpochFlag::PowerFailure);
    assert_eq!(epochs[1].sow - e.sow, 30.0);
}

#[test]
fn events_carry_their_records_and_update_the_header() {
    let mut text = v2_header("     6    C1    L1    L2    D1    S1    P2") + &v2_epoch(0, 0);
    // A flag 4 event without a time: new observation types and a new marker.
    text += &format!("{:28}4  2\n", "");
    text += &h("     2    C1    P1", "# / TYPES OF OBSERV");
    text += &h("NEWNAME", "MARKER NAME");
    // A flag 5 event with its own time, then an epoch of the new types.
    text += " 21 12 21  0  0 15.0000000  5  0\n";
    text += " 21 12 21  0  0 30.0000000  0  1G05\n";
    text += &v2_obs(&[
        Some((21_000_000.0, ' ', ' ')),
        Some((21_000_001.0, ' ', ' ')),
    ]);
    // Cycle slips: values are slip counts.
    text += " 21 12 21  0  0 30.0000000  6  1G05\n";
    text += &v2_obs(&[Some((1.0, ' ', ' '))]);
    let mut r = ObsReader::new(text.as_bytes(), Path::new(PATH)).unwrap();
    let first = r.next().unwrap().unwrap();
    let event = r.next().unwrap().unwrap();
    assert_eq!(event.flag, EpochFlag::HeaderRecords);
    assert!(!event.time_given && event.is_empty());
    assert_eq!((event.week, event.sow), (first.week, first.sow));
    assert_eq!(event.records.len(), 2);
    assert_eq!(r.header().marker_name, "NEWNAME");
    assert_eq!(r.header().rinex2_codes, ["C1", "P1"]);
    let external = r.next().unwrap().unwrap();
    assert_eq!(
        (external.flag, external.time_given),
        (EpochFlag::ExternalEvent, true)
    );
    assert_eq!(external.sow - first.sow, 15.0);
    let e = r.next().unwrap().unwrap();
    let g05 = e.sat(Sat::new(System::Gps, 5)).unwrap();
    assert_eq!(g05.get(code("C1W")).unwrap().value, 21_000_001.0);
    assert_eq!(e.codes.of(System::Gps).len(), 2);
    let slips = r.next().unwrap().unwrap();
    assert_eq!(slips.flag, EpochFlag::CycleSlips);
    assert!(!slips.flag.has_measurements());
    assert!(r.next().is_none());
}

fn v3_header(version: &str) -> String {
    h(
        &format!("{version:>9}           OBSERVATION DATA    M"),
        "RINEX VERSION / TYPE",
    ) + &h(
        "  4594489.8680  -678367.9920  4357065.8700",
        "APPROX POSITION XYZ",
    ) + &h("G    4 C1C L1C D1C S1C", "SYS / # / OBS TYPES")
        + &h("E    2 C1C C5Q", "SYS / # / OBS TYPES")
        + &h("C    1 C2I", "SYS / # / OBS TYPES")
        + &h(
            "  2024     1     1     0     0    0.0000000     BDT",
            "TIME OF FIRST OBS",
        )
        + &h("", "END OF HEADER")
}

fn v3_epoch(second: u32, clock: bool) -> String {
    let clock = if clock {
        format!("{:6}{:15.12}", "", 0.000000123456)
    } else {
        String::new()
    };
    format!(
        "> 2024 01 01 00 00{:>11.7}  0  3{clock}\n",
        f64::from(second)
    ) + "G05  22000000.125 7 115600000.12345     -1234.567          45.000\n"
        + "E11  23000000.500                              \n"
        + "C30  24000000.750  \n"
}

#[test]
fn rinex3_and_4_epochs() {
    for version in ["3.05", "4.01"] {
        let text = v3_header(version) + &v3_epoch(0, true) + &v3_epoch(1, false);
        let epochs = read_all(&text).unwrap();
        assert_eq!(epochs.len(), 2);
        let e = &epochs[0];
        assert_eq!(e.clock_offset, Some(0.000000123456));
        // 2024-01-01 00:00:00 BDT is 00:00:14 GPST, a Monday: day 1 of week 2295.
        assert_eq!((e.week, e.sow), (2295, 86_400.0 + 14.0));
        let g05 = e.sat(Sat::new(System::Gps, 5)).unwrap();
        let l1 = g05.get(code("L1C")).unwrap();
        assert_eq!(
            (l1.value, l1.lli, l1.ssi),
            (115_600_000.123, Some(4), Some(5))
        );
        assert_eq!(g05.get(code("D1C")).unwrap().value, -1234.567);
        assert_eq!(
            g05.first(ObsKind::SignalStrength, 1, "C").unwrap().1.value,
            45.0
        );
        assert_eq!(g05.iter().count(), 4);
        let e11 = e.sat(Sat::new(System::Galileo, 11)).unwrap();
        assert_eq!((e11.obs.len(), e11.code(&e11.obs[0])), (1, code("C1C")));
        assert_eq!(
            e.sat(Sat::new(System::BeiDou, 30)).unwrap().obs[0].value,
            24_000_000.75
        );
        assert_eq!(epochs[1].clock_offset, None);
    }
}

#[test]
fn errors_name_the_line_and_field() {
    let header = v3_header("3.04");
    let lines_before = header.lines().count() as u64;
    // A garbled number: the field is the code.
    let text = header.clone() + &v3_epoch(0, false).replace("-1234.567", "-12x4.567");
    let e = read_all(&text).unwrap_err();
    assert_eq!(
        (e.line, e.field.as_deref()),
        (lines_before + 2, Some("D1C"))
    );
    assert_eq!(e.kind, InputErrorKind::NotANumber);
    // A truncated epoch: the next one starts early, or the file ends.
    let short: String = v3_epoch(0, false)
        .lines()
        .take(3)
        .map(|l| l.to_owned() + "\n")
        .collect();
    let e = read_all(&(header.clone() + &short + &v3_epoch(1, false))).unwrap_err();
    assert_eq!(
        (e.line, e.field.as_deref()),
        (lines_before + 1, Some("epoch"))
    );
    assert!(e.message.contains("truncated epoch"), "{e}");
    let e = read_all(&(header.clone() + &short)).unwrap_err();
    assert!(e.message.contains("the file ends after 2"), "{e}");
    // Time going backwards.
    let e = read_all(&(header.clone() + &v3_epoch(5, false) + &v3_epoch(4, false))).unwrap_err();
    assert_eq!(
        (e.kind, e.line),
        (InputErrorKind::TimeNotIncreasing, lines_before + 5)
    );
    // A satellite of a system without types; a bad satellite; a bad epoch flag.
    let e = read_all(&(header.clone() + &v3_epoch(0, false).replace("C30", "R01"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("satellite"));
    let e = read_all(&(header.clone() + &v3_epoch(0, false).replace("C30", "Q30"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("satellite"));
    let e =
        read_all(&(header.clone() + &v3_epoch(0, false).replace("  0  3", "  9  3"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("epoch"));
    let e = read_all(&(header.clone() + &v3_epoch(0, false).replace(" 7 1", " x 1"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("C1C"), "the SSI of C1C");
    // Too many satellites for the bound.
    let e = read_all(&(header.clone() + "> 2024 01 01 00 00  0.0000000  0999\n")).unwrap_err();
    assert_eq!(e.kind, InputErrorKind::OutOfDomain);
    // RINEX 2: a garbled value names RINEX 2's code; a missing satellite block runs
    // into the next epoch.
    let v2 = v2_header("     6    C1    L1    L2    D1    S1    P2");
    let e = read_all(&(v2.clone() + &v2_epoch(0, 0).replace("-411.138", "-411.1.8"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("D1"));
    let mut short = v2_epoch(0, 0);
    short.truncate(short.len() - 60);
    let short: String = short
        .lines()
        .take(20)
        .map(|l| l.to_owned() + "\n")
        .collect();
    let e = read_all(&(v2.clone() + &short + &v2_epoch(30, 0))).unwrap_err();
    assert!(e.message.contains("truncated epoch"), "{e}");
    // An unsupported version, an unknown code, no header end, an empty file.
    let e = read_all(&v3_header("3.04").replace("3.04", "9.01")).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("RINEX VERSION / TYPE"));
    let e = read_all(&v3_header("3.04").replace("C5Q", "C5?")).unwrap_err();
    assert_eq!((e.line, e.field.as_deref()), (4, Some("C5?")));
    let e = read_all(&header[..header.len() - 81]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("END OF HEADER"));
    assert_eq!(read_all("").unwrap_err().kind, InputErrorKind::NoData);
    // After an error the reader stops.
    let mut r = ObsReader::new(text.as_bytes(), Path::new(PATH)).unwrap();
    assert!(r.next().unwrap().is_err());
    assert!(r.next().is_none());
}

#[test]
fn glonass_time_and_scale_factors() {
    let text = h(
        "     3.04           OBSERVATION DATA    R",
        "RINEX VERSION / TYPE",
    ) + &h("R    2 C1C S1C", "SYS / # / OBS TYPES")
        + &h("R   10   1 S1C", "SYS / SCALE FACTOR")
        + &h("    18", "LEAP SECONDS")
        + &h("", "END OF HEADER")
        + "> 2024 01 01 03 00  0.0000000  0  1\n"
        + "R01  21000000.000           452.000\n";
    let e = &read_all(&text).unwrap()[0];
    // GLONASS time 03:00 is 00:00 UTC, 00:00:18 GPST.
    assert_eq!((e.week, e.sow), (2295, 86_400.0 + 18.0));
    let r01 = e.sat(Sat::new(System::Glonass, 1)).unwrap();
    assert_eq!(r01.get(code("S1C")).unwrap().value, 45.2);
    assert_eq!(r01.get(code("C1C")).unwrap().value, 21_000_000.0);
}

/// A valid RINEX 2, RINEX 3 and compact RINEX 3 text, the seeds of the mutation test.
fn samples() -> [String; 3] {
    let crx = h(
        "3.0                 COMPACT RINEX FORMAT",
        "CRINEX VERS   / TYPE",
    ) + &h("hand-written", "CRINEX PROG / DATE")
        + &h(
            "     3.04           OBSERVATION DATA    M",
            "RINEX VERSION / TYPE",
        )
        + &h("G    3 C1C L1C S1C", "SYS / # / OBS TYPES")
        + &h("E    1 C1C", "SYS / # / OBS TYPES")
        + &h("", "END OF HEADER")
        + "> 2024 01 01 00 00  0.0000000  0  2      G05E11\n2&123456\n"
        + "3&22000000125 3&115600000123 3&45000 &745\n3&23000000500\n"
        + "                    1\n100\n1000 2000 -250  1&&\n-500\n";
    [
        v2_header("     6    C1    L1    L2    D1    S1    P2")
            + &v2_epoch(0, 0)
            + &v2_epoch(30, 0),
        v3_header("3.04") + &v3_epoch(0, true) + &v3_epoch(1, false),
        crx,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..3000)) {
        if let Ok(r) = ObsReader::new(&bytes[..], Path::new(PATH)) {
            for e in r.flatten() {
                prop_assert!(e.len() <= MAX_SATS_PER_EPOCH);
            }
        }
    }

    #[test]
    fn damaged_files_never_panic(
        which in 0..3usize,
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        tail in proptest::collection::vec(any::<u8>(), 0..200),
    ) {
        let mut bytes = samples()[which].clone().into_bytes();
        for (i, b) in edits {
            let i = i.index(bytes.len());
            bytes[i] = b;
        }
        bytes.extend_from_slice(&tail);
        if let Ok(r) = ObsReader::new(&bytes[..], Path::new(PATH)) {
            for e in r.flatten() {
                prop_assert!(e.len() <= MAX_SATS_PER_EPOCH);
            }
        }
    }
}
