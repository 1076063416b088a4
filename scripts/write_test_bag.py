#!/usr/bin/env python3
"""Write a ROS 2 bag (MCAP) from the files `schuler simulate` writes, with the
`mcap` and `mcap-ros2-support` packages (an implementation of MCAP and CDR that
schuler does not share), for schuler's bag tests.

Inputs (in SIM, a `schuler simulate --out` directory):
  imu.txt   t, dtheta_xyz [rad], dvel_xyz [m/s] over (t_prev, t], FRD axes
  gnss.csv  t, lat, lon [deg], h [m], std N E D [m], vn ve vd [m/s], their std
  baro.csv  t, h [m]            (optional)
  truth.nav week sow lat lon h vn ve vd roll pitch yaw (with --odometer-rate)

Messages (REP 103 body axes FLU, REP 105 world ENU):
  /imu/data  sensor_msgs/msg/Imu: angular_velocity = FLU(dtheta / dt),
             linear_acceleration = FLU(dvel / dt), dt = t - t_prev (the first
             sample uses the second's interval); covariances -1 (not given) unless
             --gyro-std / --accel-std give one sample's standard deviation
  /gnss/fix  sensor_msgs/msg/NavSatFix, covariance diag(std_E^2, std_N^2, std_D^2)
             in ENU, type DIAGONAL_KNOWN; one NO_FIX message (NaN position) at every
             whole second of a GNSS gap longer than 1.5 intervals
  /gnss/vel  geometry_msgs/msg/TwistWithCovarianceStamped, ENU (ve, vn, -vd)
  /baro      sensor_msgs/msg/FluidPressure: p = p0 (1 - L h / T0)^(g0 M / (R L)),
             the ISA troposphere with the U.S. Standard Atmosphere 1976 constants
  /odom      nav_msgs/msg/Odometry, twist.twist.linear.x = the true speed
             sqrt(vn^2 + ve^2 + vd^2) of truth.nav at the times that are multiples
             of 1/--odometer-rate (within 1e-6 of a period)

With --imu-rpy R,P,Y [deg] the IMU frame imu_link is turned from base_link by tf2's
RPY (fixed axes: R = Rz(Y) Ry(P) Rx(R)): a latched /tf_static (tf2_msgs/msg/TFMessage)
holds base_link -> imu_link, and every IMU vector is written in imu_link's axes,
v_imu = R^T v_base (base_link FLU, REP 103).

Stamps: sec = floor(t), nanosec = the rest in ns; log time = stamp + --latency
(GNSS, baro, odometry arrive late, as recorded on a robot), messages in log-time
order. The same inputs and options give the same bytes.
"""

import argparse
import csv
import math
import sys

from mcap.writer import CompressionType
from mcap_ros2.writer import Writer

SEP = "=" * 80 + "\n"
TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
QUATERNION = "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"
TWIST = "MSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n"
TWIST_COV = "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n"


def definition(main, *deps):
    return main + "".join(SEP + d for d in deps)


IMU_DEF = definition(
    "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
    "float64[9] linear_acceleration_covariance\n",
    HEADER, TIME, QUATERNION, VECTOR3)
FIX_DEF = definition(
    "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\n"
    "float64 altitude\nfloat64[9] position_covariance\nuint8 position_covariance_type\n",
    HEADER, TIME,
    "MSG: sensor_msgs/NavSatStatus\nint8 status\nuint16 service\n")
TWIST_STAMPED_DEF = definition(
    "std_msgs/Header header\ngeometry_msgs/TwistWithCovariance twist\n",
    HEADER, TIME, TWIST_COV, TWIST, VECTOR3)
PRESSURE_DEF = definition(
    "std_msgs/Header header\nfloat64 fluid_pressure\nfloat64 variance\n", HEADER, TIME)
ODOM_DEF = definition(
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
    "geometry_msgs/TwistWithCovariance twist\n",
    HEADER, TIME,
    "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n",
    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n",
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
    QUATERNION, TWIST_COV, TWIST, VECTOR3)

TF_DEF = definition(
    "geometry_msgs/TransformStamped[] transforms\n",
    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
    "Transform transform\n",
    HEADER, TIME,
    "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n",
    VECTOR3, QUATERNION)


def rpy_quaternion(roll, pitch, yaw):
    """x, y, z, w of R = Rz(yaw) Ry(pitch) Rx(roll) (tf2's setRPY)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def transposed_matrix(q):
    """R(q)^T as rows (pure Python, so that the bytes do not depend on numpy)."""
    x, y, z, w = q
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [[r[j][i] for j in range(3)] for i in range(3)]


def turned(msg, rt):
    """The IMU message with its vectors in imu_link's axes (rt = R^T)."""
    for key in ("angular_velocity", "linear_acceleration"):
        v = msg[key]
        b = (v["x"], v["y"], v["z"])
        x, y, z = (sum(rt[i][j] * b[j] for j in range(3)) for i in range(3))
        msg[key] = {"x": x, "y": y, "z": z}
    return msg


def tf_static(log_ns, q):
    """The /tf_static message base_link -> imu_link (rotation q, x y z w)."""
    return (log_ns, "/tf_static", {"transforms": [{
        "header": {"stamp": {"sec": log_ns // 1_000_000_000,
                             "nanosec": log_ns % 1_000_000_000},
                   "frame_id": "base_link"},
        "child_frame_id": "imu_link",
        "transform": {"translation": {"x": 0.5, "y": 0.0, "z": 1.0},
                      "rotation": dict(zip("xyzw", q))},
    }]})


# ISA troposphere, U.S. Standard Atmosphere 1976.
P0, T0, LAPSE = 101325.0, 288.15, 0.0065
EXPONENT = 9.80665 * 0.0289644 / (8.31432 * LAPSE)


def pressure(h):
    return P0 * (1.0 - LAPSE * h / T0) ** EXPONENT


def stamp(t):
    ns = round(t * 1e9)
    return ns, {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def header(t, frame):
    ns, st = stamp(t)
    return ns, {"stamp": st, "frame_id": frame}


def vec(x, y, z):
    return {"x": x, "y": y, "z": z}


def imu_messages(path, gyro_std, accel_std):
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip():
                rows.append([float(x) for x in line.split()])
    gyro_cov = [-1.0] + [0.0] * 8 if gyro_std is None else diag(gyro_std ** 2)
    accel_cov = [-1.0] + [0.0] * 8 if accel_std is None else diag(accel_std ** 2)
    for k, r in enumerate(rows):
        dt = r[0] - rows[k - 1][0] if k > 0 else rows[1][0] - rows[0][0]
        ns, h = header(r[0], "imu_link")
        # FRD to FLU: y and z change sign.
        yield ns, "/imu/data", {
            "header": h,
            "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
            "orientation_covariance": [-1.0] + [0.0] * 8,
            "angular_velocity": vec(r[1] / dt, -r[2] / dt, -r[3] / dt),
            "angular_velocity_covariance": gyro_cov,
            "linear_acceleration": vec(r[4] / dt, -r[5] / dt, -r[6] / dt),
            "linear_acceleration_covariance": accel_cov,
        }


def diag(v):
    return [v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, v]


def gnss_messages(path, latency_ns):
    with open(path) as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    interval = rows[1]["t"] - rows[0]["t"] if len(rows) > 1 else 1.0
    for k, r in enumerate(rows):
        if k > 0 and r["t"] - rows[k - 1]["t"] > 1.5 * interval:
            t = math.floor(rows[k - 1]["t"]) + 1.0
            while t < r["t"] - 0.5 * interval:
                ns, h = header(t, "gnss")
                yield ns + latency_ns, "/gnss/fix", {
                    "header": h,
                    "status": {"status": -1, "service": 1},
                    "latitude": math.nan, "longitude": math.nan, "altitude": math.nan,
                    "position_covariance": [0.0] * 9,
                    "position_covariance_type": 0,
                }
                t += 1.0
        ns, h = header(r["t"], "gnss")
        cov = [r["std_e_m"] ** 2, 0.0, 0.0, 0.0, r["std_n_m"] ** 2, 0.0, 0.0, 0.0,
               r["std_d_m"] ** 2]
        yield ns + latency_ns, "/gnss/fix", {
            "header": h,
            "status": {"status": 0, "service": 1},
            "latitude": r["lat_deg"], "longitude": r["lon_deg"], "altitude": r["h_m"],
            "position_covariance": cov,
            "position_covariance_type": 2,
        }
        twist_cov = [0.0] * 36
        twist_cov[0] = r["std_ve_mps"] ** 2
        twist_cov[7] = r["std_vn_mps"] ** 2
        twist_cov[14] = r["std_vd_mps"] ** 2
        yield ns + latency_ns, "/gnss/vel", {
            "header": h,
            "twist": {
                "twist": {"linear": vec(r["ve_mps"], r["vn_mps"], -r["vd_mps"]),
                          "angular": vec(0.0, 0.0, 0.0)},
                "covariance": twist_cov,
            },
        }


def baro_messages(path, latency_ns):
    with open(path) as f:
        for row in csv.DictReader(f):
            t, h_m = float(row["t"]), float(row["h_m"])
            ns, h = header(t, "baro")
            yield ns + latency_ns, "/baro", {
                "header": h, "fluid_pressure": pressure(h_m), "variance": 0.0}


def odometry_messages(path, rate_hz, latency_ns):
    with open(path) as f:
        for line in f:
            fields = [float(x) for x in line.split()]
            if not fields:
                continue
            t, (vn, ve, vd) = fields[1], fields[5:8]
            if abs(t * rate_hz - round(t * rate_hz)) > 1e-6:
                continue
            speed = math.sqrt(vn * vn + ve * ve + vd * vd)
            ns, h = header(t, "odom")
            yield ns + latency_ns, "/odom", {
                "header": h,
                "child_frame_id": "base_link",
                "pose": {"pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.0},
                                  "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                         "covariance": [0.0] * 36},
                "twist": {"twist": {"linear": vec(speed, 0.0, 0.0),
                                    "angular": vec(0.0, 0.0, 0.0)},
                          "covariance": [0.0] * 36},
            }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("sim", help="a `schuler simulate --out` directory")
    p.add_argument("out", help="the .mcap file to write")
    p.add_argument("--odometer-rate", type=float,
                   help="write /odom at this rate [Hz] from truth.nav's speed")
    p.add_argument("--latency", type=float, default=0.05,
                   help="log time after the stamp of GNSS, baro, odometry [s]")
    p.add_argument("--compression", choices=["zstd", "lz4", "none"], default="zstd")
    p.add_argument("--chunk-size", type=int, default=1024 * 1024)
    p.add_argument("--gyro-std", type=float, help="one sample's gyro std [rad/s]")
    p.add_argument("--accel-std", type=float, help="one sample's accel std [m/s^2]")
    p.add_argument("--no-baro", action="store_true")
    p.add_argument("--imu-rpy", help="imu_link's roll, pitch, yaw from base_link [deg]")
    a = p.parse_args()
    latency_ns = round(a.latency * 1e9)
    streams = [imu_messages(f"{a.sim}/imu.txt", a.gyro_std, a.accel_std),
               gnss_messages(f"{a.sim}/gnss.csv", latency_ns)]
    if not a.no_baro:
        streams.append(baro_messages(f"{a.sim}/baro.csv", latency_ns))
    if a.odometer_rate:
        streams.append(odometry_messages(f"{a.sim}/truth.nav", a.odometer_rate, latency_ns))
    messages = [m for s in streams for m in s]
    # Log-time order; ties keep the order above (IMU first), as sorted() is stable.
    messages.sort(key=lambda m: m[0])
    if a.imu_rpy:
        q = rpy_quaternion(*(math.radians(float(x)) for x in a.imu_rpy.split(",")))
        rt = transposed_matrix(q)
        messages = [(n, t, turned(m, rt) if t == "/imu/data" else m) for n, t, m in messages]
        messages.insert(0, tf_static(messages[0][0], q))
    compression = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                   "none": CompressionType.NONE}[a.compression]
    with open(a.out, "wb") as f:
        w = Writer(f, chunk_size=a.chunk_size, compression=compression)
        schemas = {
            "/imu/data": w.register_msgdef("sensor_msgs/msg/Imu", IMU_DEF),
            "/gnss/fix": w.register_msgdef("sensor_msgs/msg/NavSatFix", FIX_DEF),
            "/gnss/vel": w.register_msgdef(
                "geometry_msgs/msg/TwistWithCovarianceStamped", TWIST_STAMPED_DEF),
            "/baro": w.register_msgdef("sensor_msgs/msg/FluidPressure", PRESSURE_DEF),
            "/odom": w.register_msgdef("nav_msgs/msg/Odometry", ODOM_DEF),
        }
        if a.imu_rpy:
            schemas["/tf_static"] = w.register_msgdef("tf2_msgs/msg/TFMessage", TF_DEF)
        for seq, (log_ns, topic, msg) in enumerate(messages):
            w.write_message(topic, schemas[topic], msg, log_time=log_ns,
                            publish_time=log_ns, sequence=seq)
        w.finish()
    counts = {}
    for _, topic, _ in messages:
        counts[topic] = counts.get(topic, 0) + 1
    print(f"{a.out}: " + ", ".join(f"{t} {n}" for t, n in sorted(counts.items())),
          file=sys.stderr)


if __name__ == "__main__":
    main()
