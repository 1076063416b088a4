//! Criterion benchmark of the ROS 1 bag reader (issue 32: reading at 50 MB/s or more):
//! every message of a bag read through [`BagStream`] and each IMU message decoded to
//! its stamp, rate and specific force (what `nav --bag`'s second pass does), from the
//! page cache:
//! - `rosbag_bz2`: robot_localization's test2.bag (534 kB, rosbag's own bz2 chunks);
//! - `none`, `bz2`, `lz4`: its first 5 s as rosbags wrote them in 16-KiB chunks (the
//!   uncompressed one, 308 kB, written from its `.xz` to a temporary directory first).
//!
//! Throughput is the file's bytes per second.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler_io::bag::container::BagStream;
use schuler_io::bag::messages::{Decode, Encoding, ImuMotion};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ros1_bag")
        .join(name)
}

/// Reads `path` to the end; the IMU messages decoded.
fn read(path: &Path) -> usize {
    let mut stream = BagStream::open(path).expect("open");
    let mut imu = 0;
    while let Some(()) = stream
        .next_with(|m| {
            if m.topic.type_name == "sensor_msgs/Imu" {
                let x = ImuMotion::decode_in(Encoding::Ros1, m.data).expect("imu");
                imu += usize::from(x.angular_velocity[0].is_finite());
            }
            Ok(())
        })
        .expect("read")
    {}
    imu
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("tempdir");
    let none = dir.path().join("test2_first5s_none.bag");
    let mut xz = std::io::BufReader::new(
        std::fs::File::open(data("test2_first5s_none.bag.xz")).expect("open .xz"),
    );
    let mut bytes = Vec::new();
    lzma_rs::xz_decompress(&mut xz, &mut bytes).expect("xz");
    std::fs::write(&none, bytes).expect("write");
    let mut g = c.benchmark_group("ros1_bag");
    for (name, path) in [
        ("rosbag_bz2", data("test2.bag")),
        ("none", none),
        ("bz2", data("test2_first5s_bz2.bag")),
        ("lz4", data("test2_first5s_lz4.bag")),
    ] {
        let size = std::fs::metadata(&path).expect("size").len();
        g.throughput(Throughput::Bytes(size));
        g.bench_function(name, |b| b.iter(|| read(&path)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
