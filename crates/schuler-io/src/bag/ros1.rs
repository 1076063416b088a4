//! ROS 1 bags, format 2.0 (ROS wiki, "Bags/Format/2.0"), read front to back one
//! chunk at a time (constant memory: the largest chunk, 768 KiB by rosbag's default).
//!
//! The file is the magic line `#ROSBAG V2.0\n`, then records: `uint32 header_len`,
//! the header (fields `uint32 len` + `name=value`, `op` among them), `uint32
//! data_len`, the data. The bag header record (op 3) comes first and gives the
//! index's position; chunk records (op 5, compression `none`, `bz2` or `lz4`, its
//! uncompressed `size`) hold connection records (op 7: `conn`, `topic`, the data a
//! connection header with `type`, `md5sum`, `message_definition`) and message data
//! records (op 2: `conn`, `time` as `uint32 secs, uint32 nsecs`, the data the
//! serialized message, [`super::ros1_msg`]); each chunk is followed by its index data
//! records (op 4), and the index section at the end repeats the connections and lists
//! the chunks (op 6). Messages are read from the chunks in file order; the index is
//! not needed (a bag whose recording was cut short, `index_pos` 0, reads up to its
//! last whole chunk).
//!
//! Errors name the byte offset and the record: `run.bag: byte 4117 (chunk record):
//! field compression: "zstd" is not none, bz2 or lz4`; within a chunk, the chunk's
//! offset and the record's offset in the decompressed chunk.

use super::BagError;
use super::container::{Message, Topic};
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The first line of a ROS 1 bag of format 2.0.
pub const MAGIC: &[u8; 13] = b"#ROSBAG V2.0\n";

/// The largest record header or chunk accepted [bytes] (rosbag's chunks are 768 KiB
/// by default; a larger length is a garbled file, refused before allocating).
const LIMIT: u64 = 1 << 30;

const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_INDEX: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// The name of a record kind, for errors.
fn record_name(op: u8) -> &'static str {
    match op {
        OP_MESSAGE => "message data record",
        OP_BAG_HEADER => "bag header record",
        OP_INDEX => "index data record",
        OP_CHUNK => "chunk record",
        OP_CHUNK_INFO => "chunk info record",
        OP_CONNECTION => "connection record",
        _ => "record",
    }
}

/// The value of field `name` in a record header (or a connection header): the
/// fields are `uint32 len`, then `len` bytes `name=value`.
fn field<'a>(header: &'a [u8], name: &str) -> Result<Option<&'a [u8]>, String> {
    let mut rest = header;
    while !rest.is_empty() {
        let Some((len, tail)) = rest.split_first_chunk::<4>() else {
            return Err(format!(
                "header ends inside a field's length ({} bytes left)",
                rest.len()
            ));
        };
        let len = u32::from_le_bytes(*len) as usize;
        let Some(f) = tail.get(..len) else {
            return Err(format!(
                "a field of {len} bytes runs past the header's end ({} bytes left)",
                tail.len()
            ));
        };
        let Some(eq) = f.iter().position(|&b| b == b'=') else {
            return Err(format!(
                "field {:?} has no '='",
                String::from_utf8_lossy(&f[..f.len().min(40)])
            ));
        };
        if &f[..eq] == name.as_bytes() {
            return Ok(Some(&f[eq + 1..]));
        }
        rest = &tail[len..];
    }
    Ok(None)
}

/// Field `name` of `header`, which must be there.
fn required<'a>(header: &'a [u8], name: &str) -> Result<&'a [u8], (String, String)> {
    match field(header, name) {
        Ok(Some(v)) => Ok(v),
        Ok(None) => Err((name.to_owned(), "missing".to_owned())),
        Err(e) => Err(("header".to_owned(), e)),
    }
}

/// Field `name` as a little-endian integer of `N` bytes.
fn int<const N: usize>(header: &[u8], name: &str) -> Result<[u8; N], (String, String)> {
    let v = required(header, name)?;
    v.try_into()
        .map_err(|_| (name.to_owned(), format!("{} bytes, {N} expected", v.len())))
}

/// Field `name` as UTF-8 text.
fn text(header: &[u8], name: &str) -> Result<String, (String, String)> {
    let v = required(header, name)?;
    String::from_utf8(v.to_vec()).map_err(|_| (name.to_owned(), "not UTF-8".to_owned()))
}

/// The record's `op`.
fn op_of(header: &[u8]) -> Result<u8, (String, String)> {
    int::<1>(header, "op").map(|[op]| op)
}

/// A connection (op 7): its id and topic from the record header and its type and
/// md5sum from the connection header in its data.
fn connection(header: &[u8], data: &[u8]) -> Result<(u32, Topic), (String, String)> {
    let conn = u32::from_le_bytes(int::<4>(header, "conn")?);
    let name = text(header, "topic")?;
    let ctx = |(f, e): (String, String)| (format!("connection header {f}"), e);
    let type_name = text(data, "type").map_err(ctx)?;
    let md5sum = text(data, "md5sum").map_err(ctx)?;
    Ok((
        conn,
        Topic {
            name,
            type_name,
            schema_encoding: "ros1msg".to_owned(),
            message_encoding: "ros1".to_owned(),
            md5sum,
        },
    ))
}

/// A record in the decompressed chunk: where it is, the ranges of its header and of
/// its data in the chunk's bytes.
type ChunkRecord = (Place, Range<usize>, Range<usize>);

/// Where a record is: in the file, or in a chunk.
#[derive(Debug, Clone, Copy)]
enum Place {
    File(u64),
    Chunk { chunk: u64, offset: usize },
}

/// Reads every message of a ROS 1 bag in file order.
pub struct Ros1Stream {
    path: PathBuf,
    file: BufReader<File>,
    size: u64,
    pos: u64,
    /// Every topic seen, with its message count so far.
    topics: Vec<(Arc<Topic>, u64)>,
    /// Connection ids to places in `topics`.
    conns: HashMap<u32, usize>,
    /// The current chunk's records (decompressed), the next one's offset and the
    /// chunk's file offset.
    chunk: Vec<u8>,
    chunk_at: usize,
    chunk_pos: u64,
    /// The compressed data of the current chunk (kept to reuse its allocation).
    packed: Vec<u8>,
    /// The last message read (topic place, index), for errors between messages.
    last: Option<(usize, u64)>,
    done: bool,
}

impl Ros1Stream {
    /// Opens the bag at `path`: its magic line and bag header record.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let f = File::open(path).map_err(|e| BagError::file(path, format!("cannot open: {e}")))?;
        let size = f
            .metadata()
            .map_err(|e| BagError::file(path, e.to_string()))?
            .len();
        let mut s = Self {
            path: path.to_path_buf(),
            file: BufReader::with_capacity(1 << 16, f),
            size,
            pos: 0,
            topics: Vec::new(),
            conns: HashMap::new(),
            chunk: Vec::new(),
            chunk_at: 0,
            chunk_pos: 0,
            packed: Vec::new(),
            last: None,
            done: false,
        };
        let mut magic = [0u8; 13];
        s.read_exact(&mut magic, "magic line")?;
        if &magic != MAGIC {
            return Err(BagError::file(
                path,
                format!(
                    "byte 0: magic {:?} is not {:?} (only ROS 1 bags of format 2.0 are read)",
                    String::from_utf8_lossy(&magic),
                    String::from_utf8_lossy(MAGIC)
                ),
            ));
        }
        let at = s.pos;
        let header = s.read_header()?;
        let op = op_of(&header).map_err(|e| s.error(Place::File(at), 0, e))?;
        if op != OP_BAG_HEADER {
            let e = (
                "op".to_owned(),
                format!("{op}: the bag header record (op 3) must come first"),
            );
            return Err(s.error(Place::File(at), op, e));
        }
        let n = s.read_len(Place::File(at), OP_BAG_HEADER, "data_len")?;
        s.skip(n, Place::File(at), OP_BAG_HEADER)?;
        Ok(s)
    }

    /// Bytes read so far.
    pub fn bytes_read(&self) -> u64 {
        self.pos
    }

    /// The file's size [bytes].
    pub fn total_bytes(&self) -> u64 {
        self.size
    }

    /// An error at `place` in record `op`: `(field, reason)`.
    fn error(&self, place: Place, op: u8, (f, reason): (String, String)) -> BagError {
        let at = match place {
            Place::File(p) => format!("byte {p}"),
            Place::Chunk { chunk, offset } => {
                format!("chunk at byte {chunk}, byte {offset} of its records")
            }
        };
        let after = match self.last {
            Some((place, index)) => {
                format!(
                    ", after message {index} of topic {}",
                    self.topics[place].0.name
                )
            }
            None => String::new(),
        };
        BagError::file(
            &self.path,
            format!("{at} ({}{after}): field {f}: {reason}", record_name(op)),
        )
    }

    /// Fills `buf` from the file; the file ending first is an error naming `what`.
    fn read_exact(&mut self, buf: &mut [u8], what: &str) -> Result<(), BagError> {
        if let Err(e) = self.file.read_exact(buf) {
            let reason = if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format!(
                    "byte {}: the file ends (at byte {}) inside the {what} ({} bytes needed): truncated",
                    self.pos,
                    self.size,
                    buf.len()
                )
            } else {
                format!("byte {}: {e}", self.pos)
            };
            return Err(BagError::file(&self.path, reason));
        }
        self.pos += buf.len() as u64;
        Ok(())
    }

    /// A record's `uint32` length field `what`, checked against [`LIMIT`].
    fn read_len(&mut self, at: Place, op: u8, what: &str) -> Result<u64, BagError> {
        let mut b = [0u8; 4];
        self.read_exact(&mut b, &format!("{} {what}", record_name(op)))?;
        let n = u64::from(u32::from_le_bytes(b));
        if n > LIMIT {
            return Err(self.error(
                at,
                op,
                (what.to_owned(), format!("{n} bytes is over 1 GiB")),
            ));
        }
        Ok(n)
    }

    /// A record header at the current position.
    fn read_header(&mut self) -> Result<Vec<u8>, BagError> {
        let at = Place::File(self.pos);
        let n = self.read_len(at, 0, "header_len")?;
        let mut header = vec![0u8; n as usize];
        self.read_exact(&mut header, "record header")?;
        Ok(header)
    }

    /// Skips `n` bytes of a record's data.
    fn skip(&mut self, n: u64, at: Place, op: u8) -> Result<(), BagError> {
        if self.pos + n > self.size {
            let e = (
                "data".to_owned(),
                format!(
                    "{n} bytes of data run past the file's end at byte {}: truncated",
                    self.size
                ),
            );
            return Err(self.error(at, op, e));
        }
        self.file
            .seek_relative(n as i64)
            .map_err(|e| BagError::file(&self.path, format!("byte {}: {e}", self.pos)))?;
        self.pos += n;
        Ok(())
    }

    /// Registers a connection (a repeated id keeps its first topic).
    fn add_connection(&mut self, conn: u32, topic: Topic) {
        if self.conns.contains_key(&conn) {
            return;
        }
        let place = match self.topics.iter().position(|(t, _)| **t == topic) {
            Some(p) => p,
            None => {
                self.topics.push((Arc::new(topic), 0));
                self.topics.len() - 1
            }
        };
        self.conns.insert(conn, place);
    }

    /// Reads the next top-level record: a chunk is loaded, a connection registered,
    /// others skipped; `false` at the end of the file.
    fn next_record(&mut self) -> Result<bool, BagError> {
        if self.pos == self.size {
            return Ok(false);
        }
        let at = Place::File(self.pos);
        let header = self.read_header()?;
        let op = op_of(&header).map_err(|e| self.error(at, 0, e))?;
        let n = self.read_len(at, op, "data_len")?;
        match op {
            OP_CHUNK => self.load_chunk(at, &header, n)?,
            OP_CONNECTION | OP_MESSAGE => {
                let mut data = vec![0u8; n as usize];
                self.read_exact(&mut data, "connection record's data")?;
                if op == OP_CONNECTION {
                    let (conn, topic) =
                        connection(&header, &data).map_err(|e| self.error(at, op, e))?;
                    self.add_connection(conn, topic);
                } else {
                    // A message outside any chunk: read as a chunk of one record.
                    self.chunk.clear();
                    for part in [&header[..], &data[..]] {
                        self.chunk
                            .extend_from_slice(&(part.len() as u32).to_le_bytes());
                        self.chunk.extend_from_slice(part);
                    }
                    self.chunk_at = 0;
                    self.chunk_pos = match at {
                        Place::File(p) => p,
                        Place::Chunk { chunk, .. } => chunk,
                    };
                }
            }
            OP_INDEX | OP_CHUNK_INFO | OP_BAG_HEADER => self.skip(n, at, op)?,
            _ => {
                let e = ("op".to_owned(), format!("{op} is no record of format 2.0"));
                return Err(self.error(at, op, e));
            }
        }
        Ok(true)
    }

    /// Reads chunk record data of `n` bytes and decompresses it into `self.chunk`.
    fn load_chunk(&mut self, at: Place, header: &[u8], n: u64) -> Result<(), BagError> {
        let bad = |s: &Self, e: (String, String)| s.error(at, OP_CHUNK, e);
        let compression = text(header, "compression").map_err(|e| bad(self, e))?;
        let size = u64::from(u32::from_le_bytes(
            int::<4>(header, "size").map_err(|e| bad(self, e))?,
        ));
        let mut packed = std::mem::take(&mut self.packed);
        packed.resize(n as usize, 0);
        self.read_exact(&mut packed, "chunk record's data")?;
        let mut chunk = std::mem::take(&mut self.chunk);
        chunk.clear();
        let result = match compression.as_str() {
            "none" => {
                chunk.extend_from_slice(&packed);
                Ok(())
            }
            "bz2" => bzip2::read::BzDecoder::new(&packed[..])
                .take(size + 1)
                .read_to_end(&mut chunk)
                .map(|_| ()),
            "lz4" => lz4::Decoder::new(&packed[..])
                .and_then(|d| d.take(size + 1).read_to_end(&mut chunk))
                .map(|_| ()),
            other => {
                self.packed = packed;
                let e = (
                    "compression".to_owned(),
                    format!("{other:?} is not none, bz2 or lz4"),
                );
                return Err(bad(self, e));
            }
        };
        self.packed = packed;
        if let Err(e) = result {
            let e = ("data".to_owned(), format!("{compression} stream: {e}"));
            return Err(bad(self, e));
        }
        if chunk.len() as u64 != size {
            let e = (
                "size".to_owned(),
                format!(
                    "{size} bytes, but the {compression} data hold {}{}",
                    chunk.len().min(size as usize + 1),
                    if chunk.len() as u64 > size {
                        " or more"
                    } else {
                        ""
                    }
                ),
            );
            return Err(bad(self, e));
        }
        self.chunk = chunk;
        self.chunk_at = 0;
        self.chunk_pos = match at {
            Place::File(p) => p,
            Place::Chunk { chunk, .. } => chunk,
        };
        Ok(())
    }

    /// The next record of the current chunk: its place and the ranges of its header
    /// and data in `self.chunk`; `None` at the chunk's end.
    fn chunk_record(&self) -> Result<Option<ChunkRecord>, BagError> {
        let (buf, at) = (&self.chunk[..], self.chunk_at);
        if at >= buf.len() {
            return Ok(None);
        }
        let place = Place::Chunk {
            chunk: self.chunk_pos,
            offset: at,
        };
        let part = |from: usize, what: &str| -> Result<Range<usize>, BagError> {
            let len = buf
                .get(from..from + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
            match len.and_then(|l| (from + 4).checked_add(l)) {
                Some(end) if end <= buf.len() => Ok(from + 4..end),
                _ => Err(self.error(
                    place,
                    0,
                    (
                        what.to_owned(),
                        format!("runs past the chunk's {} bytes: truncated", buf.len()),
                    ),
                )),
            }
        };
        let header = part(at, "header_len")?;
        let data = part(header.end, "data_len")?;
        Ok(Some((place, header, data)))
    }

    /// The next message, handed to `f`; `Ok(None)` at the end of the bag. After an
    /// error the stream ends.
    pub fn next_with<R>(
        &mut self,
        mut f: impl FnMut(Message) -> Result<R, BagError>,
    ) -> Result<Option<R>, BagError> {
        while !self.done {
            let result = self.step(&mut f);
            match result {
                Ok(Some(Some(r))) => return Ok(Some(r)),
                Ok(Some(None)) => {}
                Ok(None) => self.done = true,
                Err(e) => {
                    self.done = true;
                    return Err(e);
                }
            }
        }
        Ok(None)
    }

    /// One record: `Some(Some(r))` a message handed to `f`, `Some(None)` another
    /// record, `None` the end.
    fn step<R>(
        &mut self,
        f: &mut impl FnMut(Message) -> Result<R, BagError>,
    ) -> Result<Option<Option<R>>, BagError> {
        let Some((place, h, d)) = self.chunk_record()? else {
            self.chunk.clear();
            self.chunk_at = 0;
            return Ok(self.next_record()?.then_some(None));
        };
        self.chunk_at = d.end;
        let header = &self.chunk[h];
        let op = op_of(header).map_err(|e| self.error(place, 0, e))?;
        match op {
            OP_CONNECTION => {
                let (conn, topic) =
                    connection(header, &self.chunk[d]).map_err(|e| self.error(place, op, e))?;
                self.add_connection(conn, topic);
                Ok(Some(None))
            }
            OP_MESSAGE => {
                let bad = |e| self.error(place, op, e);
                let conn = u32::from_le_bytes(int::<4>(header, "conn").map_err(bad)?);
                let time = int::<8>(header, "time").map_err(bad)?;
                let secs = u64::from(u32::from_le_bytes([time[0], time[1], time[2], time[3]]));
                let nsecs = u64::from(u32::from_le_bytes([time[4], time[5], time[6], time[7]]));
                let Some(&p) = self.conns.get(&conn) else {
                    let e = (
                        "conn".to_owned(),
                        format!("{conn}, which no connection record before it defines"),
                    );
                    return Err(self.error(place, op, e));
                };
                let count = &mut self.topics[p].1;
                *count += 1;
                let index = *count;
                self.last = Some((p, index));
                f(Message {
                    topic: &self.topics[p].0,
                    topic_index: p,
                    index,
                    log_time: secs * 1_000_000_000 + nsecs,
                    data: &self.chunk[d],
                })
                .map(|r| Some(Some(r)))
            }
            _ => {
                let e = (
                    "op".to_owned(),
                    format!("{op}: only connection and message data records belong in a chunk"),
                );
                Err(self.error(place, op, e))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record header of `fields` (`name`, value bytes).
    pub(crate) fn header(fields: &[(&str, &[u8])]) -> Vec<u8> {
        let mut h = Vec::new();
        for (name, value) in fields {
            let len = (name.len() + 1 + value.len()) as u32;
            h.extend_from_slice(&len.to_le_bytes());
            h.extend_from_slice(name.as_bytes());
            h.push(b'=');
            h.extend_from_slice(value);
        }
        h
    }

    #[test]
    fn header_fields_are_found_and_garbled_ones_named() {
        let h = header(&[
            ("op", &[5]),
            ("compression", b"bz2"),
            ("size", &7u32.to_le_bytes()),
        ]);
        assert_eq!(field(&h, "compression"), Ok(Some(&b"bz2"[..])));
        assert_eq!(field(&h, "conn"), Ok(None));
        assert_eq!(op_of(&h), Ok(5));
        assert_eq!(int::<4>(&h, "size"), Ok(7u32.to_le_bytes()));
        let e = int::<8>(&h, "size").expect_err("4 bytes");
        assert_eq!(e, ("size".to_owned(), "4 bytes, 8 expected".to_owned()));
        let e = field(&h[..h.len() - 1], "size").expect_err("cut");
        assert!(e.contains("runs past"), "{e}");
        let e = field(&[3, 0, 0, 0, b'a', b'b', b'c'], "op").expect_err("no =");
        assert!(e.contains("no '='"), "{e}");
    }
}
