//! ROS 1 bags (format 2.0) through `schuler bag info` and `schuler nav --bag`, on
//! `tests/data/ros1_bag/`: robot_localization's `test2.bag` as rosbag recorded it
//! (bz2 chunks), and its first 5 s rewritten by the Python `rosbags` package in
//! uncompressed (kept xz-compressed here), bz2 and lz4 chunks of 16 KiB (provenance
//! in tests/data/ros1_bag/README.md).
//! The counts below are rosbags' (`Reader.connections[i].msgcount`), not ours.
//! Truncated and garbled bags are refused with the byte offset, record and field.

use crate::common;

use schuler_io::bag::container::BagStream;
use std::path::{Path, PathBuf};

fn data() -> PathBuf {
    common::test_data("ros1_bag")
}

fn stdout_of(a: &assert_cmd::assert::Assert) -> String {
    String::from_utf8_lossy(&a.get_output().stdout).into_owned()
}

/// The uncompressed copy of test2.bag's first 5 s, written into `dir` from its `.xz`.
fn uncompressed_copy(dir: &Path) -> PathBuf {
    let path = dir.join("test2_first5s_none.bag");
    std::fs::write(
        &path,
        common::unxz(&data().join("test2_first5s_none.bag.xz")),
    )
    .expect("write");
    path
}

/// Every message of `bag`: topic, type, index, log time, payload.
fn messages(bag: &Path) -> Vec<(String, String, u64, u64, Vec<u8>)> {
    let mut stream = BagStream::open(bag).expect("open");
    let mut out = Vec::new();
    while let Some(m) = stream
        .next_with(|m| {
            Ok((
                m.topic.name.clone(),
                m.topic.type_name.clone(),
                m.index,
                m.log_time,
                m.data.to_vec(),
            ))
        })
        .expect("read")
    {
        out.push(m);
    }
    out
}

/// rosbags counts 3061 IMU and 3060 odometry messages, from 47.58 s to 108.781 s
/// (simulation time: stamps before 1980 are read as they are); the IMU at 50 Hz.
#[test]
fn info_reads_robot_localizations_test2_bag() {
    let a = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["bag", "info"])
        .arg(data().join("test2.bag"))
        .assert()
        .success();
    let out = stdout_of(&a);
    assert!(out.contains(": 2 topics"), "{out}");
    let imu = out
        .lines()
        .find(|l| l.starts_with("/imu/data "))
        .expect("imu line");
    let fields: Vec<&str> = imu.split_whitespace().collect();
    assert_eq!(fields[1..3], ["sensor_msgs/Imu", "3061"], "{imu}");
    assert_eq!(fields[4], "47.580000000", "{imu}");
    assert_eq!(fields[5], "108.781000000", "{imu}");
    assert!(
        out.lines()
            .any(|l| l.starts_with("/jackal_velocity_controller/odom ")
                && l.contains("nav_msgs/Odometry")
                && l.contains(" 3060 ")),
        "{out}"
    );
    assert!(
        out.contains("nav --bag reads sensor_msgs/msg/Imu from /imu/data"),
        "{out}"
    );
    assert!(
        out.contains("nav --bag reads nav_msgs/msg/Odometry from /jackal_velocity_controller/odom"),
        "{out}"
    );
}

/// The uncompressed, bz2 and lz4 copies hold the first 501 messages of test2.bag
/// (itself in rosbag's 5 bz2 chunks), byte for byte, in 18 chunks each: read, they
/// give the original's topics, indices, log times and payloads.
#[test]
fn uncompressed_bz2_and_lz4_chunks_read_as_the_original() {
    let dir = tempfile::tempdir().expect("tempdir");
    let original = messages(&data().join("test2.bag"));
    assert_eq!(original.len(), 3061 + 3060);
    for path in [
        uncompressed_copy(dir.path()),
        data().join("test2_first5s_bz2.bag"),
        data().join("test2_first5s_lz4.bag"),
    ] {
        let got = messages(&path);
        assert_eq!(got.len(), 501, "{}", path.display());
        assert!(
            got == original[..501],
            "{}: messages differ",
            path.display()
        );
    }
}

/// `schuler nav --bag` on test2.bag (IMU and wheel odometry, no GNSS, no /tf_static):
/// the IMU's axes FLU, and 61 s of navigation written.
#[test]
fn nav_runs_on_test2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("nav")
        .arg("--bag")
        .arg(data().join("test2.bag"))
        .args([
            "--init-pos",
            "45,7,100",
            "--init-att",
            "0,0,0",
            "--no-report",
        ])
        .args(["--output-rate", "1", "--odometer-std", "0.1"])
        .arg("--out")
        .arg(dir.path())
        .assert()
        .success();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(err.contains("IMU axes FLU (REP 103)"), "{err}");
    assert!(err.contains("3060 odometer readings"), "{err}");
    let rows = common::read_rows(&dir.path().join("nav.txt"));
    assert!(rows.len() >= 60, "{} rows", rows.len());
}

/// The error of reading `bytes` as a bag.
fn refused(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write");
    let mut stream = match BagStream::open(&path) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    loop {
        match stream.next_with(|_| Ok(())) {
            Ok(Some(())) => {}
            Ok(None) => panic!("{name}: read to the end"),
            Err(e) => return e.to_string(),
        }
    }
}

/// The offset of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle)
        .expect("found")
}

#[test]
fn truncated_and_garbled_bags_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    // The uncompressed copy, so that the records inside a chunk are garbled where they
    // lie. Its layout, as rosbags wrote it: the magic line (13 bytes), the bag header
    // record padded to 4096 bytes, then the first chunk record at byte 4109 (header
    // `op`, `compression=none`, `size`; 41 bytes of header), whose records start at
    // byte 4158: the connection records of /imu/data (conn 0) and of the odometry
    // (conn 1), then message data records (`op=2`, `conn`, `time`).
    let bag = std::fs::read(uncompressed_copy(dir.path())).expect("bag");
    let chunk = 4109;
    let compression = find(&bag, b"compression=none");
    assert_eq!(
        compression,
        chunk + 16,
        "the first chunk's compression field"
    );
    // Cut inside the first chunk's data (16,920 bytes).
    let e = refused(dir.path(), "cut.bag", &bag[..chunk + 5000]);
    assert!(e.contains("chunk record's data"), "{e}");
    assert!(e.contains("truncated"), "{e}");
    // An unknown compression.
    let mut b = bag.clone();
    b[compression + 12..compression + 16].copy_from_slice(b"zstd");
    let e = refused(dir.path(), "zstd.bag", &b);
    assert!(
        e.contains(
            "zstd.bag: byte 4109 (chunk record): field compression: \"zstd\" is not none, \
             bz2 or lz4"
        ),
        "{e}"
    );
    // The first odometry message (a message data record, 6027 bytes into the chunk's
    // records) on connection 9, which no connection record defines.
    let mut b = bag.clone();
    let message = find(&b, b"op=\x02\x09\x00\x00\x00conn=\x01\x00\x00\x00");
    let record = message - 8; // its header_len and the op field's length
    assert_eq!(record, chunk + 49 + 6027, "the first odometry message");
    b[message + 13] = 9;
    let e = refused(dir.path(), "conn.bag", &b);
    assert!(
        e.contains(
            "conn.bag: chunk at byte 4109, byte 6027 of its records (message data record, \
             after message 1 of topic /imu/data): field conn: 9, which no connection record \
             before it defines"
        ),
        "{e}"
    );
    // Another version's magic.
    let mut b = bag.clone();
    b[9..12].copy_from_slice(b"1.2");
    let e = refused(dir.path(), "v12.bag", &b);
    assert!(
        e.contains("byte 0: magic") && e.contains("format 2.0"),
        "{e}"
    );
    // A bz2 chunk with its stream garbled.
    let mut b = std::fs::read(data().join("test2_first5s_bz2.bag")).expect("bz2");
    let at = find(&b, b"BZh9") + 100;
    b[at..at + 8].copy_from_slice(&[0xff; 8]);
    let e = refused(dir.path(), "bz2.bag", &b);
    assert!(
        e.contains("field data: bz2 stream") || e.contains("field size"),
        "{e}"
    );
}
