//! What each reader says of its file (dropouts, a cut tail, skipped bytes, how its
//! clock was tied to GPS time), as lines for `inspect`.

use schuler_io::logs::dataflash::DataflashReport;
use schuler_io::logs::gnss_logger::{ClockTie, GnssLoggerStats};
use schuler_io::logs::ubx::UbxReport;
use schuler_io::logs::ulog::UlogReport;

/// Pushes `text` when `n` is not zero.
fn count(out: &mut Vec<String>, n: u64, text: &str) {
    if n > 0 {
        out.push(format!("{n} {text}"));
    }
}

/// A ULog's.
pub fn ulog(r: &UlogReport) -> Vec<String> {
    let mut out = Vec::new();
    out.push(match &r.gps_tie {
        Some(_) => "clock tied to GPS time at the first 3-D fix with a UTC time".to_owned(),
        None => "no GNSS fix with a UTC time: times are the autopilot's (s since boot)".to_owned(),
    });
    if r.dropouts > 0 {
        out.push(format!(
            "{} dropouts (the logger lost data): {:.3} s in all, the longest {:.3} s",
            r.dropouts, r.dropout_total_s, r.dropout_longest_s
        ));
    }
    if r.imu_gaps > 0 {
        out.push(format!(
            "{} gaps of the IMU stream, {:.3} s uncovered",
            r.imu_gaps, r.imu_gap_s
        ));
    }
    count(
        &mut out,
        u64::from(r.gnss_without_fix),
        "GNSS messages without a 3-D fix (not used)",
    );
    count(
        &mut out,
        u64::from(r.log_warnings),
        "log messages of level warning or worse",
    );
    count(
        &mut out,
        u64::from(r.reference_invalid),
        "reference samples not valid (not used)",
    );
    out
}

/// A UBX log's.
pub fn ubx(r: &UbxReport) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(t) = &r.truncated_tail {
        out.push(format!(
            "the file ends inside a frame{} at byte offset {} ({} of {} bytes)",
            t.name
                .as_deref()
                .map(|n| format!(" of {n}"))
                .unwrap_or_default(),
            t.offset,
            t.have,
            t.need
        ));
    }
    count(
        &mut out,
        r.unknown_bytes,
        "bytes that begin no frame (skipped)",
    );
    count(&mut out, r.corrupt_frames, "corrupt frames skipped");
    count(&mut out, r.pvt_without_fix, "NAV-PVT without a usable fix");
    count(
        &mut out,
        r.imu_restarts,
        "IMU stream restarts (gaps or time tags going back)",
    );
    count(
        &mut out,
        r.imu_untied,
        "IMU samples left out: no NAV-PVT tied their clock to GPS time",
    );
    out
}

/// A DataFlash log's.
pub fn dataflash(r: &DataflashReport) -> Vec<String> {
    let mut out = Vec::new();
    out.push(match &r.gps_tie {
        Some(t) => format!(
            "clock tied to GPS time at the GPS message of TimeUS {} (week {})",
            t.device_us, t.week
        ),
        None => {
            "no GPS message with a 3-D fix and a week: times are the autopilot's (s since boot)"
                .to_owned()
        }
    });
    if let Some(t) = &r.ending.truncated {
        out.push(format!("the file ends inside a message: {t:?}"));
    }
    count(
        &mut out,
        r.ending.garbage_bytes,
        "bytes of garbage at the end",
    );
    count(
        &mut out,
        r.gnss_without_fix,
        "GPS messages without a 3-D fix",
    );
    count(
        &mut out,
        r.gnss_without_accuracy,
        "fixes without GPA or accuracies (not used)",
    );
    count(
        &mut out,
        r.gnss_msl_height,
        "fixes with heights above mean sea level (no AEl)",
    );
    count(
        &mut out,
        r.reference_without_origin,
        "reference samples before the EKF origin (no position)",
    );
    out
}

/// A GnssLogger log's.
pub fn gnss_logger(tie: ClockTie, s: &GnssLoggerStats) -> Vec<String> {
    let mut out = vec![format!(
        "sensor clock tied to GPS time by {}",
        match tie {
            ClockTie::RawChipset => "the Raw rows' ChipsetElapsedRealtimeNanos",
            ClockTie::GpsFix => "the GPS fixes' elapsedRealtimeNanos",
            ClockTie::WallClock => "the phone's wall clock (good to milliseconds)",
        }
    )];
    count(
        &mut out,
        s.other_provider_fixes,
        "fixes of providers other than GPS (not used)",
    );
    count(
        &mut out,
        s.raw_invalid_state,
        "Raw rows without a valid measurement",
    );
    count(
        &mut out,
        s.clock_discontinuities,
        "hardware clock discontinuities",
    );
    count(
        &mut out,
        s.pairing.gaps,
        "gaps in the gyro events (not integrated across)",
    );
    out
}
