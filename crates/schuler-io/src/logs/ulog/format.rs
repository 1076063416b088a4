//! ULog message formats (the `F` definitions) and the byte layout of a logged
//! topic: every field of the format, nested formats flattened, at its byte offset
//! (ULog file format, "Format Message 'F'": `name:type field;type[n] field;…`, fields
//! packed without alignment, little-endian).
//!
//! Nested fields are named `parent.child` and `parent[i].child` (array elements of a
//! nested type); a base-type array keeps one entry with its length. Trailing fields
//! named `_padding…` are not written by the logger: a data message may stop before
//! them, so a topic has a smallest and a largest payload ([`Layout::min_size`],
//! [`Layout::size`]).

use std::collections::HashMap;

/// A base type of a ULog field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseType {
    /// `int8_t`.
    I8,
    /// `uint8_t`.
    U8,
    /// `int16_t`.
    I16,
    /// `uint16_t`.
    U16,
    /// `int32_t`.
    I32,
    /// `uint32_t`.
    U32,
    /// `int64_t`.
    I64,
    /// `uint64_t`.
    U64,
    /// `float` (IEEE 754 binary32).
    F32,
    /// `double`.
    F64,
    /// `bool` (one byte, 0 or 1).
    Bool,
    /// `char` (one byte; arrays are text).
    Char,
}

impl BaseType {
    /// The type of a ULog type name, `None` for a nested format's name.
    pub fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "int8_t" => Self::I8,
            "uint8_t" => Self::U8,
            "int16_t" => Self::I16,
            "uint16_t" => Self::U16,
            "int32_t" => Self::I32,
            "uint32_t" => Self::U32,
            "int64_t" => Self::I64,
            "uint64_t" => Self::U64,
            "float" => Self::F32,
            "double" => Self::F64,
            "bool" => Self::Bool,
            "char" => Self::Char,
            _ => return None,
        })
    }

    /// Size in bytes.
    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 | Self::Bool | Self::Char => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Whether the type is a floating-point one.
    pub fn is_float(self) -> bool {
        matches!(self, Self::F32 | Self::F64)
    }
}

/// One field of a format definition as written: type name, array length (0: scalar),
/// field name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldDef {
    /// The type: a base type's name or a nested format's.
    pub type_name: String,
    /// Array length; 0 for a scalar.
    pub array: usize,
    /// The field's name.
    pub name: String,
}

/// A format definition: `message_name:field;field;…`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Format {
    /// The format's (message's) name.
    pub name: String,
    /// Its fields in order.
    pub fields: Vec<FieldDef>,
}

/// Parses the text of an `F` message. `Err` says what is malformed.
pub fn parse_format(text: &str) -> Result<Format, String> {
    let (name, rest) = text
        .split_once(':')
        .ok_or_else(|| format!("no ':' after the message name in {text:?}"))?;
    if name.is_empty() {
        return Err(format!("empty message name in {text:?}"));
    }
    let mut fields = Vec::new();
    for item in rest.split(';').filter(|s| !s.is_empty()) {
        let (ty, field) = item
            .split_once(' ')
            .ok_or_else(|| format!("field {item:?} of {name} has no 'type name' pair"))?;
        let (type_name, array) = match ty.split_once('[') {
            Some((t, n)) => {
                let n = n
                    .strip_suffix(']')
                    .and_then(|n| n.parse::<usize>().ok())
                    .filter(|&n| n > 0)
                    .ok_or_else(|| format!("bad array length in {item:?} of {name}"))?;
                (t, n)
            }
            None => (ty, 0),
        };
        fields.push(FieldDef {
            type_name: type_name.to_owned(),
            array,
            name: field.trim().to_owned(),
        });
    }
    Ok(Format {
        name: name.to_owned(),
        fields,
    })
}

/// A base-type field of a flattened layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// Full name (`gyro_rad`, `esc[2].esc_rpm`).
    pub name: String,
    /// Its base type.
    pub ty: BaseType,
    /// Array length; 0 for a scalar.
    pub array: usize,
    /// Byte offset in the payload (after the message id).
    pub offset: usize,
}

/// A topic's flattened layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Every base-type field, in order.
    pub fields: Vec<Field>,
    /// The full payload size [bytes].
    pub size: usize,
    /// The size without the trailing `_padding` fields, which the logger leaves out.
    pub min_size: usize,
}

/// Nesting deeper than this is refused (a format naming itself, directly or not).
const MAX_DEPTH: usize = 16;

impl Layout {
    /// The layout of format `name` among `formats`. `Err` names an unknown type or a
    /// nesting loop.
    pub fn of(name: &str, formats: &HashMap<String, Format>) -> Result<Self, String> {
        let mut layout = Layout {
            fields: Vec::new(),
            size: 0,
            min_size: 0,
        };
        layout.add(name, "", formats, 0)?;
        layout.min_size = layout
            .fields
            .iter()
            .rev()
            .find(|f| !f.name.starts_with("_padding"))
            .map_or(0, |f| f.offset + f.ty.size() * f.array.max(1));
        Ok(layout)
    }

    fn add(
        &mut self,
        name: &str,
        prefix: &str,
        formats: &HashMap<String, Format>,
        depth: usize,
    ) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!(
                "format {name} nests deeper than {MAX_DEPTH} levels"
            ));
        }
        let format = formats
            .get(name)
            .ok_or_else(|| format!("no format definition for type {name:?}"))?;
        for f in &format.fields {
            let full = format!("{prefix}{}", f.name);
            if let Some(ty) = BaseType::parse(&f.type_name) {
                self.fields.push(Field {
                    name: full,
                    ty,
                    array: f.array,
                    offset: self.size,
                });
                self.size += ty.size() * f.array.max(1);
            } else if f.array == 0 {
                self.add(&f.type_name, &format!("{full}."), formats, depth + 1)?;
            } else {
                for i in 0..f.array {
                    self.add(&f.type_name, &format!("{full}[{i}]."), formats, depth + 1)?;
                }
            }
        }
        Ok(())
    }

    /// The field named `name`, if any.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }
}

/// A little-endian value of type `ty` at `bytes[offset..]` as f64 (exact for every
/// type but 64-bit integers beyond 2⁵³). The caller has checked the bounds.
#[inline]
pub fn value_at(bytes: &[u8], ty: BaseType, offset: usize) -> f64 {
    fn arr<const N: usize>(b: &[u8], o: usize) -> [u8; N] {
        let mut a = [0u8; N];
        a.copy_from_slice(&b[o..o + N]);
        a
    }
    match ty {
        BaseType::I8 => f64::from(bytes[offset] as i8),
        BaseType::U8 | BaseType::Bool | BaseType::Char => f64::from(bytes[offset]),
        BaseType::I16 => f64::from(i16::from_le_bytes(arr(bytes, offset))),
        BaseType::U16 => f64::from(u16::from_le_bytes(arr(bytes, offset))),
        BaseType::I32 => f64::from(i32::from_le_bytes(arr(bytes, offset))),
        BaseType::U32 => f64::from(u32::from_le_bytes(arr(bytes, offset))),
        BaseType::I64 => i64::from_le_bytes(arr(bytes, offset)) as f64,
        BaseType::U64 => u64::from_le_bytes(arr(bytes, offset)) as f64,
        BaseType::F32 => f64::from(f32::from_le_bytes(arr(bytes, offset))),
        BaseType::F64 => f64::from_le_bytes(arr(bytes, offset)),
    }
}

/// A little-endian integer of type `ty` at `bytes[offset..]` as i128 (floats
/// truncated toward zero). The caller has checked the bounds.
#[inline]
pub fn int_at(bytes: &[u8], ty: BaseType, offset: usize) -> i128 {
    match ty {
        BaseType::I64 => {
            let mut a = [0u8; 8];
            a.copy_from_slice(&bytes[offset..offset + 8]);
            i128::from(i64::from_le_bytes(a))
        }
        BaseType::U64 => {
            let mut a = [0u8; 8];
            a.copy_from_slice(&bytes[offset..offset + 8]);
            i128::from(u64::from_le_bytes(a))
        }
        _ => value_at(bytes, ty, offset) as i128,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formats(texts: &[&str]) -> HashMap<String, Format> {
        texts
            .iter()
            .map(|t| {
                let f = parse_format(t).expect("format");
                (f.name.clone(), f)
            })
            .collect()
    }

    /// Offsets are the running sum of the packed sizes; nested arrays are flattened
    /// element by element; trailing padding is optional in a message.
    #[test]
    fn layout_flattens_nested_formats_and_drops_trailing_padding() {
        let f = formats(&[
            "rep:uint32_t rpm;float v;",
            "esc:uint64_t timestamp;uint8_t n;rep[2] esc;float[3] w;uint8_t[3] _padding0;",
        ]);
        let l = Layout::of("esc", &f).expect("layout");
        let names: Vec<(&str, usize)> = l
            .fields
            .iter()
            .map(|f| (f.name.as_str(), f.offset))
            .collect();
        assert_eq!(
            names,
            [
                ("timestamp", 0),
                ("n", 8),
                ("esc[0].rpm", 9),
                ("esc[0].v", 13),
                ("esc[1].rpm", 17),
                ("esc[1].v", 21),
                ("w", 25),
                ("_padding0", 37),
            ]
        );
        assert_eq!((l.min_size, l.size), (37, 40));
    }

    #[test]
    fn malformed_formats_and_loops_are_refused() {
        assert!(parse_format("no_colon").is_err());
        assert!(parse_format("a:float[x] v;").is_err());
        assert!(parse_format("a:float;").is_err());
        let f = formats(&["a:b x;", "b:a y;"]);
        assert!(Layout::of("a", &f).expect_err("loop").contains("nests"));
        let f = formats(&["a:quaternion q;"]);
        assert!(
            Layout::of("a", &f)
                .expect_err("unknown")
                .contains("quaternion")
        );
    }

    #[test]
    fn values_are_little_endian() {
        let b = [0x01, 0x02, 0xff, 0xff, 0xff, 0xff, 0, 0, 0x80, 0x3f];
        assert_eq!(value_at(&b, BaseType::U16, 0), 513.0);
        assert_eq!(value_at(&b, BaseType::I32, 2), -1.0);
        assert_eq!(value_at(&b, BaseType::F32, 6), 1.0);
        assert_eq!(int_at(&b, BaseType::U8, 2), 255);
    }
}
