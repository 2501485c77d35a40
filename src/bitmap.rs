//! Sets of map cells at one bit per cell, in `u32` words: the ant's tabu list and the dead cells
//! of [`crate::prune`], the flood fill's marks.
//!
//! A 256 x 256 map needs 2,048 words (8 KiB) per set, where a byte per cell would need 64 KiB:
//! this is what lets the colony's memory stay independent of the map's size apart from these
//! bits. Every access is bounds-checked: a cell beyond the buffer reads as set (so it is never
//! entered) and writes to it are ignored.

/// Words needed for a set over `cells` cells.
pub const fn words(cells: usize) -> usize {
    cells.div_ceil(32)
}

/// True if cell `i` is in the set (or beyond the buffer).
#[inline]
pub fn get(bits: &[u32], i: usize) -> bool {
    match bits.get(i >> 5) {
        Some(w) => (w >> (i & 31)) & 1 == 1,
        None => true,
    }
}

/// Add cell `i` to the set.
#[inline]
pub fn set(bits: &mut [u32], i: usize) {
    if let Some(w) = bits.get_mut(i >> 5) {
        *w |= 1 << (i & 31);
    }
}

/// Add cell `i`; returns true if it was not in the set before.
#[inline]
pub fn insert(bits: &mut [u32], i: usize) -> bool {
    match bits.get_mut(i >> 5) {
        Some(w) => {
            let m = 1u32 << (i & 31);
            let fresh = *w & m == 0;
            *w |= m;
            fresh
        }
        None => false,
    }
}

/// Empty the first `words(cells)` words.
pub fn clear(bits: &mut [u32], cells: usize) {
    let n = words(cells).min(bits.len());
    if let Some(b) = bits.get_mut(..n) {
        b.fill(0);
    }
}

/// Copy the first `words(cells)` words of `src` into `dst`.
pub fn copy(dst: &mut [u32], src: &[u32], cells: usize) {
    let n = words(cells).min(dst.len()).min(src.len());
    if let (Some(d), Some(s)) = (dst.get_mut(..n), src.get(..n)) {
        d.copy_from_slice(s);
    }
}

/// Number of cells in the set among the first `cells`.
pub fn count(bits: &[u32], cells: usize) -> u32 {
    let full = cells >> 5;
    let mut n = 0u32;
    for (k, w) in bits.iter().enumerate().take(words(cells)) {
        let w = if k < full {
            *w
        } else {
            // The last, partial word: only its low `cells % 32` bits are cells (0 < rem < 32).
            *w & (1u32 << (cells & 31)).wrapping_sub(1)
        };
        n = n.wrapping_add(w.count_ones()); // <= cells < 2^32
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_get_insert_clear_count() {
        let mut b = [0u32; 3];
        assert_eq!(words(65), 3);
        assert!(!get(&b, 40));
        set(&mut b, 40);
        assert!(get(&b, 40));
        assert!(insert(&mut b, 64));
        assert!(!insert(&mut b, 64));
        assert_eq!(count(&b, 65), 2);
        assert_eq!(count(&b, 64), 1);
        // Beyond the buffer: reads as set, writes ignored.
        assert!(get(&b, 96));
        set(&mut b, 1000);
        let mut c = [0u32; 3];
        copy(&mut c, &b, 65);
        assert_eq!(c, b);
        clear(&mut b, 65);
        assert_eq!(b, [0; 3]);
    }
}
