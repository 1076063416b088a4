//! The run's output written on a second thread: the navigation thread hands the
//! session's epochs and events, in order, in batches through a bounded channel to a
//! thread that owns the [`Outputs`] and formats and writes them, so that formatting
//! and the kernel's copies overlap the navigation on the second core. The files get
//! the same bytes as from [`Outputs`] on the navigation thread: the same code, the
//! same order.
//!
//! Memory stays bounded: at most [`BATCHES`] batches of [`BATCH`] items wait in the
//! channel; a full channel makes the navigation thread wait for the writer. The
//! writer hands each emptied batch back, so that after the first few the batches are
//! reused: no allocation per epoch or per batch, none freed on the other thread.

use super::Outputs;
use anyhow::{Result, anyhow};
use schuler::earth::EarthModel;
use schuler::session::{Epoch, Event, Session};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

/// Items per batch: at 200 Hz about 1.3 s of epochs, some 180 kB.
pub const BATCH: usize = 256;
/// Batches the channel holds.
pub const BATCHES: usize = 2;

/// What the navigation thread hands over, in order. Epochs are held in place (a
/// batch is reused, so their size costs no allocation).
#[allow(clippy::large_enum_variant)]
enum Item {
    /// An output epoch.
    Epoch(Epoch),
    /// A session event.
    Event(Event),
    /// The state where a failed input stopped the run: written unless it was the
    /// last epoch written.
    Last(Epoch),
}

/// [`Outputs`] on a writer thread.
pub struct WriterThread {
    tx: SyncSender<Vec<Item>>,
    /// Emptied batches coming back from the writer.
    spare: Receiver<Vec<Item>>,
    batch: Vec<Item>,
    handle: JoinHandle<Result<Outputs>>,
}

impl WriterThread {
    /// Moves `out` onto a new writer thread.
    pub fn spawn(out: Outputs) -> Result<Self> {
        let (tx, rx) = sync_channel::<Vec<Item>>(BATCHES);
        // Room for every batch there can be: sending one back never blocks.
        let (spare_tx, spare) = sync_channel::<Vec<Item>>(BATCHES + 2);
        let handle = std::thread::Builder::new()
            .name("schuler-writer".to_owned())
            .spawn(move || write_all(out, rx, spare_tx))?;
        Ok(Self {
            tx,
            spare,
            batch: Vec::with_capacity(BATCH),
            handle,
        })
    }

    /// Hands over the session's epochs and events so far.
    pub fn take<E: EarthModel>(&mut self, session: &mut Session<E>) -> Result<()> {
        for e in session.epochs() {
            self.push(Item::Epoch(e))?;
        }
        for e in session.events() {
            self.push(Item::Event(e))?;
        }
        Ok(())
    }

    /// Hands over the state where a failed input stopped the run (written unless it
    /// was the last epoch written).
    pub fn last(&mut self, e: Epoch) -> Result<()> {
        self.push(Item::Last(e))
    }

    fn push(&mut self, item: Item) -> Result<()> {
        self.batch.push(item);
        if self.batch.len() >= BATCH {
            self.send()?;
        }
        Ok(())
    }

    /// Sends the batch; a closed channel means the writer stopped on an error, which
    /// [`WriterThread::join`] returns.
    fn send(&mut self) -> Result<()> {
        let next = self
            .spare
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH));
        let batch = std::mem::replace(&mut self.batch, next);
        if self.tx.send(batch).is_err() {
            return Err(anyhow!("the writer thread stopped"));
        }
        Ok(())
    }

    /// Sends what is left, waits for the writer and returns the outputs (or the
    /// writer's error).
    pub fn join(mut self) -> Result<Outputs> {
        let sent = if self.batch.is_empty() {
            Ok(())
        } else {
            self.send()
        };
        drop(self.tx);
        let out = self
            .handle
            .join()
            .map_err(|_| anyhow!("the writer thread panicked"))?;
        // The writer's own error explains a failed send.
        let out = out?;
        sent.map(|()| out)
    }
}

/// The writer thread: every batch from `rx` into `out`, until the channel closes or
/// a write fails; each emptied batch goes back through `spare` (dropped if the
/// navigation thread is gone).
fn write_all(
    mut out: Outputs,
    rx: Receiver<Vec<Item>>,
    spare: SyncSender<Vec<Item>>,
) -> Result<Outputs> {
    for mut batch in rx {
        for item in batch.drain(..) {
            match item {
                Item::Epoch(e) => out.write_epoch(&e)?,
                Item::Event(e) => out.event(e)?,
                Item::Last(e) => out.write_last(&e)?,
            }
        }
        let _ = spare.try_send(batch);
    }
    Ok(out)
}
