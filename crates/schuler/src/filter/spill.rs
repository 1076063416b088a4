//! Fixed-width records of `f64`, kept in memory up to a budget and beyond it in an
//! anonymous temporary file (deleted by the system when closed), so that what the
//! smoother keeps of a long log costs disk, not memory.
//!
//! Values are stored as their IEEE-754 bits (little-endian), so a record read back is
//! the record pushed, bit for bit. The first I/O error is kept (the records after it
//! stay in memory) and reported by every read, so a full disk is an error at the end,
//! never a wrong number.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};

/// Values kept in memory before they go to the file: 2 Mi values (16 MiB).
pub const DEFAULT_BUDGET: usize = 1 << 21;

/// A storage failure of the spill file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the smoother's temporary file: {0}")]
pub struct SpillError(pub String);

impl From<std::io::Error> for SpillError {
    fn from(e: std::io::Error) -> Self {
        Self(e.to_string())
    }
}

/// Records of `width` values: the first `spilled` in the file, the rest in `tail`.
#[derive(Debug)]
pub struct Records {
    width: usize,
    budget: usize,
    tail: Vec<f64>,
    file: Option<File>,
    spilled: usize,
    error: Option<SpillError>,
}

impl Records {
    /// Records of `width` values, at most about `budget` values in memory.
    pub fn new(width: usize, budget: usize) -> Self {
        Self {
            width: width.max(1),
            budget: budget.max(width),
            tail: Vec::new(),
            file: None,
            spilled: 0,
            error: None,
        }
    }

    /// Values per record.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.spilled + self.tail.len() / self.width
    }

    /// Values held in memory (at most about the budget, however many records).
    pub fn in_memory(&self) -> usize {
        self.tail.len()
    }

    /// Whether there is no record.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Append a record (`record.len()` must be the width; a shorter one is padded
    /// with zeros, a longer one cut).
    pub fn push(&mut self, record: &[f64]) {
        let start = self.tail.len();
        self.tail.extend(record.iter().take(self.width));
        self.tail.resize(start + self.width, 0.0);
        if self.tail.len() >= self.budget
            && self.error.is_none()
            && let Err(e) = self.spill()
        {
            self.error = Some(e);
        }
    }

    /// Move the records in memory to the file.
    fn spill(&mut self) -> Result<(), SpillError> {
        if self.file.is_none() {
            self.file = Some(tempfile::tempfile()?);
        }
        if let Some(f) = self.file.as_ref() {
            let mut w = BufWriter::with_capacity(1 << 20, f);
            w.seek(SeekFrom::End(0))?;
            for v in &self.tail {
                w.write_all(&v.to_le_bytes())?;
            }
            w.flush()?;
        }
        self.spilled += self.tail.len() / self.width;
        self.tail.clear();
        Ok(())
    }

    /// The file positioned at the start of record `k`.
    fn file_at(&self, k: usize) -> Result<&File, SpillError> {
        if let Some(e) = &self.error {
            return Err(e.clone());
        }
        let Some(mut f) = self.file.as_ref() else {
            return Err(SpillError("record beyond the file".into()));
        };
        f.seek(SeekFrom::Start((k * self.width * 8) as u64))?;
        Ok(f)
    }

    /// Record `k` into `out` (of the width).
    pub fn read(&self, k: usize, out: &mut [f64]) -> Result<(), SpillError> {
        let w = self.width;
        if k >= self.spilled {
            let o = (k - self.spilled) * w;
            let Some(r) = self.tail.get(o..o + w) else {
                return Err(SpillError(format!("record {k} of {}", self.len())));
            };
            out.copy_from_slice(r);
            return Ok(());
        }
        let mut f = self.file_at(k)?;
        read_values(&mut f, out)
    }

    /// Records from `k` on into `out` (a multiple of the width), as many as fit and
    /// lie on the same side of the memory/file boundary; returns how many (0: `k` is
    /// past the last). One read for a block, where [`Records::read`] costs one per
    /// record.
    pub fn read_block(&self, k: usize, out: &mut [f64]) -> Result<usize, SpillError> {
        let w = self.width;
        let room = out.len() / w;
        if k >= self.len() || room == 0 {
            return Ok(0);
        }
        let n = if k < self.spilled {
            room.min(self.spilled - k)
        } else {
            room.min(self.len() - k)
        };
        if k >= self.spilled {
            let o = (k - self.spilled) * w;
            out[..n * w].copy_from_slice(&self.tail[o..o + n * w]);
        } else {
            let mut f = self.file_at(k)?;
            read_values(&mut f, &mut out[..n * w])?;
        }
        Ok(n)
    }

    /// The records from the first, in order.
    pub fn into_sequence(mut self) -> Result<Sequence, SpillError> {
        let reader = match self.spilled {
            0 => None,
            _ => {
                self.file_at(0)?;
                self.file
                    .take()
                    .map(|f| BufReader::with_capacity(1 << 20, f))
            }
        };
        Ok(Sequence {
            width: self.width,
            reader,
            in_file: self.spilled,
            tail: self.tail,
            next_in_tail: 0,
        })
    }
}

impl Clone for Records {
    /// A copy with its own file (the records are read back and pushed again).
    fn clone(&self) -> Self {
        let mut copy = Records::new(self.width, self.budget);
        copy.error = self.error.clone();
        let mut record = vec![0.0; self.width];
        for k in 0..self.len() {
            if copy.error.is_some() {
                break;
            }
            match self.read(k, &mut record) {
                Ok(()) => copy.push(&record),
                Err(e) => copy.error = Some(e),
            }
        }
        copy
    }
}

/// Read `out.len()` values from `r`.
fn read_values(r: &mut impl Read, out: &mut [f64]) -> Result<(), SpillError> {
    let mut bytes = vec![0u8; 8 * out.len()];
    r.read_exact(&mut bytes)?;
    for (v, b) in out.iter_mut().zip(bytes.chunks_exact(8)) {
        let mut x = [0u8; 8];
        x.copy_from_slice(b);
        *v = f64::from_le_bytes(x);
    }
    Ok(())
}

/// The records of a [`Records`], read in order.
#[derive(Debug)]
pub struct Sequence {
    width: usize,
    reader: Option<BufReader<File>>,
    in_file: usize,
    tail: Vec<f64>,
    next_in_tail: usize,
}

impl Sequence {
    /// The next record into `out` (of the width): `Ok(false)` after the last.
    pub fn next_into(&mut self, out: &mut [f64]) -> Result<bool, SpillError> {
        if self.in_file > 0
            && let Some(r) = self.reader.as_mut()
        {
            read_values(r, out)?;
            self.in_file -= 1;
            return Ok(true);
        }
        let o = self.next_in_tail;
        match self.tail.get(o..o + self.width) {
            Some(r) => {
                out.copy_from_slice(r);
                self.next_in_tail += self.width;
                Ok(true)
            }
            None => Ok(false),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records with awkward bits (NaN payload, -0, subnormal, extremes).
    fn record(k: usize) -> [f64; 3] {
        [
            k as f64,
            f64::from_bits(0x7ff8_0000_dead_beef ^ k as u64),
            [-0.0, 5e-324, f64::MAX, -f64::MIN_POSITIVE][k % 4],
        ]
    }

    fn same(a: &[f64], b: &[f64]) -> bool {
        a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn records_come_back_bit_for_bit_from_memory_and_file() {
        for budget in [3, 7, 1000] {
            let mut r = Records::new(3, budget);
            for k in 0..50 {
                r.push(&record(k));
            }
            assert_eq!(r.len(), 50);
            let mut out = [0.0; 3];
            for k in (0..50).rev() {
                r.read(k, &mut out).expect("read back");
                assert!(same(&out, &record(k)), "budget {budget}, record {k}");
            }
            let copy = r.clone();
            for (name, store) in [("original", r), ("clone", copy)] {
                let mut seq = store.into_sequence().expect("sequence");
                let mut k = 0;
                while seq.next_into(&mut out).expect("next") {
                    assert!(
                        same(&out, &record(k)),
                        "{name}, budget {budget}, record {k}"
                    );
                    k += 1;
                }
                assert_eq!(k, 50, "{name}, budget {budget}");
            }
        }
    }

    #[test]
    fn blocks_come_back_bit_for_bit_across_the_file_and_memory() {
        for budget in [3, 7, 1000] {
            let mut r = Records::new(3, budget);
            for k in 0..50 {
                r.push(&record(k));
            }
            assert!(r.in_memory() <= budget, "budget {budget}");
            // A block of 4 records (and a ragged 13 values: 4 records and a rest).
            for size in [12, 13] {
                let mut out = vec![0.0; size];
                let mut k = 0;
                loop {
                    let n = r.read_block(k, &mut out).expect("block");
                    if n == 0 {
                        break;
                    }
                    for (i, got) in out.chunks_exact(3).take(n).enumerate() {
                        assert!(same(got, &record(k + i)), "budget {budget}, {}", k + i);
                    }
                    k += n;
                }
                assert_eq!(k, 50, "budget {budget}");
            }
        }
    }

    #[test]
    fn a_record_past_the_end_is_an_error() {
        let mut r = Records::new(2, 2);
        r.push(&[1.0, 2.0]);
        let mut out = [0.0; 2];
        assert!(r.read(1, &mut out).is_err());
    }
}
