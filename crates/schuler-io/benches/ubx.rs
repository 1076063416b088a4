//! Criterion benchmark of the UBX reader (issue 32: binary formats read at 50 MB/s or
//! more), on the committed logs held in memory and read to the last record:
//! - `rover_rawx_sfrbx`: the ZED-F9P log (NAV-PVT at 8 Hz, RXM-SFRBX, RXM-RAWX and
//!   the NMEA sentences of the same port; 300 kB) repeated 20 times, 6 MB;
//! - `f9_esf`: the dead-reckoning receiver's log (ESF-RAW at 100 Hz, ESF-MEAS, HNR,
//!   NAV-ATT, RAWX; its truncated last frame dropped) repeated 40 times, 6.4 MB.
//!
//! Repeating a log repeats its times: the reader does not require increasing times
//! across messages (the IMU streams restart at a tag that goes back), so the copies
//! are read as a long log would be.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_io::logs::ubx::{UbxOptions, UbxReader};
use std::io::Read;
use std::path::{Path, PathBuf};

fn data(name: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ubx")
        .join(name);
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(std::fs::File::open(path).expect("test data"))
        .read_to_end(&mut out)
        .expect("gzip");
    out
}

/// Reads `bytes` to the end; the number of records.
fn read_all(bytes: &[u8]) -> usize {
    let input = Box::new(std::io::Cursor::new(bytes.to_vec()));
    let reader = UbxReader::new(
        Path::new("bench.ubx"),
        input,
        bytes.len() as u64,
        UbxOptions::default(),
    );
    let mut n = 0;
    for item in reader {
        item.expect("valid log");
        n += 1;
    }
    n
}

fn bench(c: &mut Criterion) {
    let rover = data("f9p_rover_rawx_sfrbx.ubx.gz").repeat(20);
    let mut f9 = data("f9_esf_nav_att_truncated.ubx.gz");
    // Drop the truncated last frame so that the copies stay aligned on frames.
    let last = f9
        .windows(2)
        .rposition(|w| w == [0xB5, 0x62])
        .expect("frames");
    f9.truncate(last);
    let f9 = f9.repeat(40);
    let mut g = c.benchmark_group("ubx");
    for (name, bytes) in [("rover_rawx_sfrbx", &rover), ("f9_esf", &f9)] {
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(name, |b| b.iter(|| read_all(bytes)));
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
