//! The IMU log parsed on a second thread: a reader thread owns the sample iterator
//! (the text or CSV reader) and hands its items, in order, in blocks through a
//! bounded channel to the navigation thread, so that parsing (about half of a
//! free-inertial run's work) overlaps the mechanization on the second core. The
//! navigation thread sees the same items in the same order as from the iterator
//! itself, errors included, so the run is the same bit for bit.
//!
//! Memory stays bounded: at most [`BLOCKS`] blocks of [`BLOCK`] items wait in the
//! channel, and emptied blocks go back to the reader to be refilled (no allocation
//! per block after the first few).

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

/// Items per block: at 200 Hz about 5 s of samples, some 60 kB.
pub const BLOCK: usize = 1024;
/// Blocks the channel holds.
pub const BLOCKS: usize = 2;

/// The items of an iterator produced on a reader thread (module doc).
pub struct ReadAhead<I: Iterator> {
    rx: Receiver<Vec<I::Item>>,
    /// Emptied blocks going back to the reader.
    spare: SyncSender<Vec<I::Item>>,
    block: std::vec::IntoIter<I::Item>,
    /// Whether the reader's end has been seen (the thread has then returned).
    ended: bool,
    handle: Option<JoinHandle<I>>,
}

impl<I> ReadAhead<I>
where
    I: Iterator + Send + 'static,
    I::Item: Send + 'static,
{
    /// Moves `inner` onto a new reader thread.
    pub fn spawn(inner: I) -> std::io::Result<Self> {
        let (tx, rx) = sync_channel::<Vec<I::Item>>(BLOCKS);
        // Room for every block there can be: handing one back never blocks.
        let (spare, spare_rx) = sync_channel::<Vec<I::Item>>(BLOCKS + 2);
        let handle = std::thread::Builder::new()
            .name("schuler-reader".to_owned())
            .spawn(move || read_all(inner, &tx, &spare_rx))?;
        Ok(Self {
            rx,
            spare,
            block: Vec::new().into_iter(),
            ended: false,
            handle: Some(handle),
        })
    }

    /// The iterator back, once every item has been taken (its state, such as the
    /// gaps it met, is then complete). `None` when the consumer stopped before the
    /// end: the reader thread is left to stop on its own (at its next block, or when
    /// its input ends), rather than waited for on an input that may never end.
    pub fn finish(mut self) -> Option<I> {
        if !self.ended {
            return None;
        }
        self.handle.take()?.join().ok()
    }
}

/// The reader thread: blocks of `inner`'s items into `tx` until it ends or the
/// navigation thread hangs up; returns `inner`.
fn read_all<I: Iterator>(
    mut inner: I,
    tx: &SyncSender<Vec<I::Item>>,
    spare: &Receiver<Vec<I::Item>>,
) -> I {
    loop {
        let mut block = spare
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BLOCK));
        block.extend(inner.by_ref().take(BLOCK));
        let last = block.len() < BLOCK;
        // An empty block tells the end; a send fails when the consumer is gone.
        if tx.send(block).is_err() || last {
            return inner;
        }
    }
}

impl<I> Iterator for ReadAhead<I>
where
    I: Iterator,
{
    type Item = I::Item;

    fn next(&mut self) -> Option<I::Item> {
        loop {
            if let Some(x) = self.block.next() {
                return Some(x);
            }
            if self.ended {
                return None;
            }
            let Ok(block) = self.rx.recv() else {
                // The reader thread is gone without its end (it panicked).
                self.ended = true;
                return None;
            };
            if block.len() < BLOCK {
                self.ended = true;
            }
            let emptied = std::mem::replace(&mut self.block, block.into_iter());
            let mut emptied: Vec<I::Item> = emptied.collect();
            emptied.clear();
            let _ = self.spare.try_send(emptied);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every item comes through in order, errors in their place, for lengths around
    /// the block's; the iterator comes back with its state once all are taken.
    #[test]
    fn items_come_through_in_order_and_the_reader_comes_back() {
        for n in [0, 1, BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK + 7] {
            let items: Vec<Result<u64, String>> = (0..n as u64)
                .map(|k| {
                    if k % 500 == 499 {
                        Err(format!("bad {k}"))
                    } else {
                        Ok(k)
                    }
                })
                .collect();
            let mut ahead = ReadAhead::spawn(items.clone().into_iter()).expect("spawn");
            let got: Vec<_> = ahead.by_ref().collect();
            assert_eq!(got, items, "n = {n}");
            let mut back = ahead.finish().expect("the reader after its end");
            assert_eq!(back.next(), None);
        }
    }

    /// A consumer that stops early gets no reader back and does not wait for the
    /// reader thread (here an endless one).
    #[test]
    fn an_early_stop_does_not_wait_for_the_reader() {
        let mut ahead = ReadAhead::spawn(0u64..).expect("spawn");
        assert_eq!(ahead.by_ref().take(5).collect::<Vec<_>>(), [0, 1, 2, 3, 4]);
        assert!(ahead.finish().is_none());
    }
}
