//! Output text files that only ever hold whole lines. A run that fails to write (a
//! full disk, a quota, a pipe gone) cuts the file back to the end of its last whole
//! line and names the file in its error, so a reader of what is left never meets half
//! a number; an interrupted run (a signal, see the pipeline) closes its files between lines
//! the same way.
//!
//! - [`LineFile`] appends blocks that end on a line (the fast row writers' blocks).
//! - [`LineWriter`] is a buffered [`std::io::Write`] over it for `writeln!` users: it
//!   hands the file only whole lines, and what is left at the end when it finishes.
//! - [`write_whole`] writes a file that is only useful complete (a summary, a report):
//!   on failure it removes what it wrote.

use anyhow::{Context, Result};
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Where the lines go: a file, or in tests a sink that fails as a full disk does.
pub trait Sink: Write {
    /// Cuts the sink back to `len` bytes.
    fn truncate(&mut self, len: u64) -> io::Result<()>;
}

impl Sink for File {
    fn truncate(&mut self, len: u64) -> io::Result<()> {
        self.set_len(len)
    }
}

/// A text file written in blocks of whole lines.
#[derive(Debug)]
pub struct LineFile<S: Sink = File> {
    sink: S,
    path: PathBuf,
    /// Bytes known written and ending on a line.
    whole: u64,
}

impl LineFile {
    /// Creates (or empties) `path`.
    pub fn create(path: impl Into<PathBuf>) -> Result<Self> {
        let path = path.into();
        let file =
            File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(Self::on(file, path))
    }
}

impl<S: Sink> LineFile<S> {
    /// Lines into `sink`, named `path` in errors.
    pub fn on(sink: S, path: PathBuf) -> Self {
        Self {
            sink,
            path,
            whole: 0,
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes written so far, all of them whole lines.
    pub fn len(&self) -> u64 {
        self.whole
    }

    /// Whether nothing was written.
    pub fn is_empty(&self) -> bool {
        self.whole == 0
    }

    /// Appends `lines` (whole lines: the caller ends them with a newline). On a
    /// failed write the file is cut back to its last whole line and the error names
    /// it and says so.
    pub fn append(&mut self, lines: &[u8]) -> io::Result<()> {
        match self.sink.write_all(lines) {
            Ok(()) => {
                self.whole += lines.len() as u64;
                Ok(())
            }
            Err(e) => Err(self.failed(e)),
        }
    }

    /// The error of a failed write, after cutting the file back to `whole` bytes.
    fn failed(&mut self, e: io::Error) -> io::Error {
        let kept = match self.sink.truncate(self.whole) {
            Ok(()) => format!("it ends on its last whole line, at byte {}", self.whole),
            Err(t) => format!("and it could not be cut back to its last whole line: {t}"),
        };
        io::Error::new(
            e.kind(),
            format!("cannot write {}: {e}; {kept}", self.path.display()),
        )
    }
}

/// Text gathered before it goes to the file [bytes].
const LINE_BUFFER: usize = 1 << 16;

/// A buffered writer over a [`LineFile`]: the file only ever gets whole lines, and
/// the rest when [`LineWriter::finish`] is called (or the writer dropped).
#[derive(Debug)]
pub struct LineWriter<S: Sink = File> {
    file: LineFile<S>,
    buf: Vec<u8>,
}

impl LineWriter {
    /// Creates (or empties) `path`.
    pub fn create(path: impl Into<PathBuf>) -> Result<Self> {
        Ok(Self::over(LineFile::create(path)?))
    }
}

impl<S: Sink> LineWriter<S> {
    /// A writer over `file`.
    pub fn over(file: LineFile<S>) -> Self {
        Self {
            file,
            buf: Vec::with_capacity(LINE_BUFFER),
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        self.file.path()
    }

    /// Writes the buffered whole lines, keeping the start of an unfinished one.
    fn write_whole_lines(&mut self) -> io::Result<()> {
        let Some(end) = self.buf.iter().rposition(|&b| b == b'\n') else {
            return Ok(());
        };
        self.file.append(&self.buf[..=end])?;
        self.buf.drain(..=end);
        Ok(())
    }

    /// Writes everything, an unfinished last line too, and closes the file; the error
    /// names the file.
    pub fn finish(mut self) -> Result<()> {
        let rest = std::mem::take(&mut self.buf);
        self.file.append(&rest).map_err(anyhow::Error::new)
    }
}

impl<S: Sink> Write for LineWriter<S> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(bytes);
        if self.buf.len() >= LINE_BUFFER {
            self.write_whole_lines()?;
        }
        Ok(bytes.len())
    }

    /// Writes the whole lines buffered; an unfinished line waits for its end.
    fn flush(&mut self) -> io::Result<()> {
        self.write_whole_lines()
    }
}

impl<S: Sink> Drop for LineWriter<S> {
    /// A writer dropped on an error path still leaves its whole lines in the file.
    fn drop(&mut self) {
        let _ = self.write_whole_lines();
    }
}

/// Writes `bytes` as the whole of `path`; if that fails the file is removed, so that
/// no cut summary or report is left, and the error names it.
pub fn write_whole(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| {
        let removed = std::fs::remove_file(path).is_ok();
        anyhow::Error::new(e).context(format!(
            "cannot write {}{}",
            path.display(),
            if removed {
                " (the incomplete file was removed)"
            } else {
                ""
            }
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disk with room for `room` bytes: a write takes what fits, then fails with
    /// "no space left", as a kernel's `write` does.
    struct Disk {
        bytes: Vec<u8>,
        room: usize,
    }

    impl Write for Disk {
        fn write(&mut self, b: &[u8]) -> io::Result<usize> {
            let n = b.len().min(self.room - self.bytes.len());
            if n == 0 {
                return Err(io::Error::from(io::ErrorKind::StorageFull));
            }
            self.bytes.extend_from_slice(&b[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Sink for Disk {
        fn truncate(&mut self, len: u64) -> io::Result<()> {
            self.bytes.truncate(len as usize);
            Ok(())
        }
    }

    fn disk(room: usize) -> LineFile<Disk> {
        LineFile::on(
            Disk {
                bytes: Vec::new(),
                room,
            },
            PathBuf::from("out/nav.txt"),
        )
    }

    #[test]
    fn a_full_disk_leaves_whole_lines_and_names_the_file() {
        // Every room from empty to one byte short of the text cuts a line somewhere.
        let text: Vec<u8> = (0..40)
            .map(|k| format!("{k} 1.25 -3.5\n"))
            .collect::<String>()
            .into_bytes();
        for room in 0..text.len() {
            let mut w = LineWriter::over(disk(room));
            let written = text.chunks(7).try_for_each(|c| w.write_all(c));
            let err = match written.and_then(|()| w.flush()) {
                Err(e) => e.to_string(),
                Ok(()) => match w.finish() {
                    Err(e) => e.to_string(),
                    Ok(()) => panic!("room {room}: the write of {} bytes passed", text.len()),
                },
            };
            assert!(err.contains("out/nav.txt"), "{err}");
        }
        // The file itself, room by room: only whole lines stay, and as many as fit.
        for room in 0..text.len() {
            let mut f = disk(room);
            let mut rows = text.split_inclusive(|&b| b == b'\n');
            let failed = rows.try_for_each(|line| f.append(line)).is_err();
            assert!(failed);
            let kept = &f.sink.bytes;
            let fit = text[..room]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1);
            assert_eq!(kept.len(), fit, "room {room}");
            assert_eq!(kept[..], text[..fit]);
        }
    }

    #[test]
    fn unfinished_lines_wait_for_their_end() {
        let mut w = LineWriter::over(disk(1 << 20));
        w.write_all(b"1 2\n3 ").expect("fits");
        w.flush().expect("fits");
        assert_eq!(w.file.sink.bytes, b"1 2\n");
        w.write_all(b"4\n").expect("fits");
        w.flush().expect("fits");
        assert_eq!(w.file.sink.bytes, b"1 2\n3 4\n");
    }

    #[test]
    fn a_failed_whole_file_is_removed() {
        let dir = tempfile::tempdir().expect("tempdir");
        let missing = dir.path().join("no/such/dir/summary.json");
        let e = write_whole(&missing, "{}").expect_err("no directory");
        assert!(format!("{e:#}").contains("summary.json"), "{e:#}");
        let ok = dir.path().join("summary.json");
        write_whole(&ok, "{}\n").expect("writes");
        assert_eq!(std::fs::read(&ok).expect("read"), b"{}\n");
    }
}
