//! Error messages through the binary: the reason is printed once, after the file and
//! the key (`error: in FILE: KEY: reason`), even where the library's error carries it
//! as the source of another.

use assert_cmd::Command;
use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

/// A scripted flight that reaches the 89.9-deg limit of maneuver scripting (from
/// 89.89 deg north at 50 m/s, 1.1 km short of it, a 60-s hold) stops with the motion's
/// reason once; a start beyond the limit is refused with its reason once too.
#[test]
fn the_pole_limit_is_stated_once() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases = [
        ("89.89 deg", "reaches latitude 89.9", "motion[0]: piece 0: "),
        (
            "89.95 deg",
            "latitude must be within 89.9 deg",
            "start.position[0]: ",
        ),
    ];
    for (i, (lat, reason, key)) in cases.into_iter().enumerate() {
        let cfg = write(
            dir.path(),
            &format!("polar{i}.toml"),
            &format!(
                "[start]\nposition = [\"{lat}\", \"7 deg\", \"100 m\"]\n\
                 attitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\nspeed = \"50 m/s\"\n\
                 [[motion]]\ntype = \"hold\"\nduration = \"60 s\"\n[imu]\nrate_hz = 100\n"
            ),
        );
        let out = Command::cargo_bin("schuler")
            .expect("binary")
            .args(["simulate", "--config"])
            .arg(&cfg)
            .arg("--out")
            .arg(dir.path().join(format!("out{i}")))
            .output()
            .expect("run");
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8(out.stderr).expect("utf-8");
        assert_eq!(stderr.matches(reason).count(), 1, "{stderr}");
        assert!(
            stderr.starts_with(&format!("error: in {}: {key}", cfg.display())),
            "{stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}

/// An error whose message already holds its cause's (the simulator's failed write,
/// here into /dev/full) prints the cause once.
#[cfg(unix)]
#[test]
fn a_failed_write_is_stated_once() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).expect("mkdir");
    std::os::unix::fs::symlink("/dev/full", out.join("imu.txt")).expect("symlink");
    let cfg = write(
        dir.path(),
        "drive.toml",
        "[start]\nposition = [\"45 deg\", \"7 deg\", \"100 m\"]\n\
         attitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\nspeed = \"10 m/s\"\n\
         [[motion]]\ntype = \"hold\"\nduration = \"60 s\"\n[imu]\nrate_hz = 100\n",
    );
    let run = Command::cargo_bin("schuler")
        .expect("binary")
        .args(["simulate", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("run");
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8(run.stderr).expect("utf-8");
    assert!(
        stderr.contains("writing the simulated data failed"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("imu.txt").count(), 1, "{stderr}");
}

/// `schuler inspect FILE | head -0`: the reader of stdout is gone before the first
/// line (the pipe's read end is closed before the process starts, so every write
/// fails), and the run ends quietly with 141 (128 + SIGPIPE, as `cat` killed by the
/// signal would), not with a panic's message and 101.
#[cfg(unix)]
#[test]
fn a_closed_stdout_ends_the_run_quietly() {
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/dataflash/synthetic_circle.bin.gz");
    let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("schuler"))
        .arg("inspect")
        .arg(log)
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
