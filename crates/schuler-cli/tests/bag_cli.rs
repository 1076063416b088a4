//! `schuler bag info` and `schuler nav --bag` on `tests/data/ros2_bag/drive.mcap`, a
//! bag written by the Python `mcap` and `mcap-ros2-support` packages (not by us) from
//! `schuler simulate`'s logs of `scenario.toml` (provenance in tests/data/README.md);
//! `--out-bag` read back; malformed bags refused with the topic, message and field.

use crate::common;

use common::bag::{data, max_digits_apart, nav_bag, nav_text, simulate_scenario};
use mcap::records::MessageHeader;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use schuler_io::bag::container::BagStream;
use schuler_io::bag::messages::{
    Header, IMU, Imu, NAV_SAT_FIX, NavSatFix, Odometry, VECTOR3_STAMPED, definitions,
};
use std::collections::BTreeMap;
use std::path::Path;

fn stdout_of(a: &assert_cmd::assert::Assert) -> String {
    String::from_utf8_lossy(&a.get_output().stdout).into_owned()
}

fn stderr_of(a: &assert_cmd::assert::Assert) -> String {
    String::from_utf8_lossy(&a.get_output().stderr).into_owned()
}

/// The scenario's counts: 94.21 s at 100 Hz from t = 345600 (9422 samples), 1-Hz
/// fixes with the 11 s of 345660-345670 missing (84 fixes, 11 NO_FIX messages),
/// barometer and odometer at 10 Hz (943).
#[test]
fn info_lists_topics_counts_and_rates() {
    let a = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["bag", "info"])
        .arg(data().join("drive.mcap"))
        .assert()
        .success();
    let out = stdout_of(&a);
    for (topic, ty, count, rate) in [
        ("/imu/data", "sensor_msgs/msg/Imu", "9422", "100.000"),
        ("/gnss/fix", "sensor_msgs/msg/NavSatFix", "95", "1.000"),
        ("/baro", "sensor_msgs/msg/FluidPressure", "943", "10.000"),
        ("/odom", "nav_msgs/msg/Odometry", "943", "10.000"),
    ] {
        let line = out
            .lines()
            .find(|l| l.starts_with(topic))
            .unwrap_or_else(|| panic!("{topic} missing:\n{out}"));
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(&words[1..4], [ty, count, rate], "{line}");
    }
    assert!(out.contains("345600.000000000"), "{out}");
    assert!(
        out.contains("nav --bag reads geometry_msgs/msg/TwistWithCovarianceStamped from /gnss/vel"),
        "{out}"
    );
}

/// The bag's messages carry the text logs' numbers: rates `dθ/dt`, read back as
/// `ω·dt` with the same dt (a stamp's `sec + nanosec·1e-9` is the double nearest the
/// text's time: the sum is rounded once and `nanosec·1e-9` is within 1e-18 s of the
/// decimal), so each increment is within 1 ulp (2e-16 relative) of the text's; ENU
/// covariances and velocities swapped back exactly; the ISA pressure of each height
/// giving it back within 1e-10 m; the truth's speed as written. Both runs must then
/// print the same trajectory: every number of nav.txt within one unit of its last
/// digit (a rounding boundary between two values 1e-12 apart), the bound asserted.
/// The filter's bias estimates amplify the ulp differences (measured: 3e-12 relative
/// on a 673-mGal accelerometer bias), so imu_err.txt is held to 1e-10 relative.
#[test]
fn bag_gives_the_text_logs_trajectory() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate_scenario(dir.path());
    let (text, bag) = (dir.path().join("text"), dir.path().join("bag"));
    nav_text(&sim, &text).success();
    let a = nav_bag(&data().join("drive.mcap"), &bag, &[]).success();
    let err = stderr_of(&a);
    assert!(
        err.contains("84 GNSS fixes (11 NO_FIX skipped, 84 with velocity), 943 barometer, 943 odometer readings"),
        "{err}"
    );
    let digits = max_digits_apart(&text.join("nav.txt"), &bag.join("nav.txt"));
    assert!(digits <= 1.0, "{digits} units of the last digit apart");
    let out = stdout_of(&a);
    assert!(out.contains("84 GNSS fixes"), "{out}");
    // The filter saw the same measurements: the same sensor-error estimates.
    let (ea, eb) = (
        common::read_rows(&text.join("imu_err.txt")),
        common::read_rows(&bag.join("imu_err.txt")),
    );
    assert_eq!(ea.len(), eb.len());
    for (x, y) in ea.iter().zip(&eb) {
        for (u, v) in x.iter().zip(y) {
            assert!(
                (u - v).abs() <= 1.000_001e-9 + 1e-10 * u.abs(),
                "{x:?} / {y:?}"
            );
        }
    }
}

/// `--imu-axes FLU` is what a bag's IMU is without the flag (REP 103): the same bytes.
#[test]
fn imu_axes_default_to_flu() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bag = data().join("drive.mcap");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    nav_bag(&bag, &a, &["--gnss-topic", "none", "--end", "345630"]).success();
    nav_bag(
        &bag,
        &b,
        &[
            "--gnss-topic",
            "none",
            "--end",
            "345630",
            "--imu-axes",
            "FLU",
        ],
    )
    .success();
    assert_eq!(
        std::fs::read(a.join("nav.txt")).expect("a"),
        std::fs::read(b.join("nav.txt")).expect("b")
    );
}

/// Every bag flag is also a key of `nav --config` (paths relative to the file's
/// folder): the file's run writes the bytes of the flags' run, and a flag given beside
/// the file wins over its key.
#[test]
fn bag_flags_are_config_keys() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bag = data().join("drive.mcap");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let topics = [
        "--imu-topic",
        "/imu/data",
        "--gnss-topic",
        "/gnss/fix",
        "--gnss-vel-topic",
        "/gnss/vel",
        "--baro-topic",
        "/baro",
        "--odom-topic",
        "/odom",
        "--end",
        "345640",
    ];
    let a_bag = a.join("nav.mcap");
    let mut flags = topics.to_vec();
    flags.extend(["--out-bag", a_bag.to_str().expect("utf-8")]);
    nav_bag(&bag, &a, &flags).success();
    std::fs::create_dir_all(&b).expect("b");
    std::fs::copy(&bag, b.join("in.mcap")).expect("copy");
    std::fs::write(
        b.join("nav.toml"),
        "bag = \"in.mcap\"\nimu_topic = \"/imu/data\"\ngnss_topic = \"/gnss/fix\"\n\
         gnss_vel_topic = \"/gnss/vel\"\nbaro_topic = \"/nowhere\"\nodom_topic = \"/odom\"\n\
         out_bag = \"nav.mcap\"\nend = 345640\n",
    )
    .expect("nav.toml");
    // The flag beside the file wins: the barometer topic of the flags' run.
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--config"])
        .arg(b.join("nav.toml"))
        .args(["--baro-topic", "/baro"])
        .args(common::bag::COMMON)
        .arg("--out")
        .arg(&b)
        .assert()
        .success();
    for name in ["nav.txt", "std.txt", "imu_err.txt", "nav.mcap"] {
        assert_eq!(
            std::fs::read(a.join(name)).expect("a"),
            std::fs::read(b.join(name)).expect("b"),
            "{name}"
        );
    }
    // A misspelt key is refused, naming it.
    std::fs::write(
        b.join("bad.toml"),
        "bag = \"in.mcap\"\nimu_topics = \"/imu\"\n",
    )
    .expect("bad");
    let e = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--config"])
        .arg(b.join("bad.toml"))
        .args(common::bag::COMMON)
        .assert()
        .failure();
    let err = stderr_of(&e);
    assert!(err.contains("imu_topics"), "{err}");
}

/// `--out-bag` on a full disk (the bag's path on `/dev/full`): the run fails naming
/// the bag, and the partial file is gone (a bag without its summary is no MCAP);
/// when another output fails instead (nav.txt on `/dev/full`), the bag written so far
/// is a whole MCAP with its summary, read to its end.
#[test]
fn out_bag_on_a_full_disk_is_removed_and_named() {
    if !Path::new("/dev/full").exists() {
        eprintln!("no /dev/full here: the test needs it");
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).expect("out");
    let result = out.join("result.mcap");
    std::os::unix::fs::symlink("/dev/full", &result).expect("symlink");
    let a = nav_bag(
        &data().join("drive.mcap"),
        &out,
        &["--out-bag", result.to_str().expect("utf-8")],
    )
    .failure()
    .code(1);
    let err = stderr_of(&a);
    assert!(
        err.contains("result.mcap: cannot write: No space left on device"),
        "{err}"
    );
    assert!(
        !result.exists() && result.symlink_metadata().is_err(),
        "{err}"
    );

    let out = dir.path().join("nav_full");
    std::fs::create_dir_all(&out).expect("out");
    std::os::unix::fs::symlink("/dev/full", out.join("nav.txt")).expect("symlink");
    let result = dir.path().join("whole.mcap");
    let a = nav_bag(
        &data().join("drive.mcap"),
        &out,
        &["--out-bag", result.to_str().expect("utf-8")],
    )
    .failure();
    let err = stderr_of(&a);
    assert!(err.contains("nav.txt"), "{err}");
    let bytes = std::fs::read(&result).expect("the bag stays");
    let summary = mcap::Summary::read(&bytes).expect("a whole MCAP");
    assert!(summary.is_some_and(|s| s.stats.is_some()), "no summary");
    let _ = read_bag(&result);
}

/// Rows of `nav.csv` (header skipped).
fn nav_csv(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("nav.csv");
    common::rows(
        &text
            .lines()
            .skip(1)
            .collect::<Vec<_>>()
            .join("\n")
            .replace(',', " "),
    )
}

/// ECEF to ENU at `lat`, `lon` [deg] (the local-tangent rotation, ENU rows).
fn ecef_to_enu(lat: f64, lon: f64) -> Matrix3<f64> {
    let (sp, cp) = lat.to_radians().sin_cos();
    let (sl, cl) = lon.to_radians().sin_cos();
    Matrix3::new(-sl, cl, 0.0, -sp * cl, -sp * sl, cp, cp * cl, cp * sl, sp)
}

/// Every message of the result bag, by topic.
type Messages = BTreeMap<String, Vec<(u64, String, Vec<u8>)>>;

fn read_bag(path: &Path) -> Messages {
    let mut stream = BagStream::open(path).expect("open");
    let mut out = Messages::new();
    while let Some(()) = stream
        .next_with(|m| {
            assert_eq!(m.topic.message_encoding, "cdr");
            out.entry(m.topic.name.clone()).or_default().push((
                m.log_time,
                m.topic.type_name.clone(),
                m.data.to_vec(),
            ));
            Ok(())
        })
        .expect("message")
    {}
    out
}

/// `--out-bag`: one message per output epoch on each topic, stamped with nav.csv's
/// times; the fix at nav.csv's latitude and longitude; the odometry at the ENU
/// position of nav.csv's ECEF position relative to the first epoch, its orientation
/// turned back to FRD-to-NED giving nav.csv's roll, pitch and yaw (at the first epoch,
/// where the map frame is the local ENU); every bound is nav.csv's last printed digit.
#[test]
fn out_bag_holds_the_trajectory_in_ros_frames() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("bag");
    let result = dir.path().join("result.mcap");
    nav_bag(
        &data().join("drive.mcap"),
        &out,
        &["--out-bag", result.to_str().expect("utf-8")],
    )
    .success();
    let rows = nav_csv(&out.join("nav.csv"));
    let msgs = read_bag(&result);
    for (topic, ty) in [
        ("/schuler/odometry", "nav_msgs/msg/Odometry"),
        ("/schuler/fix", NAV_SAT_FIX),
        ("/schuler/gyro_bias", VECTOR3_STAMPED),
        ("/schuler/accel_bias", VECTOR3_STAMPED),
    ] {
        let m = &msgs[topic];
        assert_eq!(m.len(), rows.len(), "{topic}");
        assert!(m.iter().all(|x| x.1 == ty), "{topic}");
        for ((log_time, _, _), r) in m.iter().zip(&rows) {
            assert!(
                (*log_time as f64 * 1e-9 - r[0]).abs() < 1e-6,
                "{topic} at {}",
                r[0]
            );
        }
    }
    let r0 = Vector3::new(rows[0][10], rows[0][11], rows[0][12]);
    let c0 = ecef_to_enu(rows[0][1], rows[0][2]);
    for (k, r) in rows.iter().enumerate() {
        let fix = NavSatFix::decode(&msgs["/schuler/fix"][k].2).expect("fix");
        assert_eq!(fix.header.frame_id, "base_link");
        assert!((fix.header.seconds() - r[0]).abs() < 1e-6);
        assert!((fix.latitude - r[1]).abs() <= 1e-11 && (fix.longitude - r[2]).abs() <= 1e-11);
        assert!((fix.altitude - r[3]).abs() <= 1e-6);
        assert_eq!(fix.position_covariance_type, 3);
        let odo = Odometry::decode(&msgs["/schuler/odometry"][k].2).expect("odometry");
        assert_eq!(
            (odo.header.frame_id.as_str(), odo.child_frame_id.as_str()),
            ("map", "base_link")
        );
        let enu = c0 * (Vector3::new(r[10], r[11], r[12]) - r0);
        assert!(
            (Vector3::from(odo.position) - enu).norm() < 3e-6,
            "{k}: {enu}"
        );
        // Forward speed in base_link equals the NED speed's norm (no sideslip in the
        // scenario's turn to 1e-6 m/s printed).
        let speed = Vector3::new(r[4], r[5], r[6]).norm();
        assert!((Vector3::from(odo.linear).norm() - speed).abs() < 3e-6);
    }
    let odo = Odometry::decode(&msgs["/schuler/odometry"][0].2).expect("odometry");
    let [x, y, z, w] = odo.orientation;
    let c_flu_enu = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
        .to_rotation_matrix()
        .into_inner();
    let ned_enu = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    let flu_frd = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    let c_bn = ned_enu * c_flu_enu * flu_frd;
    let e = schuler::rotation::Euler::from_dcm(&c_bn);
    let got = [e.roll, e.pitch, e.yaw].map(f64::to_degrees);
    for (g, want) in got.iter().zip(&rows[0][7..10]) {
        assert!((g - want).abs() < 2e-9, "{got:?} vs {:?}", &rows[0][7..10]);
    }
}

/// A bag written here with the `mcap` crate: `topics` (name, type, message
/// encoding) and, on the first, `n` IMU messages at rest from `make(i)`.
fn write_bag(path: &Path, topics: &[(&str, &str, &str)], n: u32, make: impl Fn(u32) -> Vec<u8>) {
    let file = std::fs::File::create(path).expect("create");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(file)).expect("writer");
    let mut ids = Vec::new();
    for (topic, ty, encoding) in topics {
        let schema = w
            .add_schema(ty, "ros2msg", definitions::imu().as_bytes())
            .expect("schema");
        ids.push(
            w.add_channel(schema, topic, encoding, &BTreeMap::new())
                .expect("channel"),
        );
    }
    for i in 0..n {
        let t = 1_000_000_000 + u64::from(i) * 10_000_000;
        let header = MessageHeader {
            channel_id: ids[0],
            sequence: i,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&header, &make(i))
            .expect("message");
    }
    w.finish().expect("finish");
}

/// An IMU message at rest, FLU: no rotation, specific force 9.8 m/s² up; message
/// `i` at 1 + i/100 s.
fn at_rest(i: u32) -> Imu {
    Imu {
        header: Header {
            sec: 1 + (i / 100) as i32,
            nanosec: (i % 100) * 10_000_000,
            frame_id: "imu_link".into(),
        },
        angular_velocity: [0.0; 3],
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: [0.0, 0.0, 9.8],
        linear_acceleration_covariance: [0.0; 9],
    }
}

/// `schuler nav --bag` on `bag` at rest, free-inertial, with `extra`; fails.
fn refused(bag: &Path, extra: &[&str]) -> String {
    let out = bag.with_extension("out");
    let a = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("nav")
        .arg("--bag")
        .arg(bag)
        .args(["--init-pos", "45,7,100", "--init-att", "0,0,0", "--out"])
        .arg(&out)
        .args(extra)
        .assert()
        .failure();
    let err = stderr_of(&a);
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// The record offset of the first chunk (opcode 0x06) after the 8-byte magic.
fn first_chunk(bytes: &[u8]) -> usize {
    let mut pos = 8;
    loop {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().expect("8 bytes"));
        if bytes[pos] == 0x06 {
            return pos;
        }
        pos += 9 + len as usize;
    }
}

#[test]
fn malformed_bags_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let original = std::fs::read(data().join("drive.mcap")).expect("bag");
    // Truncated in the middle of a chunk.
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &original[..original.len() / 2]).expect("write");
    let e = refused(&cut, &[]);
    assert!(e.contains("cut.mcap: after message"), "{e}");
    assert!(e.contains("ended in the middle of a record"), "{e}");
    // The first chunk's CRC (after its op, length, start, end and size fields).
    let crc = dir.path().join("crc.mcap");
    let mut bytes = original.clone();
    let at = first_chunk(&bytes) + 9 + 24;
    bytes[at] ^= 0x5a;
    std::fs::write(&crc, bytes).expect("write");
    let e = refused(&crc, &[]);
    assert!(
        e.contains("crc.mcap: before the first message: Chunk CRC failed"),
        "{e}"
    );
    // A schema we cannot decode.
    let unknown = dir.path().join("unknown.mcap");
    write_bag(&unknown, &[("/imu", "foo_msgs/msg/Bar", "cdr")], 10, |i| {
        at_rest(i).encode()
    });
    let e = refused(&unknown, &[]);
    assert!(
        e.contains("no sensor_msgs/msg/Imu topic in the bag (topics: /imu)"),
        "{e}"
    );
    let e = refused(&unknown, &["--imu-topic", "/imu"]);
    assert!(
        e.contains("unknown.mcap: topic /imu: message schema \"foo_msgs/msg/Bar\" is not sensor_msgs/msg/Imu"),
        "{e}"
    );
    // The right type in another encoding.
    let json = dir.path().join("json.mcap");
    write_bag(&json, &[("/imu", IMU, "json")], 10, |i| at_rest(i).encode());
    let e = refused(&json, &[]);
    assert!(
        e.contains(
            "json.mcap: topic /imu: message encoding \"json\" with schema encoding \
             \"ros2msg\": only ROS 2 CDR (\"cdr\" with \"ros2msg\" or \"ros2idl\") and ROS 1 \
             bags are read"
        ),
        "{e}"
    );
    // A NaN in message 5, a payload cut short in message 7.
    for (name, bad, expected) in [
        (
            "nan.mcap",
            5,
            "topic /imu, message 5: field angular_velocity.y: NaN is not a finite number",
        ),
        (
            "short.mcap",
            7,
            "topic /imu, message 7: field linear_acceleration_covariance",
        ),
    ] {
        let path = dir.path().join(name);
        write_bag(&path, &[("/imu", IMU, "cdr")], 20, |i| {
            let mut m = at_rest(i);
            if i + 1 == bad && bad == 5 {
                m.angular_velocity[1] = f64::NAN;
            }
            let mut bytes = m.encode();
            if i + 1 == bad && bad == 7 {
                bytes.truncate(bytes.len() - 4);
            }
            bytes
        });
        let e = refused(&path, &["--no-report"]);
        assert!(e.contains(expected), "{name}: {e}");
    }
}

/// A rest bag written here reads as rest: FLU's +9.8 m/s² up is FRD's −9.8 down, so
/// free-inertial navigation stays where it started. Over 1 s the height moves by
/// ½·(9.806 − 9.8)·1² = 3 mm (normal gravity at 45° against the bag's 9.8), and the
/// horizontal velocity by g·Ω·t²/2 = 4e-4 m/s (the Earth's rate Ω, not in the bag's
/// zero rates, tilting the frame): bounds 1 cm and 1 mm/s.
#[test]
fn a_rest_bag_stays_at_rest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("rest.mcap");
    write_bag(&path, &[("/imu", IMU, "cdr")], 101, |i| at_rest(i).encode());
    let out = dir.path().join("out");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--bag"])
        .arg(&path)
        .args(["--init-pos", "45,7,100", "--init-att", "0,0,0", "--out"])
        .arg(&out)
        .assert()
        .success();
    let rows = common::read_rows(&out.join("nav.txt"));
    let last = rows.last().expect("rows");
    assert_eq!(last[1], 2.0);
    assert!((last[4] - 100.0).abs() < 0.01, "{last:?}");
    assert!(last[5].abs() < 1e-3 && last[6].abs() < 1e-3, "{last:?}");
}

/// A bag has one clock: `--imu-time-offset` moves every topic's stamps, so the run
/// shifted by −345600 s (a clock from 0) is the same trajectory at shifted times (the
/// stamps' differences, and so every dt, are the same doubles: both subtractions are
/// exact near 345600 s by Sterbenz's lemma).
#[test]
fn the_time_offset_moves_every_topic() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bag = data().join("drive.mcap");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    nav_bag(&bag, &a, &[]).success();
    nav_bag(&bag, &b, &["--imu-time-offset", "-345600"]).success();
    let shifted: String = common::read_rows(&a.join("nav.txt"))
        .iter()
        .map(|r| {
            let mut line = format!("0 {:.6}", r[1] - 345_600.0);
            for x in &r[2..] {
                line.push_str(&format!(" {x}"));
            }
            line + "\n"
        })
        .collect();
    std::fs::write(dir.path().join("shifted.txt"), shifted).expect("write");
    let digits = max_digits_apart(&dir.path().join("shifted.txt"), &b.join("nav.txt"));
    assert!(digits <= 1.0, "{digits} units of the last digit apart");
}

/// `bag` copied to `out` with every header stamp and log time `shift` seconds later
/// (the stamp's `sec` is the first field after the 4-byte CDR header in every type).
fn shifted_bag(bag: &Path, out: &Path, shift: i32) {
    let file = std::fs::File::create(out).expect("bag");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(file)).expect("writer");
    let mut channels: BTreeMap<usize, u16> = BTreeMap::new();
    let mut stream = BagStream::open(bag).expect("open");
    while let Some(()) = stream
        .next_with(|m| {
            let id = *channels.entry(m.topic_index).or_insert_with(|| {
                let t = m.topic;
                let schema = w
                    .add_schema(&t.type_name, &t.schema_encoding, b"")
                    .expect("schema");
                w.add_channel(schema, &t.name, &t.message_encoding, &BTreeMap::new())
                    .expect("channel")
            });
            let mut data = m.data.to_vec();
            let sec = i32::from_le_bytes(data[4..8].try_into().expect("4 bytes")) + shift;
            data[4..8].copy_from_slice(&sec.to_le_bytes());
            let log_time = m.log_time + u64::try_from(shift).expect("later") * 1_000_000_000;
            let h = MessageHeader {
                channel_id: id,
                sequence: 0,
                log_time,
                publish_time: log_time,
            };
            w.write_to_known_channel(&h, &data).expect("message");
            Ok(())
        })
        .expect("message")
    {}
    w.finish().expect("finish");
}

/// ROS stamps are UNIX time; the run's are GPS seconds of week. The bag's stamps moved
/// to Thursday 2023-11-16, whose 00:00:00 UTC is UNIX 1 700 092 800 (2023-11-14
/// 22:13:20 is 1 700 000 000) and 4 days + 18 leap seconds into GPS week 2288 (week
/// 2048 began on 2019-04-07, 240 weeks before its Sunday 2023-11-12): a shift of
/// 1 700 092 800 − 18 − 345 600 s puts every stamp at the same second of week as the
/// committed bag's (whose stamps, before 1980, are read as they are). nav.txt must be
/// the same bytes but for the week column, 2288; the result bag's log times move back
/// to UNIX time, exactly the shift later; `--leap-seconds 18` (the table's count in
/// 2023) changes nothing and 17 moves every time 1 s earlier.
#[test]
fn unix_stamps_become_gps_week_and_second() {
    let dir = tempfile::tempdir().expect("tempdir");
    let shift = 1_700_092_800 - 18 - 345_600;
    let unix = dir.path().join("unix.mcap");
    shifted_bag(&data().join("drive.mcap"), &unix, shift);
    let runs = [
        ("raw", &[][..]),
        ("unix", &[][..]),
        ("leap18", &["--leap-seconds", "18"][..]),
    ];
    for (name, extra) in runs {
        let bag = if name == "raw" {
            data().join("drive.mcap")
        } else {
            unix.clone()
        };
        let out = dir.path().join(name);
        let result = dir.path().join(format!("{name}_out.mcap"));
        let mut flags = vec![
            "--end",
            "345640",
            "--out-bag",
            result.to_str().expect("utf-8"),
        ];
        flags.extend(extra);
        let a = nav_bag(&bag, &out, &flags).success();
        if name == "unix" {
            let err = stderr_of(&a);
            assert!(err.contains("UNIX time: GPS week 2288"), "{err}");
        }
    }
    let nav = |name: &str| {
        std::fs::read_to_string(dir.path().join(name).join("nav.txt")).expect("nav.txt")
    };
    let raw = nav("raw");
    let expected: String = raw
        .lines()
        .map(|l| format!("2288{}\n", l.trim_start().trim_start_matches('0')))
        .collect();
    assert_eq!(nav("unix"), expected);
    assert_eq!(nav("leap18"), expected);
    let (a, b) = (
        read_bag(&dir.path().join("raw_out.mcap")),
        read_bag(&dir.path().join("unix_out.mcap")),
    );
    for (topic, msgs) in &a {
        let later: Vec<u64> = msgs
            .iter()
            .map(|m| m.0 + shift as u64 * 1_000_000_000)
            .collect();
        let got: Vec<u64> = b[topic].iter().map(|m| m.0).collect();
        assert_eq!(got, later, "{topic}");
    }
    let out = dir.path().join("leap17");
    nav_bag(&unix, &out, &["--end", "345639", "--leap-seconds", "17"]).success();
    let (r, l) = (
        common::read_rows(&dir.path().join("raw/nav.txt")),
        common::read_rows(&out.join("nav.txt")),
    );
    assert_eq!(r.len(), l.len());
    for (x, y) in r.iter().zip(&l) {
        assert!((x[1] - 1.0 - y[1]).abs() < 1e-9, "{} / {}", x[1], y[1]);
    }
}

/// The text reader's checks on a bag's IMU, named by topic, message and field: the
/// plausibility check of the first messages (a specific force in g, 1/9.8 of gravity:
/// below the 0.3 g bound), a stamp jumping by 100 s (past the 60-s interval domain),
/// and the gap report (a missing 50 ms at 100 Hz: one interval of 0.06 s, over twice
/// the nominal 0.01 s), printed as a warning of a run that succeeds.
#[test]
fn bag_imus_get_the_text_readers_checks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = [("/imu", IMU, "cdr")];
    let in_g = dir.path().join("g.mcap");
    write_bag(&in_g, &imu, 101, |i| {
        let mut m = at_rest(i);
        m.linear_acceleration[2] = 1.0;
        m.encode()
    });
    let e = refused(&in_g, &[]);
    assert!(
        e.contains("g.mcap: topic /imu: field linear_acceleration: messages 1-101 fail the plausibility check"),
        "{e}"
    );
    assert!(e.contains("--no-layout-check skips this check"), "{e}");
    let jump = dir.path().join("jump.mcap");
    write_bag(&jump, &imu, 101, |i| {
        let mut m = at_rest(i);
        if i >= 50 {
            m.header.sec += 100;
        }
        m.encode()
    });
    let e = refused(&jump, &[]);
    assert!(
        e.contains("jump.mcap: topic /imu, message 51: field header.stamp: the time jumps: IMU sample interval"),
        "{e}"
    );
    let gap = dir.path().join("gap.mcap");
    write_bag(&gap, &imu, 101, |i| {
        let i = if i >= 50 { i + 5 } else { i };
        at_rest(i).encode()
    });
    let a = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--bag"])
        .arg(&gap)
        .args(["--init-pos", "45,7,100", "--init-att", "0,0,0", "--out"])
        .arg(dir.path().join("gap"))
        .assert()
        .success();
    let err = stderr_of(&a);
    assert!(
        err.contains("warning: ")
            && err.contains("gap.mcap: topic /imu: 1 gap(s) longer than 0.02"),
        "{err}"
    );
    assert!(err.contains("longest 0.06"), "{err}");
}

/// `drive.mcap` copied to `out` with every FluidPressure's variance set to `var_p`
/// [Pa²] and every Odometry's forward-speed variance to `var_v` [m²/s²].
fn with_variances(out: &Path, var_p: f64, var_v: f64) {
    use schuler_io::bag::messages::{FLUID_PRESSURE, FluidPressure, ODOMETRY};
    let file = std::fs::File::create(out).expect("bag");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(file)).expect("writer");
    let mut channels: BTreeMap<usize, u16> = BTreeMap::new();
    let mut stream = BagStream::open(&data().join("drive.mcap")).expect("open");
    while let Some(()) = stream
        .next_with(|m| {
            let t = m.topic;
            let id = *channels.entry(m.topic_index).or_insert_with(|| {
                let schema = w
                    .add_schema(&t.type_name, &t.schema_encoding, b"")
                    .expect("schema");
                w.add_channel(schema, &t.name, &t.message_encoding, &BTreeMap::new())
                    .expect("channel")
            });
            let data = match t.type_name.as_str() {
                FLUID_PRESSURE => {
                    let mut p = FluidPressure::decode(m.data).expect("pressure");
                    p.variance = var_p;
                    p.encode()
                }
                ODOMETRY => {
                    let mut o = Odometry::decode(m.data).expect("odometry");
                    o.twist_covariance[0] = var_v;
                    o.encode()
                }
                _ => m.data.to_vec(),
            };
            let h = MessageHeader {
                channel_id: id,
                sequence: 0,
                log_time: m.log_time,
                publish_time: m.log_time,
            };
            w.write_to_known_channel(&h, &data).expect("message");
            Ok(())
        })
        .expect("message")
    {}
    w.finish().expect("finish");
}

/// The pressure variances and the odometry's speed variance are the barometer's and
/// the odometer's noise when no flag gives them: (4 Pa)² is 4·8.52 cm = 0.341 m of
/// height at the drive's 245 m (hydrostatic balance `R*·T/(p·M·g₀)` at T = 286.56 K,
/// p = 98.42 kPa; the median over the drive's heights, within 2 mm), (0.2 m/s)² is
/// 0.2 m/s. The run with them is the run of the bag without them given those noises
/// as flags (the same bytes), and a flag overrides the variances (the same bytes as
/// the bag without them).
#[test]
fn pressure_and_odometry_variances_are_the_noise() {
    let dir = tempfile::tempdir().expect("tempdir");
    // The shared flags but --odometer-std (the last two).
    let nav_bag = |bag: &Path, out: &Path, extra: &[&str]| {
        assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .arg("nav")
            .arg("--bag")
            .arg(bag)
            .args(&common::bag::COMMON[..11])
            .args(extra)
            .arg("--out")
            .arg(out)
            .assert()
    };
    let bag = dir.path().join("var.mcap");
    with_variances(&bag, 16.0, 0.04);
    let end = ["--end", "345650"];
    let a = nav_bag(&bag, &dir.path().join("a"), &end).success();
    let err = stderr_of(&a);
    let printed = |what: &str, unit: &str| -> String {
        let line = err
            .lines()
            .find(|l| l.contains(what))
            .unwrap_or_else(|| panic!("{what}: {err}"));
        let after = line.split(": ").last().expect("value");
        after
            .split(&format!(" {unit}"))
            .next()
            .expect("value")
            .to_owned()
    };
    let baro = printed("barometer noise from its pressure variances", "m");
    let odo = printed("odometer noise from its twist covariances", "m/s");
    let baro_m: f64 = baro.parse().expect("number");
    assert!((baro_m - 0.341).abs() < 0.002, "{baro}");
    assert_eq!(odo, "0.2");
    let mut flags = end.to_vec();
    flags.extend(["--baro-std", &baro, "--odometer-std", &odo]);
    nav_bag(&data().join("drive.mcap"), &dir.path().join("b"), &flags).success();
    let mut flags = end.to_vec();
    flags.extend(["--baro-std", "0.5"]);
    let c = nav_bag(&bag, &dir.path().join("c"), &flags).success();
    let err_c = stderr_of(&c);
    assert!(!err_c.contains("barometer noise from"), "{err_c}");
    let mut flags = end.to_vec();
    flags.extend(["--odometer-std", "0.2"]);
    nav_bag(&data().join("drive.mcap"), &dir.path().join("d"), &flags).success();
    let read = |d: &str| std::fs::read(dir.path().join(d).join("nav.txt")).expect("nav.txt");
    assert_eq!(read("a"), read("b"));
    assert_eq!(read("c"), read("d"));
    assert_ne!(read("a"), read("c"));
}
