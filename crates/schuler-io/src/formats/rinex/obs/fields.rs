//! Fixed-column fields of RINEX records: slices that never panic, and the decimal
//! numbers (`F14.3`, `F12.9`, `I6`) read exactly.

/// Bytes `a..b` of `line`, clamped to its length (a short line's missing columns are
/// blank).
#[inline]
pub(crate) fn cols(line: &[u8], a: usize, b: usize) -> &[u8] {
    let b = b.min(line.len());
    line.get(a..b).unwrap_or_default()
}

/// Whether every byte is a space (an empty field is blank).
#[inline]
pub(crate) fn blank(field: &[u8]) -> bool {
    field.iter().all(|&b| b == b' ')
}

/// Powers of ten that f64 holds exactly.
const POW10: [f64; 19] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18,
];

/// The decimal number a fixed-width field holds: `Ok(None)` when blank, `Err(())` when
/// it is not one number (leading and trailing blanks allowed). Digits and point only
/// (`-131857102.133`, `.5`) are read as `mantissa / 10^decimals`, one correctly
/// rounded division, which is what a correctly rounded decimal parser gives; anything
/// else (an exponent, more than 2^53 in the mantissa) through `fast_float2`.
#[inline]
pub(crate) fn decimal(field: &[u8]) -> Result<Option<f64>, ()> {
    let mut i = 0;
    while i < field.len() && field[i] == b' ' {
        i += 1;
    }
    if i == field.len() {
        return Ok(None);
    }
    let start = i;
    let neg = field[i] == b'-';
    if neg || field[i] == b'+' {
        i += 1;
    }
    let mut mantissa: u64 = 0;
    let mut digits = 0u32;
    let mut decimals: Option<usize> = None;
    while i < field.len() {
        match field[i] {
            d @ b'0'..=b'9' => {
                if digits < 19 {
                    mantissa = mantissa * 10 + u64::from(d - b'0');
                }
                digits += 1;
                if let Some(n) = decimals.as_mut() {
                    *n += 1;
                }
            }
            b'.' if decimals.is_none() => decimals = Some(0),
            b' ' => break,
            _ => return slow(&field[start..]),
        }
        i += 1;
    }
    if !blank(&field[i..]) || digits == 0 {
        return Err(());
    }
    let decimals = decimals.unwrap_or(0);
    if digits > 18 || mantissa > 1 << 53 || decimals >= POW10.len() {
        return slow(&field[start..i]);
    }
    let v = mantissa as f64 / POW10[decimals];
    Ok(Some(if neg { -v } else { v }))
}

/// A trimmed number in any form `fast_float2` reads (an exponent, a long mantissa),
/// finite, with nothing after it but blanks.
#[cold]
fn slow(text: &[u8]) -> Result<Option<f64>, ()> {
    match fast_float2::parse::<f64, _>(trim(text)) {
        Ok(v) if v.is_finite() => Ok(Some(v)),
        _ => Err(()),
    }
}

/// The integer a fixed-width field holds: `Ok(None)` when blank, `Err(())` unless an
/// optionally signed run of at most 18 digits between blanks.
#[inline]
pub(crate) fn integer(field: &[u8]) -> Result<Option<i64>, ()> {
    let trimmed = trim(field);
    if trimmed.is_empty() {
        return Ok(None);
    }
    let (neg, digits) = match trimmed {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, trimmed),
    };
    if digits.is_empty() || digits.len() > 18 || !digits.iter().all(u8::is_ascii_digit) {
        return Err(());
    }
    let v = digits
        .iter()
        .fold(0i64, |acc, &d| acc * 10 + i64::from(d - b'0'));
    Ok(Some(if neg { -v } else { v }))
}

/// `field` without leading and trailing blanks.
pub(crate) fn trim(field: &[u8]) -> &[u8] {
    let start = field.iter().position(|&b| b != b' ').unwrap_or(field.len());
    let end = field
        .iter()
        .rposition(|&b| b != b' ')
        .map_or(start, |p| p + 1);
    &field[start..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_read_as_a_decimal_parser_does() {
        for text in [
            "131857102.133",
            "  -411.138",
            "     37.350",
            "  0.000123456",
            "-.5",
            "+12.25",
            "25091572.300  ",
            "-0.000000001",
            "12",
        ] {
            let want: f64 = text.trim().parse().unwrap();
            assert_eq!(decimal(text.as_bytes()), Ok(Some(want)), "{text}");
        }
        assert_eq!(decimal(b"1.5E+02"), Ok(Some(150.0)));
        assert_eq!(
            decimal(b"12345678901234567890.5"),
            Ok(Some(12345678901234567890.5))
        );
        assert_eq!(decimal(b"      "), Ok(None));
        assert_eq!(decimal(b""), Ok(None));
        for bad in ["1.2.3", "12a", "1 2", "-", ".", "1e999", "--1", "nan"] {
            assert_eq!(decimal(bad.as_bytes()), Err(()), "{bad}");
        }
    }

    #[test]
    fn integers_and_columns() {
        assert_eq!(integer(b"  18"), Ok(Some(18)));
        assert_eq!(integer(b" -7 "), Ok(Some(-7)));
        assert_eq!(integer(b"   "), Ok(None));
        assert_eq!(integer(b"1x"), Err(()));
        assert_eq!(integer(b"1234567890123456789"), Err(()));
        assert_eq!(cols(b"abc", 1, 10), b"bc");
        assert_eq!(cols(b"abc", 5, 10), b"");
        assert!(blank(b"   ") && !blank(b" x"));
    }
}
