//! Hatanaka's compact RINEX (CRX 1.0 for RINEX 2 `.##d`, CRX 3.0 for RINEX 3 and 4
//! `.crx`) expanded back into RINEX observation text, one epoch at a time, as the
//! observation reader asks for lines.
//!
//! The format (Y. Hatanaka, "A Compression Format and Tools for GNSS Observation
//! Data", Bulletin of the Geospatial Information Authority of Japan 55, 2008), as
//! implemented here:
//! - Two header lines of its own (`CRINEX VERS   / TYPE`, `CRINEX PROG / DATE`), then
//!   the RINEX header unchanged.
//! - Per epoch, first the **epoch line**, text-differenced against the previous
//!   epoch's: a blank keeps the previous character, `&` makes it a blank, any other
//!   character replaces it. A line beginning with `&` (CRX 1; read as a blank) or `>`
//!   (CRX 3) is given whole and starts every arc afresh. CRX 1 writes the whole
//!   satellite list on the one line after column 32; CRX 3 after column 41, the
//!   columns RINEX 3 reserves before the clock offset.
//! - Then the **clock line**: empty without a clock offset, else an integer (units of
//!   the RINEX field's last digit, 1e-9 s in CRX 1, 1e-12 s in CRX 3) coded as the
//!   data below.
//! - Then one **data line** per satellite of the list: its system's observations, in
//!   the header's order, separated by one blank (an empty field: the observation is
//!   missing, its arc ends), then after one more blank the loss-of-lock and
//!   signal-strength characters of every observation, two each, text-differenced
//!   against the satellite's previous ones as the epoch line is. A field `n&v` starts
//!   an arc: `v` is the value (in units of 0.001) and later fields give its differences
//!   of order `n`, the order rising 0, 1, …, n over the arc's first epochs; a field
//!   `d` is the next difference, from which the value follows by summing up the
//!   differences of every lower order kept from the epoch before. A satellite absent
//!   from the previous epoch starts with every arc ended and blank flags.
//! - An event (epoch flag 2–5) is its epoch line, given whole, and its special records
//!   as they are; it changes neither the reference line nor the arcs.
//!
//! Memory is bounded by one epoch: the satellites of the previous epoch, their arcs
//! (at most [`MAX_ORDER`] + 1 integers per observation) and the epoch's RINEX text.

use super::header_label;
use super::obs::{MAX_SATS_PER_EPOCH, ObsHeader, Version};
use crate::formats::InputError;
use crate::formats::error::{InputErrorKind, quote_field};
use crate::formats::lines::LineReader;
use schuler::gnss::{Sat, System};
use std::io::Read;
use std::path::Path;

/// The highest difference order an arc may declare (`9&…`).
pub(crate) const MAX_ORDER: usize = 9;

/// Columns of the fixed start of an epoch line (CRX 1: ` yy mm dd hh mm ss.sssssss  f
/// nnn`; CRX 3: `> yyyy … f nnn` and six reserved blanks) before the satellite list.
const SAT_LIST_V1: usize = 32;
const SAT_LIST_V3: usize = 41;
/// RINEX 2 epoch lines: 12 satellites each, the clock offset from column 69.
const SATS_PER_LINE_V2: usize = 12;
const CLOCK_COL_V2: usize = 68;
/// RINEX 3 epoch lines: the part before the reserved columns and the clock offset.
const EPOCH_HEAD_V3: usize = 35;

/// The values of one arc: the last value and its differences up to the arc's order.
#[derive(Debug, Clone, Copy, Default)]
struct Arc {
    active: bool,
    /// The order the arc declared.
    order: u8,
    /// The order reached so far (rises by one per epoch up to `order`).
    reached: u8,
    /// `d[k]`: the latest difference of order k (`d[0]`: the value).
    d: [i64; MAX_ORDER + 1],
}

impl Arc {
    /// Decodes field `token` into the arc: the value, `None` for an empty field; an
    /// error message for what is no field.
    fn decode(&mut self, token: &[u8]) -> Result<Option<i64>, String> {
        if token.is_empty() {
            self.active = false;
            return Ok(None);
        }
        if let Some(p) = token.iter().position(|&b| b == b'&') {
            let order = match &token[..p] {
                [d @ b'0'..=b'9'] => usize::from(d - b'0'),
                other => return Err(format!("not an arc's order: {}", quote_field(other))),
            };
            let v = int(&token[p + 1..])?;
            *self = Arc {
                active: true,
                order: order as u8,
                reached: 0,
                d: [0; MAX_ORDER + 1],
            };
            self.d[0] = v;
            return Ok(Some(v));
        }
        if !self.active {
            return Err(format!(
                "a difference ({}) where an arc must start ('n&value')",
                quote_field(token)
            ));
        }
        let diff = int(token)?;
        let k = usize::from((self.reached + 1).min(self.order));
        self.d[k] = diff;
        for j in (0..k).rev() {
            self.d[j] = self.d[j]
                .checked_add(self.d[j + 1])
                .ok_or_else(|| "the value overflows".to_owned())?;
        }
        self.reached = k as u8;
        Ok(Some(self.d[0]))
    }
}

/// An optionally signed integer of at most 18 digits.
fn int(text: &[u8]) -> Result<i64, String> {
    let (neg, digits) = match text {
        [b'-', rest @ ..] => (true, rest),
        _ => (false, text),
    };
    if digits.is_empty() || digits.len() > 18 || !digits.iter().all(u8::is_ascii_digit) {
        return Err(format!("not an integer: {}", quote_field(text)));
    }
    let v = digits
        .iter()
        .fold(0i64, |acc, &d| acc * 10 + i64::from(d - b'0'));
    Ok(if neg { -v } else { v })
}

/// One satellite's state between epochs: its arcs and its flag characters.
#[derive(Debug, Clone, Default)]
struct SatState {
    id: [u8; 3],
    arcs: Vec<Arc>,
    flags: Vec<u8>,
}

/// Expands compact RINEX into RINEX lines.
pub(crate) struct Decompressor<R> {
    lines: LineReader<R>,
    /// CRX 3 (RINEX 3, 4) rather than CRX 1 (RINEX 2).
    v3: bool,
    /// Still in the RINEX header (passed through).
    in_header: bool,
    /// Special records of an event still to pass through.
    special: usize,
    /// The names of each system's columns (for messages; their count is the layout).
    columns: [Vec<String>; System::ALL.len()],
    /// The expanded text of the current record, its lines and their source line numbers.
    out: Vec<u8>,
    spans: Vec<(usize, usize, u64)>,
    next: usize,
    /// The previous epoch line, expanded.
    reference: Option<Vec<u8>>,
    clock: Arc,
    prev: Vec<SatState>,
    cur: Vec<SatState>,
    /// A copy of the compact line being decoded.
    scratch: Vec<u8>,
}

impl<R: Read> Decompressor<R> {
    /// Takes over `lines`, whose current line is `CRINEX VERS / TYPE` of `version`, and
    /// reads the `CRINEX PROG / DATE` line after it.
    pub(crate) fn new(
        mut lines: LineReader<R>,
        version: Option<Version>,
        path: &Path,
    ) -> Result<Self, InputError> {
        const LABEL: &str = "CRINEX VERS   / TYPE";
        let v3 = match version {
            Some(Version { major: 1, minor: 0 }) => false,
            Some(Version { major: 3, minor: 0 }) => true,
            other => {
                let shown = other.map_or_else(
                    || "none".to_owned(),
                    |v| format!("{}.{}", v.major, v.minor / 10),
                );
                return Err(InputError::new(
                    InputErrorKind::Header,
                    path,
                    1,
                    Some(LABEL),
                    format!("compact RINEX version {shown} is not supported (1.0 and 3.0 are)"),
                ));
            }
        };
        let second = lines.next_line();
        let label_ok = matches!(second, Ok(true))
            && header_label(&String::from_utf8_lossy(lines.line())).1 == "CRINEX PROG / DATE";
        if !label_ok {
            return Err(InputError::new(
                InputErrorKind::Header,
                path,
                2,
                Some("CRINEX PROG / DATE"),
                "the compact RINEX header lacks its second line",
            ));
        }
        Ok(Self {
            lines,
            v3,
            in_header: true,
            special: 0,
            columns: Default::default(),
            out: Vec::new(),
            spans: Vec::new(),
            next: 0,
            reference: None,
            clock: Arc::default(),
            prev: Vec::new(),
            cur: Vec::new(),
            scratch: Vec::new(),
        })
    }

    /// Sets the columns of each system from `header` (after the header, and after an
    /// event's header records).
    pub(crate) fn set_layout(&mut self, header: &ObsHeader) {
        for (k, system) in System::ALL.into_iter().enumerate() {
            self.columns[k] = (0..header.codes_of(system).len())
                .map(|i| header.column_name(system, i))
                .collect();
        }
    }

    /// The line handed out last and its number.
    pub(crate) fn current(&self) -> (&[u8], u64) {
        match self.next.checked_sub(1).and_then(|i| self.spans.get(i)) {
            Some(&(a, b, n)) => (&self.out[a..b], n),
            None => (&[], 0),
        }
    }

    /// The next RINEX line and the number of the compact line it comes from; `None`
    /// at the end.
    pub(crate) fn next_line(&mut self, path: &Path) -> Result<Option<(&[u8], u64)>, InputError> {
        if self.next == self.spans.len() {
            self.out.clear();
            self.spans.clear();
            self.next = 0;
            if !self.read_line(path)? {
                return Ok(None);
            }
            let n = self.lines.at().line_no;
            if self.in_header || self.special > 0 {
                if self.in_header {
                    let text = String::from_utf8_lossy(&self.scratch);
                    self.in_header = header_label(&text).1 != "END OF HEADER";
                } else {
                    self.special -= 1;
                }
                self.out.extend_from_slice(&self.scratch);
                self.spans.push((0, self.out.len(), n));
            } else {
                self.epoch(path, n)?;
            }
        }
        self.next += 1;
        Ok(Some(self.current()))
    }

    /// Reads the next compact line into `scratch`; `false` at the end.
    fn read_line(&mut self, path: &Path) -> Result<bool, InputError> {
        match self.lines.next_line() {
            Ok(true) => {
                self.scratch.clear();
                self.scratch.extend_from_slice(self.lines.line());
                Ok(true)
            }
            Ok(false) => Ok(false),
            Err(e) => Err(super::obs::line_error(path, &self.lines, e)),
        }
    }

    fn error(&self, path: &Path, field: &str, message: impl Into<String>) -> InputError {
        InputError::new(
            InputErrorKind::NotANumber,
            path,
            self.lines.at().line_no,
            Some(field),
            message,
        )
    }

    /// Expands the epoch whose compact epoch line is in `scratch` (line `n`).
    fn epoch(&mut self, path: &Path, n: u64) -> Result<(), InputError> {
        let whole = if self.v3 {
            self.scratch.first() == Some(&b'>')
        } else {
            self.scratch.first() == Some(&b'&')
        };
        let line = if whole {
            let mut line = self.scratch.clone();
            if !self.v3 {
                line[0] = b' ';
            }
            line
        } else {
            let Some(reference) = &self.reference else {
                return Err(self.error(
                    path,
                    "epoch",
                    "the first epoch line is a difference (no line to apply it to)",
                ));
            };
            let mut line = reference.clone();
            apply_text_diff(&mut line, &self.scratch);
            line
        };
        let (flag_col, count_cols) = if self.v3 { (31, 32..35) } else { (28, 29..32) };
        let flag = line.get(flag_col).copied().unwrap_or(b' ');
        let count_text = line.get(count_cols.clone()).unwrap_or_default();
        let count = std::str::from_utf8(count_text)
            .ok()
            .and_then(|t| t.trim().parse::<usize>().ok())
            .ok_or_else(|| {
                self.error(
                    path,
                    "epoch",
                    format!("no satellite count: {}", quote_field(count_text)),
                )
            })?;
        if matches!(flag, b'2'..=b'5') {
            self.push_line(&line, n);
            self.special = count;
            return Ok(());
        }
        if count > MAX_SATS_PER_EPOCH {
            return Err(self.error(
                path,
                "epoch",
                format!("{count} satellites (at most {MAX_SATS_PER_EPOCH} an epoch)"),
            ));
        }
        if whole {
            self.prev.clear();
            self.clock = Arc::default();
        }
        let from = if self.v3 { SAT_LIST_V3 } else { SAT_LIST_V1 };
        let list = line.get(from..from + 3 * count).ok_or_else(|| {
            self.error(
                path,
                "epoch",
                format!("the line lists fewer than {count} satellites"),
            )
        })?;
        let list = list.to_vec();
        // The clock line.
        if !self.read_line(path)? {
            return Err(self.error(path, "clock offset", "truncated epoch: the file ends"));
        }
        let clock_text = std::mem::take(&mut self.scratch);
        let clock = self
            .clock
            .decode(trim_end(&clock_text))
            .map_err(|m| self.error(path, "clock offset", m))?;
        self.scratch = clock_text;
        self.write_epoch_line(&line, &list, clock, n);
        self.reference = Some(line);
        self.cur.clear();
        for (i, id) in list.chunks_exact(3).enumerate() {
            if !self.read_line(path)? {
                return Err(self.error(
                    path,
                    "epoch",
                    format!(
                        "truncated epoch: {count} satellites announced, the file ends after {i}"
                    ),
                ));
            }
            self.satellite([id[0], id[1], id[2]], path)?;
        }
        std::mem::swap(&mut self.prev, &mut self.cur);
        Ok(())
    }

    /// Decodes the data line in `scratch` of satellite `id` and writes its RINEX lines.
    fn satellite(&mut self, id: [u8; 3], path: &Path) -> Result<(), InputError> {
        let n = self.lines.at().line_no;
        let system = std::str::from_utf8(&id)
            .ok()
            .and_then(Sat::parse)
            .map(|s| s.system)
            .ok_or_else(|| {
                self.error(
                    path,
                    "satellite",
                    format!("not a satellite: {}", quote_field(&id)),
                )
            })?;
        let k = System::ALL
            .iter()
            .position(|&s| s == system)
            .unwrap_or_default();
        let columns = self.columns[k].len();
        if columns == 0 {
            return Err(self.error(
                path,
                "satellite",
                format!(
                    "{}: no observation types for its system",
                    String::from_utf8_lossy(&id)
                ),
            ));
        }
        let mut state = match self.prev.iter().position(|s| s.id == id) {
            Some(p) => std::mem::take(&mut self.prev[p]),
            None => SatState {
                id,
                ..SatState::default()
            },
        };
        state.arcs.resize(columns, Arc::default());
        state.flags.resize(2 * columns, b' ');
        let line = std::mem::take(&mut self.scratch);
        let mut values = [None; crate::formats::rinex::obs::MAX_CODES_PER_SYSTEM];
        let mut pos = 0;
        for (i, arc) in state.arcs.iter_mut().enumerate() {
            let token = match line.get(pos..) {
                Some(rest) => {
                    let end = rest.iter().position(|&b| b == b' ').unwrap_or(rest.len());
                    pos += end + 1;
                    &rest[..end]
                }
                None => &[][..],
            };
            values[i] = arc
                .decode(token)
                .map_err(|m| self.error(path, &self.columns[k][i], m))?;
        }
        let flags = line.get(pos..).unwrap_or_default();
        if trim_end(flags).len() > 2 * columns {
            return Err(self.error(
                path,
                "LLI/SSI flags",
                format!("more flag characters than 2 × {columns} observations"),
            ));
        }
        apply_text_diff(&mut state.flags, trim_end(flags));
        self.scratch = line;
        self.write_sat(&state, &values[..columns], n);
        self.cur.push(state);
        Ok(())
    }

    /// Appends `line` (its trailing blanks dropped) as an output line from line `n`.
    fn push_line(&mut self, line: &[u8], n: u64) {
        let a = self.out.len();
        self.out.extend_from_slice(trim_end(line));
        self.spans.push((a, self.out.len(), n));
    }

    /// Ends the output line begun at `a` (its trailing blanks dropped).
    fn end_line(&mut self, a: usize, n: u64) {
        let len = a + trim_end(&self.out[a..]).len();
        self.out.truncate(len);
        self.spans.push((a, len, n));
    }

    /// Writes the RINEX epoch line(s) of expanded compact line `line`.
    fn write_epoch_line(&mut self, line: &[u8], list: &[u8], clock: Option<i64>, n: u64) {
        let a = self.out.len();
        if self.v3 {
            put_padded(&mut self.out, line, EPOCH_HEAD_V3);
            if let Some(c) = clock {
                self.out.resize(a + SAT_LIST_V3, b' ');
                put_fixed(&mut self.out, c, 12, 15);
            }
            self.end_line(a, n);
            return;
        }
        let mut chunks = list.chunks(3 * SATS_PER_LINE_V2);
        put_padded(&mut self.out, line, SAT_LIST_V1);
        self.out
            .extend_from_slice(chunks.next().unwrap_or_default());
        if let Some(c) = clock {
            self.out.resize(a + CLOCK_COL_V2, b' ');
            put_fixed(&mut self.out, c, 9, 12);
        }
        self.end_line(a, n);
        for chunk in chunks {
            let a = self.out.len();
            self.out.resize(a + SAT_LIST_V1, b' ');
            self.out.extend_from_slice(chunk);
            self.end_line(a, n);
        }
    }

    /// Writes a satellite's observation line(s).
    fn write_sat(&mut self, state: &SatState, values: &[Option<i64>], n: u64) {
        let per_line = if self.v3 { values.len() } else { 5 };
        for (l, chunk) in values.chunks(per_line).enumerate() {
            let a = self.out.len();
            if self.v3 {
                self.out.extend_from_slice(&state.id);
            }
            for (j, v) in chunk.iter().enumerate() {
                let i = l * per_line + j;
                match v {
                    Some(v) => {
                        put_fixed(&mut self.out, *v, 3, 14);
                        self.out.extend_from_slice(&state.flags[2 * i..2 * i + 2]);
                    }
                    // The flags of a missing value stay in the state but are not
                    // written: the field is blank in the original.
                    None => self.out.extend_from_slice(&[b' '; 16]),
                }
            }
            self.end_line(a, n);
        }
    }
}

/// Applies text difference `diff` to `line`: a blank keeps the character, `&` blanks
/// it, another character replaces it; the line grows to the difference's length.
fn apply_text_diff(line: &mut Vec<u8>, diff: &[u8]) {
    if line.len() < diff.len() {
        line.resize(diff.len(), b' ');
    }
    for (c, &d) in line.iter_mut().zip(diff) {
        match d {
            b' ' => {}
            b'&' => *c = b' ',
            d => *c = d,
        }
    }
}

/// `s` without trailing blanks.
fn trim_end(s: &[u8]) -> &[u8] {
    let end = s.iter().rposition(|&b| b != b' ').map_or(0, |p| p + 1);
    &s[..end]
}

/// Appends the first `width` bytes of `s`, padded with blanks to `width`.
fn put_padded(out: &mut Vec<u8>, s: &[u8], width: usize) {
    let take = s.len().min(width);
    out.extend_from_slice(&s[..take]);
    out.resize(out.len() + (width - take), b' ');
}

/// Appends integer `v` in units of 10^-`decimals` as a fixed-point number right-aligned
/// in `width` columns (Fortran `F{width}.{decimals}`: `-0.500`); wider when it does not
/// fit, as the writer would have to.
fn put_fixed(out: &mut Vec<u8>, v: i64, decimals: u32, width: usize) {
    let mut text = [0u8; 48];
    let mut k = text.len();
    let mut a = v.unsigned_abs();
    for _ in 0..decimals {
        k -= 1;
        text[k] = b'0' + (a % 10) as u8;
        a /= 10;
    }
    k -= 1;
    text[k] = b'.';
    loop {
        k -= 1;
        text[k] = b'0' + (a % 10) as u8;
        a /= 10;
        if a == 0 {
            break;
        }
    }
    if v < 0 {
        k -= 1;
        text[k] = b'-';
    }
    let digits = &text[k..];
    out.resize(out.len() + width.saturating_sub(digits.len()), b' ');
    out.extend_from_slice(digits);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(v: i64, d: u32, w: usize) -> String {
        let mut out = Vec::new();
        put_fixed(&mut out, v, d, w);
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn fixed_point_as_fortran_writes_it() {
        assert_eq!(fixed(131857102133, 3, 14), " 131857102.133");
        assert_eq!(fixed(-500, 3, 14), "        -0.500");
        assert_eq!(fixed(0, 3, 6), " 0.000");
        assert_eq!(fixed(-123456, 9, 12), "-0.000123456");
        assert_eq!(fixed(i64::MIN, 3, 4), "-9223372036854775.808");
    }

    #[test]
    fn arcs_sum_their_differences() {
        // Values 10, 13, 19, 28, 40: first differences 3, 6, 9, 12; second 3, 3, 3.
        let mut arc = Arc::default();
        let got: Vec<_> = ["2&10", "3", "3", "3", "3"]
            .iter()
            .map(|t| arc.decode(t.as_bytes()).unwrap().unwrap())
            .collect();
        assert_eq!(got, [10, 13, 19, 28, 40]);
        assert_eq!(arc.decode(b""), Ok(None));
        assert!(
            arc.decode(b"5").is_err(),
            "an ended arc takes no difference"
        );
        assert_eq!(arc.decode(b"0&-7"), Ok(Some(-7)));
        assert_eq!(arc.decode(b"-9"), Ok(Some(-9)));
        for bad in ["x&1", "12&1", "3&", "1-2", "3&1.5"] {
            assert!(Arc::default().decode(bad.as_bytes()).is_err(), "{bad}");
        }
        let mut arc = Arc::default();
        let big = b"999999999999999999";
        arc.decode(b"1&999999999999999999").unwrap();
        let overflowed = (0..12).any(|_| arc.decode(big).is_err());
        assert!(overflowed, "overflow is an error, not a panic");
    }

    #[test]
    fn text_differences() {
        let mut line = b"> 2021 12 21 00 00  0.0000000  0 38".to_vec();
        apply_text_diff(&mut line, b"                   3");
        assert_eq!(line, b"> 2021 12 21 00 00 30.0000000  0 38");
        let mut flags = b" 6 5".to_vec();
        apply_text_diff(&mut flags, b"& 7   8");
        assert_eq!(flags, b" 675  8");
    }

    fn h(content: &str, label: &str) -> String {
        format!("{content:<60}{label}\n")
    }

    /// The RINEX text of compact `text` (header included), through the reader's source.
    fn expand(text: &str) -> Result<String, InputError> {
        use crate::formats::rinex::obs::ObsReader;
        let path = Path::new("t.crx");
        // The reader parses the header and sets the layout; its source then expands.
        let mut reader = ObsReader::new(text.as_bytes(), path)?;
        let mut out = String::new();
        while let Some((line, _)) = reader.source_for_test().next(path)? {
            out += &String::from_utf8_lossy(line);
            out.push('\n');
        }
        Ok(out)
    }

    fn crx_header(version: &str) -> String {
        h(
            &format!("{version:<20}COMPACT RINEX FORMAT"),
            "CRINEX VERS   / TYPE",
        ) + &h(
            "hand-written                            27-Nov-26 00:00",
            "CRINEX PROG / DATE",
        )
    }

    #[test]
    fn crx3_epochs_clock_and_flags() {
        let header = h(
            "     3.04           OBSERVATION DATA    M",
            "RINEX VERSION / TYPE",
        ) + &h("G    3 C1C L1C S1C", "SYS / # / OBS TYPES")
            + &h("E    1 C1C", "SYS / # / OBS TYPES")
            + &h("", "END OF HEADER");
        let body = "> 2024 01 01 00 00  0.0000000  0  2      G05E11\n\
                    2&123456\n\
                    3&22000000125 3&115600000123 3&45000 &745\n\
                    3&23000000500\n\
                    \x20                   1\n\
                    100\n\
                    1000 2000 -250  1&&\n\
                    -500 \n";
        let rinex = "> 2024 01 01 00 00  0.0000000  0  2       0.000000123456\n\
                     G05  22000000.125 7 115600000.12345        45.000\n\
                     E11  23000000.500\n\
                     > 2024 01 01 00 00  1.0000000  0  2       0.000000123556\n\
                     G05  22000001.125 1 115600002.123          44.750\n\
                     E11  23000000.000\n";
        let got = expand(&(crx_header("3.0") + &header + body)).unwrap();
        assert_eq!(got, rinex);
    }

    #[test]
    fn crx1_epochs_continuations_clock_and_events() {
        let header = h(
            "     2.11           OBSERVATION DATA    G (GPS)",
            "RINEX VERSION / TYPE",
        ) + &h("     2    C1    L1", "# / TYPES OF OBSERV")
            + &h("", "END OF HEADER");
        let sats: String = (1..=13).map(|p| format!("G{p:02}")).collect();
        let mut body = format!("&21 12 21  0  0  0.0000000  0 13{sats}\n1&-123456789\n");
        for p in 1..=13 {
            body += &format!("3&{}000 3&100000000000    {}\n", 20_000_000 + p, p % 10);
        }
        body += "&21 12 21  0  0 15.0000000  4  1\n";
        body += &h("AFTER", "MARKER NAME");
        // The next epoch differences the epoch line before the event.
        body += "                3\n1\n";
        for _ in 1..=13 {
            body += "1000 0\n";
        }
        let mut rinex = format!(
            " 21 12 21  0  0  0.0000000  0 13{}-0.123456789\n{}G13\n",
            &sats[..36],
            " ".repeat(32)
        );
        let mut second = format!(
            " 21 12 21  0  0 30.0000000  0 13{}-0.123456788\n{}G13\n",
            &sats[..36],
            " ".repeat(32)
        );
        for p in 1..=13 {
            rinex += &format!(
                "{:14.3}   100000000.000 {}\n",
                f64::from(20_000_000 + p),
                p % 10
            );
            second += &format!(
                "{:14.3}   100000000.000 {}\n",
                f64::from(20_000_001 + p),
                p % 10
            );
        }
        rinex += " 21 12 21  0  0 15.0000000  4  1\n";
        rinex += &h("AFTER", "MARKER NAME");
        let got = expand(&(crx_header("1.0") + &header + &body)).unwrap();
        assert_eq!(got, rinex + &second);
    }

    #[test]
    fn compact_errors_name_the_line() {
        let header = h(
            "     3.04           OBSERVATION DATA    G",
            "RINEX VERSION / TYPE",
        ) + &h("G    1 C1C", "SYS / # / OBS TYPES")
            + &h("", "END OF HEADER");
        let text = |body: &str| crx_header("3.0") + &header + body;
        // A difference with no arc; a garbled field; a truncated epoch; a first epoch
        // line that is a difference.
        let e = expand(&text(
            "> 2024 01 01 00 00  0.0000000  0  1      G05\n\n123\n",
        ))
        .unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (8, Some("C1C")));
        let e = expand(&text(
            "> 2024 01 01 00 00  0.0000000  0  1      G05\n\n3&12x\n",
        ))
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("C1C"));
        let e = expand(&text(
            "> 2024 01 01 00 00  0.0000000  0  2      G05G06\n\n3&1\n",
        ))
        .unwrap_err();
        assert!(e.message.contains("truncated epoch"), "{e}");
        let e = expand(&text("                   3\n")).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (6, Some("epoch")));
        let e = expand(
            &(h(
                "3.1                 COMPACT RINEX FORMAT",
                "CRINEX VERS   / TYPE",
            ) + &header),
        )
        .unwrap_err();
        assert!(e.message.contains("not supported"), "{e}");
        let e = expand(&text("")).map(|_| ());
        assert!(e.is_ok());
        let e = expand(&(crx_header("1.0") + &header)).unwrap_err();
        assert!(e.message.contains("does not hold"), "{e}");
    }

    /// The compact files of tests/data/rinex_obs expand to their twins' text, line for
    /// line after the header, but for trailing blanks (which the compact form drops)
    /// and a leading zero the twin's writer left out of |x| < 1 (` .000000000000`:
    /// the compact form keeps the integer, not how it was written).
    #[test]
    fn public_files_expand_to_their_uncompressed_text() {
        use crate::formats::rinex::obs::ObsReader;
        let dir =
            std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/rinex_obs");
        for (compact, plain) in [
            ("AJAC3550.21d.gz", "AJAC3550.21o.gz"),
            ("wsra0010.21d.gz", "wsra0010.21o.gz"),
            (
                "ACOR00ESP_R_20213550000_01D_30S_MO.crx.gz",
                "ACOR00ESP_R_20213550000_01D_30S_MO.rnx.gz",
            ),
            ("VLNS0010.22d.gz", "VLNS0010.22o.gz"),
        ] {
            let path = dir.join(compact);
            let mut reader = ObsReader::open(&path).unwrap();
            let mut got = Vec::new();
            while let Some((line, _)) = reader.source_for_test().next(&path).unwrap() {
                got.push(String::from_utf8_lossy(line).into_owned());
            }
            let text = super::super::read_all(super::super::open(&dir.join(plain)).unwrap());
            let want: Vec<String> = text
                .lines()
                .skip_while(|l| !l.contains("END OF HEADER"))
                .skip(1)
                .map(|l| l.trim_end().replace(" .", "0."))
                .collect();
            assert_eq!(got.len(), want.len(), "{compact}");
            for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g, w, "{compact}: data line {}", i + 1);
            }
        }
    }
}
