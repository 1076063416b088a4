//! What the message types ask of a serialization, so that [`super::messages`] decodes
//! each type once for ROS 2's CDR ([`super::cdr::CdrReader`]) and ROS 1's
//! serialization ([`super::ros1_msg::Ros1Reader`]) alike: primitives by name, strings,
//! a sequence's length and the header's stamp (the two differ there: ROS 1's
//! `std_msgs/Header` opens with a `uint32 seq`, its `time` is two `uint32`s).

use super::cdr::{CdrError, CdrReader};
use super::ros1_msg::Ros1Reader;

/// The serialization of a topic's messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// ROS 2: OMG CDR with its encapsulation header (MCAP message encoding `cdr`).
    Cdr,
    /// ROS 1: little-endian, packed, strings and sequences prefixed by a `uint32`
    /// count (ROS wiki, "roscpp/Overview/MessagesSerializationAndAdaptingTypes").
    Ros1,
}

/// A decoder of one payload; every read names its field for the error.
pub trait WireReader {
    /// A `float64`.
    fn f64(&mut self, field: &str) -> Result<f64, CdrError>;
    /// An `int32`.
    fn i32(&mut self, field: &str) -> Result<i32, CdrError>;
    /// A `uint32` (also a sequence's length).
    fn u32(&mut self, field: &str) -> Result<u32, CdrError>;
    /// A `uint16`.
    fn u16(&mut self, field: &str) -> Result<u16, CdrError>;
    /// An `int8`.
    fn i8(&mut self, field: &str) -> Result<i8, CdrError>;
    /// A `uint8`.
    fn u8(&mut self, field: &str) -> Result<u8, CdrError>;
    /// A `string`.
    fn string(&mut self, field: &str) -> Result<String, CdrError>;
    /// Skips a `string`.
    fn skip_string(&mut self, field: &str) -> Result<(), CdrError>;
    /// Skips `n` `float64`s.
    fn skip_f64s(&mut self, n: usize, field: &str) -> Result<(), CdrError>;
    /// A `std_msgs/Header`'s stamp as `(sec, nanosec)`, before its `frame_id` (ROS 1:
    /// `seq` read and dropped first).
    fn header_stamp(&mut self) -> Result<(i32, u32), CdrError>;

    /// A `float64` that must be finite.
    fn finite(&mut self, field: &str) -> Result<f64, CdrError> {
        let x = self.f64(field)?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(CdrError {
                field: field.to_owned(),
                reason: format!("{x} is not a finite number"),
            })
        }
    }

    /// `N` `float64`s (a fixed array), each finite.
    fn finite_array<const N: usize>(&mut self, field: &str) -> Result<[f64; N], CdrError> {
        let mut out = [0.0; N];
        for (i, x) in out.iter_mut().enumerate() {
            *x = self.f64(field)?;
            if !x.is_finite() {
                return Err(CdrError {
                    field: format!("{field}[{i}]"),
                    reason: format!("{x} is not a finite number"),
                });
            }
        }
        Ok(out)
    }
}

/// A message type read field by field from either serialization.
pub trait Decode: Sized {
    /// Reads the message from `r`.
    fn read<R: WireReader>(r: &mut R) -> Result<Self, CdrError>;

    /// Decodes a payload in `encoding`.
    fn decode_in(encoding: Encoding, payload: &[u8]) -> Result<Self, CdrError> {
        match encoding {
            Encoding::Cdr => Self::read(&mut CdrReader::new(payload)?),
            Encoding::Ros1 => Self::read(&mut Ros1Reader::new(payload)),
        }
    }
}
