//! The drive with raw GNSS observations (examples/drive_raw.toml): its windows and
//! fault as stated, the files `schuler simulate` writes read back by our readers,
//! and single-point solutions of them against the written truth.

use std::path::{Path, PathBuf};

use schuler::gnss::spp::{self, SppConfig};
use schuler::gnss::{GpsTime, Sat, System};
use schuler::sim::raw_gnss::trajectory::simulate_raw;
use schuler_io::formats::rinex::nav::read_store;
use schuler_io::formats::rinex::obs::{Epoch, ObsReader};
use schuler_io::formats::rinex::raw::raw_epoch;
use schuler_run::scenario::load_scenario;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive_raw.toml")
}

/// The whole drive's raw epochs: 3 satellites in 353200–353260 s, 2 in
/// 353260–353290 s, at least 5 elsewhere; G17's pseudorange 50 m off for the 20 s
/// of its fault (against the same drive without it: same seed, same draws) and
/// nothing else changed.
#[test]
fn the_drive_has_its_windows_and_its_fault() {
    let spec = load_scenario(&example()).expect("scenario");
    let data = spec
        .gnss
        .as_ref()
        .unwrap()
        .raw
        .as_ref()
        .unwrap()
        .data
        .clone()
        .unwrap();
    let epochs = simulate_raw(&spec, &data).expect("simulated");
    assert!(epochs.len() > 1000, "{}", epochs.len());
    let mut clean = spec.clone();
    clean
        .gnss
        .as_mut()
        .unwrap()
        .raw
        .as_mut()
        .unwrap()
        .fault
        .clear();
    let reference = simulate_raw(&clean, &data).expect("simulated");
    let week = GpsTime::new(1590, 0.0);
    let g17 = Sat::new(System::Gps, 17);
    let (mut three, mut two, mut stepped) = (0, 0, 0);
    for (e, r) in epochs.iter().zip(&reference) {
        let t = e.epoch.t.diff_s(week);
        let n = e.epoch.sats().len();
        if (353_200.0..353_260.0).contains(&t) {
            assert_eq!(n, 3, "t = {t}");
            three += 1;
        } else if (353_260.0..353_290.0).contains(&t) {
            assert_eq!(n, 2, "t = {t}");
            two += 1;
        } else {
            assert!(n >= 5, "t = {t}: {n}");
        }
        for (m, c) in e.epoch.measurements.iter().zip(&r.epoch.measurements) {
            let d = m.pseudorange.unwrap() - c.pseudorange.unwrap();
            if m.sat == g17 && (353_600.0..353_620.0).contains(&t) {
                assert!((d - 50.0).abs() < 1e-7, "{d}");
                stepped += 1;
            } else {
                assert_eq!(d, 0.0);
            }
        }
    }
    assert_eq!((three, two, stepped), (60, 30, 20));
}

/// `simulate_to_dir` on the drive's first minute at rest: `gnss_obs.rnx` and
/// `gnss_nav.rnx` read by our readers, each epoch solved by SPP with FDE: the
/// position within 5 m of `gnss_raw_truth.csv`'s (code noise 0.3–1.7 m, multipath
/// 0.4 m, 20 % of the ionosphere left, 1–3 m; a bound of about 5σ of the
/// horizontal and vertical errors) and the clock bias within 30 m of c·δt_r.
#[test]
fn the_written_files_read_back_and_solve() {
    let mut spec = load_scenario(&example()).expect("scenario");
    spec.motion.truncate(1);
    spec.imu.rate_hz = 10.0;
    let dir = tempfile::tempdir().unwrap();
    schuler_run::simulate::simulate_to_dir(&spec, dir.path()).expect("simulated");
    let (_, klobuchar, store) = read_store(&dir.path().join("gnss_nav.rnx")).expect("nav");
    let truth = std::fs::read_to_string(dir.path().join("gnss_raw_truth.csv")).unwrap();
    let rows: Vec<Vec<f64>> = truth
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let mut reader = ObsReader::open(&dir.path().join("gnss_obs.rnx")).expect("obs");
    let mut e = Epoch::default();
    let mut k = 0;
    while reader.read_epoch(&mut e).expect("epoch") {
        let raw = raw_epoch(&e, &[]).unwrap();
        let row = &rows[k];
        assert_eq!(raw.t.sow, row[0]);
        let sol = spp::solve(
            &raw,
            &store,
            klobuchar.as_ref(),
            &SppConfig::default(),
            None,
        )
        .expect("solved");
        let truth = nalgebra::Vector3::new(row[4], row[5], row[6]);
        assert!(
            (sol.r_e - truth).norm() < 5.0,
            "{k}: {}",
            (sol.r_e - truth).norm()
        );
        let b = sol.clock_of(System::Gps).unwrap();
        assert!(
            (b - schuler::gnss::C * row[2]).abs() < 30.0,
            "{b} {}",
            row[2]
        );
        k += 1;
    }
    assert_eq!(k, rows.len());
    assert!(k >= 60, "{k}");
}
