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

/// `|x| pow` rounded to the nearest integer, ties to even, from the exact `u128`
/// product (see the module doc).
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

/// The 8 decimal digits of `v < 10^8` as ASCII, the first in the lowest byte (so
/// `to_le_bytes` gives them in order): both 4-digit halves split into 2-digit and then
/// 1-digit lanes at once, by multiplications with reciprocals that are exact in these
/// ranges (`x 10486 >> 20 = x / 100` for `x < 10^4`, `x 103 >> 10 = x / 10` for `x <
/// 100`), no dependent divisions.
#[inline]
fn ascii8(v: u64) -> u64 {
    let halves = (v / 10_000) | ((v % 10_000) << 32);
    let hundreds = ((halves * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let pairs = hundreds | ((halves - hundreds * 100) << 16);
    let tens = ((pairs * 103) >> 10) & 0x000F_000F_000F_000F;
    let digits = tens | ((pairs - tens * 10) << 8);
    digits | 0x3030_3030_3030_3030
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
    }
}
