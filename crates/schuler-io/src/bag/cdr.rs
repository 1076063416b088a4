//! OMG CDR (XCDR1, plain CDR as ROS 2's rmw implementations write it), the few
//! primitives the bag's message types use.
//!
//! A payload opens with a 4-byte encapsulation header: `00 01 00 00` little-endian
//! (`CDR_LE`), `00 00 00 00` big-endian (`CDR_BE`). Each primitive is aligned to its
//! own size (at most 8 bytes), counted from the end of the header; a string is a `u32`
//! length that counts its terminating NUL, then the bytes and the NUL; a fixed array is
//! its elements one after the other (DDS-XTypes 1.3, 7.4.3.5 "XCDR1").

/// What went wrong decoding a payload: the field and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("field {field}: {reason}")]
pub struct CdrError {
    /// The field being decoded (`header.stamp.sec`, `angular_velocity.x`).
    pub field: String,
    /// What was wrong.
    pub reason: String,
}

/// The payload's encapsulation: the byte order of every primitive after the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Order {
    Little,
    Big,
}

/// Decoder over one CDR payload.
pub struct CdrReader<'a> {
    body: &'a [u8],
    pos: usize,
    order: Order,
}

impl<'a> CdrReader<'a> {
    /// Reads the encapsulation header of `payload`; `CDR_LE` and `CDR_BE` only (the
    /// parameter-list and XCDR2 kinds are refused, naming the header bytes).
    pub fn new(payload: &'a [u8]) -> Result<Self, CdrError> {
        let bad = |reason: String| CdrError {
            field: "encapsulation header".into(),
            reason,
        };
        let Some(head) = payload.get(..4) else {
            return Err(bad(format!(
                "payload of {} bytes is shorter than the 4-byte header",
                payload.len()
            )));
        };
        let order = match (head[0], head[1]) {
            (0, 1) => Order::Little,
            (0, 0) => Order::Big,
            (a, b) => {
                return Err(bad(format!(
                    "representation {a:02x} {b:02x} is not plain CDR (00 00 or 00 01)"
                )));
            }
        };
        Ok(Self {
            body: &payload[4..],
            pos: 0,
            order,
        })
    }

    /// The next `n` bytes after aligning to `align`.
    fn take<const N: usize>(&mut self, field: &str) -> Result<[u8; N], CdrError> {
        let start = self.pos.next_multiple_of(N.min(8));
        let bytes = self.body.get(start..start + N).ok_or_else(|| CdrError {
            field: field.to_owned(),
            reason: format!(
                "payload ends at byte {} of its body, {N} bytes needed at {start}",
                self.body.len()
            ),
        })?;
        self.pos = start + N;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        if self.order == Order::Big {
            out.reverse();
        }
        Ok(out)
    }

    /// A `float64`.
    pub fn f64(&mut self, field: &str) -> Result<f64, CdrError> {
        self.take::<8>(field).map(f64::from_le_bytes)
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &str) -> Result<i32, CdrError> {
        self.take::<4>(field).map(i32::from_le_bytes)
    }

    /// A `uint32`.
    pub fn u32(&mut self, field: &str) -> Result<u32, CdrError> {
        self.take::<4>(field).map(u32::from_le_bytes)
    }

    /// A `uint16`.
    pub fn u16(&mut self, field: &str) -> Result<u16, CdrError> {
        self.take::<2>(field).map(u16::from_le_bytes)
    }

    /// An `int8`.
    pub fn i8(&mut self, field: &str) -> Result<i8, CdrError> {
        self.take::<1>(field).map(i8::from_le_bytes)
    }

    /// A `uint8`.
    pub fn u8(&mut self, field: &str) -> Result<u8, CdrError> {
        self.take::<1>(field).map(u8::from_le_bytes)
    }

    /// A `string`: its length (NUL included), the UTF-8 bytes, the NUL.
    pub fn string(&mut self, field: &str) -> Result<String, CdrError> {
        let n = self.u32(field)? as usize;
        let err = |reason: String| CdrError {
            field: field.to_owned(),
            reason,
        };
        let bytes = self
            .body
            .get(self.pos..self.pos.saturating_add(n))
            .ok_or_else(|| {
                err(format!(
                    "string of {n} bytes runs past the payload's {} bytes",
                    self.body.len()
                ))
            })?;
        self.pos += n;
        let text = match bytes.split_last() {
            Some((0, text)) => text,
            Some(_) => return Err(err("string lacks its terminating NUL".into())),
            None => bytes,
        };
        String::from_utf8(text.to_vec()).map_err(|_| err("string is not UTF-8".into()))
    }

    /// Skips `n` `float64`s (a fixed array not used), with one bounds check.
    pub fn skip_f64s(&mut self, n: usize, field: &str) -> Result<(), CdrError> {
        let start = self.pos.next_multiple_of(8);
        self.skip_to(start + 8 * n, field)
    }

    /// Skips a `string` without reading it.
    pub fn skip_string(&mut self, field: &str) -> Result<(), CdrError> {
        let n = self.u32(field)? as usize;
        self.skip_to(self.pos.saturating_add(n), field)
    }

    /// Moves to body byte `end`, which must be inside the payload.
    fn skip_to(&mut self, end: usize, field: &str) -> Result<(), CdrError> {
        if end > self.body.len() {
            return Err(CdrError {
                field: field.to_owned(),
                reason: format!(
                    "payload ends at byte {} of its body, {end} bytes needed",
                    self.body.len()
                ),
            });
        }
        self.pos = end;
        Ok(())
    }
}

impl super::wire::WireReader for CdrReader<'_> {
    fn f64(&mut self, field: &str) -> Result<f64, CdrError> {
        CdrReader::f64(self, field)
    }
    fn i32(&mut self, field: &str) -> Result<i32, CdrError> {
        CdrReader::i32(self, field)
    }
    fn u32(&mut self, field: &str) -> Result<u32, CdrError> {
        CdrReader::u32(self, field)
    }
    fn u16(&mut self, field: &str) -> Result<u16, CdrError> {
        CdrReader::u16(self, field)
    }
    fn i8(&mut self, field: &str) -> Result<i8, CdrError> {
        CdrReader::i8(self, field)
    }
    fn u8(&mut self, field: &str) -> Result<u8, CdrError> {
        CdrReader::u8(self, field)
    }
    fn string(&mut self, field: &str) -> Result<String, CdrError> {
        CdrReader::string(self, field)
    }
    fn skip_string(&mut self, field: &str) -> Result<(), CdrError> {
        CdrReader::skip_string(self, field)
    }
    fn skip_f64s(&mut self, n: usize, field: &str) -> Result<(), CdrError> {
        CdrReader::skip_f64s(self, n, field)
    }
    /// `builtin_interfaces/Time`: `int32 sec`, `uint32 nanosec`.
    fn header_stamp(&mut self) -> Result<(i32, u32), CdrError> {
        Ok((
            CdrReader::i32(self, "header.stamp.sec")?,
            CdrReader::u32(self, "header.stamp.nanosec")?,
        ))
    }
}

/// Encoder of one little-endian CDR payload (`CDR_LE`).
#[derive(Debug, Default)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl CdrWriter {
    /// A payload holding the `CDR_LE` encapsulation header.
    pub fn new() -> Self {
        Self {
            buf: vec![0, 1, 0, 0],
        }
    }

    /// Pads to `align` (counted after the header) and appends `bytes`.
    fn put(&mut self, align: usize, bytes: &[u8]) {
        let body = self.buf.len() - 4;
        self.buf.resize(4 + body.next_multiple_of(align), 0);
        self.buf.extend_from_slice(bytes);
    }

    /// A `float64`.
    pub fn f64(&mut self, x: f64) {
        self.put(8, &x.to_le_bytes());
    }

    /// `float64`s one after the other (a fixed array).
    pub fn f64s(&mut self, xs: &[f64]) {
        for &x in xs {
            self.f64(x);
        }
    }

    /// An `int32`.
    pub fn i32(&mut self, x: i32) {
        self.put(4, &x.to_le_bytes());
    }

    /// A `uint32`.
    pub fn u32(&mut self, x: u32) {
        self.put(4, &x.to_le_bytes());
    }

    /// A `uint16`.
    pub fn u16(&mut self, x: u16) {
        self.put(2, &x.to_le_bytes());
    }

    /// An `int8`.
    pub fn i8(&mut self, x: i8) {
        self.put(1, &x.to_le_bytes());
    }

    /// A `uint8`.
    pub fn u8(&mut self, x: u8) {
        self.put(1, &[x]);
    }

    /// A `string` (length with the NUL, bytes, NUL).
    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// The payload.
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bag::wire::WireReader;

    /// The bytes of a `std_msgs/Header` then a `float64` by the rules of the module
    /// doc, written out by hand: the string (length 5 with its NUL) ends at body byte
    /// 17, the float is padded to 24.
    #[test]
    fn alignment_and_strings_by_hand() {
        let mut w = CdrWriter::new();
        w.i32(7);
        w.u32(500);
        w.string("gnss");
        w.f64(1.5);
        let bytes = w.finish();
        let mut expected = vec![0, 1, 0, 0, 7, 0, 0, 0, 0xf4, 1, 0, 0, 5, 0, 0, 0];
        expected.extend_from_slice(b"gnss\0");
        expected.extend_from_slice(&[0; 7]);
        expected.extend_from_slice(&1.5f64.to_le_bytes());
        assert_eq!(bytes, expected);
        let mut r = CdrReader::new(&bytes).expect("header");
        assert_eq!(r.i32("sec"), Ok(7));
        assert_eq!(r.u32("nanosec"), Ok(500));
        assert_eq!(r.string("frame_id").as_deref(), Ok("gnss"));
        assert_eq!(r.f64("x"), Ok(1.5));
    }

    #[test]
    fn big_endian_payloads_read() {
        let mut bytes = vec![0, 0, 0, 0, 0, 0, 0, 7, 0, 0, 0, 0];
        bytes.extend_from_slice(&(-2.25f64).to_be_bytes());
        let mut r = CdrReader::new(&bytes).expect("header");
        assert_eq!(r.i32("sec"), Ok(7));
        assert_eq!(r.f64("x"), Ok(-2.25));
    }

    #[test]
    fn short_payloads_and_bad_headers_name_the_field() {
        let e = CdrReader::new(&[0, 1]).err().expect("short");
        assert_eq!(e.field, "encapsulation header");
        let e = CdrReader::new(&[0, 7, 0, 0]).err().expect("xcdr2");
        assert!(e.reason.contains("00 07"), "{e}");
        let mut r = CdrReader::new(&[0, 1, 0, 0, 1, 2, 3]).expect("header");
        let e = r.f64("linear_acceleration.z").expect_err("short");
        assert_eq!(e.field, "linear_acceleration.z");
        assert!(e.reason.contains("8 bytes needed"), "{e}");
        let mut r = CdrReader::new(&[0, 1, 0, 0, 9, 0, 0, 0, b'a']).expect("header");
        let e = r.string("frame_id").expect_err("long");
        assert!(e.reason.contains("runs past"), "{e}");
        let mut w = CdrWriter::new();
        w.f64(f64::NAN);
        let bytes = w.finish();
        let e = CdrReader::new(&bytes)
            .and_then(|mut r| r.finite_array::<1>("angular_velocity_covariance"))
            .expect_err("NaN");
        assert_eq!(e.field, "angular_velocity_covariance[0]");
    }
}
