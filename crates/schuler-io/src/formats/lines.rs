//! Line-by-line reading into one reused buffer, with a byte-progress counter and the
//! skip rules shared by the text formats.

use std::io::Read;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::error::{InputError, InputErrorKind};

/// Longest line a reader accepts [bytes]: bounds memory on a file without newlines.
pub const MAX_LINE_BYTES: u64 = 64 * 1024;

/// Largest configuration file read [bytes]: a TOML or YAML configuration is a few
/// kilobytes; this bounds memory on a stream that never ends.
pub const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// The UTF-8 byte-order mark, accepted (and dropped) at the start of every text file.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// The bytes of a whole text file read at once, without a leading byte-order mark;
/// a line longer than [`MAX_LINE_BYTES`] (a stream without newlines, a binary file) is
/// an error naming it, so memory stays bounded by the file's real content.
pub fn read_lines_whole(path: &Path) -> Result<Vec<u8>, InputError> {
    let file = std::fs::File::open(path).map_err(|e| cannot_read(path, &e))?;
    let mut r = LineReader::new(file);
    let mut out = Vec::new();
    loop {
        match r.next_line() {
            Ok(false) => return Ok(out),
            Ok(true) => {
                out.extend_from_slice(r.line());
                out.push(b'\n');
            }
            Err(LineReadError::Io(e)) => return Err(cannot_read(path, &e)),
            Err(LineReadError::TooLong) => return Err(too_long(path, r.at().line_no)),
        }
    }
}

/// Every data line of the text file `path`, read one at a time into a reused buffer
/// (memory bounded by the longest line, not the file): trimmed, with its 1-based
/// number, blank lines and comments left out, as [`data_lines`] gives them from
/// the whole text ([`read_lines_whole`]; a second byte-order mark dropped as
/// `gnss::utf8_text` drops it). A line that is not UTF-8 is an error naming it.
pub(crate) fn for_each_data_line(
    path: &Path,
    mut f: impl FnMut(u64, &str) -> Result<(), InputError>,
) -> Result<(), InputError> {
    let file = std::fs::File::open(path).map_err(|e| cannot_read(path, &e))?;
    let mut r = LineReader::new(file);
    loop {
        match r.next_line() {
            Ok(false) => return Ok(()),
            Ok(true) => {
                let n = r.at().line_no;
                let bytes = match r.line() {
                    l if n == 1 => l.strip_prefix(BOM).unwrap_or(l),
                    l => l,
                };
                let l = std::str::from_utf8(bytes).map_err(|_| {
                    InputError::new(InputErrorKind::NotANumber, path, n, None, "not UTF-8 text")
                })?;
                let l = l.trim();
                if !is_skippable(l.as_bytes()) {
                    f(n, l)?;
                }
            }
            Err(LineReadError::Io(e)) => return Err(cannot_read(path, &e)),
            Err(LineReadError::TooLong) => return Err(too_long(path, r.at().line_no)),
        }
    }
}

/// A configuration file's text, at most [`MAX_CONFIG_BYTES`] and lines shorter than
/// [`MAX_LINE_BYTES`], without a leading byte-order mark.
pub fn read_config_text(path: &Path) -> Result<String, InputError> {
    let file = std::fs::File::open(path).map_err(|e| cannot_read(path, &e))?;
    let mut bytes = Vec::new();
    file.take(MAX_CONFIG_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| cannot_read(path, &e))?;
    if bytes.len() as u64 > MAX_CONFIG_BYTES {
        return Err(InputError::new(
            InputErrorKind::LineTooLong,
            path,
            0,
            None,
            format!(
                "longer than {} MiB: not a configuration file",
                MAX_CONFIG_BYTES >> 20
            ),
        ));
    }
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    // A configuration's lines are short: a longer one is not a configuration, and a
    // parser's error would quote it whole (a 10-MB line, twice, on stderr).
    for (k, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if line.len() as u64 >= MAX_LINE_BYTES {
            return Err(too_long(path, k as u64 + 1));
        }
    }
    String::from_utf8(bytes).map_err(|e| {
        InputError::new(
            InputErrorKind::NotANumber,
            path,
            0,
            None,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

pub(crate) use super::error::cannot_read;

/// The error of line `n` longer than [`MAX_LINE_BYTES`].
pub(crate) fn too_long(path: &Path, n: u64) -> InputError {
    InputError::new(
        InputErrorKind::LineTooLong,
        path,
        n,
        None,
        format!(
            "line longer than {} KiB (not a text log, or no line ends)",
            MAX_LINE_BYTES >> 10
        ),
    )
}

/// Why [`LineReader::next_line`] failed.
#[derive(Debug)]
pub(crate) enum LineReadError {
    /// The underlying reader failed.
    Io(std::io::Error),
    /// The line exceeds [`MAX_LINE_BYTES`].
    TooLong,
}

/// Bytes a [`LineReader`] reads at once: a few times [`MAX_LINE_BYTES`], so a line
/// that crosses the end of the buffer always fits once the rest is moved to the front,
/// and small enough to stay in the core's second-level cache.
pub(crate) const LINE_BUFFER_BYTES: usize = 1 << 18;

/// Reads lines from large blocks of its input into its own buffer and hands each one
/// out in place (no copy per line; `memchr` finds the line ends), counting lines and
/// bytes consumed.
pub(crate) struct LineReader<R> {
    inner: R,
    buf: Box<[u8]>,
    /// The current line's content in `buf` (start, end).
    line: (usize, usize),
    /// Unread bytes in `buf`: `pos..end`.
    pos: usize,
    end: usize,
    /// Whether the input has ended.
    eof: bool,
    at: Position,
}

/// Where a line reader stands: the current line's number and the bytes consumed
/// through it, with a counter of the bytes read that another thread may watch.
#[derive(Debug, Clone, Default)]
pub(crate) struct Position {
    /// 1-based number of the current line (0 before the first).
    pub line_no: u64,
    /// Bytes consumed up to the current line's end.
    pub bytes: u64,
    /// Bytes read so far (a progress bar's; ahead of `bytes` when read ahead).
    pub progress: Arc<AtomicU64>,
}

impl<R: Read> LineReader<R> {
    /// Wraps `inner` (a file needs no `BufReader`: reads are [`LINE_BUFFER_BYTES`]).
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            buf: vec![0; LINE_BUFFER_BYTES].into_boxed_slice(),
            line: (0, 0),
            pos: 0,
            end: 0,
            eof: false,
            at: Position::default(),
        }
    }

    /// Reads the next line; `Ok(false)` at end of input. The line's content (without
    /// the line terminator, `\n` or `\r\n`, or a leading UTF-8 byte-order mark on line 1)
    /// is then in [`Self::line`]. A line of [`MAX_LINE_BYTES`] or more bytes before its
    /// terminator is [`LineReadError::TooLong`].
    pub(crate) fn next_line(&mut self) -> Result<bool, LineReadError> {
        const MAX: usize = MAX_LINE_BYTES as usize;
        let mut searched = self.pos;
        loop {
            let found = memchr::memchr(b'\n', &self.buf[searched..self.end]);
            let (content_end, next) = match found {
                Some(i) => (searched + i, searched + i + 1),
                None if self.end - self.pos >= MAX => (self.pos + MAX, self.pos + MAX),
                None if self.eof && self.pos == self.end => return Ok(false),
                None if self.eof => (self.end, self.end),
                None => {
                    // The unread bytes hold no line end: read more after them.
                    let unread = self.end - self.pos;
                    self.fill()?;
                    searched = self.pos + unread;
                    continue;
                }
            };
            self.at.line_no += 1;
            self.at.bytes += (next - self.pos) as u64;
            // A plain store: one writer, readers only want a recent value.
            self.at.progress.store(self.at.bytes, Ordering::Relaxed);
            if content_end - self.pos >= MAX {
                return Err(LineReadError::TooLong);
            }
            let mut end = content_end;
            if next > content_end && end > self.pos && self.buf[end - 1] == b'\r' {
                end -= 1;
            }
            self.line = (self.pos, end);
            self.pos = next;
            return Ok(true);
        }
    }

    /// Moves the unread bytes to the front of the buffer and reads more after them
    /// (sets `eof` when the input has ended).
    fn fill(&mut self) -> Result<(), LineReadError> {
        if self.pos > 0 {
            self.buf.copy_within(self.pos..self.end, 0);
            self.end -= self.pos;
            self.pos = 0;
        }
        loop {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(n) => {
                    self.end += n;
                    return Ok(());
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(LineReadError::Io(e)),
            }
        }
    }

    /// The current line's content.
    #[inline]
    pub(crate) fn line(&self) -> &[u8] {
        let line = &self.buf[self.line.0..self.line.1];
        if self.at.line_no == 1 {
            line.strip_prefix(BOM).unwrap_or(line)
        } else {
            line
        }
    }

    /// Where it stands.
    #[inline]
    pub(crate) fn at(&self) -> &Position {
        &self.at
    }
}

/// Whether a space or tab.
#[inline]
pub(crate) fn is_blank(b: u8) -> bool {
    b == b' ' || b == b'\t'
}

/// Whether a line carries no data: empty, only blanks, or a comment whose first
/// non-blank byte is `#` or `%`.
#[inline]
pub(crate) fn is_skippable(line: &[u8]) -> bool {
    match line.iter().find(|&&b| !is_blank(b)) {
        None => true,
        Some(&b) => b == b'#' || b == b'%',
    }
}

/// Whether a field separator of the text formats: space, tab, comma or semicolon.
#[inline]
pub(crate) fn is_separator(c: char) -> bool {
    matches!(c, ' ' | '\t' | ',' | ';')
}

/// The fields of a headerless text line: separated by runs of spaces, tabs, commas or
/// semicolons (so an empty field between two commas is no field).
pub(crate) fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(is_separator).filter(|f| !f.is_empty())
}

/// The lines of a whole text that may carry data, trimmed, with their 1-based numbers:
/// blank lines and comments ([`is_skippable`]) left out.
pub(crate) fn data_lines(text: &str) -> impl Iterator<Item = (u64, &str)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let l = line.trim();
        (!is_skippable(l.as_bytes())).then_some((i as u64 + 1, l))
    })
}

/// How the fields of a file with a header row are separated, told by the header: the
/// first of comma, semicolon and tab it holds, else runs of blanks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Delimiter {
    /// One character between two fields (an empty field is a field).
    Char(char),
    /// Runs of spaces and tabs.
    Blanks,
}

impl Delimiter {
    /// The delimiter of header line `header`.
    pub(crate) fn of_header(header: &str) -> Self {
        [',', ';', '\t']
            .into_iter()
            .find(|&c| header.contains(c))
            .map_or(Delimiter::Blanks, Delimiter::Char)
    }

    /// The fields of `line`, each trimmed of blanks.
    pub(crate) fn split(self, line: &str) -> Vec<&str> {
        match self {
            Delimiter::Char(c) => line.split(c).map(str::trim).collect(),
            Delimiter::Blanks => line.split_whitespace().collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_lines(input: &[u8]) -> Vec<Vec<u8>> {
        let mut r = LineReader::new(input);
        let mut out = Vec::new();
        while r.next_line().expect("in-memory read cannot fail") {
            out.push(r.line().to_vec());
        }
        assert_eq!(r.at().bytes, input.len() as u64);
        out
    }

    #[test]
    fn strips_terminators_and_bom() {
        let lines = all_lines(b"\xEF\xBB\xBFa b\r\nc\n\nd");
        assert_eq!(
            lines,
            vec![b"a b".to_vec(), b"c".to_vec(), b"".to_vec(), b"d".to_vec()]
        );
    }

    #[test]
    fn overlong_line_is_an_error_not_a_buffer_explosion() {
        let input = vec![b'1'; (MAX_LINE_BYTES as usize) * 3];
        let mut r = LineReader::new(&input[..]);
        assert!(matches!(r.next_line(), Err(LineReadError::TooLong)));
    }

    /// A reader handing out its bytes a few at a time (the sizes cycle through
    /// `sizes`), with an interruption before each read: what a pipe or a slow device
    /// may do.
    struct Trickle<'a> {
        bytes: &'a [u8],
        sizes: std::iter::Cycle<std::slice::Iter<'a, usize>>,
        interrupted: bool,
    }

    impl Read for Trickle<'_> {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            self.interrupted = !self.interrupted;
            if self.interrupted {
                return Err(std::io::ErrorKind::Interrupted.into());
            }
            let n = (*self.sizes.next().expect("cycle"))
                .min(out.len())
                .min(self.bytes.len());
            out[..n].copy_from_slice(&self.bytes[..n]);
            self.bytes = &self.bytes[n..];
            Ok(n)
        }
    }

    /// The lines of `input` by the definition: split at `\n`, a `\r` before it dropped,
    /// no line after a final `\n`.
    fn reference_lines(input: &[u8]) -> Vec<Vec<u8>> {
        let mut lines: Vec<Vec<u8>> = input
            .split(|&b| b == b'\n')
            .map(|l| l.strip_suffix(b"\r").unwrap_or(l).to_vec())
            .collect();
        if input.ends_with(b"\n") || input.is_empty() {
            lines.pop();
        }
        lines
    }

    /// Lines crossing the ends of the reader's blocks, in reads of any size, come out
    /// whole: 3 MiB of lines of 0 to 300 bytes (more than ten buffers), read in one go
    /// and in trickles of 1 to 7919 bytes.
    #[test]
    fn lines_across_block_ends_are_whole() {
        let mut input = Vec::new();
        let mut k: u64 = 1;
        while input.len() < 3 << 20 {
            k = k
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let len = (k >> 33) as usize % 301;
            input.extend((0..len).map(|i| b'a' + (i % 26) as u8));
            input.extend_from_slice(if k & 1 == 0 { b"\n" } else { b"\r\n" });
        }
        input.extend_from_slice(b"last line without an end");
        let expected = reference_lines(&input);
        assert_eq!(all_lines(&input), expected);
        for sizes in [&[1usize, 2, 3][..], &[7919, 1, 65536, 300_000]] {
            let mut r = LineReader::new(Trickle {
                bytes: &input,
                sizes: sizes.iter().cycle(),
                interrupted: false,
            });
            let mut got = Vec::new();
            while r.next_line().expect("in-memory read cannot fail") {
                got.push(r.line().to_vec());
            }
            assert_eq!(got, expected, "reads of {sizes:?}");
            assert_eq!(r.at().bytes, input.len() as u64);
        }
    }

    /// The longest line is `MAX_LINE_BYTES - 1` bytes before its end, with or without
    /// a terminator; one more byte is an error naming that line.
    #[test]
    fn longest_line_is_one_below_the_limit() {
        let max = MAX_LINE_BYTES as usize;
        for (len, end, ok) in [
            (max - 1, &b"\n"[..], true),
            (max - 1, b"", true),
            (max, b"\n", false),
            (max, b"", false),
        ] {
            let mut input = b"1 2\n".to_vec();
            input.extend(std::iter::repeat_n(b'7', len));
            input.extend_from_slice(end);
            let mut r = LineReader::new(&input[..]);
            assert!(r.next_line().expect("first"));
            let second = r.next_line();
            assert_eq!(second.is_ok(), ok, "{len} bytes and {end:?}");
            assert_eq!(r.at().line_no, 2);
            if ok {
                assert_eq!(r.line().len(), len);
            }
        }
    }

    #[test]
    fn whole_files_are_bounded() {
        let dir = tempfile::tempdir().expect("tempdir");
        let long = dir.path().join("long.txt");
        let mut text = b"\xEF\xBB\xBF1 2\r\n".to_vec();
        text.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES as usize + 1));
        std::fs::write(&long, &text).expect("write");
        let e = read_lines_whole(&long).expect_err("too long");
        assert_eq!((e.line, e.kind), (2, InputErrorKind::LineTooLong));
        text.truncate(8);
        std::fs::write(&long, &text).expect("write");
        assert_eq!(read_lines_whole(&long).expect("short"), b"1 2\n");
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; MAX_CONFIG_BYTES as usize + 1]).expect("write");
        let e = read_config_text(&big).expect_err("too big");
        assert!(e.to_string().contains("longer than 16 MiB"), "{e}");
        std::fs::write(&big, "\u{feff}a = 1\n").expect("write");
        assert_eq!(read_config_text(&big).expect("small"), "a = 1\n");
    }

    #[test]
    fn skip_rules() {
        assert!(is_skippable(b""));
        assert!(is_skippable(b" \t "));
        assert!(is_skippable(b"# comment"));
        assert!(is_skippable(b"  % matlab comment"));
        assert!(!is_skippable(b" 1 2 3"));
    }

    #[test]
    fn separators_comments_and_delimiters() {
        let f: Vec<&str> = fields("1\t2, 3;4  ;5,,6").collect();
        assert_eq!(f, ["1", "2", "3", "4", "5", "6"]);
        let lines: Vec<(u64, &str)> = data_lines("# c\n\n 1 2 \n% m\n3\n").collect();
        assert_eq!(lines, [(3, "1 2"), (5, "3")]);
        assert_eq!(Delimiter::of_header("t;h_m"), Delimiter::Char(';'));
        assert_eq!(Delimiter::of_header("t,h_m;x"), Delimiter::Char(','));
        assert_eq!(Delimiter::of_header("t\th_m"), Delimiter::Char('\t'));
        assert_eq!(Delimiter::of_header("t h_m"), Delimiter::Blanks);
        assert_eq!(Delimiter::Char(';').split(" 1; ;3"), ["1", "", "3"]);
        assert_eq!(Delimiter::Blanks.split(" 1  2\t3"), ["1", "2", "3"]);
    }
}
