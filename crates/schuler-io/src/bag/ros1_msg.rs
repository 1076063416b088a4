//! ROS 1 message serialization (ROS wiki, "ROS/Technical Overview" and
//! "msg": serialization): every primitive little-endian and packed (no alignment, no
//! encapsulation header); a `string` is a `uint32` byte count then the bytes (no NUL);
//! a variable-length array a `uint32` element count then the elements; a fixed array
//! its elements alone; `time` is `uint32 secs, uint32 nsecs`; `std_msgs/Header` is
//! `uint32 seq, time stamp, string frame_id`.

use super::cdr::CdrError;
use super::wire::WireReader;

/// Decoder over one ROS 1 payload.
pub struct Ros1Reader<'a> {
    body: &'a [u8],
    pos: usize,
}

impl<'a> Ros1Reader<'a> {
    /// A reader at the payload's first byte.
    pub fn new(payload: &'a [u8]) -> Self {
        Self {
            body: payload,
            pos: 0,
        }
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.body.len() - self.pos
    }

    /// Moves past `n` bytes, which must be in the payload; their start.
    fn advance(&mut self, n: usize, field: &str) -> Result<usize, CdrError> {
        let start = self.pos;
        match start.checked_add(n).filter(|&end| end <= self.body.len()) {
            Some(end) => {
                self.pos = end;
                Ok(start)
            }
            None => Err(CdrError {
                field: field.to_owned(),
                reason: format!(
                    "payload ends at byte {}, {n} bytes needed at {start}",
                    self.body.len()
                ),
            }),
        }
    }

    /// The next `N` bytes.
    fn take<const N: usize>(&mut self, field: &str) -> Result<[u8; N], CdrError> {
        let start = self.advance(N, field)?;
        let mut out = [0u8; N];
        out.copy_from_slice(&self.body[start..start + N]);
        Ok(out)
    }
}

impl WireReader for Ros1Reader<'_> {
    fn f64(&mut self, field: &str) -> Result<f64, CdrError> {
        self.take::<8>(field).map(f64::from_le_bytes)
    }

    fn i32(&mut self, field: &str) -> Result<i32, CdrError> {
        self.take::<4>(field).map(i32::from_le_bytes)
    }

    fn u32(&mut self, field: &str) -> Result<u32, CdrError> {
        self.take::<4>(field).map(u32::from_le_bytes)
    }

    fn u16(&mut self, field: &str) -> Result<u16, CdrError> {
        self.take::<2>(field).map(u16::from_le_bytes)
    }

    fn i8(&mut self, field: &str) -> Result<i8, CdrError> {
        self.take::<1>(field).map(i8::from_le_bytes)
    }

    fn u8(&mut self, field: &str) -> Result<u8, CdrError> {
        self.take::<1>(field).map(|[b]| b)
    }

    fn string(&mut self, field: &str) -> Result<String, CdrError> {
        let n = self.u32(field)? as usize;
        let start = self.advance(n, field)?;
        String::from_utf8(self.body[start..start + n].to_vec()).map_err(|_| CdrError {
            field: field.to_owned(),
            reason: "string is not UTF-8".into(),
        })
    }

    fn skip_string(&mut self, field: &str) -> Result<(), CdrError> {
        let n = self.u32(field)? as usize;
        self.advance(n, field).map(|_| ())
    }

    fn skip_f64s(&mut self, n: usize, field: &str) -> Result<(), CdrError> {
        self.advance(n.saturating_mul(8), field).map(|_| ())
    }

    /// `uint32 seq`, then `time stamp` (`uint32 secs`, `uint32 nsecs`); a stamp past
    /// 2038-01-19 (over `i32::MAX` s) is refused, as ROS 2's `int32 sec` cannot hold it.
    fn header_stamp(&mut self) -> Result<(i32, u32), CdrError> {
        self.u32("header.seq")?;
        let secs = self.u32("header.stamp.secs")?;
        let nsecs = self.u32("header.stamp.nsecs")?;
        let sec = i32::try_from(secs).map_err(|_| CdrError {
            field: "header.stamp.secs".into(),
            reason: format!("{secs} s is past 2038-01-19 (over 2^31 - 1)"),
        })?;
        Ok((sec, nsecs))
    }
}

/// Encoder of one ROS 1 payload (for tests).
#[derive(Debug, Default)]
pub struct Ros1Writer {
    buf: Vec<u8>,
}

impl Ros1Writer {
    /// An empty payload.
    pub fn new() -> Self {
        Self::default()
    }

    /// Raw little-endian bytes of a primitive.
    pub fn put(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// `float64`s one after the other.
    pub fn f64s(&mut self, xs: &[f64]) {
        for x in xs {
            self.put(&x.to_le_bytes());
        }
    }

    /// A `string`: byte count, bytes.
    pub fn string(&mut self, s: &str) {
        self.put(&(s.len() as u32).to_le_bytes());
        self.put(s.as_bytes());
    }

    /// A `std_msgs/Header`.
    pub fn header(&mut self, seq: u32, secs: u32, nsecs: u32, frame_id: &str) {
        self.put(&seq.to_le_bytes());
        self.put(&secs.to_le_bytes());
        self.put(&nsecs.to_le_bytes());
        self.string(frame_id);
    }

    /// The payload.
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header then a `float64`, laid out by hand: no padding anywhere, the string
    /// without its NUL.
    #[test]
    fn packed_layout_by_hand() {
        let mut bytes = vec![9, 0, 0, 0, 7, 0, 0, 0, 0xf4, 1, 0, 0, 4, 0, 0, 0];
        bytes.extend_from_slice(b"gnss");
        bytes.extend_from_slice(&1.5f64.to_le_bytes());
        let mut w = Ros1Writer::new();
        w.header(9, 7, 500, "gnss");
        w.f64s(&[1.5]);
        assert_eq!(w.finish(), bytes);
        let mut r = Ros1Reader::new(&bytes);
        assert_eq!(r.header_stamp(), Ok((7, 500)));
        assert_eq!(r.string("header.frame_id").as_deref(), Ok("gnss"));
        assert_eq!(r.f64("x"), Ok(1.5));
        assert_eq!(r.remaining(), 0);
    }

    #[test]
    fn short_payloads_name_the_field() {
        let mut r = Ros1Reader::new(&[1, 0, 0, 0, 2, 0]);
        let e = r.header_stamp().expect_err("short");
        assert_eq!(e.field, "header.stamp.secs");
        assert!(e.reason.contains("4 bytes needed at 4"), "{e}");
        let mut r = Ros1Reader::new(&[200, 0, 0, 0, b'a']);
        let e = r.string("frame_id").expect_err("long");
        assert!(e.reason.contains("200 bytes needed"), "{e}");
        let mut r = Ros1Reader::new(&[0, 0, 0, 0, 0, 0, 0, 0x80, 0, 0, 0, 0]);
        let e = r.header_stamp().expect_err("2038");
        assert_eq!(e.field, "header.stamp.secs");
    }
}
