//! Sensor-error files in KF-GINS's `IMU_ERR` layout, as `schuler nav` writes
//! `imu_err.txt`: `t gb_x gb_y gb_z ab_x ab_y ab_z [gs_x gs_y gs_z as_x as_y as_z]` —
//! gyro bias [deg/h], accelerometer bias [mGal], gyro and accelerometer scale factors
//! [ppm]; 7 or 13 columns, whitespace or commas. Read as the truth of the estimated
//! sensor errors (`--sensor-truth`), e.g. from a simulator that knows them.

use super::error::InputError;
use schuler::filter::SensorEstimates;
use schuler::units::{DEG_PER_H, MGAL, PPM};
use std::path::Path;

const FIELDS: [&str; 13] = [
    "time", "gb_x", "gb_y", "gb_z", "ab_x", "ab_y", "ab_z", "gs_x", "gs_y", "gs_z", "as_x", "as_y",
    "as_z",
];

/// Reads a sensor-error file whole: `(t, errors)` in time order, SI units (scale
/// factors zero where the file has 7 columns).
pub fn read_sensor_errors(path: &Path) -> Result<Vec<(f64, SensorEstimates)>, InputError> {
    let rows = super::gnss::numeric_rows(path, &FIELDS, &[7, 13], false)?;
    Ok(rows
        .into_iter()
        .map(|(_, v)| {
            let v3 = |o: usize, unit: f64| nalgebra::Vector3::new(v[o], v[o + 1], v[o + 2]) * unit;
            let mut e = SensorEstimates {
                gyro_bias: v3(1, DEG_PER_H),
                accel_bias: v3(4, MGAL),
                ..SensorEstimates::default()
            };
            if v.len() == 13 {
                e.gyro_scale = v3(7, PPM);
                e.accel_scale = v3(10, PPM);
            }
            (v[0], e)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_and_errors() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("err.txt");
        std::fs::write(
            &p,
            "# truth\n1.0 3600 0 0 1000 0 0\n2.0,0,0,0,0,0,0,0,0,100,0,0,-5\n",
        )
        .expect("write");
        let rows = read_sensor_errors(&p).expect("reads");
        // 3600 deg/h = 1 deg/s; 1000 mGal = 0.01 m/s^2; 100 and -5 ppm.
        assert!((rows[0].1.gyro_bias.x - 1f64.to_radians()).abs() < 1e-15);
        assert!((rows[0].1.accel_bias.x - 0.01).abs() < 1e-15);
        assert!((rows[1].1.gyro_scale.z - 1e-4).abs() < 1e-18);
        assert!((rows[1].1.accel_scale.z + 5e-6).abs() < 1e-18);
        std::fs::write(&p, "1.0 3600 0 0 1000 0 x\n").expect("write");
        let e = read_sensor_errors(&p).expect_err("bad").to_string();
        assert!(e.contains("err.txt:1: field ab_z: not a number"), "{e}");
    }
}
