//! The ROS message types a bag is read for and written with, decoded field by field
//! in their definitions' order (the `.msg` files of `sensor_msgs`, `geometry_msgs`,
//! `nav_msgs`, `tf2_msgs`, `std_msgs`, `builtin_interfaces`) from ROS 2's CDR or ROS
//! 1's serialization alike ([`Decode`] over [`WireReader`]), and encoded to CDR.
//!
//! Values stay in the message's own frames and units here (REP 103: body x forward,
//! y left, z up; REP 105: ENU for the world); [`super::input`] turns them into FRD
//! and NED.

use super::cdr::{CdrError, CdrWriter};
pub use super::wire::{Decode, Encoding, WireReader};

/// `sensor_msgs/msg/Imu`.
pub const IMU: &str = "sensor_msgs/msg/Imu";
/// `sensor_msgs/msg/NavSatFix`.
pub const NAV_SAT_FIX: &str = "sensor_msgs/msg/NavSatFix";
/// `geometry_msgs/msg/TwistWithCovarianceStamped`.
pub const TWIST: &str = "geometry_msgs/msg/TwistWithCovarianceStamped";
/// `sensor_msgs/msg/FluidPressure`.
pub const FLUID_PRESSURE: &str = "sensor_msgs/msg/FluidPressure";
/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: &str = "nav_msgs/msg/Odometry";
/// `geometry_msgs/msg/Vector3Stamped`.
pub const VECTOR3_STAMPED: &str = "geometry_msgs/msg/Vector3Stamped";
/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";

/// Whether `type_name` as a bag names it is the ROS 2 type `ros2` (`pkg/msg/Name`):
/// the same, or ROS 1's `pkg/Name`.
pub fn same_type(type_name: &str, ros2: &str) -> bool {
    if type_name == ros2 {
        return true;
    }
    match ros2.split_once("/msg/") {
        Some((pkg, name)) => type_name
            .strip_prefix(pkg)
            .and_then(|rest| rest.strip_prefix('/'))
            .is_some_and(|rest| rest == name),
        None => false,
    }
}

/// `NavSatStatus.status` of a receiver without a fix.
pub const STATUS_NO_FIX: i8 = -1;

/// `std_msgs/msg/Header`: the stamp and the frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    /// `stamp.sec` [s].
    pub sec: i32,
    /// `stamp.nanosec` [ns], below 10⁹.
    pub nanosec: u32,
    /// `frame_id`.
    pub frame_id: String,
}

/// The stamp in seconds (`sec + nanosec·10⁻⁹`).
fn stamp_seconds(sec: i32, nanosec: u32) -> f64 {
    f64::from(sec) + f64::from(nanosec) * 1e-9
}

/// A header's stamp `(sec, nanosec)`, `nanosec` checked below 10⁹.
fn read_stamp<R: WireReader>(r: &mut R) -> Result<(i32, u32), CdrError> {
    let (sec, nanosec) = r.header_stamp()?;
    if nanosec >= 1_000_000_000 {
        return Err(CdrError {
            field: "header.stamp.nanosec".into(),
            reason: format!("{nanosec} is not below 10^9"),
        });
    }
    Ok((sec, nanosec))
}

impl Header {
    /// The stamp in seconds (`sec + nanosec·10⁻⁹`).
    pub fn seconds(&self) -> f64 {
        stamp_seconds(self.sec, self.nanosec)
    }

    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let (sec, nanosec) = read_stamp(r)?;
        let frame_id = r.string("header.frame_id")?;
        Ok(Self {
            sec,
            nanosec,
            frame_id,
        })
    }

    fn write(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
        w.string(&self.frame_id);
    }
}

/// Three finite `float64`s of a `geometry_msgs/Vector3` (or `Point`) named `field`
/// (an error names the axis; nothing is allocated otherwise).
fn vector3<R: WireReader>(r: &mut R, field: &str) -> Result<[f64; 3], CdrError> {
    let v = [r.f64(field)?, r.f64(field)?, r.f64(field)?];
    for (x, axis) in v.iter().zip(["x", "y", "z"]) {
        if !x.is_finite() {
            return Err(CdrError {
                field: format!("{field}.{axis}"),
                reason: format!("{x} is not a finite number"),
            });
        }
    }
    Ok(v)
}

/// `sensor_msgs/msg/Imu`, without the orientation (not used).
#[derive(Debug, Clone, PartialEq)]
pub struct Imu {
    /// Header.
    pub header: Header,
    /// Angular rate [rad/s], IMU axes.
    pub angular_velocity: [f64; 3],
    /// Its covariance, row-major [rad²/s²] (`[0] = -1`: not given).
    pub angular_velocity_covariance: [f64; 9],
    /// Specific force [m/s²], IMU axes.
    pub linear_acceleration: [f64; 3],
    /// Its covariance, row-major [m²/s⁴].
    pub linear_acceleration_covariance: [f64; 9],
}

/// What navigation reads of a `sensor_msgs/msg/Imu`: the stamp, angular rate
/// [rad/s] and specific force [m/s²] (frame and covariances skipped, nothing
/// allocated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuMotion {
    /// The header's stamp: `sec`, `nanosec` (below 10⁹).
    pub stamp: (i32, u32),
    /// Angular rate, IMU axes.
    pub angular_velocity: [f64; 3],
    /// Specific force, IMU axes.
    pub linear_acceleration: [f64; 3],
}

impl ImuMotion {
    /// Decodes a payload's stamp, rate and specific force (the covariances are only
    /// checked to be there).
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }
}

impl Decode for ImuMotion {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let (sec, nanosec) = read_stamp(r)?;
        r.skip_string("header.frame_id")?;
        r.skip_f64s(4 + 9, "orientation")?;
        let angular_velocity = vector3(r, "angular_velocity")?;
        r.skip_f64s(9, "angular_velocity_covariance")?;
        let linear_acceleration = vector3(r, "linear_acceleration")?;
        r.skip_f64s(9, "linear_acceleration_covariance")?;
        Ok(Self {
            stamp: (sec, nanosec),
            angular_velocity,
            linear_acceleration,
        })
    }
}

impl Imu {
    /// Decodes a payload.
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }
}

impl Decode for Imu {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        r.skip_f64s(4 + 9, "orientation")?;
        let angular_velocity = vector3(r, "angular_velocity")?;
        let angular_velocity_covariance = r.finite_array("angular_velocity_covariance")?;
        let linear_acceleration = vector3(r, "linear_acceleration")?;
        let linear_acceleration_covariance = r.finite_array("linear_acceleration_covariance")?;
        Ok(Self {
            header,
            angular_velocity,
            angular_velocity_covariance,
            linear_acceleration,
            linear_acceleration_covariance,
        })
    }
}

impl Imu {
    /// Encodes the message (orientation unknown: identity, covariance `[-1, 0, …]`),
    /// for test and benchmark bags.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.f64s(&[0.0, 0.0, 0.0, 1.0]);
        let mut unknown = [0.0; 9];
        unknown[0] = -1.0;
        w.f64s(&unknown);
        w.f64s(&self.angular_velocity);
        w.f64s(&self.angular_velocity_covariance);
        w.f64s(&self.linear_acceleration);
        w.f64s(&self.linear_acceleration_covariance);
        w.finish()
    }
}

/// `sensor_msgs/msg/NavSatFix`.
#[derive(Debug, Clone, PartialEq)]
pub struct NavSatFix {
    /// Header.
    pub header: Header,
    /// `status.status` (-1 no fix, 0 fix, 1 SBAS, 2 GBAS).
    pub status: i8,
    /// `status.service` (bit mask of constellations).
    pub service: u16,
    /// Latitude [deg].
    pub latitude: f64,
    /// Longitude [deg].
    pub longitude: f64,
    /// Height above the WGS 84 ellipsoid [m].
    pub altitude: f64,
    /// Position covariance in ENU, row-major [m²].
    pub position_covariance: [f64; 9],
    /// 0 unknown, 1 approximated, 2 diagonal known, 3 known.
    pub position_covariance_type: u8,
}

impl NavSatFix {
    /// Decodes a payload; a fix without a position (`NO_FIX`) may hold NaN, so the
    /// position is checked by the caller, not here.
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }

    /// Encodes the message.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.i8(self.status);
        w.u16(self.service);
        w.f64s(&[self.latitude, self.longitude, self.altitude]);
        w.f64s(&self.position_covariance);
        w.u8(self.position_covariance_type);
        w.finish()
    }
}

impl Decode for NavSatFix {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let status = r.i8("status.status")?;
        let service = r.u16("status.service")?;
        let latitude = r.f64("latitude")?;
        let longitude = r.f64("longitude")?;
        let altitude = r.f64("altitude")?;
        let mut position_covariance = [0.0; 9];
        for c in &mut position_covariance {
            *c = r.f64("position_covariance")?;
        }
        let position_covariance_type = r.u8("position_covariance_type")?;
        Ok(Self {
            header,
            status,
            service,
            latitude,
            longitude,
            altitude,
            position_covariance,
            position_covariance_type,
        })
    }
}

/// `geometry_msgs/msg/TwistWithCovarianceStamped`: the linear velocity used.
#[derive(Debug, Clone, PartialEq)]
pub struct TwistStamped {
    /// Header.
    pub header: Header,
    /// Linear velocity [m/s] in the header's frame (ENU for a GNSS receiver's).
    pub linear: [f64; 3],
    /// Twist covariance 6×6 row-major (linear x, y, z, angular x, y, z).
    pub covariance: [f64; 36],
}

impl TwistStamped {
    /// Decodes a payload.
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }
}

impl Decode for TwistStamped {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let linear = vector3(r, "twist.twist.linear")?;
        r.skip_f64s(3, "twist.twist.angular")?;
        let covariance = r.finite_array("twist.covariance")?;
        Ok(Self {
            header,
            linear,
            covariance,
        })
    }
}

/// `sensor_msgs/msg/FluidPressure`.
#[derive(Debug, Clone, PartialEq)]
pub struct FluidPressure {
    /// Header.
    pub header: Header,
    /// Pressure [Pa].
    pub fluid_pressure: f64,
    /// Its variance [Pa²] (0: unknown).
    pub variance: f64,
}

impl FluidPressure {
    /// Decodes a payload.
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }

    /// Encodes the message (for test bags).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.f64(self.fluid_pressure);
        w.f64(self.variance);
        w.finish()
    }
}

impl Decode for FluidPressure {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let fluid_pressure = r.finite("fluid_pressure")?;
        let variance = r.finite("variance")?;
        Ok(Self {
            header,
            fluid_pressure,
            variance,
        })
    }
}

/// `nav_msgs/msg/Odometry`.
#[derive(Debug, Clone, PartialEq)]
pub struct Odometry {
    /// Header (the pose's frame).
    pub header: Header,
    /// The twist's frame.
    pub child_frame_id: String,
    /// Position [m] in the header's frame.
    pub position: [f64; 3],
    /// Orientation of the child frame in the header's frame, x, y, z, w.
    pub orientation: [f64; 4],
    /// Pose covariance 6×6 row-major (x, y, z, rotation about x, y, z).
    pub pose_covariance: [f64; 36],
    /// Linear velocity [m/s] in the child frame.
    pub linear: [f64; 3],
    /// Angular velocity [rad/s] in the child frame.
    pub angular: [f64; 3],
    /// Twist covariance 6×6 row-major.
    pub twist_covariance: [f64; 36],
}

impl Odometry {
    /// Decodes a payload.
    pub fn decode(payload: &[u8]) -> Result<Self, CdrError> {
        Self::decode_in(Encoding::Cdr, payload)
    }

    /// Encodes the message.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.string(&self.child_frame_id);
        w.f64s(&self.position);
        w.f64s(&self.orientation);
        w.f64s(&self.pose_covariance);
        w.f64s(&self.linear);
        w.f64s(&self.angular);
        w.f64s(&self.twist_covariance);
        w.finish()
    }
}

impl Decode for Odometry {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let child_frame_id = r.string("child_frame_id")?;
        let position = vector3(r, "pose.pose.position")?;
        let orientation = r.finite_array("pose.pose.orientation")?;
        let pose_covariance = r.finite_array("pose.covariance")?;
        let linear = vector3(r, "twist.twist.linear")?;
        let angular = vector3(r, "twist.twist.angular")?;
        let twist_covariance = r.finite_array("twist.covariance")?;
        Ok(Self {
            header,
            child_frame_id,
            position,
            orientation,
            pose_covariance,
            linear,
            angular,
            twist_covariance,
        })
    }
}

/// `geometry_msgs/msg/TransformStamped`: frame `child_frame_id` as seen from
/// `header.frame_id` (a vector `v` of the child's axes is `R(q)·v + t` in the parent's).
#[derive(Debug, Clone, PartialEq)]
pub struct TransformStamped {
    /// Header (the parent frame).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's origin in the parent frame [m].
    pub translation: [f64; 3],
    /// The child's orientation in the parent frame, x, y, z, w.
    pub rotation: [f64; 4],
}

/// `tf2_msgs/msg/TFMessage`: `geometry_msgs/TransformStamped[] transforms`.
#[derive(Debug, Clone, PartialEq)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

impl Decode for TfMessage {
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError> {
        let n = r.u32("transforms")?;
        let mut transforms = Vec::new();
        for _ in 0..n {
            let header = Header::read(r)?;
            let child_frame_id = r.string("transforms.child_frame_id")?;
            let translation = vector3(r, "transforms.transform.translation")?;
            let rotation = r.finite_array("transforms.transform.rotation")?;
            transforms.push(TransformStamped {
                header,
                child_frame_id,
                translation,
                rotation,
            });
        }
        Ok(Self { transforms })
    }
}

impl TfMessage {
    /// Encodes the message as CDR (for test bags).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u32(self.transforms.len() as u32);
        for t in &self.transforms {
            t.header.write(&mut w);
            w.string(&t.child_frame_id);
            w.f64s(&t.translation);
            w.f64s(&t.rotation);
        }
        w.finish()
    }
}

/// `geometry_msgs/msg/Vector3Stamped`.
#[derive(Debug, Clone, PartialEq)]
pub struct Vector3Stamped {
    /// Header.
    pub header: Header,
    /// The vector.
    pub vector: [f64; 3],
}

impl Vector3Stamped {
    /// Encodes the message.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.f64s(&self.vector);
        w.finish()
    }
}

/// The `ros2msg` definitions of the written types, dependencies after a line of `=`
/// and `MSG: package/Type`, as `ros2 bag record` stores them (comments left out).
pub mod definitions {
    const TIME: &str = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
    const HEADER: &str = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
    const SEP: &str =
        "================================================================================\n";

    /// A definition with its dependencies.
    fn with_deps(main: &str, deps: &[&str]) -> String {
        let mut s = main.to_owned();
        for d in deps {
            s.push_str(SEP);
            s.push_str(d);
        }
        s
    }

    /// `nav_msgs/msg/Odometry`.
    pub fn odometry() -> String {
        with_deps(
            "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n",
            &[
                HEADER,
                TIME,
                "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n",
                "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n",
                "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
                "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
                "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n",
                "MSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n",
                "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
            ],
        )
    }

    /// `sensor_msgs/msg/NavSatFix`.
    pub fn nav_sat_fix() -> String {
        with_deps(
            "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\nuint8 COVARIANCE_TYPE_UNKNOWN = 0\nuint8 COVARIANCE_TYPE_APPROXIMATED = 1\nuint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\nuint8 COVARIANCE_TYPE_KNOWN = 3\nuint8 position_covariance_type\n",
            &[
                HEADER,
                TIME,
                "MSG: sensor_msgs/NavSatStatus\nint8 STATUS_NO_FIX = -1\nint8 STATUS_FIX = 0\nint8 STATUS_SBAS_FIX = 1\nint8 STATUS_GBAS_FIX = 2\nint8 status\nuint16 SERVICE_GPS = 1\nuint16 SERVICE_GLONASS = 2\nuint16 SERVICE_COMPASS = 4\nuint16 SERVICE_GALILEO = 8\nuint16 service\n",
            ],
        )
    }

    /// `sensor_msgs/msg/Imu`.
    pub fn imu() -> String {
        with_deps(
            "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
            &[
                HEADER,
                TIME,
                "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
                "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
            ],
        )
    }

    /// `geometry_msgs/msg/Vector3Stamped`.
    pub fn vector3_stamped() -> String {
        with_deps(
            "std_msgs/Header header\nVector3 vector\n",
            &[
                HEADER,
                TIME,
                "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
            ],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        Header {
            sec: 345_600,
            nanosec: 5_000_000,
            frame_id: "gnss".into(),
        }
    }

    #[test]
    fn written_messages_read_back() {
        let fix = NavSatFix {
            header: header(),
            status: 0,
            service: 1,
            latitude: 45.07,
            longitude: 7.68,
            altitude: 245.0,
            position_covariance: [0.25, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0],
            position_covariance_type: 2,
        };
        assert_eq!(NavSatFix::decode(&fix.encode()), Ok(fix));
        let mut cov = [0.0; 36];
        cov[0] = 1.0;
        let odo = Odometry {
            header: header(),
            child_frame_id: "base_link".into(),
            position: [1.0, 2.0, 3.0],
            orientation: [0.0, 0.0, 0.0, 1.0],
            pose_covariance: cov,
            linear: [10.0, 0.0, 0.0],
            angular: [0.0, 0.0, 0.1],
            twist_covariance: cov,
        };
        assert_eq!(Odometry::decode(&odo.encode()), Ok(odo));
        let imu = Imu {
            header: header(),
            angular_velocity: [0.1, -0.2, 0.3],
            angular_velocity_covariance: [1e-6; 9],
            linear_acceleration: [0.5, 0.0, 9.8],
            linear_acceleration_covariance: [1e-4; 9],
        };
        let motion = ImuMotion::decode(&imu.encode()).expect("motion");
        assert_eq!(motion.stamp, (imu.header.sec, imu.header.nanosec));
        assert_eq!(motion.angular_velocity, imu.angular_velocity);
        assert_eq!(motion.linear_acceleration, imu.linear_acceleration);
        assert_eq!(Imu::decode(&imu.encode()), Ok(imu));
        assert!((header().seconds() - 345_600.005).abs() < 1e-10);
    }

    #[test]
    fn tf_messages_read_back() {
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                header: header(),
                child_frame_id: "imu_link".into(),
                translation: [0.1, 0.0, 0.2],
                rotation: [0.5, -0.5, 0.5, 0.5],
            }],
        };
        assert_eq!(TfMessage::decode_in(Encoding::Cdr, &tf.encode()), Ok(tf));
    }

    /// A ROS 1 `sensor_msgs/Imu` laid out by hand (header with seq, packed): the
    /// same values come out as from CDR.
    #[test]
    fn ros1_imus_read_as_cdr_ones() {
        use super::super::ros1_msg::Ros1Writer;
        let mut w = Ros1Writer::new();
        w.header(41, 345_600, 5_000_000, "gnss");
        w.f64s(&[0.0, 0.0, 0.0, 1.0]);
        w.f64s(&[-1.0; 9]);
        w.f64s(&[0.1, -0.2, 0.3]);
        w.f64s(&[1e-6; 9]);
        w.f64s(&[0.5, 0.0, 9.8]);
        w.f64s(&[1e-4; 9]);
        let imu = Imu::decode_in(Encoding::Ros1, &w.finish()).expect("ros1");
        assert_eq!(
            imu,
            Imu {
                header: header(),
                angular_velocity: [0.1, -0.2, 0.3],
                angular_velocity_covariance: [1e-6; 9],
                linear_acceleration: [0.5, 0.0, 9.8],
                linear_acceleration_covariance: [1e-4; 9],
            }
        );
        assert!(same_type("sensor_msgs/Imu", IMU));
        assert!(same_type(IMU, IMU));
        assert!(!same_type("sensor_msgs/Imu2", IMU));
        assert!(!same_type("sensor_msgsImu", IMU));
    }

    #[test]
    fn a_truncated_imu_names_its_field() {
        let odo_bytes = Vector3Stamped {
            header: header(),
            vector: [1.0, 2.0, 3.0],
        }
        .encode();
        let e = Imu::decode(&odo_bytes).expect_err("too short for an Imu");
        assert_eq!(e.field, "orientation");
        let mut w = CdrWriter::new();
        w.i32(1);
        w.u32(2_000_000_000);
        let e = Imu::decode(&w.finish()).expect_err("nanosec");
        assert_eq!(e.field, "header.stamp.nanosec");
    }
}
