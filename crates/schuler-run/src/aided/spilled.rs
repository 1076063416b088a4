//! What an aided run keeps for its report, in bounded memory: records of a fixed
//! number of `f64` in the library's spill store ([`schuler::filter::spill`]), at most
//! [`BUDGET`] values in memory and the rest in an anonymous temporary file, read back
//! bit for bit as often as the report needs them. A 10-hour run thus keeps the same
//! memory as a 1-hour one (issue 22), and its disk holds about 90 bytes per
//! innovation and 300 per snapshot.

use anyhow::Result;
use schuler::filter::spill::{Records, SpillError};
use std::cell::RefCell;
use std::marker::PhantomData;

/// Values a log keeps in memory before it spills (256 KiB).
pub const BUDGET: usize = 1 << 15;

/// Records read per block when a log is read back.
const BLOCK: usize = 256;

/// A value stored as a fixed number of `f64`, bit for bit.
pub trait Record: Sized {
    /// Values per record.
    const WIDTH: usize;
    /// The values of `self` into `out` (of the width).
    fn encode(&self, out: &mut [f64]);
    /// The value of `r` (of the width), as [`Record::encode`] wrote it.
    fn decode(r: &[f64]) -> Self;
}

/// Records of `T` in time order, spilled beyond [`BUDGET`] (a copy gets its own
/// file).
#[derive(Debug, Clone)]
pub struct Spilled<T: Record> {
    records: Records,
    buf: Vec<f64>,
    /// The first failure of a read, reported by [`Spilled::status`].
    error: RefCell<Option<SpillError>>,
    kind: PhantomData<T>,
}

impl<T: Record> Default for Spilled<T> {
    fn default() -> Self {
        Self::with_budget(BUDGET)
    }
}

impl<T: Record> Spilled<T> {
    /// An empty log keeping at most about `budget` values in memory.
    pub fn with_budget(budget: usize) -> Self {
        Self {
            records: Records::new(T::WIDTH, budget),
            buf: vec![0.0; T::WIDTH],
            error: RefCell::new(None),
            kind: PhantomData,
        }
    }

    /// Appends `x`.
    pub fn push(&mut self, x: &T) {
        x.encode(&mut self.buf);
        self.records.push(&self.buf);
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Values held in memory (bounded by the budget, whatever the length).
    pub fn in_memory(&self) -> usize {
        self.records.in_memory()
    }

    /// The records from the first, in order. A storage failure ends the iteration
    /// early and is reported by [`Spilled::status`], which every reader checks.
    pub fn iter(&self) -> Iter<'_, T> {
        Iter {
            log: self,
            block: Vec::new(),
            next: 0,
            at: 0,
        }
    }

    /// The last record, if any.
    pub fn last(&self) -> Option<T> {
        let k = self.len().checked_sub(1)?;
        let mut r = vec![0.0; T::WIDTH];
        match self.records.read(k, &mut r) {
            Ok(()) => Some(T::decode(&r)),
            Err(e) => {
                self.error.borrow_mut().get_or_insert(e);
                None
            }
        }
    }

    /// An error if a store or a read of the records failed (a full temporary disk).
    pub fn status(&self) -> Result<()> {
        match self.error.borrow().as_ref() {
            Some(e) => Err(anyhow::Error::new(e.clone())),
            None => Ok(()),
        }
    }
}

/// The records of a [`Spilled`] from the first, read in blocks.
pub struct Iter<'a, T: Record> {
    log: &'a Spilled<T>,
    block: Vec<f64>,
    /// Index of the next record to read from the store.
    next: usize,
    /// Offset of the next record in `block`.
    at: usize,
}

impl<T: Record> Iterator for Iter<'_, T> {
    type Item = T;

    fn next(&mut self) -> Option<T> {
        let w = T::WIDTH;
        if self.at + w > self.block.len() {
            self.block.resize(BLOCK * w, 0.0);
            match self.log.records.read_block(self.next, &mut self.block) {
                Ok(0) => return None,
                Ok(n) => {
                    self.block.truncate(n * w);
                    self.next += n;
                    self.at = 0;
                }
                Err(e) => {
                    self.log.error.borrow_mut().get_or_insert(e);
                    return None;
                }
            }
        }
        let x = T::decode(&self.block[self.at..self.at + w]);
        self.at += w;
        Some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Record for (f64, f64) {
        const WIDTH: usize = 2;
        fn encode(&self, out: &mut [f64]) {
            out.copy_from_slice(&[self.0, self.1]);
        }
        fn decode(r: &[f64]) -> Self {
            (r[0], r[1])
        }
    }

    /// Whatever the length, the memory held stays under the budget, and every record
    /// comes back in order, bit for bit (NaN payloads, -0 too).
    #[test]
    fn memory_is_bounded_and_records_come_back() {
        let x = |k: usize| (k as f64, f64::from_bits(0x7ff8_0000_0000_0001 ^ k as u64));
        for n in [0, 1, 100, 10_000] {
            let mut log: Spilled<(f64, f64)> = Spilled::with_budget(64);
            for k in 0..n {
                log.push(&x(k));
                assert!(log.in_memory() <= 64);
            }
            assert_eq!(log.len(), n);
            let mut k = 0;
            for (a, b) in log.iter() {
                assert_eq!(
                    (a.to_bits(), b.to_bits()),
                    (x(k).0.to_bits(), x(k).1.to_bits())
                );
                k += 1;
            }
            assert_eq!(k, n);
            assert_eq!(log.last().map(|r| r.0), n.checked_sub(1).map(|k| k as f64));
            log.status().expect("no failure");
        }
    }
}
