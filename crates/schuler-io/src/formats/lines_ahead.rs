//! A log's lines read, and their fields parsed, on a second thread: a helper thread
//! owns the [`LineReader`], copies each line into a block with its fields already
//! parsed (by the caller's function, the one the reader itself would use) and hands
//! the blocks in order through a bounded channel. The reader's own logic (the time
//! checks, the window, the conversions) stays on the consuming thread, which takes
//! the parsed fields instead of parsing; a line the function declines (a comment, a
//! bad field) it parses itself, so every error is its own, at its place. This splits
//! a free-inertial run's work about evenly between the two cores: the helper reads
//! and parses the numbers, the navigation thread checks them and navigates.
//!
//! While the consumer has taken every block the helper made (it waits for the
//! helper), the helper leaves one line in [`LEFT_TO_CONSUMER`] unparsed, for the consumer to parse: the work then balances between the threads
//! whichever is the slower. Which lines are parsed where changes only the timing:
//! both parse with the same function.
//!
//! Memory stays bounded: at most [`BLOCKS`] blocks of [`BLOCK_LINES`] lines wait in
//! the channel, and emptied blocks go back to the helper to be refilled.

use super::lines::{LineReadError, LineReader, Position, is_skippable};
use std::io::Read;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

/// Lines per block: at 200 Hz about 5 s of a log, some 240 kB.
pub const BLOCK_LINES: usize = 1024;
/// Blocks the channel holds.
pub const BLOCKS: usize = 2;

/// When the consumer is waiting, one data line in this many is left to it.
pub const LEFT_TO_CONSUMER: usize = 4;

/// A line's fields parsed ahead: the values in slot order and where the time lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Parsed {
    pub values: [f64; 7],
    pub time_span: (usize, usize),
}

/// One line of a block: its text in the block's buffer, its number, the bytes read
/// up to its end, and its fields if parsed.
struct Entry {
    start: usize,
    end: usize,
    line_no: u64,
    bytes: u64,
    parsed: Option<Parsed>,
}

/// How the lines ended.
enum End {
    Eof,
    Failed {
        error: LineReadError,
        line_no: u64,
        bytes: u64,
    },
}

#[derive(Default)]
struct Block {
    text: Vec<u8>,
    entries: Vec<Entry>,
    /// After the last entry: the input's end or the read's failure.
    end: Option<End>,
}

/// The lines of a [`LineReader`] read ahead on a helper thread (module doc), with the
/// same answers as the reader itself: each line's content, number and bytes, then the
/// end or the error.
pub(crate) struct LinesAhead {
    /// Blocks from the helper (`None` once its end has been taken).
    rx: Option<Receiver<Block>>,
    /// Emptied blocks going back to the helper.
    spare: SyncSender<Block>,
    /// Blocks sent and not yet taken.
    in_flight: Arc<AtomicUsize>,
    block: Block,
    /// The current line's entry in `block` (`None` before the first and at the end).
    current: Option<usize>,
    at: Position,
}

impl LinesAhead {
    /// Moves `lines` onto a helper thread that parses each data line with `parse`.
    pub(crate) fn spawn<R, P>(lines: LineReader<R>, parse: P) -> std::io::Result<Self>
    where
        R: Read + Send + 'static,
        P: Fn(&[u8]) -> Option<Parsed> + Send + 'static,
    {
        let at = lines.at().clone();
        let (tx, rx) = sync_channel(BLOCKS);
        // Room for every block there can be: handing one back never blocks.
        let (spare, spare_rx) = sync_channel(BLOCKS + 2);
        let in_flight = Arc::new(AtomicUsize::new(0));
        let sent = Arc::clone(&in_flight);
        std::thread::Builder::new()
            .name("schuler-lines".to_owned())
            .spawn(move || read_all(lines, &parse, (&tx, &sent), &spare_rx))?;
        Ok(Self {
            rx: Some(rx),
            spare,
            in_flight,
            block: Block::default(),
            current: None,
            at,
        })
    }

    /// A source with no lines (what a reader holds while it moves its own).
    pub(crate) fn ended() -> Self {
        let (spare, _) = sync_channel(0);
        Self {
            rx: None,
            spare,
            in_flight: Arc::default(),
            block: Block {
                end: Some(End::Eof),
                ..Block::default()
            },
            current: None,
            at: Position::default(),
        }
    }

    /// The next line; `Ok(false)` at the end (as [`LineReader::next_line`]).
    pub(crate) fn next_line(&mut self) -> Result<bool, LineReadError> {
        loop {
            let next = self.current.map_or(0, |i| i + 1);
            if let Some(e) = self.block.entries.get(next) {
                (self.current, self.at.line_no, self.at.bytes) = (Some(next), e.line_no, e.bytes);
                return Ok(true);
            }
            self.current = None;
            match self.block.end.take() {
                Some(End::Eof) => {
                    self.rx = None;
                    self.block.end = Some(End::Eof);
                    return Ok(false);
                }
                Some(End::Failed {
                    error,
                    line_no,
                    bytes,
                }) => {
                    (self.rx, self.at.line_no, self.at.bytes) = (None, line_no, bytes);
                    self.block.end = Some(End::Eof);
                    return Err(error);
                }
                None => {}
            }
            let Some(rx) = &self.rx else {
                return Ok(false);
            };
            let Ok(block) = rx.recv() else {
                // The helper ended without saying how: it panicked.
                self.rx = None;
                return Err(LineReadError::Io(std::io::Error::other(
                    "the line reader thread stopped",
                )));
            };
            self.in_flight.fetch_sub(1, Ordering::Relaxed);
            let done = std::mem::replace(&mut self.block, block);
            // The helper may be gone at the end: the block is then simply dropped.
            let _ = self.spare.try_send(done);
        }
    }

    /// The current line's content.
    #[inline]
    pub(crate) fn line(&self) -> &[u8] {
        self.entry()
            .map_or(&[][..], |e| &self.block.text[e.start..e.end])
    }

    /// The current line's fields, when the helper parsed them.
    #[inline]
    pub(crate) fn parsed(&self) -> Option<&Parsed> {
        self.entry().and_then(|e| e.parsed.as_ref())
    }

    fn entry(&self) -> Option<&Entry> {
        self.current.map(|i| &self.block.entries[i])
    }

    /// Where it stands (the helper's byte counter is a little ahead).
    #[inline]
    pub(crate) fn at(&self) -> &Position {
        &self.at
    }
}

/// The helper thread: blocks of lines into `tx` until the input ends or fails, or
/// the consumer hangs up.
fn read_all<R: Read>(
    mut lines: LineReader<R>,
    parse: &impl Fn(&[u8]) -> Option<Parsed>,
    (tx, in_flight): (&SyncSender<Block>, &AtomicUsize),
    spare: &Receiver<Block>,
) {
    loop {
        let mut block = spare.try_recv().unwrap_or_default();
        block.text.clear();
        block.entries.clear();
        while block.entries.len() < BLOCK_LINES && block.end.is_none() {
            match lines.next_line() {
                Ok(true) => {
                    let line = lines.line();
                    let start = block.text.len();
                    block.text.extend_from_slice(line);
                    // While the consumer has taken every block, it waits: leave it
                    // some parsing (module doc).
                    let leave = (block.entries.len() + 1).is_multiple_of(LEFT_TO_CONSUMER)
                        && in_flight.load(Ordering::Relaxed) == 0;
                    block.entries.push(Entry {
                        start,
                        end: block.text.len(),
                        line_no: lines.at().line_no,
                        bytes: lines.at().bytes,
                        parsed: if leave || is_skippable(line) {
                            None
                        } else {
                            parse(line)
                        },
                    });
                }
                Ok(false) => block.end = Some(End::Eof),
                Err(error) => {
                    block.end = Some(End::Failed {
                        error,
                        line_no: lines.at().line_no,
                        bytes: lines.at().bytes,
                    });
                }
            }
        }
        let last = block.end.is_some();
        in_flight.fetch_add(1, Ordering::Relaxed);
        if tx.send(block).is_err() || last {
            return;
        }
    }
}

/// A reader's lines: read here, or ahead on a helper thread.
pub(crate) enum Lines<R> {
    Here(LineReader<R>),
    Ahead(LinesAhead),
}

impl<R: Read> Lines<R> {
    #[inline]
    pub(crate) fn next_line(&mut self) -> Result<bool, LineReadError> {
        match self {
            Lines::Here(l) => l.next_line(),
            Lines::Ahead(l) => l.next_line(),
        }
    }

    #[inline]
    pub(crate) fn line(&self) -> &[u8] {
        match self {
            Lines::Here(l) => l.line(),
            Lines::Ahead(l) => l.line(),
        }
    }

    /// The current line's fields parsed ahead (never when read here).
    #[inline]
    pub(crate) fn parsed(&self) -> Option<&Parsed> {
        match self {
            Lines::Here(_) => None,
            Lines::Ahead(l) => l.parsed(),
        }
    }

    #[inline]
    pub(crate) fn at(&self) -> &Position {
        match self {
            Lines::Here(l) => l.at(),
            Lines::Ahead(l) => l.at(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a reader yields: each line with its number and bytes, then how it ended.
    type Transcript = (Vec<(Vec<u8>, u64, u64, Option<Parsed>)>, String);

    fn transcript<R: Read>(mut lines: Lines<R>) -> Transcript {
        let mut seen = Vec::new();
        let end = loop {
            match lines.next_line() {
                Ok(true) => seen.push((
                    lines.line().to_vec(),
                    lines.at().line_no,
                    lines.at().bytes,
                    lines.parsed().copied(),
                )),
                Ok(false) => break "end".to_owned(),
                Err(LineReadError::TooLong) => break format!("too long at {}", lines.at().line_no),
                Err(LineReadError::Io(e)) => break format!("{e} after {}", lines.at().line_no),
            }
        };
        (seen, end)
    }

    /// The first number of a line, as a stand-in parser.
    fn first_number(line: &[u8]) -> Option<Parsed> {
        let text = std::str::from_utf8(line).ok()?;
        let v: f64 = text.split_whitespace().next()?.parse().ok()?;
        Some(Parsed {
            values: [v; 7],
            time_span: (0, 1),
        })
    }

    /// Read ahead, the lines, numbers, bytes and end are those read here, across
    /// many blocks, with comments and bad lines left unparsed, and after the first
    /// lines were read here (as the IMU reader reads its header and first samples).
    #[test]
    fn lines_read_ahead_are_the_lines_read_here() {
        let mut input = Vec::new();
        for k in 0..5 * BLOCK_LINES + 17 {
            match k % 97 {
                0 => input.extend_from_slice(b"# comment\n"),
                1 => input.extend_from_slice(b"\r\n"),
                2 => input.extend_from_slice(b"x 1 2\n"),
                _ => input.extend_from_slice(format!("{k}.5 1 2 3\r\n").as_bytes()),
            }
        }
        input.extend_from_slice(b"7 8");
        for skip in [0, 3] {
            let here = |skip| {
                let mut l = LineReader::new(std::io::Cursor::new(input.clone()));
                for _ in 0..skip {
                    assert!(l.next_line().expect("read"));
                }
                l
            };
            let (lines, end) = transcript(Lines::Here(here(skip)));
            let ahead = LinesAhead::spawn(here(skip), first_number).expect("helper thread");
            let (lines_ahead, end_ahead) = transcript(Lines::<&[u8]>::Ahead(ahead));
            assert_eq!(end_ahead, end);
            assert_eq!(lines_ahead.len(), lines.len());
            let mut parsed_ahead = 0;
            for ((a, na, ba, pa), (b, nb, bb, _)) in lines_ahead.iter().zip(&lines) {
                assert_eq!((a, na, ba), (b, nb, bb));
                // Parsed ahead, or left to the consumer: never anything else.
                let expected = if is_skippable(b) {
                    None
                } else {
                    first_number(b)
                };
                assert!(pa.is_none() || *pa == expected, "line {nb}");
                parsed_ahead += usize::from(pa.is_some());
            }
            assert_eq!(lines.last().map(|l| l.1), Some(5 * BLOCK_LINES as u64 + 18));
            // At least the lines of the blocks made while the consumer was busy.
            assert!(parsed_ahead >= lines.len() / 2, "{parsed_ahead}");
        }
    }

    /// A line too long ends the lines read ahead with the same error at the same line.
    #[test]
    fn an_error_comes_at_its_place() {
        let mut input = b"1 2\n3 4\n".repeat(BLOCK_LINES);
        input.extend(std::iter::repeat_n(
            b'7',
            super::super::lines::MAX_LINE_BYTES as usize,
        ));
        input.extend_from_slice(b"\n5 6\n");
        let here = || LineReader::new(std::io::Cursor::new(input.clone()));
        let expected = transcript(Lines::Here(here()));
        assert_eq!(expected.1, format!("too long at {}", 2 * BLOCK_LINES + 1));
        let ahead = LinesAhead::spawn(here(), first_number).expect("helper thread");
        let got = transcript(Lines::<&[u8]>::Ahead(ahead));
        assert_eq!((got.0.len(), &got.1), (expected.0.len(), &expected.1));
    }

    /// A consumer that stops early returns at once, even on an input that never ends.
    #[test]
    fn an_early_stop_does_not_wait_for_the_helper() {
        let endless = std::io::repeat(b'\n');
        let mut ahead =
            LinesAhead::spawn(LineReader::new(endless), first_number).expect("helper thread");
        for _ in 0..3 * BLOCK_LINES {
            assert!(ahead.next_line().expect("endless"));
        }
        drop(ahead);
    }
}
