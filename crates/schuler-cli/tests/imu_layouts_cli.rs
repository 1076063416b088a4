//! Real logs as users bring them, through `schuler nav`: the example drive's IMU
//! (KF-GINS increments, FRD, GPS seconds) rewritten as devices write it — rates in
//! deg/s and g with the accelerometer first, integer nanoseconds of a clock that
//! started before the drive, RBD and FLU axes, a CSV header of common names with units
//! — navigates with GNSS to the canonical file's trajectory; files read the wrong way
//! are refused with the flags that fix them; and a real device's excerpt reads with its
//! flags.

use crate::common;

use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::Path;

use schuler_io::formats::ImuReader;
use schuler_run::imu_input::ImuInputOptions;

/// The runs stop here [s]: the rest, the turn, the climb and the GNSS outage.
const END: f64 = 600.0;
/// The device's clock had been running this long [s] when the drive began.
const BOOT: f64 = 1000.0;
const G0: f64 = 9.806_65;

/// One line of the canonical file: time, angle and velocity increments (FRD).
#[derive(Clone, Copy)]
struct Row {
    t: f64,
    dtheta: [f64; 3],
    dvel: [f64; 3],
}

/// The simulated IMU up to [`END`].
fn canonical(sim: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(sim.join("imu.txt")).expect("imu.txt");
    text.lines()
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect();
            Row {
                t: v[0],
                dtheta: [v[1], v[2], v[3]],
                dvel: [v[4], v[5], v[6]],
            }
        })
        .take_while(|r| r.t <= END)
        .collect()
}

/// The device's stamp [ns] of a time.
fn stamp_ns(t: f64) -> i64 {
    ((t + BOOT) * 1e9).round() as i64
}

/// The time the reader makes of a stamp with `--imu-time-unit ns --imu-time-offset
/// -BOOT` (whole seconds plus the offset, then the fraction), so that rates times the
/// reader's intervals give back the increments.
fn read_back(ns: i64) -> f64 {
    (ns.div_euclid(1_000_000_000) as f64 - BOOT) + ns.rem_euclid(1_000_000_000) as f64 / 1e9
}

/// FRD components in the IMU's axes.
type Axes = fn([f64; 3]) -> [f64; 3];

/// FRD components as they are.
fn frd(v: [f64; 3]) -> [f64; 3] {
    v
}

/// FRD components in RBD axes (x right, y back, z down).
fn rbd([f, r, d]: [f64; 3]) -> [f64; 3] {
    [r, -f, d]
}

/// FRD components in FLU axes (ROS REP 103).
fn flu([f, r, d]: [f64; 3]) -> [f64; 3] {
    [f, -r, -d]
}

/// How a device writes the drive, and the flags that read it.
struct Variant {
    name: &'static str,
    /// Field separator and header line.
    format: (&'static str, Option<&'static str>),
    /// Integer nanoseconds of a clock started [`BOOT`] s before the drive (else the
    /// canonical seconds).
    nanoseconds: bool,
    /// Rates in deg/s and g, the accelerometer first (else increments, gyro first).
    device_rates: bool,
    axes: Axes,
    flags: &'static str,
}

/// The layouts devices write.
fn variants() -> Vec<Variant> {
    const NS: &str = "--imu-time-unit ns --imu-time-offset -1000";
    let v = |name, format, nanoseconds, device_rates, axes, flags| Variant {
        name,
        format,
        nanoseconds,
        device_rates,
        axes,
        flags,
    };
    vec![
        v(
            "accelerometer first, deg/s and g",
            (",", None),
            false,
            true,
            frd as Axes,
            "--imu-columns t,fx,fy,fz,wx,wy,wz --gyro-unit deg/s --accel-unit g",
        ),
        v("nanoseconds from boot", (" ", None), true, false, frd, NS),
        v("RBD axes", (" ", None), false, false, rbd, "--imu-axes RBD"),
        v(
            "RBD axes as a rotation",
            (" ", None),
            false,
            false,
            rbd,
            "--imu-rotation 0,0,90",
        ),
        v(
            "FLU axes (ROS)",
            ("\t", None),
            false,
            false,
            flu,
            "--imu-axes FLU",
        ),
        v(
            "CSV header of common names",
            (",", Some("time_ns,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps")),
            true,
            true,
            frd,
            "--imu-time-offset -1000",
        ),
        v(
            "the issue's rover",
            (",", None),
            true,
            true,
            rbd,
            "--imu-columns t,fx,fy,fz,wx,wy,wz --gyro-unit deg/s --accel-unit g --imu-time-unit ns --imu-time-offset -1000 --imu-axes RBD",
        ),
    ]
}

impl Variant {
    /// A row's time field and the reader's time of it.
    fn time(&self, r: &Row) -> (String, f64) {
        if self.nanoseconds {
            let n = stamp_ns(r.t);
            (n.to_string(), read_back(n))
        } else {
            (r.t.to_string(), r.t)
        }
    }

    /// A row's six values in the file's order, its rates over the reader's `dt`.
    fn values(&self, r: &Row, dt: f64) -> [f64; 6] {
        let (w, f) = ((self.axes)(r.dtheta), (self.axes)(r.dvel));
        let [a, b] = if self.device_rates {
            [f.map(|x| x / dt / G0), w.map(|x| (x / dt).to_degrees())]
        } else {
            [w, f]
        };
        [a[0], a[1], a[2], b[0], b[1], b[2]]
    }

    /// Writes `rows` as the device would into `path`.
    fn write(&self, path: &Path, rows: &[Row]) {
        let (sep, header) = self.format;
        let mut text = header.map(|h| format!("{h}\n")).unwrap_or_default();
        let mut t_prev = None;
        for r in rows {
            let (field, t) = self.time(r);
            // The first interval is the reader's nominal one; its sample is never
            // integrated.
            let dt = t_prev.map_or(0.005, |p| t - p);
            t_prev = Some(t);
            let values: Vec<String> = self.values(r, dt).iter().map(f64::to_string).collect();
            writeln!(text, "{field}{sep}{}", values.join(sep)).expect("String");
        }
        std::fs::write(path, text).expect("write variant");
    }
}

/// The largest difference per column of two nav.txt files, which must have the same
/// epochs.
fn differences(a: &Path, b: &Path) -> Vec<f64> {
    let (a, b) = (common::read_rows(a), common::read_rows(b));
    assert_eq!(a.len(), b.len(), "epochs");
    let mut max = vec![0.0f64; a[0].len()];
    for (ra, rb) in a.iter().zip(&b) {
        for (m, (x, y)) in max.iter_mut().zip(ra.iter().zip(rb)) {
            *m = m.max((x - y).abs());
        }
    }
    max
}

/// Every layout navigates to the canonical trajectory: nav.txt prints 1e-11 deg, 1 µm,
/// 1 µm/s and 1e-9 deg, and the variants differ from the canonical file only by the
/// round-off of their written digits (shortest round-trip numbers: an exact permutation
/// for the axes, about 1e-16 relative after deg/s and g, the reader's nanosecond times
/// within an ulp of the canonical ones), which 600 s of aided navigation cannot carry
/// to a printed digit: two units of the last printed digit are allowed.
#[test]
fn every_layout_gives_the_canonical_trajectory() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sim = common::simulate_drive(dir.path());
    let rows = canonical(&sim);
    let end = ["--end", "600", "--no-report"].map(OsStr::new);
    common::nav_drive(&sim, &dir.path().join("canonical"), &end).success();
    let tolerance = [
        0.0, 2e-6, 2e-11, 2e-11, 2e-6, 2e-6, 2e-6, 2e-6, 2e-9, 2e-9, 2e-9,
    ];
    for (k, variant) in variants().iter().enumerate() {
        let (name, flags) = (variant.name, variant.flags);
        let imu = dir.path().join(format!("variant{k}.txt"));
        variant.write(&imu, &rows);
        let out = dir.path().join(format!("out{k}"));
        let mut args: Vec<&OsStr> = flags.split(' ').map(OsStr::new).collect();
        args.extend(end);
        common::nav_drive_imu(&sim, &imu, &out, &args).success();
        let diff = differences(&dir.path().join("canonical/nav.txt"), &out.join("nav.txt"));
        println!("{name}: largest differences per nav.txt column {diff:?}");
        for (col, (d, tol)) in diff.iter().zip(tolerance).enumerate() {
            assert!(
                *d <= tol,
                "{name}: column {col} differs by {d} (allowed {tol})"
            );
        }
    }
}

/// Runs `nav` on the first 1000 lines of `text` with `flags` and returns stderr.
fn refused(dir: &Path, text: &str, flags: &[&str]) -> String {
    let imu = dir.join("refused.txt");
    let head: String = text.lines().take(1000).map(|l| format!("{l}\n")).collect();
    std::fs::write(&imu, head).expect("write");
    let out = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args([
            "nav",
            "--init-pos",
            "45.07,7.68,245",
            "--init-att",
            "0,0,10",
            "--imu",
        ])
        .arg(&imu)
        .arg("--out")
        .arg(dir.join("refused"))
        .args(flags)
        .assert()
        .failure();
    String::from_utf8_lossy(&out.get_output().stderr).into_owned()
}

/// Files read the wrong way are refused, the error naming the check, its numbers and
/// the flags that read the file right; increments scaled ×5, ×20 and ×1000 are refused
/// as scale errors (steady above 3 g, or above 50 g).
#[test]
fn mistaken_files_are_refused_with_the_fix() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sim = common::simulate_drive(dir.path());
    let text = std::fs::read_to_string(sim.join("imu.txt")).expect("imu.txt");
    let rows = canonical(&sim)[..1000].to_vec();
    let device = dir.path().join("device.txt");
    variants()[0].write(&device, &rows);
    let device_text = std::fs::read_to_string(&device).expect("device");
    let e = refused(dir.path(), &device_text, &[]);
    // The gyro columns hold 1 g: as radians in 5 ms, 11464 deg/s.
    assert!(
        e.contains("refused.txt:1: field dtheta (columns 2-4): lines 1-201"),
        "{e}"
    );
    assert!(
        e.contains("median angular rate is 11464 deg/s, above the 3000 deg/s"),
        "{e}"
    );
    assert!(e.contains("look like the gyro and accelerometer columns exchanged and rates, not increments and the accelerometer in g"), "{e}");
    assert!(
        e.contains("give --imu-columns t,fx,fy,fz,wx,wy,wz --accel-unit g"),
        "{e}"
    );
    // The gyro columns read as accelerometers: increments in the other order.
    let swapped: String = text
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            format!(
                "{} {} {} {} {} {} {}\n",
                f[0], f[4], f[5], f[6], f[1], f[2], f[3]
            )
        })
        .take(1000)
        .collect();
    let e = refused(dir.path(), &swapped, &[]);
    assert!(
        e.contains("field dvel (columns 5-7)") && e.contains("below the 0.3 g"),
        "{e}"
    );
    assert!(
        e.contains("give --imu-columns t,dvx,dvy,dvz,dtx,dty,dtz"),
        "{e}"
    );
    for k in [5.0, 20.0, 1000.0] {
        let scaled: String = rows
            .iter()
            .map(|r| {
                let [x, y, z] = r.dvel.map(|v| v * k);
                let [a, b, c] = r.dtheta;
                format!("{} {a} {b} {c} {x} {y} {z}\n", r.t)
            })
            .collect();
        let e = refused(dir.path(), &scaled, &[]);
        assert!(e.contains("fail the plausibility check"), "×{k}: {e}");
        assert!(
            e.contains("times g): check --imu-columns, --imu-layout, --gyro-unit, --accel-unit"),
            "×{k}: {e}"
        );
        let why = if k < 50.0 {
            "and steady (scatter below 10 %), above the 3 g"
        } else {
            "above the 50 g"
        };
        assert!(e.contains(why), "×{k}: {e}");
    }
}

/// The real device's excerpt (`tests/data/airbrakes_3dm_cx5/`, provenance in its
/// README): a MicroStrain 3DM-CX5 at rest, z down, 1 kHz, accelerometer in g, gyro in
/// rad/s, UNIX nanoseconds, a header the reader does not know. Read with the flags
/// the README gives, the values are the file's, by hand, and the plausibility check
/// passes at 1 g. Without them the header's deltaVel and deltaTheta columns are
/// recognised as increments, and the check refuses the nanoseconds read as seconds
/// (the device writes deltaVel in g·s, a unit the reader does not take).
#[test]
fn a_real_device_reads_with_its_flags() {
    let file = common::test_data("airbrakes_3dm_cx5").join("zminus_rest.csv");
    let options = ImuInputOptions {
        imu_columns: Some("_,_,t,_,fx,fy,fz,wx,wy,wz,...".into()),
        accel_unit: Some(schuler_io::formats::imu_columns::AccelUnit::G),
        imu_time_unit: Some(schuler_io::formats::imu_columns::TimeUnit::Ns),
        imu_time_offset: Some(-1_730_147_509.0),
        ..Default::default()
    };
    let read = options.read_options(None, None).expect("options");
    let samples: Vec<_> = ImuReader::open(&file, &read)
        .expect("plausible")
        .collect::<Result<_, _>>()
        .expect("all rows");
    assert_eq!(samples.len(), 300);
    // Row 2: S,-0.5,1730147509122819072,,-0.00375034,0.00229063,-1.00165129,-1e-08,0.00076463,0.00302415,...
    let s = samples[1];
    assert_eq!(samples[0].t, 0.12181412);
    assert_eq!(s.t, 0.122819072);
    assert!((s.dt - 0.001004952).abs() < 1e-15, "{}", s.dt);
    let dvel = [-0.00375034, 0.00229063, -1.00165129].map(|g| g * G0 * s.dt);
    let dtheta = [-1e-08, 0.00076463, 0.00302415].map(|w| w * s.dt);
    for i in 0..3 {
        assert!((s.dvel[i] - dvel[i]).abs() < 1e-15, "dvel {i}");
        assert!((s.dtheta[i] - dtheta[i]).abs() < 1e-18, "dtheta {i}");
    }
    // At rest: |f| within 0.3 % of 1 g over the excerpt (the sensor's bias and scale).
    let f_g: Vec<f64> = samples[1..]
        .iter()
        .map(|s| s.dvel.norm() / s.dt / G0)
        .collect();
    let mean = f_g.iter().sum::<f64>() / f_g.len() as f64;
    assert!((mean - 1.0).abs() < 3e-3, "{mean}");
    // Through the binary: with the flags it navigates the 0.3 s; without, it names the fix.
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |flags: &[&str]| {
        assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args([
                "nav",
                "--init-pos",
                "35.77,-78.67,120",
                "--init-att",
                "-0.29,-0.33,0",
                "--imu",
            ])
            .arg(&file)
            .arg("--out")
            .arg(dir.path().join("out"))
            .args(flags)
            .assert()
    };
    run(&[
        "--imu-columns",
        "_,_,t,_,fx,fy,fz,wx,wy,wz,...",
        "--accel-unit",
        "g",
        "--imu-time-unit",
        "ns",
        "--imu-time-offset",
        "-1730147509",
    ])
    .success();
    let out = run(&[]).failure();
    let e = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        e.contains("zminus_rest.csv:2: field timestamp: lines 2-202 fail the plausibility check"),
        "{e}"
    );
    assert!(e.contains("median sample interval is 1.002e6 s"), "{e}");
}

/// The same options as keys of `nav --config` and as flags of `schuler align`: the
/// rover's file configured in TOML navigates to the flags' nav.txt byte for byte, and
/// aligns at rest to the canonical file's attitude within 1e-9 deg (the round-off of
/// its deg/s and g digits; the printed attitude has 1e-4 deg).
#[test]
fn config_keys_and_align_take_the_same_options() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sim = common::simulate_drive(dir.path());
    let rows: Vec<Row> = canonical(&sim)
        .into_iter()
        .take_while(|r| r.t <= 100.0)
        .collect();
    let rover = variants().pop().expect("the rover");
    let imu = dir.path().join("rover.csv");
    rover.write(&imu, &rows);
    let flags: Vec<&str> = rover.flags.split(' ').collect();
    let short = ["--end", "100", "--no-report"].map(OsStr::new);
    let mut with_flags: Vec<&OsStr> = flags.iter().map(OsStr::new).collect();
    with_flags.extend(short);
    common::nav_drive_imu(&sim, &imu, &dir.path().join("flags"), &with_flags).success();
    let config = dir.path().join("rover.toml");
    std::fs::write(
        &config,
        "imu_columns = \"t,fx,fy,fz,wx,wy,wz\"\ngyro_unit = \"deg/s\"\naccel_unit = \"g\"\n\
         imu_time_unit = \"ns\"\nimu_time_offset = -1000\nimu_axes = \"RBD\"\n",
    )
    .expect("write config");
    let mut with_config = vec![OsStr::new("--config"), config.as_os_str()];
    with_config.extend(short);
    common::nav_drive_imu(&sim, &imu, &dir.path().join("config"), &with_config).success();
    let read = |d: &str| std::fs::read(dir.path().join(d).join("nav.txt")).expect("nav.txt");
    assert!(
        read("flags") == read("config"),
        "config keys and flags differ"
    );
    let align = |file: &Path, extra: &[&str], out: &str| {
        assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args([
                "align",
                "--pos",
                "45.07,7.68,245",
                "--coarse",
                "20s",
                "--fine",
                "30s",
            ])
            .args(["--heading", "10", "--imu"])
            .arg(file)
            .args(extra)
            .arg("--out")
            .arg(dir.path().join(out))
            .assert()
            .success();
        let text = std::fs::read_to_string(dir.path().join(out).join("align.json")).expect("json");
        let v: serde_json::Value = serde_json::from_str(&text).expect("json");
        ["roll_deg", "pitch_deg", "yaw_deg"].map(|k| v[k].as_f64().expect("number"))
    };
    let canonical = align(&sim.join("imu.txt"), &[], "align_canonical");
    let device = align(&imu, &flags, "align_rover");
    println!("align roll, pitch, yaw [deg]: canonical {canonical:?}, rover {device:?}");
    for (a, b) in canonical.iter().zip(device) {
        assert!((a - b).abs() < 1e-9, "{canonical:?} vs {device:?}");
    }
}
