//! Line-by-line reading into one reused buffer, with a byte-progress counter and the
//! skip rules shared by the text formats.

use std::io::{BufRead, Read};
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
    let mut r = LineReader::new(std::io::BufReader::with_capacity(1 << 20, file));
    let mut out = Vec::new();
    loop {
        match r.next_line() {
            Ok(false) => return Ok(out),
            Ok(true) => {
                out.extend_from_slice(r.line());
                out.push(b'\n');
            }
            Err(LineReadError::Io(e)) => return Err(cannot_read(path, &e)),
            Err(LineReadError::TooLong) => return Err(too_long(path, r.line_no())),
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
    let mut r = LineReader::new(std::io::BufReader::with_capacity(1 << 16, file));
    loop {
        match r.next_line() {
            Ok(false) => return Ok(()),
            Ok(true) => {
                let n = r.line_no();
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
            Err(LineReadError::TooLong) => return Err(too_long(path, r.line_no())),
        }
    }
}

/// A configuration file's text, at most [`MAX_CONFIG_BYTES`], without a leading
/// byte-order mark.
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

pub(crate) fn cannot_read(path: &Path, e: &std::io::Error) -> InputError {
    InputError::new(
        InputErrorKind::Io,
        path,
        0,
        None,
        format!("cannot read: {e}"),
    )
}

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

/// Reads lines into one reused buffer (no allocation per line once it has grown),
/// counting lines and bytes consumed.
pub(crate) struct LineReader<R> {
    inner: R,
    buf: Vec<u8>,
    /// 1-based number of the line in `buf` (0 before the first).
    line_no: u64,
    /// Bytes consumed so far, mirrored into `progress`.
    bytes: u64,
    progress: Arc<AtomicU64>,
}

impl<R: BufRead> LineReader<R> {
    /// Wraps `inner`.
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            buf: Vec::with_capacity(256),
            line_no: 0,
            bytes: 0,
            progress: Arc::new(AtomicU64::new(0)),
        }
    }

    /// Reads the next line; `Ok(false)` at end of input. The line's content (without
    /// the line terminator, `\n` or `\r\n`, or a leading UTF-8 byte-order mark on line 1)
    /// is then in [`Self::line`].
    pub(crate) fn next_line(&mut self) -> Result<bool, LineReadError> {
        self.buf.clear();
        let n = (&mut self.inner)
            .take(MAX_LINE_BYTES)
            .read_until(b'\n', &mut self.buf)
            .map_err(LineReadError::Io)?;
        if n == 0 {
            return Ok(false);
        }
        self.line_no += 1;
        self.bytes += n as u64;
        // A plain store: one writer, readers only want a recent value.
        self.progress.store(self.bytes, Ordering::Relaxed);
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
            if self.buf.last() == Some(&b'\r') {
                self.buf.pop();
            }
        } else if n as u64 == MAX_LINE_BYTES {
            return Err(LineReadError::TooLong);
        }
        Ok(true)
    }

    /// The current line's content.
    #[inline]
    pub(crate) fn line(&self) -> &[u8] {
        if self.line_no == 1 {
            self.buf.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&self.buf)
        } else {
            &self.buf
        }
    }

    /// 1-based number of the current line (0 before the first).
    #[inline]
    pub(crate) fn line_no(&self) -> u64 {
        self.line_no
    }

    /// Bytes consumed so far.
    #[inline]
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }

    /// The shared counter mirroring [`Self::bytes`].
    pub(crate) fn progress(&self) -> Arc<AtomicU64> {
        Arc::clone(&self.progress)
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
        assert_eq!(r.bytes(), input.len() as u64);
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
