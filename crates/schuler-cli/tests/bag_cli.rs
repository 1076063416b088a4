//! `schuler bag info` and `schuler nav --bag` on `tests/data/ros2_bag/drive.mcap`, a
//! bag written by the Python `mcap` and `mcap-ros2-support` packages (not by us) from
//! `schuler simulate`'s logs of `scenario.toml` (provenance in tests/data/README.md);
//! `--out-bag` read back; malformed bags refused with the topic, message and field.

mod common;

use common::bag::{data, max_digits_apart, nav_bag, nav_text, simulate_scenario};
use mcap::records::MessageHeader;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use schuler_cli::bag::container::BagStream;
use schuler_cli::bag::messages::{
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
        e.contains("json.mcap: topic /imu: message encoding \"json\": only ROS 2 CDR"),
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
