//! The fast row writer of every full-rate text output (`schuler simulate`'s files,
//! `nav.txt`/`nav.csv`, the filter's `std.txt`/`imu_err.txt` and KF-GINS's files): a
//! block of text whose bytes past its end are scratch that a line is stored into in
//! whole 8-byte words ([`crate::fixed::Words`]) before it counts, so a line costs no
//! capacity check per number and no copy. A line whose numbers
//! [`crate::fixed::put_field`] declines is made by the `Vec` writers and appended:
//! the same bytes either way.

use crate::fixed::{Line, put_bytes, put_field};

/// The text of one file for one block, `bytes[..len]`; the bytes past `len` are
/// scratch, kept from block to block.
#[derive(Default)]
pub struct TextBlock {
    bytes: Vec<u8>,
    len: usize,
}

impl TextBlock {
    /// Empties the text (the scratch stays).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Bytes of text.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there is no text.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Make `room` bytes of scratch after the text. An empty text takes fresh zeroed
    /// memory (pages the system zeroes when first touched, no writes of zeros).
    #[inline(always)]
    pub fn reserve(&mut self, room: usize) {
        let end = self.len + room;
        if self.bytes.len() < end {
            let size = end.max(2 * self.bytes.len());
            if self.len == 0 {
                self.bytes = vec![0; size];
            } else {
                self.bytes.resize(size, 0);
            }
        }
    }

    /// The first `room` bytes of scratch after the text.
    #[inline(always)]
    pub fn scratch(&mut self, room: usize) -> &mut [u8] {
        self.reserve(room);
        &mut self.bytes[self.len..self.len + room]
    }

    /// Count `n` bytes of the scratch as text.
    #[inline(always)]
    pub fn advance(&mut self, n: usize) {
        self.len += n;
        debug_assert!(self.len <= self.bytes.len());
    }

    /// Append `text`.
    pub fn extend(&mut self, text: &[u8]) {
        self.scratch(text.len()).copy_from_slice(text);
        self.advance(text.len());
    }

    /// The text.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len]
    }

    /// Store one line into a window of `N` bytes after the text, fields separated by
    /// `sep`: `line` writes it and returns its length (newline included), or `None`
    /// when it declines (then nothing counts). Returns whether the line was stored.
    #[inline(always)]
    pub fn put_line<const N: usize>(
        &mut self,
        sep: u8,
        line: impl FnOnce(&mut Line<'_, N>) -> Option<usize>,
    ) -> bool {
        let mut w = Line {
            bytes: window::<N>(self.scratch(N), 0),
            sep,
        };
        match line(&mut w) {
            Some(len) => {
                self.advance(Line::<N>::end(len));
                true
            }
            None => false,
        }
    }
}

/// The `N` bytes of `scratch` from `at`.
#[inline(always)]
pub fn window<const N: usize>(scratch: &mut [u8], at: usize) -> &mut [u8; N] {
    (&mut scratch[at..at + N]).try_into().expect("N bytes")
}

/// Store `x` with `decimals` digits after the point (the text of
/// [`crate::fixed::push_fixed`]) at `pos` without a separator before it, and return
/// the end; `None` where [`put_field`] declines.
#[inline(always)]
pub fn put_first_field<W: crate::fixed::Words + ?Sized>(
    out: &mut W,
    pos: usize,
    x: f64,
    decimals: usize,
) -> Option<usize> {
    let mut field = [0u8; 40];
    let end = put_field(
        &mut Line {
            bytes: &mut field,
            sep: b' ',
        },
        0,
        x,
        decimals,
    )?;
    Some(put_bytes(out, pos, &field[1..end]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{Words, push_fixed};

    /// A line stored through `put_line` is the text of the `Vec` writers, and a
    /// declined line leaves the text as it was.
    #[test]
    fn put_line_writes_the_vec_writers_text() {
        let mut block = TextBlock::default();
        let values = [1.5, -0.000_000_000_4, 123_456.789_012_345, -7.0];
        let stored = block.put_line::<{ 256 + 8 }>(b' ', |w| {
            let mut pos = put_first_field(w, 0, 529.99, 6)?;
            for v in values {
                pos = put_field(w, pos, v, 9)?;
            }
            w.put(pos, u64::from(b'\n'));
            Some(pos + 1)
        });
        assert!(stored);
        let mut want = Vec::new();
        push_fixed(&mut want, 529.99, 6);
        for v in values {
            want.push(b' ');
            push_fixed(&mut want, v, 9);
        }
        want.push(b'\n');
        assert_eq!(block.as_bytes(), want.as_slice());
        let declined = block.put_line::<{ 256 + 8 }>(b' ', |w| put_field(w, 0, f64::NAN, 9));
        assert!(!declined);
        assert_eq!(block.as_bytes(), want.as_slice());
    }
}
