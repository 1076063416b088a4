//! UBX framing: the byte stream of a receiver log cut into UBX frames, NMEA sentences,
//! RTCM 3 frames and bytes that are none of these.
//!
//! A UBX frame (u-blox interface description, "UBX protocol", §3.2 of the F9 and M8
//! documents) is `B5 62 class id len_lo len_hi payload ck_a ck_b`: a little-endian
//! 16-bit payload length and an 8-bit Fletcher checksum (RFC 1146) over class, id,
//! length and payload: `ck_a += b; ck_b += ck_a` for every byte, modulo 256.
//!
//! Receivers interleave NMEA 0183 sentences (`$…\r\n`, printable ASCII) and RTCM 3
//! frames (`D3`, 6 zero bits, a 10-bit length, the message, a CRC-24Q over header and
//! message; RTCM 10403.3 §4) in the same port; both are recognised and skipped whole
//! so that a `B5 62` inside an RTCM message is never taken for a UBX frame. Anything
//! else (a logger's text header, a torn sentence) is skipped up to the next byte that
//! can begin one of the three.
//!
//! Garbled or truncated input: a UBX frame whose checksum fails right after a valid
//! frame (the scanner is *in sync*) is corruption and is returned as such, with its
//! offset, for the reader to refuse; one met while resynchronising after unknown bytes
//! is a false sync word and is skipped as unknown bytes. A UBX frame cut by the end of
//! the input (a receiver log usually ends inside a frame) is returned as
//! [`Piece::TruncatedUbx`] for the reader to report.

use std::io::{self, Read};

/// The two sync bytes of a UBX frame.
pub(crate) const SYNC: [u8; 2] = [0xB5, 0x62];
/// The first byte of an RTCM 3 frame.
const RTCM_PREAMBLE: u8 = 0xD3;
/// The longest NMEA sentence looked for [bytes]: NMEA 0183 allows 82, u-blox's PUBX
/// and some talkers write longer ones.
const MAX_NMEA: usize = 1024;
/// Bytes read from the input at a time.
const CHUNK: usize = 1 << 16;

/// What the scanner found at the current offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Piece {
    /// A UBX frame with a valid checksum; its payload is `buf[start..start + len]`
    /// ([`Scanner::payload`]).
    Ubx {
        /// Offset of the sync word in the input.
        offset: u64,
        /// Message class.
        class: u8,
        /// Message id.
        id: u8,
        /// Start of the payload in the scanner's buffer.
        start: usize,
        /// Payload length.
        len: usize,
    },
    /// An NMEA sentence of `len` bytes.
    Nmea { offset: u64, len: usize },
    /// An RTCM 3 frame of `len` bytes with a valid CRC.
    Rtcm { offset: u64, len: usize },
    /// `len` bytes that begin no frame.
    Unknown { offset: u64, len: usize },
    /// A UBX frame cut by the end of the input: `have` of its `need` bytes are there.
    TruncatedUbx {
        offset: u64,
        class: u8,
        id: u8,
        have: usize,
        need: usize,
    },
    /// A UBX frame whose checksum fails while the scanner is in sync.
    BadChecksum {
        offset: u64,
        class: u8,
        id: u8,
        len: usize,
    },
    /// The end of the input.
    End,
}

/// Cuts a byte stream into [`Piece`]s, holding at most one frame (plus a read chunk)
/// in memory.
pub(crate) struct Scanner<R> {
    input: R,
    buf: Vec<u8>,
    /// Start of the bytes not yet consumed.
    pos: usize,
    /// End of the valid bytes.
    end: usize,
    /// Input offset of `buf[0]`.
    base: u64,
    eof: bool,
    /// The previous piece was a valid frame ending where this one begins.
    in_sync: bool,
}

/// The Fletcher-8 checksum of UBX over `bytes` (class, id, length and payload).
pub(crate) fn checksum(bytes: &[u8]) -> [u8; 2] {
    let (mut a, mut b) = (0u8, 0u8);
    for &x in bytes {
        a = a.wrapping_add(x);
        b = b.wrapping_add(a);
    }
    [a, b]
}

/// CRC-24Q of RTCM 3 (polynomial 0x1864CFB, initial value 0; RTCM 10403.3 §4.2).
fn crc24q(bytes: &[u8]) -> u32 {
    let mut crc = 0u32;
    for &b in bytes {
        crc ^= u32::from(b) << 16;
        for _ in 0..8 {
            crc <<= 1;
            if crc & 0x100_0000 != 0 {
                crc ^= 0x186_4CFB;
            }
        }
    }
    crc & 0xFF_FFFF
}

impl<R: Read> Scanner<R> {
    /// A scanner of `input`, in sync at its first byte.
    pub(crate) fn new(input: R) -> Self {
        Self {
            input,
            buf: Vec::with_capacity(2 * CHUNK),
            pos: 0,
            end: 0,
            base: 0,
            eof: false,
            in_sync: true,
        }
    }

    /// Bytes consumed so far.
    pub(crate) fn consumed(&self) -> u64 {
        self.base + self.pos as u64
    }

    /// The payload of a [`Piece::Ubx`] just returned.
    pub(crate) fn payload(&self, start: usize, len: usize) -> &[u8] {
        &self.buf[start..start + len]
    }

    /// Makes at least `n` bytes available after `pos` unless the input ends first;
    /// returns how many are.
    fn fill(&mut self, n: usize) -> io::Result<usize> {
        while self.end - self.pos < n && !self.eof {
            if self.pos > 0 && self.pos >= self.buf.len() / 2 {
                self.buf.copy_within(self.pos..self.end, 0);
                self.end -= self.pos;
                self.base += self.pos as u64;
                self.pos = 0;
            }
            let want = (n - (self.end - self.pos)).max(CHUNK);
            if self.buf.len() < self.end + want {
                self.buf.resize(self.end + want, 0);
            }
            match self.input.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(k) => self.end += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        Ok(self.end - self.pos)
    }

    /// The next piece of the input.
    pub(crate) fn next_piece(&mut self) -> io::Result<Piece> {
        let avail = self.fill(1)?;
        if avail == 0 {
            return Ok(Piece::End);
        }
        let offset = self.consumed();
        let piece = match self.buf[self.pos] {
            0xB5 => self.ubx(offset)?,
            RTCM_PREAMBLE => self.rtcm(offset)?,
            b'$' => self.nmea(offset)?,
            _ => None,
        };
        Ok(match piece {
            Some(p) => p,
            None => self.unknown(offset),
        })
    }

    /// Skips the sync byte of a frame returned as [`Piece::BadChecksum`], to look
    /// for the next frame after it.
    pub(crate) fn skip_false_sync(&mut self) {
        self.pos += 1;
        self.in_sync = false;
    }

    /// Unknown bytes from `pos` to the next byte that may begin a frame (at least one).
    fn unknown(&mut self, offset: u64) -> Piece {
        self.in_sync = false;
        let rest = &self.buf[self.pos + 1..self.end];
        let len = 1 + memchr::memchr3(0xB5, RTCM_PREAMBLE, b'$', rest).unwrap_or(rest.len());
        self.pos += len;
        Piece::Unknown { offset, len }
    }

    fn ubx(&mut self, offset: u64) -> io::Result<Option<Piece>> {
        let avail = self.fill(6)?;
        let p = self.pos;
        if avail < 2 || self.buf[p + 1] != SYNC[1] {
            return Ok(None);
        }
        if avail < 6 {
            let (class, id) = (self.buf.get(p + 2).copied(), self.buf.get(p + 3).copied());
            return Ok(Some(self.truncated(
                offset,
                class.unwrap_or(0),
                id.unwrap_or(0),
                avail,
                8,
            )));
        }
        let (class, id) = (self.buf[p + 2], self.buf[p + 3]);
        let len = usize::from(u16::from_le_bytes([self.buf[p + 4], self.buf[p + 5]]));
        let need = len + 8;
        let avail = self.fill(need)?;
        let p = self.pos;
        if avail < need {
            return Ok(Some(self.truncated(offset, class, id, avail, need)));
        }
        let ck = checksum(&self.buf[p + 2..p + 6 + len]);
        if ck != [self.buf[p + 6 + len], self.buf[p + 7 + len]] {
            if self.in_sync {
                return Ok(Some(Piece::BadChecksum {
                    offset,
                    class,
                    id,
                    len,
                }));
            }
            return Ok(None);
        }
        self.pos += need;
        self.in_sync = true;
        Ok(Some(Piece::Ubx {
            offset,
            class,
            id,
            start: p + 6,
            len,
        }))
    }

    /// A frame cut by the end of the input: everything left is consumed.
    fn truncated(&mut self, offset: u64, class: u8, id: u8, have: usize, need: usize) -> Piece {
        self.pos = self.end;
        Piece::TruncatedUbx {
            offset,
            class,
            id,
            have,
            need,
        }
    }

    fn rtcm(&mut self, offset: u64) -> io::Result<Option<Piece>> {
        let avail = self.fill(3)?;
        let p = self.pos;
        if avail < 3 || self.buf[p + 1] & 0xFC != 0 {
            return Ok(None);
        }
        let len = (usize::from(self.buf[p + 1] & 0x03) << 8) | usize::from(self.buf[p + 2]);
        let need = len + 6;
        if self.fill(need)? < need {
            return Ok(None);
        }
        let p = self.pos;
        let crc = crc24q(&self.buf[p..p + 3 + len]);
        let stored = u32::from_be_bytes([
            0,
            self.buf[p + 3 + len],
            self.buf[p + 4 + len],
            self.buf[p + 5 + len],
        ]);
        if crc != stored {
            return Ok(None);
        }
        self.pos += need;
        self.in_sync = true;
        Ok(Some(Piece::Rtcm { offset, len: need }))
    }

    fn nmea(&mut self, offset: u64) -> io::Result<Option<Piece>> {
        let avail = self.fill(MAX_NMEA)?;
        let p = self.pos;
        let window = &self.buf[p..p + avail.min(MAX_NMEA)];
        let Some(nl) = memchr::memchr(b'\n', window) else {
            return Ok(None);
        };
        let body = &window[1..nl];
        let body = body.strip_suffix(b"\r").unwrap_or(body);
        if body.len() < 5 || !body.iter().all(|b| (0x20..0x7F).contains(b)) {
            return Ok(None);
        }
        self.pos += nl + 1;
        self.in_sync = true;
        Ok(Some(Piece::Nmea {
            offset,
            len: nl + 1,
        }))
    }
}

/// A UBX frame of `class`, `id` around `payload` (for tests).
#[cfg(test)]
pub(crate) fn frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
    let mut f = vec![SYNC[0], SYNC[1], class, id];
    f.extend_from_slice(&(payload.len() as u16).to_le_bytes());
    f.extend_from_slice(payload);
    let ck = checksum(&f[2..]);
    f.extend_from_slice(&ck);
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pieces(bytes: &[u8]) -> Vec<Piece> {
        let mut s = Scanner::new(bytes);
        let mut out = Vec::new();
        loop {
            let p = s.next_piece().unwrap();
            if p == Piece::End {
                return out;
            }
            if let Piece::BadChecksum { .. } = p {
                s.skip_false_sync();
            }
            out.push(p);
        }
    }

    #[test]
    fn checksum_of_a_known_frame() {
        // UBX-CFG-MSG poll of NAV-PVT as the interface description's example writes
        // it: B5 62 06 01 02 00 01 07, checksum 11 3A.
        assert_eq!(
            checksum(&[0x06, 0x01, 0x02, 0x00, 0x01, 0x07]),
            [0x11, 0x3A]
        );
    }

    #[test]
    fn crc24q_of_a_known_frame() {
        // A CRC appended to its message makes the CRC of the whole zero (the
        // defining property of a CRC without final XOR); an empty message's is 0.
        assert_eq!(crc24q(&[]), 0);
        let body = [0xD3, 0x00, 0x02, 0x3E, 0xD0];
        let c = crc24q(&body);
        let mut whole = body.to_vec();
        whole.extend_from_slice(&c.to_be_bytes()[1..]);
        assert_eq!(crc24q(&whole), 0);
    }

    #[test]
    fn frames_sentences_and_junk_are_told_apart() {
        let ubx = frame(0x01, 0x07, &[1, 2, 3]);
        let mut bytes = b"# a logger's header\n".to_vec();
        bytes.extend_from_slice(&ubx);
        bytes.extend_from_slice(b"$GNGGA,1,2,3*00\r\n");
        let rtcm_body = [0xD3, 0x00, 0x03, 0xB5, 0x62, 0x01];
        let c = crc24q(&rtcm_body);
        bytes.extend_from_slice(&rtcm_body);
        bytes.extend_from_slice(&c.to_be_bytes()[1..]);
        bytes.extend_from_slice(&ubx);
        let p = pieces(&bytes);
        assert_eq!(p.len(), 5, "{p:?}");
        assert!(matches!(p[0], Piece::Unknown { offset: 0, len: 20 }));
        assert!(matches!(
            p[1],
            Piece::Ubx {
                offset: 20,
                class: 1,
                id: 7,
                len: 3,
                ..
            }
        ));
        assert!(matches!(
            p[2],
            Piece::Nmea {
                offset: 31,
                len: 17
            }
        ));
        assert!(matches!(p[3], Piece::Rtcm { offset: 48, len: 9 }));
        assert!(matches!(p[4], Piece::Ubx { offset: 57, .. }));
    }

    #[test]
    fn a_bad_checksum_in_sync_is_corruption_out_of_sync_a_false_sync() {
        let mut bad = frame(0x01, 0x07, &[1, 2, 3]);
        bad[7] ^= 0xFF;
        let mut bytes = frame(0x01, 0x07, &[9]);
        bytes.extend_from_slice(&bad);
        let p = pieces(&bytes);
        assert!(matches!(
            p[1],
            Piece::BadChecksum {
                offset: 9,
                class: 1,
                id: 7,
                len: 3
            }
        ));
        // After unknown bytes the same frame is a false sync word: skipped.
        let mut bytes = b"xyz".to_vec();
        bytes.extend_from_slice(&bad);
        let p = pieces(&bytes);
        assert!(
            p.iter().all(|x| matches!(x, Piece::Unknown { .. })),
            "{p:?}"
        );
    }

    #[test]
    fn a_frame_cut_by_the_end_is_truncated() {
        let mut bytes = frame(0x02, 0x15, &[0; 16]);
        let whole = bytes.len();
        bytes.extend_from_slice(&frame(0x02, 0x15, &[0; 16])[..10]);
        let p = pieces(&bytes);
        assert_eq!(
            p[1],
            Piece::TruncatedUbx {
                offset: whole as u64,
                class: 2,
                id: 0x15,
                have: 10,
                need: 24
            }
        );
        // A cut inside the 6-byte header too.
        let p = pieces(&[0xB5, 0x62, 0x02]);
        assert!(matches!(
            p[0],
            Piece::TruncatedUbx {
                have: 3,
                need: 8,
                ..
            }
        ));
    }

    #[test]
    fn frames_longer_than_a_read_chunk() {
        let payload: Vec<u8> = (0..60_000u32).map(|i| i as u8).collect();
        let bytes = [frame(0x02, 0x15, &payload), frame(0x01, 0x07, &[1])].concat();
        let p = pieces(&bytes);
        assert!(matches!(p[0], Piece::Ubx { len: 60_000, .. }));
        assert!(matches!(p[1], Piece::Ubx { offset: 60_008, .. }));
    }
}
