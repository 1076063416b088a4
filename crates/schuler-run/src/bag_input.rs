//! A ROS 1 or ROS 2 bag as a navigation run's input (`schuler nav --bag`) (its IMU, GNSS,
//! velocity, barometer and odometry topics, [`schuler_io::bag::input`]) and `--out-bag`, the
//! result as a bag ([`schuler_io::bag::output`]). The IMU's mounting comes from the bag's
//! `/tf_static` (the IMU's frame up to `--base-frame`, default its parent), else its axes
//! are FLU (REP 103); `--imu-axes`/`--imu-rotation` given by hand win over the transform
//! tree (the run says so), and are refused together with `--base-frame`; `--imu-time-offset` shifts every
//! topic's stamps (a bag has one clock); `--gnss-std` and `--gnss-vel-std` stand in
//! for missing covariances; the IMU's covariances give the noise model where
//! `--arw`/`--vrw` are not given.

use crate::nav::NavPlan;
use crate::options::Triple;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::units::{Dimension, parse_as_or_si};
use schuler_io::bag::input::{BagPlan, BagReadOptions, flu_to_frd, plan};
use std::path::PathBuf;

/// The bag flags of `schuler nav`, also the keys of `--config` with underscores
/// (`bag = "run.mcap"`, `imu_topic = "/imu/data"`, `out_bag = "nav.mcap"`; flags win).
#[derive(clap::Args, Debug, Default, Clone, PartialEq)]
pub struct BagArgs {
    /// A ROS bag as the input: ROS 1 (.bag, format 2.0) or ROS 2 (.mcap file or
    /// rosbag2 directory), told by content: sensor_msgs/Imu, NavSatFix, FluidPressure,
    /// geometry_msgs/TwistWithCovarianceStamped (GNSS velocity, ENU) and
    /// nav_msgs/Odometry topics, found by type; the IMU's mounting from /tf_static.
    #[arg(long, value_name = "BAG", conflicts_with = "imu")]
    pub bag: Option<PathBuf>,
    /// The IMU topic, when the bag has several.
    #[arg(long, value_name = "TOPIC")]
    pub imu_topic: Option<String>,
    /// The NavSatFix topic, when the bag has several (`none`: no GNSS).
    #[arg(long, value_name = "TOPIC")]
    pub gnss_topic: Option<String>,
    /// The GNSS velocity topic (TwistWithCovarianceStamped, ENU), when several.
    #[arg(long, value_name = "TOPIC")]
    pub gnss_vel_topic: Option<String>,
    /// The FluidPressure topic, when several.
    #[arg(long, value_name = "TOPIC")]
    pub baro_topic: Option<String>,
    /// The Odometry topic (forward speed), when several.
    #[arg(long, value_name = "TOPIC")]
    pub odom_topic: Option<String>,
    /// The robot's body frame in the bag's /tf_static (its axes FLU by REP 103): the
    /// IMU's mounting is the rotation from the IMU messages' frame_id up to it
    /// (default: the IMU frame's parent). Not with --imu-axes/--imu-rotation.
    #[arg(long, value_name = "FRAME")]
    pub base_frame: Option<String>,
    /// GPS - UTC [s] for a bag whose header stamps are UNIX time (default: the
    /// leap seconds of each stamp's date, 18 since 2017-01-01).
    #[arg(long, value_name = "SECONDS")]
    pub leap_seconds: Option<i64>,
    /// Also write the result as a ROS 2 bag (MCAP): nav_msgs/Odometry (pose in ENU),
    /// sensor_msgs/NavSatFix and the sensor-error estimates (any IMU input).
    #[arg(long, value_name = "FILE.mcap")]
    pub out_bag: Option<PathBuf>,
}

impl BagArgs {
    /// `self` (the flags) with what they lack taken from `other` (the configuration).
    pub fn or(self, other: BagArgs) -> BagArgs {
        BagArgs {
            bag: self.bag.or(other.bag),
            imu_topic: self.imu_topic.or(other.imu_topic),
            gnss_topic: self.gnss_topic.or(other.gnss_topic),
            gnss_vel_topic: self.gnss_vel_topic.or(other.gnss_vel_topic),
            baro_topic: self.baro_topic.or(other.baro_topic),
            odom_topic: self.odom_topic.or(other.odom_topic),
            base_frame: self.base_frame.or(other.base_frame),
            out_bag: self.out_bag.or(other.out_bag),
            leap_seconds: self.leap_seconds.or(other.leap_seconds),
        }
    }

    /// The paths relative to `base` (a configuration file's folder).
    pub fn relative_to(mut self, base: &std::path::Path) -> BagArgs {
        for p in [&mut self.bag, &mut self.out_bag].into_iter().flatten() {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        self
    }
}

/// The reading options of the run's flags.
pub fn read_options(plan: &NavPlan, args: &BagArgs, axes_given: bool) -> Result<BagReadOptions> {
    let read = &plan.settings.read;
    let a = &plan.aiding;
    if axes_given && let Some(frame) = &args.base_frame {
        bail!(
            "--base-frame {frame} takes the IMU's mounting from the bag's /tf_static; \
             --imu-axes and --imu-rotation give it by hand: give one"
        );
    }
    let default_gnss_std = match a.gnss_std {
        Some(Triple(s)) if s.iter().all(|&x| x > 0.0) => Some(Vector3::from(s)),
        Some(Triple(s)) => bail!("--gnss-std must be positive, got {s:?}"),
        None => None,
    };
    let default_vel_std = match &a.gnss_vel_std {
        Some(text) => parse_as_or_si(text.trim(), Dimension::Velocity)?,
        None => 0.1,
    };
    Ok(BagReadOptions {
        topics: [
            args.imu_topic.clone(),
            args.gnss_topic.clone(),
            args.gnss_vel_topic.clone(),
            args.baro_topic.clone(),
            args.odom_topic.clone(),
        ],
        c_vs: match (axes_given, read.c_vs) {
            (false, _) => flu_to_frd(),
            (true, c) => c.unwrap_or_else(nalgebra::Matrix3::identity),
        },
        axes_given,
        base_frame: args.base_frame.clone(),
        time_offset: read.time_offset,
        t_start: read.t_start,
        t_end: read.t_end,
        default_gnss_std,
        default_vel_std,
        leap_seconds: args.leap_seconds,
        check_layout: read.check_layout,
    })
}

/// [`plan`] with the error as anyhow's.
pub fn plan_bag(path: &std::path::Path, options: &BagReadOptions) -> Result<BagPlan> {
    Ok(plan(path, options)?)
}
