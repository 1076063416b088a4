//! The ULog container: the 16-byte file header, the message framing
//! (`uint16 msg_size, uint8 msg_type, payload[msg_size]`, little-endian) and the flag
//! bits message `B` with its appended-data offsets (ULog file format, "Header",
//! "Flag Bits Message 'B'", "Appended data").
//!
//! Appended data: the `B` message lists up to three file offsets where appended
//! sections begin. The section before each offset may end in a message cut short (the
//! logger wrote until it stopped, then appended at the offset); such a tail is skipped,
//! and reading goes on at the offset. A file that ends inside a message anywhere else
//! is truncated, and refused.
//!
//! Errors carry the byte offset of the message at fault in [`InputError::line`] (a
//! binary file has no lines), and say "byte N" in their message.

use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The first seven bytes of every ULog file.
pub const MAGIC: [u8; 7] = [b'U', b'L', b'o', b'g', 0x01, 0x12, 0x35];

/// The eight bytes of a synchronisation message `S`.
pub const SYNC_MAGIC: [u8; 8] = [0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12];

/// An error at byte `offset` of `path`: `line` holds the offset.
pub fn error_at(
    kind: InputErrorKind,
    path: &Path,
    offset: u64,
    field: Option<&str>,
    message: impl std::fmt::Display,
) -> InputError {
    InputError::new(
        kind,
        path,
        offset,
        field,
        format!("byte {offset}: {message}"),
    )
}

/// A ULog file read message by message.
pub struct Container<R> {
    r: R,
    path: PathBuf,
    /// Bytes consumed so far.
    pos: u64,
    /// Offsets of the appended sections not yet reached, ascending.
    appended: Vec<u64>,
    /// The current message's payload.
    buf: Vec<u8>,
    /// Whether the first message (possibly `B`) has been read.
    started: bool,
    /// The file format version (header byte 7).
    pub version: u8,
    /// The header's timestamp: the logger's start [µs, device clock].
    pub start_us: u64,
    /// Appended sections the flag bits announced.
    pub appended_sections: usize,
}

/// One framed message: its type byte and the byte offset of its 3-byte header. Its
/// payload is [`Container::payload`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// The message type (`b'D'`, `b'F'`, …).
    pub kind: u8,
    /// Byte offset of the message header in the file.
    pub offset: u64,
}

impl<R: Read> Container<R> {
    /// Reads the file header of `r` (named `path` in errors).
    pub fn open(mut r: R, path: &Path) -> Result<Self, InputError> {
        let mut header = [0u8; 16];
        let got = read_full(&mut r, &mut header)
            .map_err(|e| error_at(InputErrorKind::Io, path, 0, None, e))?;
        if got < 16 || header[..7] != MAGIC {
            return Err(error_at(
                InputErrorKind::Header,
                path,
                0,
                None,
                "not a ULog file (the 16-byte header must start with \"ULog\" 01 12 35)",
            ));
        }
        let mut ts = [0u8; 8];
        ts.copy_from_slice(&header[8..]);
        Ok(Self {
            r,
            path: path.to_path_buf(),
            pos: 16,
            appended: Vec::new(),
            buf: Vec::with_capacity(1024),
            started: false,
            version: header[7],
            start_us: u64::from_le_bytes(ts),
            appended_sections: 0,
        })
    }

    /// Bytes consumed so far.
    pub fn position(&self) -> u64 {
        self.pos
    }

    /// The payload of the message [`Self::next_frame`] returned last.
    pub fn payload(&self) -> &[u8] {
        &self.buf
    }

    /// The next message, `None` at a clean end of file. The flag bits message is
    /// taken in here and not returned.
    pub fn next_frame(&mut self) -> Result<Option<Frame>, InputError> {
        loop {
            let section_end = self.appended.first().copied();
            if let Some(end) = section_end
                && self.pos + 3 > end
            {
                self.skip_to(end)?;
                continue;
            }
            let offset = self.pos;
            let mut header = [0u8; 3];
            let got = read_full(&mut self.r, &mut header).map_err(|e| self.io(offset, e))?;
            self.pos += got as u64;
            if got == 0 {
                return Ok(None);
            }
            if got < 3 {
                return Err(self.truncated(offset, "in a message header", 3, got));
            }
            let size = usize::from(u16::from_le_bytes([header[0], header[1]]));
            let kind = header[2];
            if let Some(end) = section_end
                && self.pos + size as u64 > end
            {
                self.skip_to(end)?;
                continue;
            }
            self.buf.resize(size, 0);
            let got = read_full(&mut self.r, &mut self.buf).map_err(|e| self.io(offset, e))?;
            self.pos += got as u64;
            if got < size {
                let what = format!("in the payload of a '{}' message", printable(kind));
                return Err(self.truncated(offset, &what, size, got));
            }
            let first = !self.started;
            self.started = true;
            if first && kind == b'B' {
                self.flag_bits(offset)?;
                continue;
            }
            return Ok(Some(Frame { kind, offset }));
        }
    }

    /// Takes in the flag bits: `uint8 compat[8], uint8 incompat[8], uint64
    /// appended_offsets[3]`. Incompatible flags other than "data appended" (bit 0 of
    /// byte 0) are refused, as the format requires of a reader that does not know them.
    fn flag_bits(&mut self, offset: u64) -> Result<(), InputError> {
        if self.buf.len() < 40 {
            return Err(self.garbled(
                offset,
                Some("flag_bits"),
                format!("flag bits message of {} bytes, 40 expected", self.buf.len()),
            ));
        }
        let incompat = &self.buf[8..16];
        if incompat[0] & !1 != 0 || incompat[1..].iter().any(|&b| b != 0) {
            return Err(error_at(
                InputErrorKind::Header,
                &self.path,
                offset,
                Some("incompat_flags"),
                format!(
                    "incompatible flags {incompat:02x?} that this reader does not know \
                     (only 'data appended' is)"
                ),
            ));
        }
        if incompat[0] & 1 == 1 {
            for i in 0..3 {
                let mut a = [0u8; 8];
                a.copy_from_slice(&self.buf[16 + 8 * i..24 + 8 * i]);
                let o = u64::from_le_bytes(a);
                if o == 0 {
                    break;
                }
                if o < self.pos || self.appended.last().is_some_and(|&l| o <= l) {
                    return Err(self.garbled(
                        offset,
                        Some("appended_offsets"),
                        format!("appended data offset {o} lies before byte {}", self.pos),
                    ));
                }
                self.appended.push(o);
            }
            self.appended_sections = self.appended.len();
        }
        Ok(())
    }

    /// Skips the cut tail of a section up to the appended section at `end`.
    fn skip_to(&mut self, end: u64) -> Result<(), InputError> {
        self.appended.remove(0);
        if end < self.pos {
            return Err(self.garbled(
                self.pos,
                Some("appended_offsets"),
                format!("appended data offset {end} lies inside an earlier message"),
            ));
        }
        let want = end - self.pos;
        let got = std::io::copy(&mut (&mut self.r).take(want), &mut std::io::sink())
            .map_err(|e| self.io(self.pos, e))?;
        self.pos += got;
        if got < want {
            return Err(error_at(
                InputErrorKind::NoData,
                &self.path,
                self.pos,
                Some("appended_offsets"),
                format!("the file ends before the appended data at byte {end}: truncated"),
            ));
        }
        Ok(())
    }

    fn io(&self, offset: u64, e: std::io::Error) -> InputError {
        error_at(InputErrorKind::Io, &self.path, offset, None, e)
    }

    fn truncated(&self, offset: u64, what: &str, want: usize, got: usize) -> InputError {
        error_at(
            InputErrorKind::NoData,
            &self.path,
            offset,
            None,
            format!("the file ends {what} ({got} of {want} bytes): truncated"),
        )
    }

    /// A garbled-message error at `offset`.
    pub fn garbled(
        &self,
        offset: u64,
        field: Option<&str>,
        message: impl std::fmt::Display,
    ) -> InputError {
        error_at(
            InputErrorKind::LayoutMismatch,
            &self.path,
            offset,
            field,
            message,
        )
    }
}

/// The message type byte as text for an error (`D`, or `0x9c`).
pub fn printable(kind: u8) -> String {
    if kind.is_ascii_graphic() {
        char::from(kind).to_string()
    } else {
        format!("0x{kind:02x}")
    }
}

/// Reads until `buf` is full or the end of the input; the number of bytes read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}
