//! ROS 2 bags (MCAP) in and out, kept apart from the command line so that another
//! front end (the Python package) can use them as they are: [`container`] reads the
//! MCAP records front to back, [`clock`] turns UNIX stamps into GPS time, [`cdr`] and [`messages`] decode and encode the few
//! message types, [`info`] summarises a bag, [`input`] turns its topics into the
//! session's samples and aids (FLU/ENU to FRD/NED at this edge, REP 103/105), and
//! [`output`] writes a trajectory Foxglove can show.

pub mod cdr;
pub mod clock;
pub mod container;
pub mod info;
pub mod input;
pub mod messages;
pub mod output;
pub mod ros1;
pub mod ros1_msg;
pub mod tf;
pub mod wire;

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong in a bag: the file, then the topic, the message's 1-based index
/// within its topic and the field when one is to blame.
///
/// Displays as `run.mcap: topic /imu, message 12: field angular_velocity.x: NaN is
/// not a finite number`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct BagError {
    /// The `.mcap` file (or `metadata.yaml`).
    pub file: PathBuf,
    /// The topic, when the error is one topic's.
    pub topic: Option<String>,
    /// 1-based index of the message within its topic (0: the topic as a whole).
    pub index: u64,
    /// The field at fault.
    pub field: Option<String>,
    /// What went wrong.
    pub reason: String,
}

impl BagError {
    /// An error of the file as a whole (or of its container).
    pub fn file(file: &Path, reason: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            topic: None,
            index: 0,
            field: None,
            reason: reason.into(),
        }
    }

    /// An error of topic `topic`, message `index` (0: the topic), field `field`.
    pub fn topic(
        file: &Path,
        topic: &str,
        index: u64,
        field: Option<&str>,
        reason: impl Into<String>,
    ) -> Self {
        Self {
            file: file.to_path_buf(),
            topic: Some(topic.to_owned()),
            index,
            field: field.map(str::to_owned),
            reason: reason.into(),
        }
    }

    /// A decoding error of message `index` of `topic`.
    pub fn decode(file: &Path, topic: &str, index: u64, e: cdr::CdrError) -> Self {
        Self::topic(file, topic, index, Some(&e.field), e.reason)
    }
}

impl fmt::Display for BagError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(topic) = &self.topic {
            write!(f, ": topic {topic}")?;
            if self.index > 0 {
                write!(f, ", message {}", self.index)?;
            }
        }
        if let Some(field) = &self.field {
            write!(f, ": field {field}")?;
        }
        write!(f, ": {}", self.reason)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_topic_message_and_field() {
        let e = BagError::topic(
            Path::new("run.mcap"),
            "/imu",
            12,
            Some("angular_velocity.x"),
            "NaN is not a finite number",
        );
        assert_eq!(
            e.to_string(),
            "run.mcap: topic /imu, message 12: field angular_velocity.x: NaN is not a finite number"
        );
        assert_eq!(
            BagError::file(Path::new("run.mcap"), "Bad magic number").to_string(),
            "run.mcap: Bad magic number"
        );
    }
}
