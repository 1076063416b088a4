//! Which device log a file is, told by its content (never by its name): the first
//! bytes of the file, gunzipped first when it begins with gzip's magic bytes (every
//! log reader reads `.gz` files as plain ones).
//!
//! | format | signature |
//! |---|---|
//! | PX4 ULog | `ULog` `01 12 35` (ULog file format, "File header") |
//! | ROS 1 bag | `#ROSBAG V2.0` (rosbag format 2.0) |
//! | ROS 2 MCAP | `89 'MCAP0' 0D 0A` (MCAP specification, "Magic"); a rosbag2 directory |
//! | ArduPilot DataFlash | `A3 95` then the `FMT` message type 128 (`LogStructure.h`) |
//! | Android GnssLogger | `#` comment lines, one of them a record header `# Raw,`, `# Fix,`, `# UncalAccel,` … |
//! | u-blox UBX | a frame `B5 62` class id length payload checksum whose Fletcher checksum holds, after any text (NMEA sentences, a logger's header) |
//!
//! GnssLogger is tried before UBX: a UBX log may open with text lines too (gpsd's
//! `# Name: …` header), but never with a GnssLogger record header.

use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use crate::formats::error::cannot_read;
use std::io::Read;
use std::path::Path;

/// Bytes of the (decompressed) file looked at.
pub const HEAD_BYTES: usize = 64 * 1024;

/// The record types whose header line (`# Type,col,…`) marks a GnssLogger file.
const GNSS_LOGGER_TYPES: [&str; 9] = [
    "Raw",
    "Fix",
    "UncalAccel",
    "UncalGyro",
    "Accel",
    "Gyro",
    "Status",
    "OrientationDeg",
    "Nav",
];

/// A device log's format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LogFormat {
    /// PX4 ULog.
    Ulog,
    /// ROS 1 bag, format 2.0.
    Ros1Bag,
    /// ROS 2 bag: an MCAP file or a rosbag2 directory.
    Mcap,
    /// u-blox UBX.
    Ubx,
    /// ArduPilot DataFlash.
    Dataflash,
    /// Android GnssLogger text.
    GnssLogger,
}

impl LogFormat {
    /// Every format, in the order detection tries them.
    pub const ALL: [LogFormat; 6] = [
        LogFormat::Ulog,
        LogFormat::Ros1Bag,
        LogFormat::Mcap,
        LogFormat::Dataflash,
        LogFormat::GnssLogger,
        LogFormat::Ubx,
    ];

    /// Its name as printed (and in `inspect --json`).
    pub fn name(self) -> &'static str {
        match self {
            LogFormat::Ulog => "PX4 ULog",
            LogFormat::Ros1Bag => "ROS 1 bag",
            LogFormat::Mcap => "ROS 2 bag (MCAP)",
            LogFormat::Ubx => "u-blox UBX",
            LogFormat::Dataflash => "ArduPilot DataFlash",
            LogFormat::GnssLogger => "Android GnssLogger",
        }
    }

    /// A short key (`ulog`, `ros1-bag`, `mcap`, `ubx`, `dataflash`, `gnss-logger`).
    pub fn key(self) -> &'static str {
        match self {
            LogFormat::Ulog => "ulog",
            LogFormat::Ros1Bag => "ros1-bag",
            LogFormat::Mcap => "mcap",
            LogFormat::Ubx => "ubx",
            LogFormat::Dataflash => "dataflash",
            LogFormat::GnssLogger => "gnss-logger",
        }
    }

    /// Whether it is a ROS bag (read by [`crate::bag`], not a [`super::LogReader`]).
    pub fn is_bag(self) -> bool {
        matches!(self, LogFormat::Ros1Bag | LogFormat::Mcap)
    }
}

/// The format of the log at `path` (a file, plain or gzip; or a rosbag2 directory).
/// A file no signature matches is refused naming it and what was looked for.
pub fn detect(path: &Path) -> Result<LogFormat, InputError> {
    let io = |e: std::io::Error| cannot_read(path, &e);
    if path.is_dir() {
        return match crate::bag::container::files_of(path) {
            Ok(_) => Ok(LogFormat::Mcap),
            Err(e) => Err(InputError::new(
                InputErrorKind::Header,
                path,
                0,
                None,
                format!("a directory that is no rosbag2 bag: {e}"),
            )),
        };
    }
    let head = read_head(path).map_err(io)?;
    detect_bytes(&head).ok_or_else(|| {
        InputError::new(
            InputErrorKind::Header,
            path,
            0,
            None,
            format!(
                "not a device log schuler reads: its first {} bytes match none of PX4 ULog \
                 (`ULog` magic), ROS 1 bag (`#ROSBAG V2.0`), MCAP (`\\x89MCAP0`), ArduPilot \
                 DataFlash (A3 95 and a FMT message), Android GnssLogger (`# Raw,`/`# Fix,` \
                 header lines) nor u-blox UBX (a B5 62 frame with a valid checksum)",
                head.len()
            ),
        )
    })
}

/// The first [`HEAD_BYTES`] of the file, gunzipped when it is gzip.
fn read_head(path: &Path) -> std::io::Result<Vec<u8>> {
    let mut file = std::fs::File::open(path)?;
    let mut raw = Vec::with_capacity(HEAD_BYTES);
    (&mut file).take(HEAD_BYTES as u64).read_to_end(&mut raw)?;
    if !raw.starts_with(&[0x1f, 0x8b]) {
        return Ok(raw);
    }
    let file = std::fs::File::open(path)?;
    let mut out = Vec::with_capacity(HEAD_BYTES);
    // A gzip stream cut short (a truncated file) still gives what it decoded.
    let mut gz = flate2::read::MultiGzDecoder::new(std::io::BufReader::new(file));
    let mut buf = [0u8; 8192];
    while out.len() < HEAD_BYTES {
        match gz.read(&mut buf) {
            Ok(0) => break,
            Ok(k) => out.extend_from_slice(&buf[..k.min(HEAD_BYTES - out.len())]),
            Err(e) if out.is_empty() => return Err(e),
            Err(_) => break,
        }
    }
    Ok(out)
}

/// The format of a log beginning with `head`, if any matches.
pub fn detect_bytes(head: &[u8]) -> Option<LogFormat> {
    LogFormat::ALL.into_iter().find(|&f| matches(f, head))
}

fn matches(format: LogFormat, head: &[u8]) -> bool {
    match format {
        LogFormat::Ulog => head.starts_with(b"ULog\x01\x12\x35"),
        LogFormat::Ros1Bag => head.starts_with(b"#ROSBAG V2.0"),
        LogFormat::Mcap => head.starts_with(b"\x89MCAP0\r\n"),
        // The first message is the FMT of FMT: header A3 95, type 128.
        LogFormat::Dataflash => head.len() >= 3 && head[..3] == [0xA3, 0x95, 0x80],
        LogFormat::GnssLogger => is_gnss_logger(head),
        LogFormat::Ubx => first_ubx_frame(head).is_some(),
    }
}

/// Whether the text lines at the start are GnssLogger's: comment lines (`#`) among
/// which a record header `# Type,` of a type GnssLogger writes, before any line that
/// is no comment.
fn is_gnss_logger(head: &[u8]) -> bool {
    for line in head.split(|&b| b == b'\n') {
        let Ok(line) = std::str::from_utf8(line) else {
            return false;
        };
        let line = line.trim_end_matches('\r');
        let Some(rest) = line.strip_prefix('#') else {
            // A data row of a type GnssLogger writes also tells it.
            return GNSS_LOGGER_TYPES
                .iter()
                .any(|t| line.strip_prefix(t).is_some_and(|r| r.starts_with(',')));
        };
        let rest = rest.trim_start();
        if GNSS_LOGGER_TYPES
            .iter()
            .any(|t| rest.strip_prefix(t).is_some_and(|r| r.starts_with(',')))
        {
            return true;
        }
    }
    false
}

/// The offset of the first complete UBX frame whose checksum holds (u-blox
/// interface description, "UBX checksum": 8-bit Fletcher over class, id, length and
/// payload).
pub fn first_ubx_frame(head: &[u8]) -> Option<usize> {
    let mut i = 0;
    while i + 8 <= head.len() {
        if head[i] == 0xB5 && head[i + 1] == 0x62 {
            let len = usize::from(u16::from_le_bytes([head[i + 4], head[i + 5]]));
            let end = i + 6 + len + 2;
            if end <= head.len() {
                let (mut a, mut b) = (0u8, 0u8);
                for &x in &head[i + 2..i + 6 + len] {
                    a = a.wrapping_add(x);
                    b = b.wrapping_add(a);
                }
                if head[end - 2] == a && head[end - 1] == b {
                    return Some(i);
                }
            }
        }
        i += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A UBX frame of `payload` with its checksum computed by hand.
    fn ubx(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
        let mut f = vec![0xB5, 0x62, class, id];
        f.extend_from_slice(&(payload.len() as u16).to_le_bytes());
        f.extend_from_slice(payload);
        let (mut a, mut b) = (0u8, 0u8);
        for &x in &f[2..] {
            a = a.wrapping_add(x);
            b = b.wrapping_add(a);
        }
        f.extend_from_slice(&[a, b]);
        f
    }

    #[test]
    fn magic_bytes_tell_the_binary_formats() {
        assert_eq!(
            detect_bytes(b"ULog\x01\x12\x35\x01rest"),
            Some(LogFormat::Ulog)
        );
        assert_eq!(
            detect_bytes(b"#ROSBAG V2.0\nE\0\0\0"),
            Some(LogFormat::Ros1Bag)
        );
        assert_eq!(detect_bytes(b"\x89MCAP0\r\n\x01"), Some(LogFormat::Mcap));
        assert_eq!(
            detect_bytes(&[0xA3, 0x95, 0x80, 0x80, 89]),
            Some(LogFormat::Dataflash)
        );
        // A3 95 followed by another message type is not a DataFlash log's start.
        assert_eq!(detect_bytes(&[0xA3, 0x95, 0x81, 0, 0]), None);
        // An older ROS bag version is not read.
        assert_eq!(detect_bytes(b"#ROSBAG V1.2\n"), None);
    }

    #[test]
    fn ubx_after_nmea_text_and_only_with_a_valid_checksum() {
        let frame = ubx(0x01, 0x07, &[7u8; 92]);
        let mut log =
            b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n".to_vec();
        let at = log.len();
        log.extend_from_slice(&frame);
        assert_eq!(first_ubx_frame(&log), Some(at));
        assert_eq!(detect_bytes(&log), Some(LogFormat::Ubx));
        // One checksum byte flipped: no frame, no format.
        let n = log.len();
        log[n - 1] ^= 1;
        assert_eq!(detect_bytes(&log), None);
        // gpsd's text header before the frames (neo_m8u_esf.ubx) is skipped alike.
        let mut gpsd = b"# Name: ublox-neo-m8u.log\n# Chipset: u-blox\n".to_vec();
        gpsd.extend_from_slice(&frame);
        assert_eq!(detect_bytes(&gpsd), Some(LogFormat::Ubx));
    }

    #[test]
    fn gnss_logger_by_its_record_headers() {
        let log = b"# \n# Header Description:\n# \n# Version: v3.0.6.4 Platform: 14\n# \n# Raw,utcTimeMillis,TimeNanos\n# Fix,Provider,LatitudeDegrees\n# \nRaw,1,2\n";
        assert_eq!(detect_bytes(log), Some(LogFormat::GnssLogger));
        // 2.0's `#,` line between the header lines does not stop it.
        let v2 = b"# \n#,\n# Raw,utcTimeMillis\n";
        assert_eq!(detect_bytes(v2), Some(LogFormat::GnssLogger));
        // Comment lines without a record header, then other text: not GnssLogger.
        assert_eq!(detect_bytes(b"# a comment\n1 2 3\n"), None);
        assert_eq!(detect_bytes(b"time,ax,ay,az\n0,1,2,3\n"), None);
        assert_eq!(detect_bytes(b""), None);
    }

    #[test]
    fn a_garbage_file_is_refused_naming_it() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("garbage.ulg");
        std::fs::write(&path, b"not a log at all\n\x00\x01\x02").expect("write");
        let e = detect(&path).expect_err("garbage");
        let text = e.to_string();
        assert!(text.contains("garbage.ulg"), "{text}");
        assert!(text.contains("PX4 ULog"), "{text}");
        // A ULog cut inside its magic is no ULog either.
        std::fs::write(&path, b"ULog\x01").expect("write");
        assert!(detect(&path).is_err());
    }

    /// Every log the repository holds is told by its content, gzip or not (the
    /// names are not looked at: the UBX logs are `.ubx.gz`, the bag `.bag`).
    #[test]
    fn the_committed_logs_are_told_by_content() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
        let cases = [
            ("ulog/sample_log_small.ulg.gz", LogFormat::Ulog),
            ("ulog/sample_px4_events.ulg.gz", LogFormat::Ulog),
            ("ros1_bag/test2.bag", LogFormat::Ros1Bag),
            ("ros1_bag/test2_first5s_lz4.bag", LogFormat::Ros1Bag),
            ("ros2_bag/drive.mcap", LogFormat::Mcap),
            ("ubx/f9p_rover_rawx_sfrbx.ubx.gz", LogFormat::Ubx),
            ("ubx/neo_m8u_esf.ubx.gz", LogFormat::Ubx),
            ("ubx/f9_esf_nav_att_truncated.ubx.gz", LogFormat::Ubx),
            ("dataflash/pymavlink_test.bin.gz", LogFormat::Dataflash),
            ("dataflash/synthetic_circle.bin.gz", LogFormat::Dataflash),
            (
                "gnss_logger/pixel4_gsdc2021_gnsslog.txt",
                LogFormat::GnssLogger,
            ),
            (
                "gnss_logger/pixel7_2023_11_07.txt.gz",
                LogFormat::GnssLogger,
            ),
            (
                "gnss_logger/pseudoranges_log_2016_06_30_21_26_07_cut.txt.gz",
                LogFormat::GnssLogger,
            ),
        ];
        for (file, format) in cases {
            assert_eq!(detect(&data.join(file)).expect(file), format, "{file}");
        }
        // Files of other kinds the repository holds are refused.
        for other in [
            "nmea/aircraft_dgps.nmea",
            "drive9min/GNSS.txt",
            "ros2_bag/scenario.toml",
        ] {
            assert!(detect(&data.join(other)).is_err(), "{other}");
        }
    }
}
