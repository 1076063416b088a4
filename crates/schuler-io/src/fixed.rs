//! Fixed-decimal numbers for the text writers: `x` with exactly `d` digits after the
//! point, correctly rounded, the digits of std's `{x:.d$}`.
//!
//! Rounding: the product `|x| 10^d` in floating point is off by at most half an ulp
//! (`2^-53` of itself), so unless its fraction lies within twice that of one half it
//! rounds to the same integer as the exact product. Near such a tie the exact product
//! decides: with `x = m 2^e` (`m` the 53-bit significand), `m 10^d < 2^53 10^19 <
//! 2^117` is an exact `u128`, and its shift by `-e`, with the remainder compared
//! against one half, is the correctly rounded integer (ties to even, as std rounds the
//! exact binary value).
//!
//! Digits: the 16 digits of the integer are made at once in byte lanes (SWAR), the
//! leading zeros shifted out and the point shifted in, all in registers, and stored
//! once, so a number costs a few dozen instructions, no call and no reload. Values of
//! 10^15 and more after scaling take a digit loop; beyond `u64`, more than 19 decimals
//! and NaN or infinity go through std's formatter.
//!
//! Lines in bulk (`schuler simulate`, a few hundred numbers per IMU sample) go through
//! [`put_field`] and [`put_bytes`] instead of [`push_fixed`] and `Vec` pushes: each
//! line is stored in whole 8-byte words into a fixed-size window ([`Line`]; a text
//! line and its CSV twin in step, [`Twin`]), no capacity check per number, no copy
//! of variable length; [`put_field`] covers the numbers of a navigation line (below
//! `10^15` after scaling) and declines the rest, whose line the `Vec` writers then
//! make. Both write the same bytes (tested against std and each other).

use std::io::Write;

/// `10^k` for `k = 0..=19` (all that fit `u64`; each exact as an `f64` too).
const POW10: [u64; 20] = {
    let mut p = [1u64; 20];
    let mut k = 1;
    while k < 20 {
        p[k] = p[k - 1] * 10;
        k += 1;
    }
    p
};

/// `"00" "01" … "99"`: two digits per lookup.
const DIGIT_PAIRS: [u8; 200] = {
    let mut t = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        t[2 * i] = b'0' + (i / 10) as u8;
        t[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    t
};

/// Largest scaled value whose floating-point fraction is exact (`< 2^52`).
const FAST_LIMIT: f64 = 4.0e15;

/// `|x| 10^decimals` rounded to the nearest integer, ties to even (see the module
/// doc); `None` when `x` is not finite, `decimals > 19` or the result does not fit a
/// `u64`.
#[inline]
fn scaled(x: f64, decimals: usize) -> Option<u64> {
    let pow = *POW10.get(decimals)?;
    let product = x.abs() * pow as f64;
    // NaN fails the comparison and goes to the exact path, which refuses it.
    if product < FAST_LIMIT {
        // `as` truncates: the floor of a non-negative value; both exact below 2^52.
        // Through i64, one instruction each way (u64 conversions take a dozen).
        let int = product as i64;
        let frac = product - int as f64;
        if (frac - 0.5).abs() > product * 2.3e-16 {
            return Some(int as u64 + u64::from(frac > 0.5));
        }
    }
    scaled_exact(x, pow)
}

/// [`scaled`] when the result is below `10^15`, else `None`. The rounding to an
/// integer is the addition of `2^52` (where the spacing of f64s is 1), which leaves the
/// integer in the low bits: no conversion instruction and its saturation checks.
#[inline(always)]
fn scaled_below_1e15(x: f64, decimals: usize) -> Option<u64> {
    const SHIFT: f64 = (1u64 << 52) as f64;
    let pow = *POW10.get(decimals)?;
    let product = x.abs() * pow as f64;
    // NaN fails the comparison. Below 10^15 - 1 the result is at most 10^15 - 1.
    if product < 999_999_999_999_999.0 {
        let rounded = product + SHIFT;
        // product minus its nearest integer, exactly: in [-0.5, 0.5].
        let off = product - (rounded - SHIFT);
        if 0.5 - off.abs() > product * 2.3e-16 {
            return Some(rounded.to_bits() - SHIFT.to_bits());
        }
        return scaled_exact(x, pow);
    }
    None
}

/// `|x| pow` rounded to the nearest integer, ties to even, from the exact `u128`
/// product (see the module doc). Out of line: near ties only.
#[inline(never)]
fn scaled_exact(x: f64, pow: u64) -> Option<u64> {
    let bits = x.to_bits() & !(1u64 << 63);
    let biased = (bits >> 52) as i32;
    if biased == 0x7ff {
        return None;
    }
    let fraction = bits & ((1u64 << 52) - 1);
    // x = m 2^e exactly (subnormals have no hidden bit and the smallest exponent).
    let (m, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), biased - 1075)
    };
    let p = u128::from(m) * u128::from(pow);
    if e >= 0 {
        // An integer: exact unless it overflows.
        if p != 0 && p.leading_zeros() <= e as u32 {
            return None;
        }
        return u64::try_from(p << e).ok();
    }
    let s = e.unsigned_abs();
    if s >= 128 {
        // p < 2^117, so p 2^-s < 2^-11: rounds to zero.
        return Some(0);
    }
    let (q, rem) = (p >> s, p & ((1u128 << s) - 1));
    let half = 1u128 << (s - 1);
    let up = rem > half || (rem == half && q & 1 == 1);
    u64::try_from(q + u128::from(up)).ok()
}

/// ASCII `'0'` in every byte.
const ZEROS: u64 = 0x3030_3030_3030_3030;

/// The 8 decimal digits of `v < 10^8` as ASCII, the first in the lowest byte (so
/// `to_le_bytes` gives them in order): both 4-digit halves split into 2-digit and then
/// 1-digit lanes at once, by multiplications with reciprocals that are exact in these
/// ranges (`v 109951163 >> 40 = v / 10^4` for `v < 10^8`, `x 10486 >> 20 = x / 100`
/// for `x < 10^4`, `x 103 >> 10 = x / 10` for `x < 100`), no dependent divisions.
/// Quotient `q` and remainder of `x` go to the low and high half of a lane at once, as
/// `(x << s) - ((d << s) - 1) q = ((x - d q) << s) + q` (the split of zmij's `to_bcd8`).
#[inline]
fn ascii8(v: u64) -> u64 {
    let q = (v * 109_951_163) >> 40;
    let halves = (v << 32) - ((10_000 << 32) - 1) * q;
    let hundreds = ((halves * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let pairs = (halves << 16) - ((100 << 16) - 1) * hundreds;
    let tens = ((pairs * 103) >> 10) & 0x000F_000F_000F_000F;
    let digits = (pairs << 8) - ((10 << 8) - 1) * tens;
    digits | ZEROS
}

/// The 16 decimal digits of `n < 10^16` as ASCII, the first in the lowest byte.
#[inline]
fn ascii16(n: u64) -> u128 {
    u128::from(ascii8(n / 100_000_000)) | (u128::from(ascii8(n % 100_000_000)) << 64)
}

/// Write the `dst.len()` lowest decimal digits of `n` into `dst` (zero-padded) and
/// return what is left, `n / 10^dst.len()`.
fn put_digits(dst: &mut [u8], mut n: u64) -> u64 {
    let mut i = dst.len();
    while i >= 2 {
        let r = (n % 100) as usize * 2;
        n /= 100;
        dst[i - 2] = DIGIT_PAIRS[r];
        dst[i - 1] = DIGIT_PAIRS[r + 1];
        i -= 2;
    }
    if i == 1 {
        dst[0] = b'0' + (n % 10) as u8;
        n /= 10;
    }
    n
}

/// The text of `n / 10^decimals` with `decimals` digits after the point (no sign) as
/// ASCII bytes in a `u128`, the first in the lowest byte, and its length; `None` past
/// 15 digits (the text would not fit 16 bytes). All in registers: the leading zeros
/// shifted out, the point shifted in, so that the caller stores it once and nothing is
/// read back (a load of bytes just stored piecewise stalls the pipeline).
#[inline]
fn fixed_ascii(n: u64, decimals: usize) -> Option<(u128, usize)> {
    if n >= POW10[15] || decimals >= 15 {
        return None;
    }
    let ascii = ascii16(n);
    // Leading zero digits: the zero bytes of `ascii - '0'`, from the lowest (at least
    // one, n < 10^15).
    let zeros = ((ascii ^ 0x3030_3030_3030_3030_3030_3030_3030_3030).trailing_zeros() / 8) as usize;
    // At least one digit before the point; at most 15 in all.
    let digits = (16 - zeros).max(decimals + 1);
    let all = ascii >> (8 * (16 - digits));
    if decimals == 0 {
        return Some((all, digits));
    }
    let int_len = digits - decimals;
    let int_mask = (1u128 << (8 * int_len)) - 1;
    let text = (all & int_mask) | (u128::from(b'.') << (8 * int_len)) | ((all & !int_mask) << 8);
    Some((text, digits + 1))
}

/// The text of `n / 10^decimals` as [`fixed_ascii`] gives it, for any `n`, by a digit
/// loop: into a buffer, with its length.
fn fixed_digits(n: u64, decimals: usize) -> ([u8; 24], usize) {
    let mut buf = [0u8; 24];
    // At least one digit before the point.
    let digits = n
        .checked_ilog10()
        .map_or(1, |l| l as usize + 1)
        .max(decimals + 1);
    let int_end = digits - decimals;
    let len = if decimals > 0 { digits + 1 } else { digits };
    let int = put_digits(&mut buf[len - decimals..len], n);
    if decimals > 0 {
        buf[int_end] = b'.';
    }
    put_digits(&mut buf[..int_end], int);
    (buf, len)
}

/// Append `x` with exactly `decimals` digits after the point, correctly rounded: the
/// text of std's `{x:.decimals$}`, except that a value rounding to zero has no sign.
/// Always inlined, so that constant decimals fold into the arithmetic.
#[inline(always)]
pub fn push_fixed(out: &mut Vec<u8>, x: f64, decimals: usize) {
    let Some(n) = scaled(x, decimals) else {
        // Writing to a Vec cannot fail.
        let _ = write!(out, "{x:.decimals$}");
        return;
    };
    if x.is_sign_negative() && n != 0 {
        out.push(b'-');
    }
    if let Some((text, len)) = fixed_ascii(n, decimals) {
        // All 16 bytes (a store of constant size), then back to the length.
        let start = out.len();
        out.extend_from_slice(&text.to_le_bytes());
        out.truncate(start + len);
    } else {
        let (buf, len) = fixed_digits(n, decimals);
        out.extend_from_slice(&buf[..len]);
    }
}

/// Byte windows that the line writers store into whole 8-byte words: each word lands
/// at a position, its bytes past the text's end are scratch that the next word or a
/// later line overwrites. Stores of constant size need no call and no loop.
pub trait Words {
    /// Store the 8 bytes of `word` (the first in the lowest byte) at `pos`.
    fn put(&mut self, pos: usize, word: u64);
    /// Store the field separator at `pos`.
    fn sep(&mut self, pos: usize);
    /// Store the field separator at `pos` and the 7 lowest bytes of `word` after it.
    fn sep_then(&mut self, pos: usize, word: u64);
}

/// One line's window of `N` bytes and its field separator. A line holds at most `N -
/// 8` bytes (a power of two): positions are taken modulo that, so that a store needs
/// no bounds check, and the writer checks the line's end once ([`Line::end`]).
pub struct Line<'a, const N: usize> {
    /// The window.
    pub bytes: &'a mut [u8; N],
    /// Field separator (b' ' or b',').
    pub sep: u8,
}

impl<const N: usize> Line<'_, N> {
    /// Positions modulo the longest line.
    const MASK: usize = {
        assert!(N > 8 && (N - 8).is_power_of_two());
        N - 9
    };

    /// The line's length `end` after checking it: a line longer than the window would
    /// have wrapped around.
    #[inline(always)]
    pub fn end(end: usize) -> usize {
        assert!(
            end <= Self::MASK,
            "a line of {end} bytes overflows its window"
        );
        end
    }
}

impl<const N: usize> Words for Line<'_, N> {
    #[inline(always)]
    fn put(&mut self, pos: usize, word: u64) {
        let p = pos & Self::MASK;
        self.bytes[p..p + 8].copy_from_slice(&word.to_le_bytes());
    }

    #[inline(always)]
    fn sep(&mut self, pos: usize) {
        self.bytes[pos & Self::MASK] = self.sep;
    }

    #[inline(always)]
    fn sep_then(&mut self, pos: usize, word: u64) {
        self.put(pos, u64::from(self.sep) | (word << 8));
    }
}

/// Two lines written in step, the same text at the same positions, each with its own
/// separator: a text file's line and its CSV twin, formatted once.
pub struct Twin<'a, const A: usize, const B: usize>(pub Line<'a, A>, pub Line<'a, B>);

impl<const A: usize, const B: usize> Words for Twin<'_, A, B> {
    #[inline(always)]
    fn put(&mut self, pos: usize, word: u64) {
        self.0.put(pos, word);
        self.1.put(pos, word);
    }

    #[inline(always)]
    fn sep(&mut self, pos: usize) {
        self.0.sep(pos);
        self.1.sep(pos);
    }

    #[inline(always)]
    fn sep_then(&mut self, pos: usize, word: u64) {
        self.0.sep_then(pos, word);
        self.1.sep_then(pos, word);
    }
}

/// The little-endian word of `bytes[i..i + 8]`.
#[inline(always)]
fn load8(bytes: &[u8], i: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&bytes[i..i + 8]);
    u64::from_le_bytes(w)
}

/// The little-endian word of `bytes[i..i + 4]`.
#[inline(always)]
fn load4(bytes: &[u8], i: usize) -> u64 {
    let mut w = [0u8; 4];
    w.copy_from_slice(&bytes[i..i + 4]);
    u64::from(u32::from_le_bytes(w))
}

/// Store `text` at `pos` and return its end: words of 8 bytes, the last one ending at
/// the text's end (overlapping the one before), or one word assembled from two
/// overlapping 4-byte halves for a short text. For a number's text (at most 24 bytes
/// from zmij) this is a handful of loads and stores, no loop, where a copy of a
/// variable length calls `memcpy`.
#[inline(always)]
pub fn put_bytes<W: Words + ?Sized>(out: &mut W, pos: usize, text: &[u8]) -> usize {
    let n = text.len();
    if n >= 16 {
        out.put(pos, load8(text, 0));
        out.put(pos + 8, load8(text, 8));
        let mut i = 16;
        while i + 8 < n {
            out.put(pos + i, load8(text, i));
            i += 8;
        }
        out.put(pos + n - 8, load8(text, n - 8));
    } else if n >= 8 {
        out.put(pos, load8(text, 0));
        out.put(pos + n - 8, load8(text, n - 8));
    } else if n >= 4 {
        // The bytes both halves hold are the same, so or-ing them is harmless.
        out.put(pos, load4(text, 0) | (load4(text, n - 4) << (8 * (n - 4))));
    } else {
        let mut w = 0;
        for (i, &b) in text.iter().enumerate() {
            w |= u64::from(b) << (8 * i);
        }
        out.put(pos, w);
    }
    pos + n
}

/// Leading zero digits of the 8 ASCII digits `a` (first in the lowest byte), at most
/// `max`.
#[inline(always)]
fn leading_zeros(a: u64, max: usize) -> usize {
    (((a ^ ZEROS).trailing_zeros() / 8) as usize).min(max)
}

/// Store the field separator at `pos`, then `x` with exactly `decimals` digits after
/// the point, the text of [`push_fixed`], and return the end; `None` (and scratch
/// written) unless `x` is finite, `decimals <= 14` and `|x| 10^decimals < 10^15`, the
/// range of every number a navigation line holds.
///
/// The integer `n` (rounded as [`push_fixed`] does) is split at `10^8`: the low 8
/// digits and the at most 7 above them are each made at once in byte lanes, the high
/// ones only when there are any (else their text is a constant). With 8 or more
/// decimals the low digits are all fraction digits and the point goes among the high
/// ones; with fewer, the point sits at a constant place in the low digits. The words
/// are stored where they belong and overlap, so that no text is shifted twice.
#[inline(always)]
pub fn put_field<W: Words + ?Sized>(
    out: &mut W,
    pos: usize,
    x: f64,
    decimals: usize,
) -> Option<usize> {
    if decimals > 14 {
        return None;
    }
    let n = scaled_below_1e15(x, decimals)?;
    // The separator and a minus sign, which counts for a negative number that does not
    // round to zero: the sign bit of `x` where `n - 1` (wrapping) has none, `n != 0`.
    out.sep_then(pos, u64::from(b'-'));
    let minus = (x.to_bits() & !n.wrapping_sub(1)) >> 63;
    let mut pos = pos + 1 + minus as usize;
    let (high, low) = (n / 100_000_000, n % 100_000_000);
    if decimals >= 8 {
        // `high`: the integer digits, then `decimals - 8` fraction digits; at least one
        // integer digit is kept (`high < 10^7`: at least one leading zero). Stored are
        // those digits, then over the fraction digits the point and them again, then
        // the low digits.
        let frac_high = decimals - 8;
        if high == 0 {
            // `0.` and zeros: a constant.
            out.put(pos, (ZEROS & !0xFF00) | (u64::from(b'.') << 8));
            pos += 2 + frac_high;
        } else {
            let a = ascii8(high);
            let lz = leading_zeros(a, 7 - frac_high);
            out.put(pos, a >> (8 * lz));
            pos += 8 - lz - frac_high;
            if frac_high > 0 {
                out.put(pos, u64::from(b'.') | ((a >> (8 * (8 - frac_high))) << 8));
            } else {
                out.put(pos, u64::from(b'.'));
            }
            pos += 1 + frac_high;
        }
        out.put(pos, ascii8(low));
        pos += 8;
    } else {
        // `low`: `8 - decimals` integer digits, then the fraction digits.
        let int_low = 8 - decimals;
        let low = if high == 0 {
            let low = ascii8(low);
            let lz = leading_zeros(low, int_low - 1);
            out.put(pos, low >> (8 * lz));
            pos += int_low - lz;
            low
        } else {
            let (a, low) = (ascii8(high), ascii8(low));
            let lz = leading_zeros(a, 7);
            out.put(pos, a >> (8 * lz));
            pos += 8 - lz;
            out.put(pos, low);
            pos += int_low;
            low
        };
        if decimals > 0 {
            // The point and at most 7 fraction digits: one word.
            out.put(pos, u64::from(b'.') | ((low >> (8 * int_low)) << 8));
            pos += decimals + 1;
        }
    }
    Some(pos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn fixed(x: f64, d: usize) -> String {
        let mut v = Vec::new();
        push_fixed(&mut v, x, d);
        String::from_utf8(v).expect("ascii")
    }

    /// std's text, with the sign dropped from a value that rounds to zero.
    fn std_text(x: f64, d: usize) -> String {
        let s = format!("{x:.d$}");
        match s.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
            _ => s,
        }
    }

    /// [`put_field`]'s text after its separator, `None` outside its range. The window
    /// starts with other text and has old bytes after the end, as a block's scratch.
    fn field(x: f64, d: usize) -> Option<String> {
        let mut bytes = [b'#'; 72];
        let mut line = Line {
            bytes: &mut bytes,
            sep: b',',
        };
        let end = Line::<72>::end(put_field(&mut line, 3, x, d)?);
        assert_eq!(&bytes[..4], b"###,");
        Some(String::from_utf8(bytes[4..end].to_vec()).expect("ascii"))
    }

    /// Whether `x` with `d` decimals is within [`put_field`]'s range (with a margin at
    /// its edge, where the floating-point product decides).
    fn in_range(x: f64, d: usize) -> bool {
        x.is_finite() && d <= 14 && x.abs() * POW10[d] as f64 <= 9.99e14
    }

    /// The reciprocal that splits 8 digits into 4 and 4 is exact for every 8-digit
    /// number, and so are those for 4 and 2 digits in their ranges.
    #[test]
    fn digit_split_reciprocals_are_exact() {
        for v in 0..100_000_000u64 {
            assert_eq!((v * 109_951_163) >> 40, v / 10_000, "{v}");
        }
        for x in 0..10_000u64 {
            assert_eq!((x * 10_486) >> 20, x / 100, "{x}");
        }
        for x in 0..100u64 {
            assert_eq!((x * 103) >> 10, x / 10, "{x}");
        }
    }

    /// [`put_field`] against std and [`push_fixed`] at every decimal count it takes,
    /// on the numbers of a navigation line and around every change of length.
    #[test]
    fn fields_examples() {
        for (d, &pow) in POW10.iter().enumerate().take(15) {
            for x in [
                0.0,
                -0.0,
                1.0,
                -1.0,
                0.5,
                -0.5,
                45.07123456789,
                -179.99999999999,
                7.0,
                359.999999999,
                -9.80665,
                30.000000,
                1e-300,
                -5e-324,
                f64::MIN_POSITIVE,
            ] {
                for scale in [1.0, 10.0, 1e3, 1e5, 1e7, 1e-3, 1e-7] {
                    let x = x * scale;
                    match field(x, d) {
                        Some(text) => {
                            assert_eq!(text, std_text(x, d), "{x} {d}");
                            assert_eq!(text, fixed(x, d), "{x} {d}");
                        }
                        None => assert!(!in_range(x, d), "{x} {d}"),
                    }
                }
            }
            // The last digits alone.
            for k in 0..=20 {
                let x = f64::from(k) / pow as f64;
                for x in [x, -x] {
                    assert_eq!(field(x, d), Some(std_text(x, d)), "{x} {d}");
                }
            }
            // Every length of the integer part, at the largest value of each.
            for &p in &POW10[..15] {
                let x = (p as f64 - 1.0) / pow as f64;
                if let Some(text) = field(x, d) {
                    assert_eq!(text, std_text(x, d), "{x} {d}");
                }
                if let Some(text) = field(-x, d) {
                    assert_eq!(text, std_text(-x, d), "{x} {d}");
                }
            }
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
            assert_eq!(field(x, 6), None);
        }
        assert_eq!(field(1.0, 15), None);
    }

    /// [`put_bytes`] stores any text of any length, the bytes around it untouched.
    #[test]
    fn bytes_of_every_length() {
        let text: Vec<u8> = (0..40u8).map(|i| b'a' + i % 26).collect();
        for n in 0..=text.len() {
            let mut bytes = [b'#'; 72];
            let mut line = Line {
                bytes: &mut bytes,
                sep: b' ',
            };
            let end = put_bytes(&mut line, 5, &text[..n]);
            assert_eq!(end, 5 + n);
            assert_eq!(&bytes[..5], b"#####");
            assert_eq!(&bytes[5..end], &text[..n]);
        }
    }

    /// Both lines of a twin hold the same text, each with its separator.
    #[test]
    fn twin_lines() {
        let (mut a, mut b) = ([0u8; 72], [0u8; 136]);
        let mut w = Twin(
            Line {
                bytes: &mut a,
                sep: b' ',
            },
            Line {
                bytes: &mut b,
                sep: b',',
            },
        );
        let end = put_bytes(&mut w, 0, b"0.25");
        let end = put_field(&mut w, end, -1.5, 3).expect("in range");
        let end = put_field(&mut w, end, 2e-7, 6).expect("in range");
        assert_eq!(&a[..end], b"0.25 -1.500 0.000000");
        assert_eq!(&b[..end], b"0.25,-1.500,0.000000");
    }

    /// A line longer than its window is refused, not wrapped around.
    #[test]
    #[should_panic(expected = "overflows its window")]
    fn line_longer_than_window() {
        Line::<72>::end(65);
    }

    /// The digit lanes against the plain text of every kind of number: zeros inside,
    /// at the ends, the largest.
    #[test]
    fn ascii_digits() {
        for n in [
            0u64,
            7,
            10,
            99_999_999,
            12_340_056,
            10_000_000,
            9_999_999_999_999_999,
        ] {
            let text = String::from_utf8(ascii16(n).to_le_bytes().to_vec()).expect("ascii");
            assert_eq!(text, format!("{n:016}"));
        }
    }

    #[test]
    fn examples() {
        assert_eq!(fixed(45.07123456789, 11), "45.07123456789");
        assert_eq!(fixed(-0.0000004, 6), "0.000000");
        assert_eq!(fixed(-1.5, 0), "-2");
        assert_eq!(fixed(2.5, 0), "2");
        // An exact binary tie rounds to even, as std does.
        assert_eq!(fixed(-12.25, 1), "-12.2");
        assert_eq!(fixed(0.125, 2), "0.12");
        assert_eq!(fixed(0.000123, 6), "0.000123");
        assert_eq!(fixed(0.0, 3), "0.000");
        assert_eq!(fixed(-0.0, 0), "0");
        assert_eq!(fixed(9.9999996, 6), "10.000000");
        assert_eq!(fixed(1e300, 3), format!("{:.3}", 1e300));
        assert_eq!(fixed(f64::MIN_POSITIVE / 4.0, 19), "0.0000000000000000000");
        assert_eq!(fixed(1.8e19, 0), "18000000000000000000");
        assert_eq!(fixed(f64::NAN, 3), "NaN");
        assert_eq!(fixed(f64::NEG_INFINITY, 3), "-inf");
        assert_eq!(fixed(0.1, 25), format!("{:.25}", 0.1));
        // 14 and 15 digits take the lane path, 16 and more the digit loop.
        assert_eq!(fixed(-1234.5678901234, 11), "-1234.56789012340");
        assert_eq!(fixed(1234.5678901234, 11), "1234.56789012340");
        assert_eq!(fixed(12345.678901234, 11), "12345.67890123400");
        assert_eq!(fixed(123456789012345.0, 0), "123456789012345");
        assert_eq!(fixed(1234567890123456.0, 0), "1234567890123456");
    }

    /// Longitudes past 176 deg at 11 decimals: the product with 1e11 exceeds 2^44, where
    /// a floating-point product's rounding error (half an ulp, 0.002) can flip a
    /// near-tie unless the exact product decides. std is the reference.
    #[test]
    fn large_products_round_like_std() {
        let mut x: f64 = 179.99999999999;
        for _ in 0..100_000 {
            x = f64::from_bits(x.to_bits() - 7919);
            assert_eq!(fixed(x, 11), std_text(x, 11));
        }
    }

    proptest! {
        /// The same text as std for up to 12 decimals.
        #[test]
        fn agrees_with_std(x in -1e6..1e6f64, d in 0usize..=12) {
            prop_assert_eq!(fixed(x, d), std_text(x, d));
        }

        /// Any finite bit pattern, scaled to fit or not (then std itself writes it).
        #[test]
        fn agrees_with_std_on_any_bits(bits in any::<u64>(), d in 0usize..=19) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            prop_assert_eq!(fixed(x, d), std_text(x, d));
        }

        /// Values a few ulps around decimal ties, where a floating-point product fails.
        #[test]
        fn near_ties_agree_with_std(
            k in 0u64..1_000_000_000_000_000,
            d in 1usize..=12,
            ulps in -4i64..=4,
        ) {
            let tie = (k as f64 + 0.5) / POW10[d] as f64;
            let x = f64::from_bits(tie.to_bits().wrapping_add_signed(ulps));
            prop_assert_eq!(fixed(x, d), std_text(x, d));
        }

        /// [`put_field`]: std's text wherever it is in range, and in range for every
        /// number of a navigation line.
        #[test]
        fn fields_agree_with_std(x in -1e7..1e7f64, d in 0usize..=14) {
            match field(x, d) {
                Some(text) => prop_assert_eq!(text, std_text(x, d)),
                None => prop_assert!(!in_range(x, d)),
            }
        }

        /// The same for any bit pattern, NaN and infinities included.
        #[test]
        fn fields_agree_with_std_on_any_bits(bits in any::<u64>(), d in 0usize..=16) {
            let x = f64::from_bits(bits);
            match field(x, d) {
                Some(text) => prop_assert_eq!(text, std_text(x, d)),
                None => prop_assert!(!in_range(x, d)),
            }
        }

        /// A few ulps around decimal ties, where the exact product decides.
        #[test]
        fn fields_near_ties_agree_with_std(
            k in 0u64..1_000_000_000_000_000,
            d in 1usize..=14,
            ulps in -4i64..=4,
        ) {
            let tie = (k as f64 + 0.5) / POW10[d] as f64;
            let x = f64::from_bits(tie.to_bits().wrapping_add_signed(ulps));
            if let Some(text) = field(x, d) {
                prop_assert_eq!(text, std_text(x, d));
            }
        }
    }
}
