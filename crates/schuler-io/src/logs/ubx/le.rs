//! Little-endian fields of a UBX payload at a byte offset (the caller checks the
//! payload's length against the message's layout first).

/// `u16` at `off`.
pub fn u16(p: &[u8], off: usize) -> u16 {
    u16::from_le_bytes([p[off], p[off + 1]])
}

/// `u32` at `off`.
pub fn u32(p: &[u8], off: usize) -> u32 {
    u32::from_le_bytes([p[off], p[off + 1], p[off + 2], p[off + 3]])
}

/// `i32` at `off`.
pub fn i32(p: &[u8], off: usize) -> i32 {
    u32(p, off) as i32
}

/// `f64` (IEEE 754 binary64) at `off`.
pub fn f64(p: &[u8], off: usize) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&p[off..off + 8]);
    f64::from_le_bytes(b)
}
