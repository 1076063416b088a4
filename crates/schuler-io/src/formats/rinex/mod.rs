//! RINEX, the receiver-independent exchange format of GNSS observations (`obs`) and
//! broadcast navigation messages (`nav`): versions 2.11, 3.0x and 4.0x.
//!
//! Header lines carry their label in columns 61–80 and their content in columns 1–60;
//! records are fixed-width. Both readers stream: they hold one epoch (or one
//! ephemeris) at a time, and name the file, the line and the field of what they refuse.

mod hatanaka;
pub mod nav;
pub mod obs;
pub mod raw;
pub mod write;

use crate::formats::InputError;
use crate::formats::error::cannot_read;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// The bytes that begin a gzip stream (RFC 1952).
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// The file at `path` as a buffered stream of its text, gunzipped when it begins with
/// gzip's magic bytes (whatever its name).
pub(crate) fn open(path: &Path) -> Result<Box<dyn BufRead + Send>, InputError> {
    let io = |e: std::io::Error| cannot_read(path, &e);
    let mut file = BufReader::with_capacity(1 << 20, File::open(path).map_err(io)?);
    let gzipped = file.fill_buf().map_err(io)?.starts_with(&GZIP_MAGIC);
    Ok(if gzipped {
        let gz = flate2::bufread::MultiGzDecoder::new(file);
        Box::new(BufReader::with_capacity(1 << 20, gz))
    } else {
        Box::new(file)
    })
}

/// Everything `r` holds, for tests.
#[cfg(test)]
pub(crate) fn read_all(mut r: impl std::io::Read) -> String {
    let mut s = String::new();
    r.read_to_string(&mut s).expect("read");
    s
}

/// The content (columns 1–60) and the label (columns 61–80, trimmed) of a header line.
pub(crate) fn header_label(line: &str) -> (&str, &str) {
    match line.char_indices().nth(60) {
        Some((i, _)) => (&line[..i], line[i..].trim()),
        None => (line, ""),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_label_is_what_follows_column_60() {
        let line = format!(
            "{:<60}{}",
            "     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE"
        );
        let (content, label) = header_label(&line);
        assert_eq!(label, "RINEX VERSION / TYPE");
        assert_eq!(content.len(), 60);
        assert_eq!(header_label("short"), ("short", ""));
    }

    #[test]
    fn gzip_is_told_by_its_magic_bytes() {
        use std::io::Write;
        let text = "     3.04           OBSERVATION DATA    M\n";
        let plain = crate::formats::temp_file(text);
        assert_eq!(read_all(open(plain.path()).unwrap()), text);
        let gz = tempfile::NamedTempFile::new().unwrap();
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(text.as_bytes()).unwrap();
        std::fs::write(gz.path(), enc.finish().unwrap()).unwrap();
        assert_eq!(read_all(open(gz.path()).unwrap()), text);
        let missing = open(Path::new("/no/such/file.rnx")).err().unwrap();
        assert_eq!(missing.kind, crate::formats::error::InputErrorKind::Io);
    }
}
