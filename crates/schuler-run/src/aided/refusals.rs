//! What the gate refused, by measurement kind, read back from the run's
//! `rejected.csv`, and the likely causes of each kind's refusals: a warning that
//! names the measurement refused instead of always blaming the IMU noise model.

use std::path::Path;

/// Gate refusals of each measurement kind in `dir/rejected.csv` (rows whose reason
/// is the chi-square gate), most refused first; empty when the file is absent
/// (a run without the diagnostics) or unreadable.
pub fn by_kind(dir: &Path) -> Vec<(String, u64)> {
    let Ok(text) = std::fs::read_to_string(dir.join("rejected.csv")) else {
        return Vec::new();
    };
    let mut counts: Vec<(String, u64)> = Vec::new();
    for row in text.lines().skip(1) {
        let mut f = row.split(',');
        let (Some(_), Some(kind), Some("chi-square gate")) = (f.next(), f.next(), f.next()) else {
            continue;
        };
        match counts.iter_mut().find(|(k, _)| k == kind) {
            Some((_, n)) => *n += 1,
            None => counts.push((kind.to_owned(), 1)),
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    counts
}

/// The likely causes of the gate refusing many measurements of `kind` (as
/// `rejected.csv` names it), with the options that set them.
pub fn likely_causes(kind: &str) -> &'static str {
    match kind {
        "gnss_position" => {
            "fixes far from the solution: a wrong lever arm (--lever-arm), a misread \
             column or swapped latitude and longitude, fixes of another time (--gnss-time-offset), \
             a standard deviation far too small (--gnss-std), or an IMU noise model too \
             optimistic (--imu-grade, --arw)"
        }
        "gnss_velocity" => {
            "velocities misread (columns, units, frame) or their standard deviation too small \
             (--gnss-vel-std)"
        }
        "baro_height" => {
            "the barometer's height column misread, its bias unmodelled (--baro-bias-std) or its \
             standard deviation too small (--baro-std)"
        }
        "zupt" | "zaru" => {
            "the vehicle was not at rest in the given intervals (--zupt), or their standard \
             deviation is too small (--zupt-std, --zaru-std)"
        }
        "nhc" => {
            "the IMU is not mounted along the vehicle (--mounting-angles) or the vehicle \
             slides (--nhc-std)"
        }
        "odometer" => {
            "the odometer's speed misread or scaled (--odometer-scale-std) or its standard \
             deviation too small (--odometer-std)"
        }
        "heading" => {
            "the dual-antenna baseline misaligned (--dual-antenna-baseline-yaw) or the \
             file's heading standard deviations too small (--dual-antenna)"
        }
        _ => "the measurement or its noise model is wrong",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_the_gate_refusals_by_kind() {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(
            dir.path().join("rejected.csv"),
            "t,measurement,reason,nis,threshold\n1,baro_height,chi-square gate,99,15\n\
             2,gnss_position,before the IMU data,,\n3,baro_height,chi-square gate,98,15\n\
             4,gnss_position,chi-square gate,50,21\n",
        )
        .expect("write");
        assert_eq!(
            by_kind(dir.path()),
            [
                ("baro_height".to_owned(), 2),
                ("gnss_position".to_owned(), 1)
            ]
        );
        assert!(by_kind(&dir.path().join("absent")).is_empty());
        assert!(likely_causes("baro_height").contains("--baro-std"));
    }
}
