//! Criterion benchmark of the ArduPilot DataFlash reader (issue 32: binary formats read
//! at 50 MB/s or more): the committed logs of tests/data/dataflash, gunzipped and
//! repeated into a temporary file (so the page cache holds it) and read to the last
//! record, the pass ahead for the GPS tie included; throughput in bytes of the plain
//! log.
//! - `synthetic`: `synthetic_circle.bin` (ArduPilot 4.5 layouts, two IMUs at 100 Hz;
//!   129 kB) repeated 40 times, 5.2 MB;
//! - `pymavlink_test`: pymavlink's `test.BIN` (ArduPlane 2017, 47 message types; its cut
//!   last message dropped, 65 512 bytes) repeated 80 times, 5.2 MB.
//!
//! Repeating a log repeats its FMT messages (redefinitions of the same formats) and its
//! times (each IMU stream restarts where its time goes back), so the copies read as
//! one long log.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_io::logs::dataflash::DataflashReader;
use std::io::Read;
use std::path::{Path, PathBuf};

fn repeated(dir: &Path, name: &str, keep: usize, times: usize) -> PathBuf {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/dataflash")
        .join(format!("{name}.bin.gz"));
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(&src).expect("test data"))
        .read_to_end(&mut bytes)
        .expect("gzip");
    bytes.truncate(keep);
    let path = dir.join(format!("{name}.bin"));
    std::fs::write(&path, bytes.repeat(times)).expect("write");
    path
}

fn read(path: &Path) -> usize {
    let mut n = 0;
    for item in DataflashReader::open(path).expect("opens") {
        item.expect("reads");
        n += 1;
    }
    n
}

fn bench_dataflash(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut group = c.benchmark_group("dataflash");
    group.sample_size(10);
    for (label, name, keep, times) in [
        ("synthetic", "synthetic_circle", usize::MAX, 40),
        ("pymavlink_test", "pymavlink_test", 65_512, 80),
    ] {
        let path = repeated(dir.path(), name, keep, times);
        let bytes = std::fs::metadata(&path).expect("size").len();
        group.throughput(Throughput::Bytes(bytes));
        group.bench_function(label, |b| b.iter(|| read(&path)));
    }
    group.finish();
}

criterion_group!(benches, bench_dataflash);
criterion_main!(benches);
