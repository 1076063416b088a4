//! Criterion benchmark of the PX4 ULog reader (issue 32: binary formats at 50 MB/s or
//! more): PX4/pyulog's test logs of tests/data/ulog, gunzipped into a temporary file
//! (so the page cache holds them) and read to the last record, the pass ahead for the
//! GPS tie included; throughput in bytes of the plain `.ulg`.
//! - `px4_events`: `sample_px4_events.ulg` (PX4 1.15 SITL, 1.6 MB; the tie found 1 s in);
//! - `log_small`: `sample_log_small.ulg` (a Cube Orange, 0.9 MB);
//! - `appended`: `sample_appended_multiple.ulg` (0.5 MB; no GNSS, so the pass ahead reads
//!   the whole file).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_io::logs::ulog::UlogReader;
use std::io::Read;
use std::path::{Path, PathBuf};

fn plain(dir: &Path, name: &str) -> PathBuf {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ulog")
        .join(format!("{name}.ulg.gz"));
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(&src).expect("test data"))
        .read_to_end(&mut bytes)
        .expect("gzip");
    let path = dir.join(format!("{name}.ulg"));
    std::fs::write(&path, bytes).expect("write");
    path
}

fn read(path: &Path) -> usize {
    let mut n = 0;
    for item in UlogReader::open(path).expect("opens") {
        item.expect("reads");
        n += 1;
    }
    n
}

fn bench_ulog(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut group = c.benchmark_group("ulog");
    group.sample_size(10);
    for (label, name) in [
        ("px4_events", "sample_px4_events"),
        ("log_small", "sample_log_small"),
        ("appended", "sample_appended_multiple"),
    ] {
        let path = plain(dir.path(), name);
        let bytes = std::fs::metadata(&path).expect("size").len();
        group.throughput(Throughput::Bytes(bytes));
        group.bench_function(label, |b| b.iter(|| read(&path)));
    }
    group.finish();
}

criterion_group!(benches, bench_ulog);
criterion_main!(benches);
