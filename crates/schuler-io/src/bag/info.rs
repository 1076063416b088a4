//! What a bag holds: each topic's type, encodings, message count, log-time span and
//! mean rate (what `schuler bag info` prints), gathered in one pass that can also
//! hand every message to a caller.

use super::BagError;
use super::container::{BagStream, Message, Topic};
use std::fmt::Write as _;
use std::path::Path;

/// One topic of a bag.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicSummary {
    /// The channel.
    pub topic: Topic,
    /// Messages.
    pub count: u64,
    /// First and last log time [ns].
    pub log_span_ns: (u64, u64),
}

impl TopicSummary {
    /// Mean rate over the span [Hz] (`(count − 1) / span`; 0 for one message).
    pub fn rate_hz(&self) -> f64 {
        let span = (self.log_span_ns.1 - self.log_span_ns.0) as f64 * 1e-9;
        if self.count < 2 || span <= 0.0 {
            0.0
        } else {
            (self.count - 1) as f64 / span
        }
    }
}

/// Reads the whole bag at `path`, handing each message to `visit`; returns the
/// topics in order of their first message.
pub fn scan(
    path: &Path,
    mut visit: impl FnMut(&Message) -> Result<(), BagError>,
) -> Result<Vec<TopicSummary>, BagError> {
    let mut stream = BagStream::open(path)?;
    let mut order: Vec<usize> = Vec::new();
    // By the stream's topic places; a topic whose channel has no message stays None.
    let mut places: Vec<Option<TopicSummary>> = Vec::new();
    while let Some(()) = stream.next_with(|m| {
        if places.len() <= m.topic_index {
            places.resize(m.topic_index + 1, None);
        }
        match &mut places[m.topic_index] {
            Some(s) => {
                s.count += 1;
                s.log_span_ns.0 = s.log_span_ns.0.min(m.log_time);
                s.log_span_ns.1 = s.log_span_ns.1.max(m.log_time);
            }
            empty => {
                *empty = Some(TopicSummary {
                    topic: m.topic.clone(),
                    count: 1,
                    log_span_ns: (m.log_time, m.log_time),
                });
                order.push(m.topic_index);
            }
        }
        visit(&m)
    })? {}
    Ok(order.into_iter().filter_map(|p| places[p].take()).collect())
}

/// The table `schuler bag info` prints: one line per topic.
pub fn table(path: &Path, topics: &[TopicSummary]) -> String {
    let mut s = format!("{}: {} topics\n", path.display(), topics.len());
    let _ = writeln!(
        s,
        "{:<32} {:<44} {:>9} {:>10} {:>20} {:>20} {:>10}",
        "topic",
        "type",
        "messages",
        "rate [Hz]",
        "first log time [s]",
        "last log time [s]",
        "span [s]"
    );
    for t in topics {
        let (a, b) = t.log_span_ns;
        let _ = writeln!(
            s,
            "{:<32} {:<44} {:>9} {:>10.3} {:>20.9} {:>20.9} {:>10.3}",
            t.topic.name,
            if t.topic.type_name.is_empty() {
                "(no schema)"
            } else {
                &t.topic.type_name
            },
            t.count,
            t.rate_hz(),
            a as f64 * 1e-9,
            b as f64 * 1e-9,
            (b - a) as f64 * 1e-9
        );
    }
    s
}
