//! The map's bit layout, in one place: what the protocol receives, the firmware stores and the
//! grid reads.
//!
//! Cell `(x, y)` of a map `width` cells wide is cell `i = y * width + x` (row-major), stored as
//! bit `i % 8` of byte `i / 8` (least significant bit first); 1 = blocked. A map of `cells`
//! cells takes [`bytes`]`(cells)` bytes, the unused bits of its last byte being ignored.
//!
//! Every access is bounds-checked and panic-free: reading past the end gives `None` (each caller
//! says what that means: blocked for the grid, free for a change's bookkeeping), and writing past
//! the end does nothing.

/// Bytes a map of `cells` cells takes.
pub const fn bytes(cells: usize) -> usize {
    cells.div_ceil(8)
}

/// Cell `i`'s bit: `Some(true)` if blocked, `None` past the end of `bits`.
#[inline]
pub fn get(bits: &[u8], i: usize) -> Option<bool> {
    bits.get(i >> 3).map(|b| (b >> (i & 7)) & 1 == 1)
}

/// Set cell `i`'s bit to `blocked` (nothing past the end).
#[inline]
pub fn set(bits: &mut [u8], i: usize, blocked: bool) {
    if let Some(b) = bits.get_mut(i >> 3) {
        let m = 1u8 << (i & 7);
        if blocked {
            *b |= m;
        } else {
            *b &= !m;
        }
    }
}

/// Set cells `from .. from + len` to `blocked`, whole bytes at a time where it can (nothing past
/// the end).
pub fn fill(bits: &mut [u8], from: usize, len: usize, blocked: bool) {
    let end = from.saturating_add(len);
    let mut i = from;
    while i < end && i & 7 != 0 {
        set(bits, i, blocked);
        i = i.saturating_add(1);
    }
    let whole = end.saturating_sub(i) >> 3;
    if whole > 0 {
        let a = i >> 3;
        if let Some(s) = bits.get_mut(a..a.saturating_add(whole)) {
            s.fill(if blocked { 0xFF } else { 0 });
        }
        i = i.saturating_add(whole.saturating_mul(8));
    }
    while i < end {
        set(bits, i, blocked);
        i = i.saturating_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_row_major_least_significant_bit_first() {
        // Cell 0 is bit 0 of byte 0, cell 9 bit 1 of byte 1: what PROTOCOL.md's SetMap says.
        let mut b = [0u8; 3];
        set(&mut b, 0, true);
        set(&mut b, 9, true);
        assert_eq!(b, [0b1, 0b10, 0]);
        assert_eq!(
            (get(&b, 9), get(&b, 10), get(&b, 24)),
            (Some(true), Some(false), None)
        );
        set(&mut b, 9, false);
        set(&mut b, 99, true);
        assert_eq!(b, [0b1, 0, 0]);
        assert_eq!(bytes(17), 3);
    }

    #[test]
    fn fill_sets_exactly_its_cells() {
        // Every (from, len) over three bytes against setting the cells one by one.
        for from in 0..24 {
            for len in 0..(30 - from) {
                for blocked in [false, true] {
                    let start = if blocked { 0u8 } else { 0xFF };
                    let (mut a, mut b) = ([start; 3], [start; 3]);
                    fill(&mut a, from, len, blocked);
                    for i in from..from + len {
                        set(&mut b, i, blocked);
                    }
                    assert_eq!(a, b, "{from} {len} {blocked}");
                }
            }
        }
    }
}
