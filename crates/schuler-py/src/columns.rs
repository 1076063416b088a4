//! Tables built row by row in Rust and handed to Python as a dict of numpy arrays (one
//! per column, moved, not copied), from which the Python layer makes DataFrames.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Numeric columns with fixed names (units in the names).
#[derive(Debug, Clone)]
pub struct Columns {
    names: Vec<&'static str>,
    data: Vec<Vec<f64>>,
}

impl Columns {
    /// Empty columns named `names`.
    pub fn new(names: &[&'static str]) -> Self {
        Self {
            names: names.to_vec(),
            data: vec![Vec::new(); names.len()],
        }
    }

    /// Empty columns named by the lists `parts` one after the other (a table that
    /// extends another's columns, e.g. the simulated fixes' `outlier` after [`GNSS`]).
    pub fn joined(parts: &[&[&'static str]]) -> Self {
        Self::new(&parts.concat())
    }

    /// Appends one row: `first` then `rest`, as many values as there are columns.
    pub fn push(&mut self, first: f64, rest: &[f64]) {
        debug_assert_eq!(rest.len() + 1, self.names.len());
        for (col, x) in self
            .data
            .iter_mut()
            .zip(std::iter::once(first).chain(rest.iter().copied()))
        {
            col.push(x);
        }
    }

    /// Moves the columns into `dict` as numpy arrays, leaving them empty.
    pub fn drain_into(&mut self, dict: &Bound<'_, PyDict>) -> PyResult<()> {
        for (name, col) in self.names.iter().zip(self.data.iter_mut()) {
            dict.set_item(*name, std::mem::take(col).into_pyarray(dict.py()))?;
        }
        Ok(())
    }

    /// The columns as a new dict of numpy arrays, leaving them empty.
    pub fn take_dict<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        self.drain_into(&d)?;
        Ok(d)
    }
}

/// Columns of a navigation result: time and [`schuler_io::output::nav_fields`].
pub const NAV: &[&str] = &[
    "t_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "vn_mps",
    "ve_mps",
    "vd_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
];

/// Columns of the standard deviations, as `std.txt` ([`schuler_run::drive::std_row`]).
pub const STD: &[&str] = &[
    "t_s",
    "std_n_m",
    "std_e_m",
    "std_d_m",
    "std_vn_mps",
    "std_ve_mps",
    "std_vd_mps",
    "std_roll_deg",
    "std_pitch_deg",
    "std_yaw_deg",
    "std_gyro_bias_x_degph",
    "std_gyro_bias_y_degph",
    "std_gyro_bias_z_degph",
    "std_accel_bias_x_mgal",
    "std_accel_bias_y_mgal",
    "std_accel_bias_z_mgal",
    "std_gyro_scale_x_ppm",
    "std_gyro_scale_y_ppm",
    "std_gyro_scale_z_ppm",
    "std_accel_scale_x_ppm",
    "std_accel_scale_y_ppm",
    "std_accel_scale_z_ppm",
];

/// Columns of the sensor-error estimates, as `imu_err.txt`
/// ([`schuler_run::drive::imu_err_row`]).
pub const SENSOR: &[&str] = &[
    "t_s",
    "gyro_bias_x_degph",
    "gyro_bias_y_degph",
    "gyro_bias_z_degph",
    "accel_bias_x_mgal",
    "accel_bias_y_mgal",
    "accel_bias_z_mgal",
    "gyro_scale_x_ppm",
    "gyro_scale_y_ppm",
    "gyro_scale_z_ppm",
    "accel_scale_x_ppm",
    "accel_scale_y_ppm",
    "accel_scale_z_ppm",
];

/// Numeric columns of the innovations, as `innovations.csv` (its `kind` apart);
/// components past `dof` are NaN.
pub const INNOVATIONS: &[&str] = &[
    "t_s", "accepted", "dof", "nis", "z_1", "z_2", "z_3", "sigma_1", "sigma_2", "sigma_3",
];

/// Columns of IMU samples: the interval's end and length, the increments over it.
pub const IMU: &[&str] = &[
    "t_s",
    "dt_s",
    "dtheta_x_rad",
    "dtheta_y_rad",
    "dtheta_z_rad",
    "dvel_x_mps",
    "dvel_y_mps",
    "dvel_z_mps",
];

/// Columns of GNSS fixes (velocity columns NaN where a fix has none).
pub const GNSS: &[&str] = &[
    "t_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "std_n_m",
    "std_e_m",
    "std_d_m",
    "vn_mps",
    "ve_mps",
    "vd_mps",
    "std_vn_mps",
    "std_ve_mps",
    "std_vd_mps",
];

/// Columns of an alignment's convergence, as `align_convergence.csv`
/// ([`schuler_run::alignment::convergence_row`]).
pub const CONVERGENCE: &[&str] = &[
    "t_s",
    "roll_std_deg",
    "pitch_std_deg",
    "yaw_std_deg",
    "gyro_bias_std_x_degph",
    "gyro_bias_std_y_degph",
    "gyro_bias_std_z_degph",
    "accel_bias_std_x_mgal",
    "accel_bias_std_y_mgal",
    "accel_bias_std_z_mgal",
];
