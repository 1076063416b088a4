//! A bag as the session's input: the topics chosen by type (or by name when several
//! have it), the aids read in a first pass (GNSS fixes with their velocities,
//! barometer heights, odometer speeds), then the IMU samples streamed in a second.
//!
//! # Frames and units (REP 103, REP 105)
//! - `sensor_msgs/Imu`: angular rate [rad/s] and specific force [m/s²] in the IMU's
//!   axes, FLU by REP 103 unless told otherwise ([`BagReadOptions::c_vs`]); a sample
//!   stamped `t` is taken as the mean rate over `(t_prev, t]`, so `dθ = ω·dt`,
//!   `dv = f·dt` (the rectangular rule of the text readers), then turned to FRD.
//!   The covariance diagonals, when given, are the white noise of one sample:
//!   `ARW = σ_ω·√dt`, `VRW = σ_f·√dt` (a rate's white noise of density N averages over
//!   dt to a standard deviation N/√dt).
//! - `sensor_msgs/NavSatFix`: latitude, longitude [deg], height above the WGS 84
//!   ellipsoid [m]; the covariance is ENU, so `σ_N² = C[4]`, `σ_E² = C[0]`,
//!   `σ_D² = C[8]`. `NO_FIX` messages are skipped and counted.
//! - `geometry_msgs/TwistWithCovarianceStamped`: the receiver's velocity in ENU,
//!   `v_N = y, v_E = x, v_D = −z`, joined to the fix of the same stamp (within 1 µs).
//! - `sensor_msgs/FluidPressure` [Pa]: the height of the ISA troposphere
//!   ([`isa_height`]).
//! - `nav_msgs/Odometry`: the forward speed `twist.twist.linear.x` of the child frame.
//! - `tf2_msgs/TFMessage` on `/tf_static`: the IMU's mounting ([`Mounting`],
//!   [`super::tf`]): the rotation from the IMU message's `frame_id` up to the base
//!   frame (`--base-frame`, default the IMU frame's parent), then FLU to FRD, unless
//!   the IMU's axes are given by hand.
//!
//! ROS 1 bags and ROS 2 bags read alike: the types match as `pkg/Name` or
//! `pkg/msg/Name`, and each topic's messages decode in its own serialization
//! ([`Encoding`]).
//!
//! Every time is the header stamp on the run's clock ([`StampClock`]: UNIX stamps as
//! GPS seconds of week, stamps before 1980 as they are) plus
//! [`BagReadOptions::time_offset`] (one clock for every topic of a bag).

use super::BagError;
use super::clock::StampClock;
use super::container::{BagStream, Message, Topic};
use super::info::{TopicSummary, scan};
use super::messages::{
    Decode, Encoding, FLUID_PRESSURE, FluidPressure, IMU, Imu, ImuMotion, NAV_SAT_FIX, NavSatFix,
    ODOMETRY, Odometry, STATUS_NO_FIX, TF_MESSAGE, TWIST, TfMessage, TwistStamped, same_type,
};
use super::tf::{TfTree, frame_name};
use crate::formats::imu_log::{GAP_FACTOR, GapReport};
use nalgebra::{Matrix3, Vector3};
use schuler::domain;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The kinds of topic a run reads, with their message type and the flag that
/// chooses among several.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// IMU.
    Imu,
    /// GNSS position.
    Gnss,
    /// GNSS velocity.
    GnssVel,
    /// Barometer.
    Baro,
    /// Wheel odometry.
    Odometry,
}

impl Kind {
    /// Every kind.
    pub const ALL: [Kind; 5] = [
        Kind::Imu,
        Kind::Gnss,
        Kind::GnssVel,
        Kind::Baro,
        Kind::Odometry,
    ];

    /// The message type of its topics.
    pub fn type_name(self) -> &'static str {
        match self {
            Kind::Imu => IMU,
            Kind::Gnss => NAV_SAT_FIX,
            Kind::GnssVel => TWIST,
            Kind::Baro => FLUID_PRESSURE,
            Kind::Odometry => ODOMETRY,
        }
    }

    /// The flag that names its topic.
    pub fn flag(self) -> &'static str {
        match self {
            Kind::Imu => "--imu-topic",
            Kind::Gnss => "--gnss-topic",
            Kind::GnssVel => "--gnss-vel-topic",
            Kind::Baro => "--baro-topic",
            Kind::Odometry => "--odom-topic",
        }
    }

    fn index(self) -> usize {
        self as usize
    }

    /// The kind whose type `type_name` is (ROS 1 or ROS 2 spelling).
    pub fn of_type(type_name: &str) -> Option<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| same_type(type_name, k.type_name()))
    }
}

/// The topic the static transforms are read from.
pub const TF_STATIC: &str = "/tf_static";

/// Where the IMU's axes were taken from.
#[derive(Debug, Clone, PartialEq)]
pub enum Mounting {
    /// The bag's `/tf_static`: the IMU message's frame up to the base frame.
    Tf {
        /// The IMU messages' `frame_id`.
        imu_frame: String,
        /// The base frame (FLU).
        base_frame: String,
    },
    /// `--imu-axes`/`--imu-rotation`, over the transform tree's when it had the IMU's
    /// frame (`tf_ignored`: that frame's parent).
    Given {
        /// The base frame the tree would have given.
        tf_ignored: Option<String>,
    },
    /// REP 103: the IMU's axes FLU, as the tree does not place the IMU's frame
    /// (`imu_frame`, when the messages name one).
    Flu {
        /// The IMU messages' `frame_id`.
        imu_frame: Option<String>,
    },
}

/// How a bag is read.
#[derive(Debug, Clone, PartialEq)]
pub struct BagReadOptions {
    /// The topic of each [`Kind`] (by [`Kind::index`]) when named; `"none"` reads none.
    pub topics: [Option<String>; 5],
    /// From the IMU message's axes to the vehicle's FRD (FLU by default:
    /// `diag(1, −1, −1)`), used when `axes_given` or when `/tf_static` does not place
    /// the IMU's frame.
    pub c_vs: Matrix3<f64>,
    /// Whether `c_vs` was given by hand (then it wins over `/tf_static`).
    pub axes_given: bool,
    /// The base frame of the mounting from `/tf_static` (`None`: the parent of the
    /// IMU's frame); an error when `axes_given`.
    pub base_frame: Option<String>,
    /// Seconds added to every stamp.
    pub time_offset: f64,
    /// First and last IMU time read [s, after the offset].
    pub t_start: Option<f64>,
    /// Last IMU time read.
    pub t_end: Option<f64>,
    /// Position standard deviations N, E, D [m] for fixes without a covariance.
    pub default_gnss_std: Option<Vector3<f64>>,
    /// Velocity standard deviation [m/s] for velocities without a covariance.
    pub default_vel_std: f64,
    /// GPS − UTC [s] for UNIX stamps (`None`: the leap-second table).
    pub leap_seconds: Option<i64>,
    /// Run the plausibility check of the IMU's first messages (as the text reader's).
    pub check_layout: bool,
}

impl Default for BagReadOptions {
    fn default() -> Self {
        Self {
            topics: Default::default(),
            c_vs: flu_to_frd(),
            axes_given: false,
            base_frame: None,
            time_offset: 0.0,
            t_start: None,
            t_end: None,
            default_gnss_std: None,
            default_vel_std: 0.1,
            leap_seconds: None,
            check_layout: true,
        }
    }
}

pub use super::tf::flu_to_frd;

/// The aids a bag holds, in the session's frames and units.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BagAids {
    /// GNSS fixes in time order, with velocities where a twist had the same stamp.
    pub fixes: Vec<GnssFix>,
    /// `NO_FIX` messages skipped.
    pub no_fix: u64,
    /// Velocity messages without a fix at their stamp (not used).
    pub unmatched_velocities: u64,
    /// Barometer heights `(t, h)` [s, m].
    pub baro: Vec<(f64, f64)>,
    /// Odometer speeds `(t, v)` [s, m/s].
    pub odometer: Vec<(f64, f64)>,
    /// The barometer's height noise [m] from the pressure variances, when messages
    /// give them: the median over those messages of `σ_p·|dh/dp|` ([`isa_height_std`]).
    pub baro_std: Option<f64>,
    /// The odometer's speed noise [m/s] from the twists' covariances, when messages
    /// give them: the median of `√C[0]` (forward speed's variance) over those messages.
    pub odometer_std: Option<f64>,
}

/// Intervals of the IMU's first messages kept to settle its nominal interval (as the
/// text readers' lookahead).
const LOOKAHEAD: usize = 200;

/// What the first pass found on one topic of a kind we read.
#[derive(Debug, Default)]
struct Gathered {
    imu_stamps: Vec<(i32, u32)>,
    /// The first messages' angular rates and specific forces (IMU axes).
    imu_motion: Vec<([f64; 3], [f64; 3])>,
    imu_covariance: Option<([f64; 9], [f64; 9])>,
    /// The first IMU message's `frame_id`.
    imu_frame: Option<String>,
    fixes: Vec<(u64, NavSatFix)>,
    twists: Vec<(u64, TwistStamped)>,
    pressures: Vec<(u64, FluidPressure)>,
    odometry: Vec<(u64, Odometry)>,
    /// The first decoding error (reported only if the topic is chosen).
    error: Option<BagError>,
}

/// A bag read for a run: the chosen topics, the IMU's nominal interval and noise,
/// the aids.
#[derive(Debug, Clone)]
pub struct BagPlan {
    /// The bag.
    pub path: PathBuf,
    /// Every topic of the bag.
    pub topics: Vec<TopicSummary>,
    /// The chosen topic of each kind (by [`Kind`] order).
    pub chosen: [Option<String>; 5],
    /// Median interval of the IMU's first stamps [s].
    pub nominal_dt: f64,
    /// How the stamps become the run's times.
    pub clock: StampClock,
    /// ARW [rad/√s] and VRW [m/s/√s] per FRD axis from the IMU's covariances, if given.
    pub imu_noise: Option<(Vector3<f64>, Vector3<f64>)>,
    /// The aids.
    pub aids: BagAids,
    /// Where the IMU's axes come from.
    pub mounting: Mounting,
    /// From the IMU's axes to FRD, as [`Self::mounting`] gives it.
    pub c_vs: Matrix3<f64>,
    options: BagReadOptions,
}

/// The serialization of `topic`'s messages: ROS 2 CDR (schema `ros2msg`/`ros2idl`,
/// messages `cdr`) or ROS 1 (`ros1msg`, `ros1`); another is an error.
fn check_encoding(path: &Path, topic: &Topic) -> Result<Encoding, BagError> {
    topic.encoding().ok_or_else(|| {
        BagError::topic(
            path,
            &topic.name,
            0,
            None,
            format!(
                "message encoding {:?} with schema encoding {:?}: only ROS 2 CDR (\"cdr\" with \
                 \"ros2msg\" or \"ros2idl\") and ROS 1 bags are read",
                topic.message_encoding, topic.schema_encoding
            ),
        )
    })
}

/// Stores message `m` of kind `kind` in `g` (decoding errors kept, not raised).
fn gather(path: &Path, m: &Message, kind: Kind, g: &mut Gathered) {
    if g.error.is_some() {
        return;
    }
    let Ok(enc) = check_encoding(path, m.topic) else {
        return;
    };
    let err = |e| BagError::decode(path, &m.topic.name, m.index, e);
    let result = match kind {
        Kind::Imu if g.imu_stamps.len() <= LOOKAHEAD => Imu::decode_in(enc, m.data).map(|imu| {
            if g.imu_covariance.is_none() && imu.angular_velocity_covariance[0] > 0.0 {
                g.imu_covariance = Some((
                    imu.angular_velocity_covariance,
                    imu.linear_acceleration_covariance,
                ));
            }
            if g.imu_frame.is_none() {
                g.imu_frame = Some(imu.header.frame_id.clone());
            }
            g.imu_stamps.push((imu.header.sec, imu.header.nanosec));
            g.imu_motion
                .push((imu.angular_velocity, imu.linear_acceleration));
        }),
        Kind::Imu => Ok(()),
        Kind::Gnss => NavSatFix::decode_in(enc, m.data).map(|x| g.fixes.push((m.index, x))),
        Kind::GnssVel => TwistStamped::decode_in(enc, m.data).map(|x| g.twists.push((m.index, x))),
        Kind::Baro => FluidPressure::decode_in(enc, m.data).map(|x| g.pressures.push((m.index, x))),
        Kind::Odometry => Odometry::decode_in(enc, m.data).map(|x| g.odometry.push((m.index, x))),
    };
    if let Err(e) = result {
        g.error = Some(err(e));
    }
}

/// Takes the transforms of a `/tf_static` message into `tree`.
fn gather_tf(path: &Path, m: &Message, tree: &mut TfTree) -> Result<(), BagError> {
    let enc = check_encoding(path, m.topic)?;
    let tf = TfMessage::decode_in(enc, m.data)
        .map_err(|e| BagError::decode(path, &m.topic.name, m.index, e))?;
    for t in &tf.transforms {
        tree.insert(t)
            .map_err(|(f, e)| BagError::topic(path, &m.topic.name, m.index, Some(&f), e))?;
    }
    Ok(())
}

/// The topic of `kind`: the one named (`"none"`: no topic), else the only one of its
/// type; several of the type without a name is an error listing them.
fn choose(
    path: &Path,
    topics: &[TopicSummary],
    kind: Kind,
    named: Option<&str>,
) -> Result<Option<String>, BagError> {
    let of_type: Vec<&str> = topics
        .iter()
        .filter(|t| same_type(&t.topic.type_name, kind.type_name()))
        .map(|t| t.topic.name.as_str())
        .collect();
    match named {
        Some("none") => Ok(None),
        Some(name) => {
            let Some(t) = topics.iter().find(|t| t.topic.name == name) else {
                return Err(BagError::file(
                    path,
                    format!(
                        "{} {name}: no such topic; the bag's {} topics: {}",
                        kind.flag(),
                        kind.type_name(),
                        list(&of_type)
                    ),
                ));
            };
            if !same_type(&t.topic.type_name, kind.type_name()) {
                return Err(BagError::topic(
                    path,
                    name,
                    0,
                    None,
                    format!(
                        "message schema {:?} is not {} ({} names a topic of that type; the bag's: {})",
                        t.topic.type_name,
                        kind.type_name(),
                        kind.flag(),
                        list(&of_type)
                    ),
                ));
            }
            check_encoding(path, &t.topic)?;
            Ok(Some(name.to_owned()))
        }
        None => match of_type[..] {
            [] => Ok(None),
            [one] => {
                let t = topics.iter().find(|t| t.topic.name == one);
                if let Some(t) = t {
                    check_encoding(path, &t.topic)?;
                }
                Ok(Some(one.to_owned()))
            }
            _ => Err(BagError::file(
                path,
                format!(
                    "{} topics of type {}: choose one with {}",
                    list(&of_type),
                    kind.type_name(),
                    kind.flag()
                ),
            )),
        },
    }
}

/// Names for a message: `a, b` or `(none)`.
fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "(none)".to_owned()
    } else {
        names.join(", ")
    }
}

/// The first pass over the bag at `path`: topics, the chosen ones, the IMU's
/// interval and noise, the aids.
pub fn plan(path: &Path, options: &BagReadOptions) -> Result<BagPlan, BagError> {
    let mut by_place: Vec<Option<(Kind, Gathered)>> = Vec::new();
    // Each topic's kind, by its place, settled at its first message.
    let mut kinds: Vec<Option<Option<Kind>>> = Vec::new();
    let mut names: HashMap<usize, String> = HashMap::new();
    let mut tree = TfTree::default();
    let topics = scan(path, |m| {
        let place = m.topic_index;
        if kinds.len() <= place {
            kinds.resize(place + 1, None);
            by_place.resize_with(place + 1, || None);
        }
        let kind = *kinds[place].get_or_insert_with(|| Kind::of_type(&m.topic.type_name));
        if let Some(kind) = kind {
            let (_, g) = by_place[place].get_or_insert_with(|| {
                names.insert(place, m.topic.name.clone());
                (kind, Gathered::default())
            });
            gather(path, m, kind, g);
        } else if m.topic.name == TF_STATIC && same_type(&m.topic.type_name, TF_MESSAGE) {
            gather_tf(path, m, &mut tree)?;
        }
        Ok(())
    })?;
    let mut gathered: HashMap<String, Gathered> = HashMap::new();
    for (place, g) in by_place.into_iter().enumerate() {
        if let (Some((_, g)), Some(name)) = (g, names.remove(&place)) {
            gathered.insert(name, g);
        }
    }
    let mut chosen: [Option<String>; 5] = Default::default();
    for kind in Kind::ALL {
        chosen[kind.index()] =
            choose(path, &topics, kind, options.topics[kind.index()].as_deref())?;
    }
    let Some(imu_topic) = chosen[Kind::Imu.index()].clone() else {
        return Err(BagError::file(
            path,
            format!("no {IMU} topic in the bag (topics: {})", {
                let names: Vec<&str> = topics.iter().map(|t| t.topic.name.as_str()).collect();
                list(&names)
            }),
        ));
    };
    let mut take = |kind: Kind| -> Result<Gathered, BagError> {
        let g = chosen[kind.index()]
            .as_ref()
            .and_then(|t| gathered.remove(t))
            .unwrap_or_default();
        match g.error {
            Some(e) => Err(e),
            None => Ok(g),
        }
    };
    let imu = take(Kind::Imu)?;
    let (clock, nominal_dt) = imu_clock(path, &imu_topic, &imu, options)?;
    let (mounting, c_vs) = mounting(path, &imu_topic, imu.imu_frame.as_deref(), &tree, options)?;
    let imu_noise = imu
        .imu_covariance
        .map(|(w, f)| noise_from_covariance(&w, &f, &c_vs, nominal_dt));
    let gathered = [Kind::Gnss, Kind::GnssVel, Kind::Baro, Kind::Odometry].map(take);
    let [gnss, vel, baro, odometry] = gathered;
    let topic = |k: Kind| chosen[k.index()].clone().unwrap_or_default();
    let aids = aids(
        path,
        [topic(Kind::Gnss), topic(Kind::Baro)],
        [gnss?, vel?, baro?, odometry?],
        &Times {
            clock,
            offset: options.time_offset,
        },
        options,
    )?;
    Ok(BagPlan {
        path: path.to_path_buf(),
        topics,
        chosen,
        nominal_dt,
        clock,
        imu_noise,
        aids,
        mounting,
        c_vs,
        options: options.clone(),
    })
}

/// The IMU's mounting: given by hand (`options.c_vs` when `axes_given`), else from
/// `/tf_static` (the IMU messages' frame `imu_frame` up to the base frame: the one
/// named, else the IMU frame's parent), else FLU.
fn mounting(
    path: &Path,
    imu_topic: &str,
    imu_frame: Option<&str>,
    tree: &TfTree,
    options: &BagReadOptions,
) -> Result<(Mounting, Matrix3<f64>), BagError> {
    let imu_frame = imu_frame.map(frame_name).filter(|f| !f.is_empty());
    let parent = imu_frame.and_then(|f| tree.parent(f)).map(str::to_owned);
    if options.axes_given {
        if options.base_frame.is_some() {
            return Err(BagError::file(
                path,
                "--base-frame takes the IMU's mounting from /tf_static, --imu-axes and \
                 --imu-rotation give it by hand: give one",
            ));
        }
        return Ok((Mounting::Given { tf_ignored: parent }, options.c_vs));
    }
    let base = match (&options.base_frame, &parent) {
        (Some(b), _) => frame_name(b).to_owned(),
        (None, Some(p)) => p.clone(),
        (None, None) => {
            let imu_frame = imu_frame.map(str::to_owned);
            return Ok((Mounting::Flu { imu_frame }, options.c_vs));
        }
    };
    let Some(imu_frame) = imu_frame else {
        return Err(BagError::topic(
            path,
            imu_topic,
            1,
            Some("header.frame_id"),
            format!("empty: --base-frame {base} needs the IMU's frame to find it in /tf_static"),
        ));
    };
    let c_base_imu = tree.rotation(imu_frame, &base).map_err(|e| {
        let topic = if tree.is_empty() {
            "the bag has no /tf_static transform".to_owned()
        } else {
            e
        };
        BagError::file(path, format!("--base-frame {base}: {topic}"))
    })?;
    let mounting = Mounting::Tf {
        imu_frame: imu_frame.to_owned(),
        base_frame: base,
    };
    Ok((mounting, flu_to_frd() * c_base_imu))
}

/// The run's time of a header: its stamp on the clock plus the offset.
#[derive(Debug, Clone, Copy)]
struct Times {
    clock: StampClock,
    offset: f64,
}

impl Times {
    /// The time [s] of header `h`.
    fn of(&self, h: &super::messages::Header) -> f64 {
        self.clock.seconds(h.sec, h.nanosec) + self.offset
    }
}

/// The clock of the IMU topic `topic`'s first stamps (UNIX or not) and its nominal
/// interval on it, after the plausibility check of its first messages.
fn imu_clock(
    path: &Path,
    topic: &str,
    imu: &Gathered,
    options: &BagReadOptions,
) -> Result<(StampClock, f64), BagError> {
    let first_sec = imu.imu_stamps.first().map_or(0, |s| i64::from(s.0));
    let clock = StampClock::of_first_stamp(first_sec, options.leap_seconds)
        .map_err(|e| BagError::topic(path, topic, 1, Some("header.stamp"), e))?;
    let stamps: Vec<f64> = imu
        .imu_stamps
        .iter()
        .map(|&(sec, ns)| clock.seconds(sec, ns))
        .collect();
    let nominal_dt = nominal_interval(path, topic, &stamps)?;
    if options.check_layout {
        plausible(path, topic, &stamps, &imu.imu_motion)?;
    }
    Ok((clock, nominal_dt))
}

/// The aids of the chosen topics' messages (GNSS, velocity, barometer, odometry as
/// gathered; `topics` the GNSS and barometer topics' names for errors), in the
/// session's frames and units and in time order.
fn aids(
    path: &Path,
    topics: [String; 2],
    [gnss, vel, baro, odometry]: [Gathered; 4],
    times: &Times,
    options: &BagReadOptions,
) -> Result<BagAids, BagError> {
    let [gnss_topic, baro_topic] = topics;
    let mut aids = BagAids::default();
    (aids.fixes, aids.no_fix) = fixes(path, &gnss_topic, &gnss.fixes, times, options)?;
    aids.unmatched_velocities =
        join_velocities(&mut aids.fixes, &vel.twists, times, options.default_vel_std);
    aids.baro = baro
        .pressures
        .iter()
        .map(|(i, p)| {
            isa_height(p.fluid_pressure)
                .map(|h| (times.of(&p.header), h))
                .ok_or_else(|| {
                    BagError::topic(
                        path,
                        &baro_topic,
                        *i,
                        Some("fluid_pressure"),
                        format!("{} Pa is not a pressure (must be > 0)", p.fluid_pressure),
                    )
                })
        })
        .collect::<Result<_, _>>()?;
    aids.odometer = odometry
        .odometry
        .iter()
        .map(|(_, o)| (times.of(&o.header), o.linear[0]))
        .collect();
    aids.baro_std = median_of(
        baro.pressures
            .iter()
            .filter(|(_, p)| p.variance > 0.0)
            .map(|(_, p)| isa_height_std(p.fluid_pressure, p.variance.sqrt())),
    );
    aids.odometer_std = median_of(
        odometry
            .odometry
            .iter()
            .filter(|(_, o)| o.twist_covariance[0] > 0.0)
            .map(|(_, o)| o.twist_covariance[0].sqrt()),
    );
    sort_by_time(&mut aids.baro);
    sort_by_time(&mut aids.odometer);
    Ok(aids)
}

/// The median of `xs` (the upper one of an even count); `None` when empty.
fn median_of(xs: impl Iterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = xs.collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}

/// Sorts `(t, x)` readings by time (bags store messages in arrival order).
fn sort_by_time(v: &mut [(f64, f64)]) {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
}

/// Median of the intervals between the IMU's first stamps.
fn nominal_interval(path: &Path, topic: &str, stamps: &[f64]) -> Result<f64, BagError> {
    let mut dts: Vec<f64> = stamps.windows(2).map(|w| w[1] - w[0]).collect();
    dts.sort_by(f64::total_cmp);
    match dts.get(dts.len() / 2) {
        Some(&dt) if dt > 0.0 => Ok(dt),
        _ => Err(BagError::topic(
            path,
            topic,
            0,
            Some("header.stamp"),
            "fewer than two increasing stamps: cannot settle the sample interval",
        )),
    }
}

/// The text reader's plausibility check ([`crate::formats::imu_plausibility`]) of the
/// IMU's first messages (`stamps` [s] and their rates): rad/s, m/s² and seconds as
/// `sensor_msgs/Imu` defines them. A failure names the messages and the field.
fn plausible(
    path: &Path,
    topic: &str,
    stamps: &[f64],
    motion: &[([f64; 3], [f64; 3])],
) -> Result<(), BagError> {
    use crate::formats::ImuLayout;
    use crate::formats::imu_columns::Plan;
    use crate::formats::imu_log::LAYOUT_CHECK_MIN_INTERVALS;
    use crate::formats::imu_plausibility::{Reading, Sensor, check};
    let readings: Vec<Reading> = stamps
        .windows(2)
        .zip(motion.iter().skip(1))
        .map(|(t, (w, f))| Reading {
            dt: t[1] - t[0],
            gyro: Vector3::from(*w),
            accel: Vector3::from(*f),
        })
        .collect();
    if readings.len() < LAYOUT_CHECK_MIN_INTERVALS {
        return Ok(());
    }
    let Err(finding) = check(&readings, &Plan::kf_gins(ImuLayout::Rates), false) else {
        return Ok(());
    };
    let field = match finding.sensor {
        Sensor::Time => "header.stamp",
        Sensor::Gyro => "angular_velocity",
        Sensor::Accel => "linear_acceleration",
    };
    Err(BagError::topic(
        path,
        topic,
        0,
        Some(field),
        format!(
            "messages 1-{} {} (sensor_msgs/Imu holds rad/s and m/s^2 at stamps in s: the \
             recording's publisher is at fault, and --no-layout-check skips this check)",
            stamps.len(),
            finding.message
        ),
    ))
}

/// ARW and VRW per FRD axis from one sample's rate covariances (IMU axes), turned by
/// `c_vs`: `N = √(diag(C Σ Cᵀ)·dt)`.
fn noise_from_covariance(
    w: &[f64; 9],
    f: &[f64; 9],
    c_vs: &Matrix3<f64>,
    dt: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let density = |cov: &[f64; 9]| {
        let s = Matrix3::from_row_slice(cov);
        (c_vs * s * c_vs.transpose())
            .diagonal()
            .map(|v| (v.max(0.0) * dt).sqrt())
    };
    (density(w), density(f))
}

/// The fixes of `msgs` (topic `topic`) in time order, and the count of `NO_FIX`.
fn fixes(
    path: &Path,
    topic: &str,
    msgs: &[(u64, NavSatFix)],
    times: &Times,
    options: &BagReadOptions,
) -> Result<(Vec<GnssFix>, u64), BagError> {
    let mut out = Vec::with_capacity(msgs.len());
    let mut no_fix = 0;
    for (i, m) in msgs {
        if m.status == STATUS_NO_FIX {
            no_fix += 1;
            continue;
        }
        let bad =
            |field: &str, reason: String| BagError::topic(path, topic, *i, Some(field), reason);
        for (field, x, limit) in [
            ("latitude", m.latitude, 90.0),
            ("longitude", m.longitude, 360.0),
            ("altitude", m.altitude, f64::INFINITY),
        ] {
            if !(x.is_finite() && x.abs() <= limit) {
                return Err(bad(
                    field,
                    format!("{x} is not a {field} (status {})", m.status),
                ));
            }
        }
        let c = &m.position_covariance;
        let std = Vector3::new(c[4], c[0], c[8]).map(f64::sqrt);
        let pos_std = if m.position_covariance_type > 0 && std.iter().all(|s| *s > 0.0) {
            std
        } else {
            options.default_gnss_std.ok_or_else(|| {
                bad(
                    "position_covariance",
                    format!(
                        "no usable covariance (type {}, diagonal {} {} {}): give --gnss-std N,E,D",
                        m.position_covariance_type, c[0], c[4], c[8]
                    ),
                )
            })?
        };
        out.push(GnssFix {
            t: times.of(&m.header),
            pos: Geodetic::from_degrees(m.latitude, m.longitude, m.altitude),
            pos_std,
            vel: None,
        });
    }
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    Ok((out, no_fix))
}

/// Joins each ENU twist to the fix of the same stamp (within 1 µs) as an NED
/// velocity (`default_std` [m/s] where the twist has no covariance); returns the
/// twists without a fix.
fn join_velocities(
    fixes: &mut [GnssFix],
    twists: &[(u64, TwistStamped)],
    times: &Times,
    default_std: f64,
) -> u64 {
    let mut unmatched = 0;
    for (_, tw) in twists {
        let t = times.of(&tw.header);
        let j = fixes.partition_point(|f| f.t < t - 1e-6);
        let Some(fix) = fixes.get_mut(j).filter(|f| (f.t - t).abs() <= 1e-6) else {
            unmatched += 1;
            continue;
        };
        let [e, n, u] = tw.linear;
        let c = &tw.covariance;
        let std = Vector3::new(c[7], c[0], c[14]).map(f64::sqrt);
        let std = if std.iter().all(|s| *s > 0.0) {
            std
        } else {
            Vector3::repeat(default_std)
        };
        fix.vel = Some((Vector3::new(n, e, -u), std));
    }
    unmatched
}

/// ISA sea-level pressure p₀ [Pa].
pub const ISA_P0: f64 = 101_325.0;
/// ISA sea-level temperature T₀ [K].
pub const ISA_T0: f64 = 288.15;
/// ISA troposphere lapse rate L [K/m].
pub const ISA_LAPSE: f64 = 0.0065;
/// The troposphere's exponent `R*·L/(g₀·M)` with the U.S. Standard Atmosphere
/// 1976's constants (R* = 8.314 32 J/(mol·K), g₀ = 9.806 65 m/s²,
/// M = 0.028 964 4 kg/mol), whose tables the test checks.
pub const ISA_EXPONENT: f64 = 8.314_32 * ISA_LAPSE / (9.806_65 * 0.028_964_4);

/// Height [m] of pressure `p` [Pa] in the ISA troposphere (ICAO Doc 7488):
/// `h = (T₀/L)·(1 − (p/p₀)^(R·L/(g₀·M)))`; `None` for `p ≤ 0`.
pub fn isa_height(p: f64) -> Option<f64> {
    (p > 0.0).then(|| ISA_T0 / ISA_LAPSE * (1.0 - (p / ISA_P0).powf(ISA_EXPONENT)))
}

/// The height's standard deviation [m] of a pressure `p > 0` [Pa] with standard
/// deviation `sigma_p` [Pa], to first order: `σ_h = σ_p·|dh/dp|`,
/// `dh/dp = −(T₀/L)·n·(p/p₀)^(n−1)/p₀` with [`ISA_EXPONENT`] `n`.
pub fn isa_height_std(p: f64, sigma_p: f64) -> f64 {
    let n = ISA_EXPONENT;
    sigma_p * ISA_T0 / ISA_LAPSE * n * (p / ISA_P0).powf(n - 1.0) / ISA_P0
}

impl BagPlan {
    /// The chosen topic of `kind`.
    pub fn topic(&self, kind: Kind) -> Option<&str> {
        self.chosen[kind.index()].as_deref()
    }

    /// The second pass: the IMU samples, streamed.
    pub fn imu_samples(&self) -> Result<BagImu, BagError> {
        Ok(BagImu {
            stream: BagStream::open(&self.path)?,
            path: self.path.clone(),
            topic: self.topic(Kind::Imu).unwrap_or_default().to_owned(),
            c_vs: self.c_vs,
            times: Times {
                clock: self.clock,
                offset: self.options.time_offset,
            },
            window: (self.options.t_start, self.options.t_end),
            nominal_dt: self.nominal_dt,
            gaps: GapReport {
                threshold_s: GAP_FACTOR * self.nominal_dt,
                ..GapReport::default()
            },
            place: None,
            prev: None,
            started: false,
            finished: false,
        })
    }
}

/// The IMU topic's samples in FRD increments, in file order (an error if the stamps
/// do not increase).
pub struct BagImu {
    stream: BagStream,
    path: PathBuf,
    topic: String,
    c_vs: Matrix3<f64>,
    times: Times,
    window: (Option<f64>, Option<f64>),
    nominal_dt: f64,
    gaps: GapReport,
    /// The IMU topic's place in the stream ([`Message::topic_index`]), once seen.
    place: Option<usize>,
    prev: Option<(f64, u64)>,
    started: bool,
    finished: bool,
}

impl BagImu {
    /// Bytes of the bag read so far.
    pub fn bytes_read(&self) -> u64 {
        self.stream.bytes_read()
    }

    /// The gaps met so far (intervals over [`GAP_FACTOR`] nominal ones, as the text
    /// reader counts them); complete once the iteration has ended.
    pub fn gaps(&self) -> GapReport {
        self.gaps
    }

    /// The IMU topic's name.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// The next IMU message decoded: `(index, t, ω, f)`.
    fn next_message(&mut self) -> Result<Option<(u64, f64, ImuMotion)>, BagError> {
        let (path, topic, times) = (&self.path, &self.topic, self.times);
        let place = &mut self.place;
        loop {
            let got = self.stream.next_with(|m| {
                // The topic's place, once known, spares a name comparison per message.
                match *place {
                    Some(p) if p != m.topic_index => return Ok(None),
                    None if m.topic.name != *topic => return Ok(None),
                    _ => *place = Some(m.topic_index),
                }
                let enc = check_encoding(path, m.topic)?;
                let imu = ImuMotion::decode_in(enc, m.data)
                    .map_err(|e| BagError::decode(path, topic, m.index, e))?;
                let (sec, nanosec) = imu.stamp;
                let t = times.clock.seconds(sec, nanosec) + times.offset;
                Ok(Some((m.index, t, imu)))
            })?;
            match got {
                None => return Ok(None),
                Some(None) => continue,
                Some(Some(x)) => return Ok(Some(x)),
            }
        }
    }

    /// The sample of message `index` at `t`: increments over `(t_prev, t]`.
    fn sample(&mut self, index: u64, t: f64, imu: &ImuMotion) -> Result<ImuSample, BagError> {
        let dt = match self.prev {
            Some((t_prev, i_prev)) if t <= t_prev => {
                return Err(BagError::topic(
                    &self.path,
                    &self.topic,
                    index,
                    Some("header.stamp"),
                    format!("stamp {t} s does not follow message {i_prev}'s {t_prev} s"),
                ));
            }
            Some((t_prev, _)) => t - t_prev,
            None => self.nominal_dt,
        };
        self.prev = Some((t, index));
        let w = Vector3::from(imu.angular_velocity);
        let f = Vector3::from(imu.linear_acceleration);
        // The text reader's domains: the interval, the rate, the specific force.
        for (field, d, value) in [
            ("header.stamp", &domain::IMU_INTERVAL, dt),
            ("angular_velocity", &domain::ANGULAR_RATE, w.norm()),
            ("linear_acceleration", &domain::SPECIFIC_FORCE, f.norm()),
        ] {
            if let Err(e) = d.check(value) {
                let what = if field == "header.stamp" {
                    format!("the time jumps: {e}")
                } else {
                    e.to_string()
                };
                let topic = &self.topic;
                return Err(BagError::topic(&self.path, topic, index, Some(field), what));
            }
        }
        Ok(ImuSample {
            t,
            dt,
            dtheta: self.c_vs * (w * dt),
            dvel: self.c_vs * (f * dt),
        })
    }
}

impl Iterator for BagImu {
    type Item = Result<ImuSample, BagError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if self.finished {
                return None;
            }
            let (index, t, imu) = match self.next_message() {
                Ok(Some(x)) => x,
                Ok(None) => {
                    self.finished = true;
                    return None;
                }
                Err(e) => {
                    self.finished = true;
                    return Some(Err(e));
                }
            };
            let had_prev = self.prev.is_some();
            let sample = match self.sample(index, t, &imu) {
                Ok(s) => s,
                Err(e) => {
                    self.finished = true;
                    return Some(Err(e));
                }
            };
            if !self.started && self.window.0.is_some_and(|s| t < s) {
                continue;
            }
            self.started = true;
            if self.window.1.is_some_and(|e| t > e) {
                self.finished = true;
                return None;
            }
            if had_prev && sample.dt > self.gaps.threshold_s {
                self.gaps.record(t, sample.dt);
            }
            return Some(Ok(sample));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ISA's table values (ICAO Doc 7488, U.S. Standard Atmosphere 1976): 1000 m
    /// at 89 874.6 Pa, 5000 m at 54 019.9 Pa, 11 000 m at 22 632.1 Pa (geopotential
    /// heights); the tables print 6 digits, so 0.5 of the last digit in pressure, about
    /// 0.05 m in height near the ground and 0.3 m at 11 km.
    #[test]
    fn isa_heights_match_the_standard_tables() {
        for (p, h, tol) in [
            (101_325.0, 0.0, 1e-9),
            (89_874.6, 1000.0, 0.05),
            (54_019.9, 5000.0, 0.1),
            (22_632.1, 11_000.0, 0.3),
        ] {
            let got = isa_height(p).expect("positive");
            assert!((got - h).abs() < tol, "{p} Pa: {got} m, table {h} m");
        }
        assert_eq!(isa_height(0.0), None);
    }

    /// Hydrostatic balance, independent of the ISA formula's form: `dp/dh = −ρ·g₀ =
    /// −p·M·g₀/(R*·T)` with `T = T₀ − L·h`, so 1 Pa is `R*·T/(p·M·g₀)` of height: 8.32 cm
    /// at sea level, 11.2 cm at 3000 m (where T = 268.65 K). The first-order σ_h must
    /// be that to rounding (1e-12 relative).
    #[test]
    fn pressure_noise_becomes_height_noise_by_hydrostatic_balance() {
        let (r, m, g0) = (8.314_32, 0.028_964_4, 9.806_65);
        for h in [0.0, 3000.0, 10_000.0] {
            let t = ISA_T0 - ISA_LAPSE * h;
            let p = ISA_P0 * (t / ISA_T0).powf(1.0 / ISA_EXPONENT);
            let expected = 2.0 * r * t / (p * m * g0);
            let got = isa_height_std(p, 2.0);
            assert!(
                (got / expected - 1.0).abs() < 1e-12,
                "{h} m: {got} / {expected}"
            );
        }
        assert!((isa_height_std(ISA_P0, 1.0) - 0.083_24).abs() < 1e-5);
    }

    /// White noise of density N sampled every dt has σ = N/√dt: the covariance gives N
    /// back, the FLU axes' y and z turned onto FRD's (same variances).
    #[test]
    fn covariance_gives_the_noise_density() {
        let n = 0.003f64.to_radians() / 60.0; // 0.003 deg/√h in rad/√s
        let dt: f64 = 0.005;
        let var = (n / dt.sqrt()).powi(2);
        let w = [var, 0.0, 0.0, 0.0, 4.0 * var, 0.0, 0.0, 0.0, 9.0 * var];
        let (arw, _) = noise_from_covariance(&w, &w, &flu_to_frd(), dt);
        assert!((arw - Vector3::new(n, 2.0 * n, 3.0 * n)).norm() < 1e-12 * n);
    }
}
