//! The DataFlash container: message framing and the `FMT`/`FMTU` messages that define
//! every other message (ArduPilot `libraries/AP_Logger/LogStructure.h`).
//!
//! A log is a sequence of messages `A3 95 TYPE body`, with no file header and no
//! checksums; the body's length is the `Length` of the `FMT` message for `TYPE`
//! (which counts the 3-byte header). `FMT` itself is type 128, 89 bytes, `BBnNZ`:
//! `Type, Length, Name, Format, Columns`, known before any is read. `FMTU`
//! (`QBNN`: `TimeUS, FmtType, UnitIds, MultIds`, defined by an `FMT` like any
//! message) gives each column of a type a unit character; the column whose unit is
//! `#` holds the instance number (IMU `I`, EKF3 `C`), by which pymavlink names
//! streams `IMU[0]`, `IMU[1]`.
//!
//! **The end of a log.** Autopilots stop logging anywhere: a message cut by the end
//! of the file is the log's end, reported ([`Truncation`]), not refused; so are bytes
//! that begin no message when the end of the file is less than [`TAIL`] bytes after
//! them (block-based loggers pad their last page; pymavlink ignores the same 528
//! bytes). Anywhere else such bytes are refused: a missing `A3 95` or a type no `FMT`
//! has defined, naming the byte offset ([`InputError::line`] holds it).

use super::format::{Format, text};
use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The two bytes that begin every message.
pub const HEAD: [u8; 2] = [0xA3, 0x95];
/// The type of `FMT` messages.
pub const FMT_TYPE: u8 = 128;
/// The length of an `FMT` message, header included.
pub const FMT_LEN: usize = 89;
/// Bytes before the end of the file within which garbage is the logger's tail.
pub const TAIL: u64 = 528;

/// The read buffer's size: room for [`TAIL`] bytes of look-ahead and many messages.
const BUF: usize = 1 << 16;

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

/// A message cut by the end of the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Truncation {
    /// Byte offset of its header.
    pub offset: u64,
    /// Its message name, when its header was complete and its type defined.
    pub name: Option<String>,
    /// Bytes present.
    pub have: usize,
    /// Bytes the message needs.
    pub need: usize,
}

/// How a log ended.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Ending {
    /// A message cut by the end of the file.
    pub truncated: Option<Truncation>,
    /// Bytes at the end that began no message (within [`TAIL`] of the end).
    pub garbage_bytes: u64,
    /// The byte offset of the first of them.
    pub garbage_offset: Option<u64>,
}

/// One framed message: its type and the byte offset of its header; its body is
/// [`Container::body`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Message {
    /// The type byte.
    pub ty: u8,
    /// Byte offset of the header in the (decompressed) log.
    pub offset: u64,
}

/// A DataFlash log read message by message, with the formats met so far.
pub struct Container<R> {
    r: R,
    path: PathBuf,
    buf: Vec<u8>,
    start: usize,
    end: usize,
    eof: bool,
    /// Offset of `buf[start]` in the log.
    pos: u64,
    /// The current message's body range in `buf`.
    body: (usize, usize),
    /// Formats by type.
    formats: Vec<Option<Format>>,
    /// The type of `FMTU`, once an `FMT` defined it.
    fmtu: Option<u8>,
    /// How the log ended (once it has).
    pub ending: Ending,
    /// `FMT` messages read.
    pub fmt_count: u64,
}

impl<R: Read> Container<R> {
    /// A container over `r` (named `path` in errors).
    pub fn new(r: R, path: &Path) -> Self {
        let mut formats = vec![None; 256];
        formats[usize::from(FMT_TYPE)] = Some(
            Format::new(
                FMT_TYPE,
                "FMT",
                FMT_LEN,
                "BBnNZ",
                "Type,Length,Name,Format,Columns",
            )
            .expect("the FMT format is valid"),
        );
        Self {
            r,
            path: path.to_path_buf(),
            buf: vec![0; BUF],
            start: 0,
            end: 0,
            eof: false,
            pos: 0,
            body: (0, 0),
            formats,
            fmtu: None,
            ending: Ending::default(),
            fmt_count: 0,
        }
    }

    /// The format of type `ty`, if an `FMT` has defined it.
    pub fn format(&self, ty: u8) -> Option<&Format> {
        self.formats[usize::from(ty)].as_ref()
    }

    /// The body of the message [`Self::next_message`] returned last.
    pub fn body(&self) -> &[u8] {
        &self.buf[self.body.0..self.body.1]
    }

    /// Bytes consumed so far.
    pub fn position(&self) -> u64 {
        self.pos
    }

    /// Makes at least `n` bytes available from `start` unless the input ends first;
    /// the bytes available.
    fn fill(&mut self, n: usize) -> Result<usize, InputError> {
        if self.end - self.start >= n || self.eof {
            return Ok(self.end - self.start);
        }
        if self.start > 0 {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        while self.end < n.max(BUF / 2) && !self.eof {
            match self.r.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(k) => self.end += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(error_at(InputErrorKind::Io, &self.path, self.pos, None, e));
                }
            }
        }
        Ok(self.end - self.start)
    }

    /// Whether the log ends within [`TAIL`] bytes of the current position.
    fn near_end(&mut self) -> Result<bool, InputError> {
        let have = self.fill(TAIL as usize + 1)?;
        Ok((have as u64) <= TAIL)
    }

    /// Takes the rest of the log as its garbage tail.
    fn garbage_tail(&mut self) {
        let n = self.end - self.start;
        self.ending.garbage_bytes = n as u64;
        self.ending.garbage_offset = Some(self.pos);
        self.pos += n as u64;
        self.start = self.end;
    }

    /// The next message, `None` at the log's end (see [`Self::ending`]). `FMT` and
    /// `FMTU` messages are taken in here, and returned too.
    pub fn next_message(&mut self) -> Result<Option<Message>, InputError> {
        let offset = self.pos;
        let have = self.fill(3)?;
        if have == 0 {
            return Ok(None);
        }
        let mut head = [0u8; 3];
        head[..have.min(3)].copy_from_slice(&self.buf[self.start..self.start + have.min(3)]);
        if head[0] != HEAD[0] || (have > 1 && head[1] != HEAD[1]) {
            if offset == 0 {
                return Err(error_at(
                    InputErrorKind::Header,
                    &self.path,
                    0,
                    Some("header"),
                    format!(
                        "not a DataFlash log: it begins with {:02x?}, every message with \
                         a3 95",
                        &head[..have.min(3)]
                    ),
                ));
            }
            if self.near_end()? {
                self.garbage_tail();
                return Ok(None);
            }
            return Err(self.garbled(
                offset,
                Some("header"),
                format!(
                    "no message header (a3 95) but {:02x?} where a message should begin: \
                     the log is garbled",
                    &head[..2]
                ),
            ));
        }
        if have < 3 {
            self.cut(offset, None, have, 3);
            return Ok(None);
        }
        let ty = head[2];
        let Some(fmt) = self.formats[usize::from(ty)].as_ref() else {
            if self.near_end()? {
                self.garbage_tail();
                return Ok(None);
            }
            return Err(self.garbled(
                offset,
                Some("msg_type"),
                format!("message type {ty}, which no FMT message has defined"),
            ));
        };
        let len = fmt.len;
        let have = self.fill(len)?;
        if have < len {
            let name = self.formats[usize::from(ty)]
                .as_ref()
                .map(|f| f.name.clone());
            self.cut(offset, name, have, len);
            return Ok(None);
        }
        self.body = (self.start + 3, self.start + len);
        self.start += len;
        self.pos += len as u64;
        if ty == FMT_TYPE {
            self.take_fmt(offset)?;
        } else if Some(ty) == self.fmtu {
            self.take_fmtu(offset);
        }
        Ok(Some(Message { ty, offset }))
    }

    fn cut(&mut self, offset: u64, name: Option<String>, have: usize, need: usize) {
        self.ending.truncated = Some(Truncation {
            offset,
            name,
            have,
            need,
        });
        self.pos += have as u64;
        self.start = self.end;
    }

    /// Takes in an `FMT` body: `Type B, Length B, Name n, Format N, Columns Z`.
    fn take_fmt(&mut self, offset: u64) -> Result<(), InputError> {
        let b = self.body();
        let (ty, len) = (b[0], usize::from(b[1]));
        let name = text(&b[2..6]);
        let format = text(&b[6..22]);
        let labels = text(&b[22..86]);
        if ty == FMT_TYPE {
            if len != FMT_LEN || name != "FMT" {
                return Err(self.garbled(
                    offset,
                    Some("FMT.Length"),
                    format!("FMT redefines itself as {name:?}, {len} bytes (FMT is 89 bytes)"),
                ));
            }
            self.fmt_count += 1;
            return Ok(());
        }
        let f = Format::new(ty, &name, len, &format, &labels)
            .map_err(|(field, e)| self.garbled(offset, Some(field), e))?;
        if name == "FMTU" {
            self.fmtu = Some(ty);
        }
        // A redefinition keeps the instance column FMTU gave (pymavlink does the same).
        let instance = self.formats[usize::from(ty)]
            .as_ref()
            .and_then(|old| old.instance.map(|i| &old.columns[i].name))
            .and_then(|n| f.columns.iter().position(|c| &c.name == n));
        self.formats[usize::from(ty)] = Some(Format { instance, ..f });
        self.fmt_count += 1;
        Ok(())
    }

    /// Takes in an `FMTU` body: the column whose unit is `#` is the instance column.
    /// An `FMTU` without the columns it needs, or for an undefined type, is ignored.
    fn take_fmtu(&mut self, _offset: u64) {
        let Some(fmtu) = self
            .fmtu
            .and_then(|t| self.formats[usize::from(t)].as_ref())
        else {
            return;
        };
        let (Some(ty), Some(units)) = (fmtu.field("FmtType"), fmtu.column("UnitIds")) else {
            return;
        };
        let (ty, units_at, units_ch) = (ty, units.offset, units.ch);
        let b = self.body();
        let Some(ty) = ty.int(b).and_then(|t| u8::try_from(t).ok()) else {
            return;
        };
        let Some(size) = super::format::size_of(units_ch) else {
            return;
        };
        let units = text(&b[units_at..units_at + size]);
        // As pymavlink: a unit string without `#` leaves the instance column as it was.
        if let Some(f) = self.formats[usize::from(ty)].as_mut()
            && let Some(i) = units.bytes().position(|u| u == b'#')
            && i < f.columns.len()
        {
            f.instance = Some(i);
        }
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
