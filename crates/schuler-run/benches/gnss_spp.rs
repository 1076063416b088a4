//! Criterion benchmark of `schuler gnss` (issue 31; docs/validation/gnss_spp.md): the
//! whole run of [`schuler_run::gnss::run`] — the navigation files read, the observation
//! file streamed, every epoch solved, `nav.txt`, `nav.csv`, `solution.pos` and
//! `satellites.csv` written — on the public stations of `tests/data/rinex_obs` that have
//! navigation data, with the settings of `crates/schuler-cli/tests/gnss_stations.rs`
//! (GPS, mask 10°, Klobuchar, Saastamoinen, FDE). Throughput is in epochs, so criterion
//! prints epochs per second.
//!
//! `cargo bench -p schuler-run --bench gnss_spp`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_run::gnss::{Args, run};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/rinex_obs")
        .join(name)
}

fn bench_gnss_spp(c: &mut Criterion) {
    let out = tempfile::tempdir().expect("tempdir");
    let cases = [
        ("0759", "07590920.05o.gz", "07590920.05n.gz"),
        ("WSRA", "wsra0010.21o.gz", "brdc0010.21n.gz"),
        ("VLNS", "VLNS0010.22o.gz", "brdc0010.22n.gz"),
    ];
    let mut group = c.benchmark_group("gnss_spp");
    group.sample_size(20);
    for (name, obs, nav) in cases {
        let args = Args {
            gnss_obs: data(obs),
            gnss_nav: vec![data(nav)],
            out: out.path().join(name),
            elevation_mask: 10.0,
            no_iono: false,
            no_tropo: false,
            systems: vec!['G'],
        };
        let summary = run(&args).expect("schuler gnss runs");
        assert_eq!(summary.solved, summary.epochs, "{name}: every epoch solves");
        group.throughput(Throughput::Elements(summary.epochs));
        group.bench_function(name, |b| b.iter(|| run(std::hint::black_box(&args))));
    }
    group.finish();
}

criterion_group!(benches, bench_gnss_spp);
criterion_main!(benches);
