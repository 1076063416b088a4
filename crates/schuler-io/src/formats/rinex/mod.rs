//! RINEX, the receiver-independent exchange format of GNSS observations (`obs`) and
//! broadcast navigation messages (`nav`): versions 2.11, 3.0x and 4.0x.
//!
//! Header lines carry their label in columns 61–80 and their content in columns 1–60;
//! records are fixed-width. Both readers stream: they hold one epoch (or one
//! ephemeris) at a time, and name the file, the line and the field of what they refuse.

pub mod nav;
pub mod obs;

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
}
