//! Criterion benchmark of the RINEX observation reader (issue 31: parsing at 50 MB/s or
//! more): a day of 30-s epochs made by repeating the epochs of tests/data/rinex_obs with
//! new times, held in memory and read to the last observation.
//! - `rinex3_day`: ACOR's 25 RINEX 3.04 epochs (38 satellites of four systems, 9 to 15
//!   types) repeated to 2,880 epochs, 17 MB;
//! - `rinex2_day`: WSRA's RINEX 2.11 epochs (21 satellites, 7 types on two lines,
//!   continuation lines) repeated to 2,880 epochs;
//! - `crx3`: ACOR's compact RINEX repeated over 28 days (the reader expands it to
//!   RINEX text and parses that).
//!
//! `RINEX_OBS_BENCH_WRITE=DIR` also writes the three texts into DIR (to time other
//! readers on the same bytes).

use chrono::{Datelike, NaiveDate, NaiveDateTime, TimeDelta, Timelike};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_io::formats::rinex::obs::{Epoch, ObsReader};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Epochs in a day at 30 s.
const EPOCHS: usize = 2880;

fn data(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/rinex_obs")
        .join(name);
    let file = std::fs::File::open(&path).expect("test data");
    let mut text = String::new();
    flate2::read::GzDecoder::new(file)
        .read_to_string(&mut text)
        .expect("gzip text");
    text
}

/// The header (through `END OF HEADER`) and the epochs (each its lines) of `text`,
/// an epoch starting at each line `starts` accepts.
fn split(text: &str, starts: impl Fn(&str) -> bool) -> (String, Vec<Vec<&str>>) {
    let mut lines = text.lines();
    let mut header = String::new();
    for l in lines.by_ref() {
        header += l;
        header.push('\n');
        if l.contains("END OF HEADER") {
            break;
        }
    }
    let mut epochs: Vec<Vec<&str>> = Vec::new();
    for l in lines {
        if starts(l) || epochs.is_empty() {
            epochs.push(Vec::new());
        }
        if let Some(e) = epochs.last_mut() {
            e.push(l);
        }
    }
    (header, epochs)
}

fn start() -> NaiveDateTime {
    NaiveDate::from_ymd_opt(2021, 12, 21)
        .and_then(|d| d.and_hms_opt(0, 0, 0))
        .expect("date")
}

fn rinex3_day() -> String {
    let text = data("ACOR00ESP_R_20213550000_01D_30S_MO.rnx.gz");
    let (mut out, epochs) = split(&text, |l| l.starts_with('>'));
    for k in 0..EPOCHS {
        let e = &epochs[k % epochs.len()];
        let t = start() + TimeDelta::seconds(30 * k as i64);
        out += &format!(
            "> {} {:02} {:02} {:02} {:02} {:02}.0000000{}\n",
            t.year(),
            t.month(),
            t.day(),
            t.hour(),
            t.minute(),
            t.second(),
            &e[0][29..]
        );
        for l in &e[1..] {
            out += l;
            out.push('\n');
        }
    }
    out
}

fn rinex2_day() -> String {
    let text = data("wsra0010.21o.gz");
    // An epoch line: ` yy mm dd hh mm ss.sssssss  f` (a satellite line starts otherwise).
    let (mut out, epochs) = split(&text, |l| {
        l.len() > 29
            && &l[26..28] == "  "
            && &l[0..1] == " "
            && &l[3..4] == " "
            && l.as_bytes()[18] == b'.'
    });
    for k in 0..EPOCHS {
        let e = &epochs[k % epochs.len()];
        let t = start() + TimeDelta::seconds(30 * k as i64);
        out += &format!(
            " {:02} {:2} {:2} {:2} {:2} {:2}.0000000{}\n",
            t.year() % 100,
            t.month(),
            t.day(),
            t.hour(),
            t.minute(),
            t.second(),
            &e[0][26..]
        );
        for l in &e[1..] {
            out += l;
            out.push('\n');
        }
    }
    out
}

fn crx3_days() -> String {
    let text = data("ACOR00ESP_R_20213550000_01D_30S_MO.crx.gz");
    let (mut out, epochs) = split(&text, |l| l.starts_with('>'));
    // Every epoch after the first is a difference of the line before: each repetition
    // begins with the whole first line, a day later.
    let body: Vec<&str> = epochs.concat();
    for day in 0..28 {
        let t = start() + TimeDelta::days(day);
        for (i, l) in body.iter().enumerate() {
            if i == 0 {
                out += &format!(
                    "> {} {:02} {:02}{}\n",
                    t.year(),
                    t.month(),
                    t.day(),
                    &l[12..]
                );
            } else {
                out += l;
                out.push('\n');
            }
        }
    }
    out
}

/// Reads every epoch of `text`; the number of observations.
fn read(text: &[u8]) -> usize {
    let mut r = ObsReader::new(text, Path::new("bench.rnx")).expect("header");
    let mut epoch = Epoch::default();
    let mut n = 0;
    while r.read_epoch(&mut epoch).expect("epoch") {
        n += epoch.sats().map(|s| s.obs.len()).sum::<usize>();
    }
    n
}

fn bench_rinex_obs(c: &mut Criterion) {
    let cases = [
        ("rinex3_day", rinex3_day()),
        ("rinex2_day", rinex2_day()),
        ("crx3", crx3_days()),
    ];
    if let Some(dir) = std::env::var_os("RINEX_OBS_BENCH_WRITE") {
        for (name, text) in &cases {
            std::fs::write(Path::new(&dir).join(format!("{name}.txt")), text).expect("write");
        }
    }
    let mut group = c.benchmark_group("rinex_obs");
    group.sample_size(10);
    for (name, text) in &cases {
        let n = read(text.as_bytes());
        assert!(n > 0);
        eprintln!("{name}: {} bytes, {n} observations", text.len());
        group.throughput(Throughput::Bytes(text.len() as u64));
        group.bench_function(*name, |b| {
            b.iter(|| read(std::hint::black_box(text.as_bytes())))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_rinex_obs);
criterion_main!(benches);
