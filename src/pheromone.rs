//! The pheromone table `tau`: one `f32` per undirected edge between 8-connected neighbours.
//!
//! Each cell owns the four edges that leave it towards E, SE, S and SW; the other four directions
//! are the same edges seen from the neighbour. So the table is `[[f32; 4]; cells]`: 16 bytes a
//! cell (a 32x32 map: 16 KiB), half of what directed edges would cost, and an ant that walks an
//! edge in either direction reinforces the same entry. The table lives in storage the caller
//! provides ([`crate::planner::Storage`] or a host `Vec`).
//!
//! Values are kept in `[tau_min, tau_max]` (max-min ant system bounds): the wolves rule subtracts
//! pheromone, and without the floor an edge could go to zero or below and never be tried again.

use crate::grid::{Dir, Point, DX, DY};

/// Index of the undirected edge `(p, d)` as `(cell, slot)`, or `None` if the neighbour would be
/// off the map's index range (the caller only asks about allowed moves, so this does not happen).
#[inline]
pub fn edge(width: u16, p: Point, d: Dir) -> Option<(usize, usize)> {
    let d = d & 7;
    let (q, slot) = if d < 4 {
        (p, d)
    } else {
        let di = usize::from(d);
        // A u16 plus -1..=1: no i32 overflow.
        let x = i32::from(p.x).wrapping_add(DX.get(di).copied().unwrap_or(0));
        let y = i32::from(p.y).wrapping_add(DY.get(di).copied().unwrap_or(0));
        if x < 0 || y < 0 {
            return None;
        }
        (Point::new(x as u16, y as u16), d.wrapping_sub(4)) // d >= 4
    };
    // At most 65535 * 65535 + 65535 < 2^32: fits the (at least 32-bit) usize, see `crate::grid`.
    let cell = usize::from(q.y)
        .wrapping_mul(usize::from(width))
        .wrapping_add(usize::from(q.x));
    Some((cell, usize::from(slot)))
}

/// For each direction, the offset from `4 * cell` to the edge's slot in a flattened table: `d`
/// for the four directions a cell owns, `4 * offset(d) + (d - 4)` for the other four (the edge
/// is stored with the neighbour). `offsets` are [`crate::grid::Grid::offsets`].
pub fn slot_offsets(offsets: &[isize; 8]) -> [isize; 8] {
    let mut s = [0isize; 8];
    for (d, (slot, off)) in s.iter_mut().zip(offsets).enumerate() {
        *slot = if d < 4 {
            d as isize
        } else {
            // |off| <= width + 1 <= 65536: no overflow.
            off.wrapping_mul(4).wrapping_add(d as isize).wrapping_sub(4)
        };
    }
    s
}

/// A pheromone (or pheromone-increment) table over a map of width `width`.
#[derive(Debug)]
pub struct Table<'a> {
    width: u16,
    tau: &'a mut [[f32; 4]],
}

impl<'a> Table<'a> {
    /// A table over `tau` (at least `cells` entries) for a map `width` wide.
    pub fn new(width: u16, tau: &'a mut [[f32; 4]]) -> Self {
        Table { width, tau }
    }

    /// Set every edge to `value`.
    pub fn fill(&mut self, value: f32) {
        self.tau.fill([value; 4]);
    }

    /// The pheromone on edge `(p, d)` (0 if out of range).
    #[inline]
    pub fn get(&self, p: Point, d: Dir) -> f32 {
        edge(self.width, p, d)
            .and_then(|(c, s)| self.tau.get(c).and_then(|e| e.get(s)))
            .copied()
            .unwrap_or(0.0)
    }

    /// Add `amount` (may be negative) to edge `(p, d)`.
    #[inline]
    pub fn add(&mut self, p: Point, d: Dir, amount: f32) {
        if let Some(v) =
            edge(self.width, p, d).and_then(|(c, s)| self.tau.get_mut(c).and_then(|e| e.get_mut(s)))
        {
            *v += amount;
        }
    }

    /// `tau = clamp((1 - rho) tau + delta, lo, hi)` for every edge, and clears `delta`.
    pub fn evaporate_and_merge(&mut self, delta: &mut Table<'_>, rho: f32, lo: f32, hi: f32) {
        let keep = 1.0 - rho;
        for (t, d) in self.tau.iter_mut().zip(delta.tau.iter_mut()) {
            for (tv, dv) in t.iter_mut().zip(d.iter_mut()) {
                // Comparisons rather than `f32::clamp` (which has a panic path and pulls float
                // formatting into the firmware) or `max`/`min` (library calls on the M4, 6% of a
                // plan). A NaN would land on `lo`.
                let v = keep * *tv + *dv;
                *tv = if v > hi {
                    hi
                } else if v >= lo {
                    v
                } else {
                    lo
                };
                *dv = 0.0;
            }
        }
    }

    /// The table as one flat slice: edge `(cell, slot)` is at `4 * cell + slot`.
    #[inline]
    pub fn flat(&self) -> &[f32] {
        self.tau.as_flattened()
    }

    /// Add `amount` at a flat index (see [`Table::flat`]); out-of-range indices are ignored.
    #[inline]
    pub fn add_flat(&mut self, i: usize, amount: f32) {
        if let Some(v) = self.tau.as_flattened_mut().get_mut(i) {
            *v += amount;
        }
    }

    /// The raw entries, `[E, SE, S, SW]` per cell (for pictures and tests).
    pub fn entries(&self) -> &[[f32; 4]] {
        self.tau
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::opposite;

    #[test]
    fn both_directions_share_one_entry() {
        let mut buf = [[0.0f32; 4]; 9];
        let mut t = Table::new(3, &mut buf);
        let p = Point::new(1, 1);
        for d in 0..8u8 {
            let q = Point::new((1 + DX[d as usize]) as u16, (1 + DY[d as usize]) as u16);
            t.add(p, d, 1.0);
            assert_eq!(t.get(q, opposite(d)), 1.0, "dir {d}");
            t.add(q, opposite(d), -1.0);
            assert_eq!(t.get(p, d), 0.0);
        }
    }

    #[test]
    fn evaporation_clamps_and_clears_delta() {
        let mut a = [[1.0f32; 4]; 2];
        let mut b = [[0.5f32; 4]; 2];
        let mut ta = Table::new(2, &mut a);
        let mut tb = Table::new(2, &mut b);
        ta.evaporate_and_merge(&mut tb, 0.5, 0.01, 0.9);
        assert!(ta.entries().iter().flatten().all(|v| *v == 0.9));
        assert!(tb.entries().iter().flatten().all(|v| *v == 0.0));
    }
}
