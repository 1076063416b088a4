//! The `schuler nav` command line that navigates an inspected log.
//!
//! - The IMU stream of the highest rate and the GNSS stream of the most fixes (named
//!   on the line when the log has several, as `nav --log` would choose them).
//! - The start: where the log holds the device's own attitude of the IMU's body
//!   after its first fix (PX4, ArduPilot, a phone's orientation; not a u-blox
//!   receiver's, whose NAV-ATT is the vehicle's while ESF-RAW is in the sensor's
//!   axes), from it (`--start` at that attitude's time, `--init-pos` the first fix,
//!   `--init-vel` its velocity, `--init-att` the device's roll, pitch and yaw); else,
//!   when the IMU is at rest at the start and the first fix does not move (below
//!   [`REST_SPEED`]), from the first fix with roll and pitch from the specific force
//!   and the heading unknown (yaw 0 ± 180°); else in motion from the fixes:
//!   `--init gnss` for phones and robots (the course is the heading of a vehicle
//!   driving forward), `--init gnss-any-heading` for the others (multicopters fly
//!   sideways; a receiver's IMU is mounted any way).
//! - `--imu-grade consumer-mems`: every device these formats come from carries a
//!   MEMS IMU.

use super::{Inspection, StreamInfo};
use std::path::Path;

/// A first fix slower than this [m/s] does not contradict an IMU at rest.
pub const REST_SPEED: f64 = 0.3;

/// The stream of the largest `key`, the first of equals.
fn best<'a>(
    streams: &[&'a StreamInfo],
    key: impl Fn(&StreamInfo) -> f64,
) -> Option<&'a StreamInfo> {
    streams
        .iter()
        .copied()
        .rev()
        .max_by(|a, b| key(a).total_cmp(&key(b)))
}

fn of_kind<'a>(i: &'a Inspection, kind: &str) -> Vec<&'a StreamInfo> {
    i.streams
        .iter()
        .filter(|s| s.kind == kind && s.timing.records > 0)
        .collect()
}

/// The command line (`schuler nav --log …`), or why there is none.
pub fn suggest(path: &Path, i: &Inspection) -> (Option<Vec<String>>, Option<String>) {
    let imus = of_kind(i, "imu");
    let gnss = of_kind(i, "gnss");
    let Some(imu) = best(&imus, |s| s.timing.rate_hz) else {
        return (
            None,
            Some("no IMU stream with samples: nothing to navigate".into()),
        );
    };
    let Some(fix) = best(&gnss, |s| s.timing.records as f64) else {
        return (
            None,
            Some(
                "no GNSS fixes: a free-inertial run needs the start given by hand \
                 (schuler nav --log FILE --init-pos LAT,LON,H --init-att R,P,Y)"
                    .into(),
            ),
        );
    };
    if let (Some(last), Some(first)) = (imu.timing.t_last, fix.timing.t_first)
        && last < first
    {
        return (
            None,
            Some(format!(
                "the IMU stream {} ends (t = {last} s) before the first fix of {} (t = {first} s)",
                imu.name, fix.name
            )),
        );
    }
    let mut args: Vec<String> = ["schuler", "nav", "--log"].map(String::from).to_vec();
    args.push(path.display().to_string());
    let bag = i.format == "mcap" || i.format == "ros1-bag";
    if imus.len() > 1 {
        args.push(if bag { "--imu-topic" } else { "--imu-stream" }.into());
        args.push(imu.name.clone());
    }
    if gnss.len() > 1 {
        args.push(if bag { "--gnss-topic" } else { "--gnss-stream" }.into());
        args.push(fix.name.clone());
    }
    args.extend(["--imu-grade", "consumer-mems"].map(String::from));
    let note = start_args(i, imu, fix, &mut args);
    (Some(args), Some(note))
}

/// The start's flags (see the module's doc), and a note saying which was chosen.
fn start_args(
    i: &Inspection,
    imu: &StreamInfo,
    fix: &StreamInfo,
    args: &mut Vec<String>,
) -> String {
    let body_attitude = matches!(i.format, "ulog" | "dataflash" | "gnss-logger");
    let attitude = i
        .streams
        .iter()
        .filter_map(|s| s.reference.as_ref()?.first_attitude)
        .find(|_| body_attitude);
    let first = fix
        .gnss
        .as_ref()
        .and_then(|g| g.first.map(|p| (p, g.first_velocity)));
    let Some(([t_fix, lat, lon, h], vel)) = first else {
        // A bag's topics are not decoded by `inspect`: the start in motion.
        args.extend(["--init".into(), "gnss".into()]);
        return "starts in motion from the fixes (--init gnss); the vehicle must move within the log".into();
    };
    let v = vel.unwrap_or([0.0; 3]);
    let pos = format!("{lat:.9},{lon:.9},{h:.3}");
    if let Some([t, roll, pitch, yaw]) = attitude {
        args.extend([
            "--start".into(),
            format!("{t}"),
            "--init-pos".into(),
            pos,
            "--init-vel".into(),
            format!("{:.3},{:.3},{:.3}", v[0], v[1], v[2]),
            "--init-att".into(),
            format!("{roll:.3},{pitch:.3},{yaw:.3}"),
        ]);
        return format!(
            "starts at t = {t} s from the first fix and the device's own attitude at that time"
        );
    }
    let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if let Some(m) = imu
        .imu
        .as_ref()
        .filter(|m| m.at_rest_at_start && speed < REST_SPEED)
    {
        // FRD at rest: f = (g sin θ, −g sin φ cos θ, −g cos φ cos θ).
        let f = m.start_specific_force;
        let roll = (-f[1]).atan2(-f[2]).to_degrees();
        let pitch = f[0].atan2(f[1].hypot(f[2])).to_degrees();
        args.extend([
            "--start".into(),
            format!("{t_fix}"),
            "--init-pos".into(),
            pos,
            "--init-att".into(),
            format!("{roll:.3},{pitch:.3},0"),
            "--init-att-std".into(),
            "2,2,180".into(),
        ]);
        return format!(
            "at rest at the start: starts at the first fix (t = {t_fix} s), roll and pitch from \
             the specific force, the heading unknown (0 ± 180 deg: it stays so while the \
             vehicle does not move)"
        );
    }
    let init = if matches!(i.format, "gnss-logger" | "mcap" | "ros1-bag") {
        "gnss"
    } else {
        "gnss-any-heading"
    };
    args.extend(["--init".into(), init.into()]);
    format!("starts in motion from the fixes (--init {init}); the vehicle must move within the log")
}
