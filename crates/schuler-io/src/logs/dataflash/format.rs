//! DataFlash message formats: what an `FMT` message defines (ArduPilot
//! `libraries/AP_Logger/LogStructure.h`, "format characters"; pymavlink's
//! `DFReader.py` reads them the same way).
//!
//! Every message is `A3 95 TYPE` and a body laid out, little-endian and packed, by the
//! format string of its type's `FMT` message, one character per column:
//!
//! | char | type | value |
//! |---|---|---|
//! | `b` `B` `M` | int8, uint8, uint8 (flight mode) | as is |
//! | `h` `H` | int16, uint16 | as is |
//! | `i` `I` | int32, uint32 | as is |
//! | `q` `Q` | int64, uint64 | as is |
//! | `f` `d` | float32, float64 | as is |
//! | `g` | float16 | as is |
//! | `c` `C` | int16, uint16 | × 0.01 |
//! | `e` `E` | int32, uint32 | × 0.01 |
//! | `L` | int32 | × 10⁻⁷ (latitude, longitude in degrees) |
//! | `n` `N` `Z` | char\[4\], char\[16\], char\[64\] | text, NUL-padded |
//! | `a` | int16\[32\] | array |
//!
//! The scale factors of `c C e E L` belong to the format character (pymavlink applies
//! them on reading); the `MULT` multipliers that `FMTU` attaches to columns are for
//! display and are not applied.

/// The size in bytes of a format character's value, `None` for an unknown character.
pub fn size_of(ch: u8) -> Option<usize> {
    Some(match ch {
        b'b' | b'B' | b'M' => 1,
        b'h' | b'H' | b'c' | b'C' | b'g' => 2,
        b'i' | b'I' | b'f' | b'e' | b'E' | b'L' | b'n' => 4,
        b'q' | b'Q' | b'd' => 8,
        b'N' => 16,
        b'Z' | b'a' => 64,
        _ => return None,
    })
}

/// One column of a message: its name, format character and byte offset in the body
/// (after the 3-byte header).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    /// The label (`TimeUS`, `GyrX`).
    pub name: String,
    /// The format character.
    pub ch: u8,
    /// Offset in the body [bytes].
    pub offset: usize,
}

/// A message type as its `FMT` message defines it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Format {
    /// The type byte.
    pub ty: u8,
    /// The name (`IMU`).
    pub name: String,
    /// The whole message's length, header included [bytes].
    pub len: usize,
    /// The format string.
    pub format: String,
    /// The columns.
    pub columns: Vec<Column>,
    /// The column holding the instance number (`FMTU` unit `#`), if any.
    pub instance: Option<usize>,
}

impl Format {
    /// The format of type `ty` named `name`, `len` bytes long, with format string
    /// `format` and comma-separated `labels`; an error `(field, message)` when a
    /// character is unknown, the labels do not match the characters one to one, or
    /// the sizes do not add up to `len − 3`.
    pub fn new(
        ty: u8,
        name: &str,
        len: usize,
        format: &str,
        labels: &str,
    ) -> Result<Self, (&'static str, String)> {
        let labels: Vec<&str> = if labels.is_empty() {
            Vec::new()
        } else {
            labels.split(',').collect()
        };
        if labels.len() != format.len() {
            return Err((
                "FMT.Columns",
                format!(
                    "message {name} (type {ty}) has {} format characters ({format:?}) but {} \
                     column labels",
                    format.len(),
                    labels.len()
                ),
            ));
        }
        let mut columns = Vec::with_capacity(labels.len());
        let mut offset = 0;
        for (&ch, label) in format.as_bytes().iter().zip(labels) {
            let Some(size) = size_of(ch) else {
                return Err((
                    "FMT.Format",
                    format!(
                        "message {name} (type {ty}): format character {:?} of column {label} \
                         is no DataFlash format character",
                        char::from(ch)
                    ),
                ));
            };
            columns.push(Column {
                name: label.to_owned(),
                ch,
                offset,
            });
            offset += size;
        }
        if offset + 3 != len {
            return Err((
                "FMT.Length",
                format!(
                    "message {name} (type {ty}): format {format:?} takes {} bytes with the \
                     header, the FMT message says {len}",
                    offset + 3
                ),
            ));
        }
        Ok(Self {
            ty,
            name: name.to_owned(),
            len,
            format: format.to_owned(),
            columns,
            instance: None,
        })
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    /// The field reader of column `name`.
    pub fn field(&self, name: &str) -> Option<Field> {
        self.column(name).map(|c| Field {
            offset: c.offset,
            ch: c.ch,
        })
    }

    /// The instance column's reader, if the format has one.
    pub fn instance_field(&self) -> Option<Field> {
        self.instance.map(|i| Field {
            offset: self.columns[i].offset,
            ch: self.columns[i].ch,
        })
    }
}

/// Reads one numeric column out of a message body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Offset in the body [bytes].
    pub offset: usize,
    /// The format character.
    pub ch: u8,
}

impl Field {
    fn bytes<const N: usize>(&self, body: &[u8]) -> [u8; N] {
        let mut b = [0u8; N];
        b.copy_from_slice(&body[self.offset..self.offset + N]);
        b
    }

    /// The value with its format character's scale (`c`, `C`, `e`, `E`: × 0.01, `L`:
    /// × 10⁻⁷); text and arrays read as NaN. `body` must be the whole body of a
    /// message of this field's format (the container checks its length).
    pub fn f64(&self, body: &[u8]) -> f64 {
        match self.ch {
            b'b' => f64::from(self.bytes::<1>(body)[0] as i8),
            b'B' | b'M' => f64::from(body[self.offset]),
            b'h' => f64::from(i16::from_le_bytes(self.bytes(body))),
            b'H' => f64::from(u16::from_le_bytes(self.bytes(body))),
            b'i' => f64::from(i32::from_le_bytes(self.bytes(body))),
            b'I' => f64::from(u32::from_le_bytes(self.bytes(body))),
            b'q' => i64::from_le_bytes(self.bytes(body)) as f64,
            b'Q' => u64::from_le_bytes(self.bytes(body)) as f64,
            b'f' => f64::from(f32::from_le_bytes(self.bytes(body))),
            b'd' => f64::from_le_bytes(self.bytes(body)),
            b'g' => half_to_f64(u16::from_le_bytes(self.bytes(body))),
            b'c' => f64::from(i16::from_le_bytes(self.bytes(body))) * 0.01,
            b'C' => f64::from(u16::from_le_bytes(self.bytes(body))) * 0.01,
            b'e' => f64::from(i32::from_le_bytes(self.bytes(body))) * 0.01,
            b'E' => f64::from(u32::from_le_bytes(self.bytes(body))) * 0.01,
            b'L' => f64::from(i32::from_le_bytes(self.bytes(body))) * 1e-7,
            _ => f64::NAN,
        }
    }

    /// The raw integer of an integer column (unscaled; `None` for floats, text,
    /// arrays, and a `Q` beyond `i64`).
    pub fn int(&self, body: &[u8]) -> Option<i64> {
        Some(match self.ch {
            b'b' => i64::from(self.bytes::<1>(body)[0] as i8),
            b'B' | b'M' => i64::from(body[self.offset]),
            b'h' | b'c' => i64::from(i16::from_le_bytes(self.bytes(body))),
            b'H' | b'C' => i64::from(u16::from_le_bytes(self.bytes(body))),
            b'i' | b'e' | b'L' => i64::from(i32::from_le_bytes(self.bytes(body))),
            b'I' | b'E' => i64::from(u32::from_le_bytes(self.bytes(body))),
            b'q' => i64::from_le_bytes(self.bytes(body)),
            b'Q' => i64::try_from(u64::from_le_bytes(self.bytes(body))).ok()?,
            _ => return None,
        })
    }

    /// Whether the column holds an integer (see [`Field::int`]).
    pub fn is_int(&self) -> bool {
        matches!(
            self.ch,
            b'b' | b'B'
                | b'M'
                | b'h'
                | b'H'
                | b'c'
                | b'C'
                | b'i'
                | b'I'
                | b'e'
                | b'E'
                | b'L'
                | b'q'
                | b'Q'
        )
    }
}

/// An IEEE 754 half-precision value (format character `g`).
fn half_to_f64(h: u16) -> f64 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f64::from(h & 0x3ff);
    sign * match exp {
        0 => frac * 2f64.powi(-24),
        0x1f if frac == 0.0 => f64::INFINITY,
        0x1f => f64::NAN,
        e => (1.0 + frac / 1024.0) * 2f64.powi(e - 15),
    }
}

/// Text of a NUL-padded `n`/`N`/`Z` column.
pub fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_sizes_and_scales_follow_the_format_characters() {
        let f = Format::new(1, "T", 3 + 8 + 2 + 4 + 4, "QcLf", "TimeUS,R,Lat,V").expect("ok");
        assert_eq!(f.column("V").expect("V").offset, 14);
        let mut body = 7u64.to_le_bytes().to_vec();
        body.extend_from_slice(&(-718i16).to_le_bytes());
        body.extend_from_slice(&(-353_626_277i32).to_le_bytes());
        body.extend_from_slice(&0.5f32.to_le_bytes());
        assert_eq!(f.field("TimeUS").expect("t").int(&body), Some(7));
        assert_eq!(f.field("R").expect("R").f64(&body), -718.0 * 0.01);
        assert_eq!(f.field("Lat").expect("L").f64(&body), -353_626_277.0 * 1e-7);
        assert_eq!(f.field("V").expect("V").f64(&body), 0.5);
        assert_eq!(
            Format::new(1, "T", 20, "Qc", "A,B").map_err(|e| e.0),
            Err("FMT.Length")
        );
        assert_eq!(
            Format::new(1, "T", 11, "Qx", "A,B").map_err(|e| e.0),
            Err("FMT.Format")
        );
        assert_eq!(
            Format::new(1, "T", 11, "Q", "A,B").map_err(|e| e.0),
            Err("FMT.Columns")
        );
        // Half precision: 1.0, −2.5, the smallest subnormal.
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc100), -2.5);
        assert_eq!(half_to_f64(0x0001), 2f64.powi(-24));
    }
}
