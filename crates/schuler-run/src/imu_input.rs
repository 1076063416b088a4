//! How to read the IMU log, shared by `schuler nav` and `schuler align`: the file's
//! format, layout, column order, units, clock and axes, as flags and as keys of `nav
//! --config` (the same names with underscores, at the top level of the file).

use anyhow::{Context, Result, bail};
use schuler::imu::axes::SensorAxes;
use schuler::rotation::Euler;
use serde::Deserialize;
use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, Deserializer};

use crate::options::{FormatChoice, LayoutChoice, Triple, rate};
use schuler_io::formats::ImuReadOptions;
use schuler_io::formats::imu_columns::{AccelUnit, ColumnSpec, GyroUnit, TimeUnit};

/// The IMU log's reading options (see [`schuler_io::formats::imu_log`]).
#[derive(clap::Args, Debug, Default, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuInputOptions {
    /// IMU file format.
    #[arg(long, value_enum)]
    pub imu_format: Option<FormatChoice>,
    /// Whether the IMU columns hold increments or rates (default: as --gyro-unit,
    /// --accel-unit or the column names say; else increments for KF-GINS text, the
    /// header's names for CSV).
    #[arg(long, value_enum)]
    pub imu_layout: Option<LayoutChoice>,
    /// Nominal IMU rate [Hz] (default: estimated from the first intervals).
    #[arg(long, value_name = "HZ")]
    pub imu_rate: Option<f64>,
    /// Column order of an IMU file without a header (a header line is then skipped),
    /// e.g. t,fx,fy,fz,wx,wy,wz (rates) or t,dtx,dty,dtz,dvx,dvy,dvz (increments);
    /// `_` skips a column, a last `...` ignores further ones.
    #[arg(long, value_name = "NAMES")]
    pub imu_columns: Option<String>,
    /// Unit of the gyro columns: rad/s or deg/s (rates), rad or deg (increments).
    #[arg(long, value_name = "UNIT", value_parser = crate::options::named::<GyroUnit>())]
    pub gyro_unit: Option<GyroUnit>,
    /// Unit of the accelerometer columns: m/s^2 or g (rates), m/s (increments).
    #[arg(long, value_name = "UNIT", value_parser = crate::options::named::<AccelUnit>())]
    pub accel_unit: Option<AccelUnit>,
    /// Unit of the IMU time column: s, or integer ticks of ms, us, ns.
    #[arg(long, value_name = "UNIT", value_parser = crate::options::named::<TimeUnit>())]
    pub imu_time_unit: Option<TimeUnit>,
    /// Seconds added to the IMU's times after the unit conversion (a clock that starts
    /// at 0 put on the GNSS's time); --start and --end are on the shifted clock.
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    pub imu_time_offset: Option<f64>,
    /// Where the IMU's x, y, z axes point on the vehicle, three of F, B, R, L, U, D
    /// (FRD: as the vehicle, the default; RBD: x right, y back, z down; FLU: ROS REP
    /// 103); samples are turned into the vehicle's FRD axes, so attitudes are the
    /// vehicle's.
    #[arg(long, value_name = "XYZ")]
    pub imu_axes: Option<String>,
    /// The IMU's mounting on the vehicle, roll, pitch, yaw [deg]: the Z-Y-X rotation
    /// that turns the vehicle's FRD axes onto the IMU's axes (yaw about down, then pitch,
    /// then roll); samples are taken to FRD by C = Rz(yaw) Ry(pitch) Rx(roll), so
    /// 0,0,90 is an IMU whose x points right (as RBD), 180,0,0 one whose z points up
    /// (FLU). The opposite sense of --mounting-angles.
    #[arg(long, value_name = "R,P,Y", allow_hyphen_values = true)]
    pub imu_rotation: Option<Triple>,
    /// Skip the plausibility check of the IMU's first samples (specific force, angular
    /// rate, sample interval; for free fall, rockets, centrifuges).
    #[arg(long)]
    #[serde(default)]
    pub no_layout_check: bool,
}

impl ImuInputOptions {
    /// `self` with missing values taken from `other`.
    pub fn or(self, other: Self) -> Self {
        Self {
            imu_format: self.imu_format.or(other.imu_format),
            imu_layout: self.imu_layout.or(other.imu_layout),
            imu_rate: self.imu_rate.or(other.imu_rate),
            imu_columns: self.imu_columns.or(other.imu_columns),
            gyro_unit: self.gyro_unit.or(other.gyro_unit),
            accel_unit: self.accel_unit.or(other.accel_unit),
            imu_time_unit: self.imu_time_unit.or(other.imu_time_unit),
            imu_time_offset: self.imu_time_offset.or(other.imu_time_offset),
            imu_axes: self.imu_axes.or(other.imu_axes),
            imu_rotation: self.imu_rotation.or(other.imu_rotation),
            no_layout_check: self.no_layout_check || other.no_layout_check,
        }
    }

    /// The names of these options as configuration keys.
    pub fn keys() -> Vec<String> {
        use clap::Args;
        Self::augment_args(clap::Command::new("keys"))
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .collect()
    }

    /// Reads a configuration `text` whose top-level keys are these options' and
    /// `T`'s; errors carry TOML's line and column, and an unknown key's lists these
    /// options' keys too.
    pub fn split_config<T: DeserializeOwned>(text: &str) -> Result<(T, Self)> {
        let root = DeTable::parse(text)?;
        let span = root.span();
        let mut rest = root.into_inner();
        let keys = Self::keys();
        let mine_keys: Vec<_> = rest
            .keys()
            .filter(|k| keys.iter().any(|m| m == k.get_ref().as_ref()))
            .cloned()
            .collect();
        let mut mine = DeTable::new();
        for k in mine_keys {
            if let Some(v) = rest.remove(&k) {
                mine.insert(k, v);
            }
        }
        let read = |table| Deserializer::from(Spanned::new(span.clone(), table));
        let with_input = |mut e: toml::de::Error| {
            e.set_input(Some(text));
            e
        };
        let input = Self::deserialize(read(mine)).map_err(with_input)?;
        let other = T::deserialize(read(rest)).map_err(|e| {
            let e = with_input(e);
            if e.message().starts_with("unknown field") {
                anyhow::anyhow!("{e}(or one of the IMU input keys {})", keys.join(", "))
            } else {
                e.into()
            }
        })?;
        Ok((other, input))
    }

    /// The DCM from the IMU's axes to the vehicle's FRD, if not the identity.
    fn c_vs(&self) -> Result<Option<nalgebra::Matrix3<f64>>> {
        match (&self.imu_axes, self.imu_rotation) {
            (Some(_), Some(_)) => bail!(
                "give --imu-axes or --imu-rotation, not both (--imu-rotation alone turns \
                 the IMU any way: RBD is 0,0,90)"
            ),
            (Some(letters), None) => {
                let axes: SensorAxes = letters.parse().context("--imu-axes")?;
                Ok((!axes.is_frd()).then(|| axes.c_vs()))
            }
            (None, Some(Triple([r, p, y]))) => Ok(Some(Euler::from_degrees(r, p, y).to_dcm())),
            (None, None) => Ok(None),
        }
    }

    /// The reader's options, with the time window `t_start`, `t_end`; each value
    /// checked, errors naming the flag.
    pub fn read_options(&self, t_start: Option<f64>, t_end: Option<f64>) -> Result<ImuReadOptions> {
        let imu_rate = rate("imu-rate", &schuler::domain::IMU_RATE, self.imu_rate)?;
        let offset = self.imu_time_offset;
        crate::options::opt_in_domain("--imu-time-offset", &schuler::domain::TIME, offset)?;
        let columns = match &self.imu_columns {
            Some(text) => Some(
                ColumnSpec::parse(text)
                    .map_err(anyhow::Error::msg)
                    .with_context(|| format!("--imu-columns {text:?}"))?,
            ),
            None => None,
        };
        Ok(ImuReadOptions {
            format: self.imu_format.unwrap_or_default().format(),
            layout: self.imu_layout.map(LayoutChoice::layout),
            columns,
            gyro_unit: self.gyro_unit,
            accel_unit: self.accel_unit,
            time_unit: self.imu_time_unit,
            time_offset: self.imu_time_offset.unwrap_or(0.0),
            c_vs: self.c_vs()?,
            nominal_dt: imu_rate.map(|r| 1.0 / r),
            t_start,
            t_end,
            check_layout: !self.no_layout_check,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    #[test]
    fn keys_are_the_flags() {
        let keys = ImuInputOptions::keys();
        assert!(keys.contains(&"imu_time_offset".to_owned()), "{keys:?}");
        assert!(keys.contains(&"no_layout_check".to_owned()), "{keys:?}");
        assert_eq!(keys.len(), 11);
    }

    #[test]
    fn config_keys_read_and_leave_the_rest() {
        let (rest, o): (toml::Table, _) = ImuInputOptions::split_config(
            r#"
            imu = "IMU.txt"
            imu_columns = "t,fx,fy,fz,wx,wy,wz"
            gyro_unit = "deg/s"
            accel_unit = "g"
            imu_time_unit = "ns"
            imu_time_offset = 345600
            imu_axes = "RBD"
            no_layout_check = true
            "#,
        )
        .expect("keys");
        assert_eq!(rest.len(), 1, "imu stays for nav's own keys");
        assert_eq!(o.gyro_unit, Some(GyroUnit::DegPerSecond));
        assert_eq!(o.accel_unit, Some(AccelUnit::G));
        assert_eq!(o.imu_time_unit, Some(TimeUnit::Ns));
        let r = o.read_options(None, None).expect("valid");
        assert_eq!(r.time_offset, 345600.0);
        assert!(!r.check_layout);
        assert_eq!(
            r.c_vs,
            Some(Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0))
        );
        let bad = ImuInputOptions::split_config::<toml::Table>("a = 1\ngyro_unit = \"deg/h\"\n");
        let e = format!("{:#}", bad.expect_err("unknown unit"));
        assert!(e.contains("line 2, column 13"), "{e}");
    }

    #[test]
    fn flags_are_checked() {
        let err =
            |o: ImuInputOptions| format!("{:#}", o.read_options(None, None).expect_err("bad"));
        let e = err(ImuInputOptions {
            imu_axes: Some("FRU".into()),
            ..Default::default()
        });
        assert!(
            e.starts_with("--imu-axes: \"FRU\" is a left-handed frame"),
            "{e}"
        );
        let e = err(ImuInputOptions {
            imu_axes: Some("ENU".into()),
            ..Default::default()
        });
        assert!(e.contains("direction on the Earth"), "{e}");
        let e = err(ImuInputOptions {
            imu_axes: Some("RBD".into()),
            imu_rotation: Some(Triple([0.0, 0.0, 90.0])),
            ..Default::default()
        });
        assert!(e.contains("not both"), "{e}");
        let e = err(ImuInputOptions {
            imu_columns: Some("t,wx,wy,wz,dvx,dvy,dvz".into()),
            ..Default::default()
        });
        assert!(e.contains("--imu-columns") && e.contains("mixed"), "{e}");
        // The rotation's sense: yaw 90 deg is an IMU whose x points right.
        let r = ImuInputOptions {
            imu_rotation: Some(Triple([0.0, 0.0, 90.0])),
            ..Default::default()
        }
        .read_options(None, None)
        .expect("rotation");
        let c = r.c_vs.expect("not identity");
        let x_imu_in_frd = c * nalgebra::Vector3::x();
        assert!((x_imu_in_frd - nalgebra::Vector3::y()).norm() < 1e-15);
        // FRD is no rotation at all.
        let r = ImuInputOptions {
            imu_axes: Some("FRD".into()),
            ..Default::default()
        }
        .read_options(None, None)
        .expect("identity");
        assert_eq!(r.c_vs, None);
    }
}
