//! The KF-GINS YAML configuration the benchmarks write (`kf_gins_drop_in`, `memory`).

use std::path::Path;

/// The runs' first time, KF-GINS's `starttime` [s of week].
pub const T0: f64 = 86_400.0;

/// KF-GINS's configuration of a run from `T0` at the given initial position [deg,
/// deg, m], velocity [m/s] and attitude [deg], reading `dir/imu.txt` and
/// `dir/gnss.txt` and writing into `dir/out`.
pub fn yaml(dir: &Path, lat: f64, lon: f64, h: f64, v: [f64; 3], att: [f64; 3]) -> String {
    let d = dir.display();
    format!(
        "imupath: \"{d}/imu.txt\"\ngnsspath: \"{d}/gnss.txt\"\noutputpath: \"{d}/out\"\n\
         imudatalen: 7\nimudatarate: 200\nstarttime: {T0}\nendtime: -1\n\
         initpos: [ {lat:.12}, {lon:.12}, {h:.6} ]\ninitvel: [ {}, {}, {} ]\n\
         initatt: [ {}, {}, {} ]\ninitgyrbias: [ 0, 0, 0 ]\ninitaccbias: [ 0, 0, 0 ]\n\
         initgyrscale: [ 0, 0, 0 ]\ninitaccscale: [ 0, 0, 0 ]\n\
         initposstd: [ 0.1, 0.1, 0.1 ]\ninitvelstd: [ 0.01, 0.01, 0.01 ]\n\
         initattstd: [ 0.01, 0.01, 0.01 ]\n\
         imunoise:\n  arw: [0.1, 0.1, 0.1]\n  vrw: [0.1, 0.1, 0.1]\n  gbstd: [1.0, 1.0, 1.0]\n\
         \x20 abstd: [100.0, 100.0, 100.0]\n  gsstd: [300.0, 300.0, 300.0]\n\
         \x20 asstd: [300.0, 300.0, 300.0]\n  corrtime: 1.0\nantlever: [ 0.0, 0.0, 0.0 ]\n",
        v[0], v[1], v[2], att[0], att[1], att[2]
    )
}
