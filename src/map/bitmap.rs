//! Sets of map cells at one bit per cell, in `u32` words: the ant's tabu list and the dead cells
//! of [`crate::map::prune`], the flood fill's marks.
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

/// Whether cell `i` is in the optional set `bits`: an empty set has no cells (where [`get`]
/// reads every cell beyond a set as in it). For the pruning marks, which a workspace may lack.
#[inline]
pub fn marked(bits: &[u32], i: usize) -> bool {
    !bits.is_empty() && get(bits, i)
}

/// Cells `i..i + 33` (at least) of the set as the low bits of a word (bit `k` = cell `i + k`);
/// cells beyond the buffer read as set, as [`get`] reads them. For passes over a map's rows 32
/// cells at a time.
#[inline]
pub fn window(bits: &[u32], i: usize) -> u64 {
    let k = i >> 5;
    let word = |n: usize| u64::from(bits.get(k.wrapping_add(n)).copied().unwrap_or(u32::MAX));
    let r = (i & 31) as u32;
    let low = (word(0) | word(1) << 32) >> r;
    if r == 0 {
        low
    } else {
        low | word(2) << (64u32.wrapping_sub(r) & 63)
    }
}

/// Add cell `i` to the set.
#[inline]
pub fn set(bits: &mut [u32], i: usize) {
    if let Some(w) = bits.get_mut(i >> 5) {
        *w |= 1 << (i & 31);
    }
}

/// Remove cell `i` from the set.
#[inline]
pub fn unset(bits: &mut [u32], i: usize) {
    if let Some(w) = bits.get_mut(i >> 5) {
        *w &= !(1 << (i & 31));
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

/// The bits of cells `i`, `i + 1`, `i + 2`, wrapping (bits 0-2; beyond the buffer: set).
#[inline]
pub fn three(bits: &[u32], i: usize) -> u32 {
    let (k, s) = (i >> 5, (i & 31) as u32);
    let lo = bits.get(k).copied().unwrap_or(u32::MAX) >> s;
    if s <= 29 {
        return lo & 7;
    }
    // The three bits straddle two words (s is 30 or 31, so 32 - s is 1 or 2): the next word is
    // cell `i + 2`'s, which wraps to word 0 for `i` at `usize::MAX - 1` or `usize::MAX` (what
    // [`around`] reads on the map's first row and column).
    let hi = bits
        .get(i.wrapping_add(2) >> 5)
        .copied()
        .unwrap_or(u32::MAX);
    (lo | hi << (32u32.wrapping_sub(s) & 31)) & 7
}

/// The set's members among the eight neighbours of cell `i` of a map `width` cells wide, as a
/// direction mask (bit `d`: the neighbour in direction `d` of [`crate::map::dir`]). The
/// neighbours' indices are taken as `i +- 1`, `i +- width`, ... (wrapping): on the map's border a
/// direction off the map reads another row's cell, or a cell beyond the words (set), so a caller
/// on the border masks those directions out.
#[inline]
pub fn around(bits: &[u32], i: usize, width: usize) -> u8 {
    around_top(bits, i.wrapping_sub(width).wrapping_sub(1), width)
}

/// [`around`] of the cell whose 3 x 3 neighbourhood's top-left cell is `top`.
#[inline(always)]
pub fn around_top(bits: &[u32], top: usize, width: usize) -> u8 {
    let mid = top.wrapping_add(width);
    let bottom = mid.wrapping_add(width);
    ring(three(bits, top) | three(bits, mid) << 3 | three(bits, bottom) << 6)
}

/// A 3 x 3 neighbourhood's cells (bit `3 r + c` = cell `(x - 1 + c, y - 1 + r)`; bits above 8
/// ignored) as a direction mask (bit `d` = the neighbour in direction `d`; the centre left out).
#[inline(always)]
pub fn ring(nb: u32) -> u8 {
    RING9.get(nb as usize & 511).copied().unwrap_or(0)
}

/// For each 3 x 3 neighbourhood (bit `3 r + c` = cell `(x - 1 + c, y - 1 + r)`), the same cells as
/// a direction mask (bit `d` = the neighbour in direction `d`; the centre is left out).
#[allow(clippy::indexing_slicing, clippy::arithmetic_side_effects)]
static RING9: [u8; 512] = {
    use crate::map::dir::{DX, DY};
    let mut t = [0u8; 512];
    let mut nb = 0usize;
    while nb < 512 {
        let mut m = 0u8;
        let mut d = 0usize;
        while d < 8 {
            let bit = ((1 + DY[d]) * 3 + (1 + DX[d])) as usize;
            if (nb >> bit) & 1 == 1 {
                m |= 1 << d;
            }
            d += 1;
        }
        t[nb] = m;
        nb += 1;
    }
    t
};

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

    /// A set over `cells` cells, each in it with probability 1/2 (the crate's generator from
    /// `seed`).
    fn random_bits(cells: usize, seed: u64) -> Vec<u32> {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(seed);
        let mut b = vec![0u32; words(cells)];
        for i in 0..cells {
            if rng.next_word() & 1 == 1 {
                set(&mut b, i);
            }
        }
        b
    }

    #[test]
    fn around_reads_the_eight_neighbours() {
        use crate::map::dir::{DX, DY};
        let (w, h) = (37usize, 5usize);
        let b = random_bits(w * h, 12345);
        for y in 1..h - 1 {
            for cx in 1..w - 1 {
                let i = y * w + cx;
                let mut want = 0u8;
                for d in 0..8 {
                    let j = ((y as i32 + DY[d]) * w as i32 + cx as i32 + DX[d]) as usize;
                    if get(&b, j) {
                        want |= 1 << d;
                    }
                }
                assert_eq!(around(&b, i, w), want, "cell {i}");
            }
        }
    }

    #[test]
    fn around_reads_the_neighbours_on_the_map_from_the_border_too() {
        // On the border a direction off the map reads anything (the caller masks it out); a
        // neighbour on the map reads its own bit, the first row's and column's too, whose reads
        // wrap below index 0 (`three` takes the next word from cell `i + 2`, wrapping).
        use crate::map::dir::{DX, DY};
        for (w, h) in [(37usize, 5usize), (32, 3), (3, 3), (30, 4)] {
            let b = random_bits(w * h, 987);
            for y in 0..h as i32 {
                for cx in 0..w as i32 {
                    let i = (y * w as i32 + cx) as usize;
                    let got = around(&b, i, w);
                    for d in 0..8 {
                        let (nx, ny) = (cx + DX[d], y + DY[d]);
                        if nx < 0 || ny < 0 || nx >= w as i32 || ny >= h as i32 {
                            continue;
                        }
                        let j = (ny * w as i32 + nx) as usize;
                        assert_eq!(got >> d & 1 == 1, get(&b, j), "{w}x{h} cell {i} dir {d}");
                    }
                }
            }
        }
    }
}
