//! The container of a bag, read front to back in constant memory, told by its
//! content: a ROS 1 bag (`#ROSBAG V2.0`, [`super::ros1`]), else MCAP: a single
//! `.mcap` file, or a rosbag2 directory (its `metadata.yaml` names the `.mcap` files in
//! order). The `mcap` crate's streaming reader checks every chunk's CRC and
//! decompresses zstd and lz4 chunks; here each message is paired with its channel
//! (topic, type, encodings) and numbered within its topic, so that errors can name
//! the topic and the message.

use super::BagError;
use mcap::records::{MessageHeader, Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A channel of the bag: its topic and what its messages are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topic {
    /// Topic name (`/imu/data`).
    pub name: String,
    /// Message type (`sensor_msgs/msg/Imu`); empty without a schema.
    pub type_name: String,
    /// Schema encoding (`ros2msg`, `ros2idl`).
    pub schema_encoding: String,
    /// Message encoding (`cdr`; `ros1` for a ROS 1 bag).
    pub message_encoding: String,
    /// The MD5 sum of the message definition (ROS 1 bags; empty for MCAP).
    pub md5sum: String,
}

impl Topic {
    /// The serialization of its messages, when schuler reads it: ROS 2 CDR with a
    /// ROS 2 definition, or ROS 1's; `None` for another.
    pub fn encoding(&self) -> Option<super::wire::Encoding> {
        use super::wire::Encoding;
        match (
            self.message_encoding.as_str(),
            self.schema_encoding.as_str(),
        ) {
            ("cdr", "ros2msg" | "ros2idl") => Some(Encoding::Cdr),
            ("ros1", "ros1msg") => Some(Encoding::Ros1),
            _ => None,
        }
    }
}

/// One message as it comes: its topic, its 1-based index within the topic, its log
/// time [ns] and its payload.
pub struct Message<'a> {
    /// The channel.
    pub topic: &'a Topic,
    /// The topic's place among the bag's topics, in order of their channel records
    /// (the same across the files of a rosbag2 directory).
    pub topic_index: usize,
    /// 1-based index of the message within its topic, in file order.
    pub index: u64,
    /// MCAP log time [ns].
    pub log_time: u64,
    /// The payload (CDR for ROS 2).
    pub data: &'a [u8],
}

/// The `.mcap` files of `path`: itself, or those a rosbag2 directory's
/// `metadata.yaml` lists (else every `.mcap` file in it, by name).
pub fn files_of(path: &Path) -> Result<Vec<PathBuf>, BagError> {
    if !path.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let meta = path.join("metadata.yaml");
    let listed = match std::fs::read_to_string(&meta) {
        Ok(text) => rosbag2_files(&meta, &text)?,
        Err(_) => Vec::new(),
    };
    let mut files: Vec<PathBuf> = if listed.is_empty() {
        let entries = std::fs::read_dir(path).map_err(|e| BagError::file(path, e.to_string()))?;
        let mut v: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
            .collect();
        v.sort();
        v
    } else {
        listed.iter().map(|f| path.join(f)).collect()
    };
    files.dedup();
    if files.is_empty() {
        return Err(BagError::file(
            path,
            "a directory without metadata.yaml listing .mcap files, nor any .mcap file",
        ));
    }
    Ok(files)
}

/// The `relative_file_paths` of a rosbag2 `metadata.yaml`; a storage other than
/// MCAP (`sqlite3`) is refused with the conversion command.
fn rosbag2_files(meta: &Path, text: &str) -> Result<Vec<String>, BagError> {
    #[derive(serde::Deserialize)]
    struct Info {
        #[serde(default)]
        storage_identifier: String,
        #[serde(default)]
        relative_file_paths: Vec<String>,
    }
    #[derive(serde::Deserialize)]
    struct Meta {
        rosbag2_bagfile_information: Info,
    }
    let m: Meta = serde_saphyr::from_str(text).map_err(|e| BagError::file(meta, e.to_string()))?;
    let info = m.rosbag2_bagfile_information;
    if !info.storage_identifier.is_empty() && info.storage_identifier != "mcap" {
        return Err(BagError::file(
            meta,
            format!(
                "storage {:?}: only MCAP bags are read (convert with `ros2 bag convert` \
                 to storage_id mcap)",
                info.storage_identifier
            ),
        ));
    }
    Ok(info.relative_file_paths)
}

/// The schemas, channels and topics seen so far, and the last message read.
#[derive(Default)]
struct Catalog {
    schemas: HashMap<u16, (String, String)>,
    /// This file's channel ids to places in `topics`.
    channels: HashMap<u16, usize>,
    /// Every topic seen, with its message count so far.
    topics: Vec<(Arc<Topic>, u64)>,
    /// The last message read: its topic's place and index, for errors between
    /// messages.
    last: Option<(usize, u64)>,
}

impl Catalog {
    /// An error in the container of `file` (placed after the last message read).
    fn container_error(&self, file: &Path, reason: impl std::fmt::Display) -> BagError {
        let after = match self.last {
            Some((place, index)) => {
                format!(
                    "after message {index} of topic {}",
                    self.topics[place].0.name
                )
            }
            None => "before the first message".to_owned(),
        };
        BagError::file(file, format!("{after}: {reason}"))
    }

    /// Takes in record `opcode` of `file`: schemas and channels are remembered, a
    /// message is counted and handed to `f`; `Ok(None)` for any other record.
    fn record<R>(
        &mut self,
        file: &Path,
        opcode: u8,
        data: &[u8],
        f: &mut impl FnMut(Message) -> Result<R, BagError>,
    ) -> Result<Option<R>, BagError> {
        if !matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
            return Ok(None);
        }
        let record = mcap::parse_record(opcode, data).map_err(|e| self.container_error(file, e))?;
        match record {
            Record::Schema { header, .. } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(c) => {
                let topic = channel_topic(&self.schemas, &c)
                    .map_err(|reason| BagError::topic(file, &c.topic, 0, None, reason))?;
                let place = match self.topics.iter().position(|(t, _)| **t == topic) {
                    Some(place) => place,
                    None => {
                        self.topics.push((Arc::new(topic), 0));
                        self.topics.len() - 1
                    }
                };
                self.channels.insert(c.id, place);
            }
            Record::Message { header, data } => {
                let MessageHeader {
                    channel_id,
                    log_time,
                    ..
                } = header;
                let Some(&place) = self.channels.get(&channel_id) else {
                    return Err(self.container_error(
                        file,
                        format!(
                            "a message on channel {channel_id}, which no channel record defines"
                        ),
                    ));
                };
                let (topic, count) = &mut self.topics[place];
                *count += 1;
                self.last = Some((place, *count));
                return f(Message {
                    topic,
                    topic_index: place,
                    index: *count,
                    log_time,
                    data: &data,
                })
                .map(Some);
            }
            _ => {}
        }
        Ok(None)
    }
}

/// One open `.mcap` file and its streaming reader.
struct OpenFile {
    path: PathBuf,
    file: File,
    reader: LinearReader,
}

/// Reads every message of an MCAP bag in file order.
pub struct McapStream {
    files: Vec<PathBuf>,
    next_file: usize,
    open: Option<OpenFile>,
    catalog: Catalog,
    bytes: u64,
}

impl McapStream {
    /// Opens the bag at `path` (a `.mcap` file or a rosbag2 directory).
    pub fn open(path: &Path) -> Result<Self, BagError> {
        Ok(Self {
            files: files_of(path)?,
            next_file: 0,
            open: None,
            catalog: Catalog::default(),
            bytes: 0,
        })
    }

    /// Bytes read from the files so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes
    }

    /// Total size of the bag's files [bytes].
    pub fn total_bytes(&self) -> u64 {
        self.files
            .iter()
            .filter_map(|f| std::fs::metadata(f).ok())
            .map(|m| m.len())
            .sum()
    }

    /// Opens the next file; `false` when none is left.
    fn open_next(&mut self) -> Result<bool, BagError> {
        let Some(path) = self.files.get(self.next_file).cloned() else {
            return Ok(false);
        };
        self.next_file += 1;
        let file =
            File::open(&path).map_err(|e| BagError::file(&path, format!("cannot open: {e}")))?;
        // Every chunk's CRC is checked before any of its messages is used.
        let options = LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(1 << 30);
        // Channel and schema ids are per file.
        self.catalog.schemas.clear();
        self.catalog.channels.clear();
        self.open = Some(OpenFile {
            path,
            file,
            reader: LinearReader::new_with_options(options),
        });
        Ok(true)
    }

    /// The next message, handed to `f`; `Ok(None)` at the end of the bag. After an
    /// error the stream ends.
    pub fn next_with<R>(
        &mut self,
        mut f: impl FnMut(Message) -> Result<R, BagError>,
    ) -> Result<Option<R>, BagError> {
        loop {
            if self.open.is_none() && !self.open_next()? {
                return Ok(None);
            }
            let Some(OpenFile { path, file, reader }) = self.open.as_mut() else {
                continue;
            };
            let result = match reader.next_event() {
                None => Ok(None),
                Some(Err(e)) => Err(self.catalog.container_error(path, e)),
                Some(Ok(LinearReadEvent::ReadRequest(n))) => match file.read(reader.insert(n)) {
                    Ok(k) => {
                        reader.notify_read(k);
                        self.bytes += k as u64;
                        continue;
                    }
                    Err(e) => Err(self.catalog.container_error(path, e)),
                },
                Some(Ok(LinearReadEvent::Record { opcode, data })) => {
                    match self.catalog.record(path, opcode, data, &mut f) {
                        Ok(None) => continue,
                        other => other,
                    }
                }
            };
            match result {
                Ok(Some(r)) => return Ok(Some(r)),
                Ok(None) => self.open = None,
                Err(e) => {
                    self.open = None;
                    self.next_file = self.files.len();
                    return Err(e);
                }
            }
        }
    }
}

/// The topic of channel `c` with its schema's name and encoding (a channel without
/// schema, id 0, has an empty type); a schema id the file never defined is an error.
fn channel_topic(
    schemas: &HashMap<u16, (String, String)>,
    c: &mcap::records::Channel,
) -> Result<Topic, String> {
    let (type_name, schema_encoding) = match c.schema_id {
        0 => (String::new(), String::new()),
        id => schemas.get(&id).cloned().ok_or_else(|| {
            format!("its channel names schema {id}, which the file does not define")
        })?,
    };
    Ok(Topic {
        name: c.topic.clone(),
        type_name,
        schema_encoding,
        message_encoding: c.message_encoding.clone(),
        md5sum: String::new(),
    })
}

/// Reads every message of a bag, ROS 1 or MCAP, in file order. Both streams are
/// boxed (one allocation per bag opened), so that the enum is a pointer's size
/// whichever it holds.
pub enum BagStream {
    /// A ROS 1 bag (format 2.0).
    Ros1(Box<super::ros1::Ros1Stream>),
    /// An MCAP file or rosbag2 directory.
    Mcap(Box<McapStream>),
}

/// Whether the file at `path` opens with `#ROSBAG` (a ROS 1 bag of any version).
fn is_ros1(path: &Path) -> Result<bool, BagError> {
    if path.is_dir() {
        return Ok(false);
    }
    let mut head = [0u8; 8];
    let mut f = File::open(path).map_err(|e| BagError::file(path, format!("cannot open: {e}")))?;
    let n = f
        .read(&mut head)
        .map_err(|e| BagError::file(path, e.to_string()))?;
    Ok(&head[..n] == b"#ROSBAG ")
}

impl BagStream {
    /// Opens the bag at `path`: a ROS 1 bag (told by its first line), else MCAP (a
    /// `.mcap` file or a rosbag2 directory).
    pub fn open(path: &Path) -> Result<Self, BagError> {
        if is_ros1(path)? {
            super::ros1::Ros1Stream::open(path).map(|s| BagStream::Ros1(Box::new(s)))
        } else {
            McapStream::open(path).map(|s| BagStream::Mcap(Box::new(s)))
        }
    }

    /// Bytes read from the files so far.
    pub fn bytes_read(&self) -> u64 {
        match self {
            BagStream::Ros1(s) => s.bytes_read(),
            BagStream::Mcap(s) => s.bytes_read(),
        }
    }

    /// Total size of the bag's files [bytes].
    pub fn total_bytes(&self) -> u64 {
        match self {
            BagStream::Ros1(s) => s.total_bytes(),
            BagStream::Mcap(s) => s.total_bytes(),
        }
    }

    /// The next message, handed to `f`; `Ok(None)` at the end of the bag. After an
    /// error the stream ends.
    pub fn next_with<R>(
        &mut self,
        f: impl FnMut(Message) -> Result<R, BagError>,
    ) -> Result<Option<R>, BagError> {
        match self {
            BagStream::Ros1(s) => s.next_with(f),
            BagStream::Mcap(s) => s.next_with(f),
        }
    }
}
