//! A heap-backed workspace: every buffer the core's [`Workspace`] borrows, as `Vec`s sized for any
//! cell count (the core's [`ohaca::Storage`] needs its capacity at compile time).

use ohaca::grid::Dir;
use ohaca::{CurvePoint, Point, Workspace};

/// Convergence-curve entries [`HeapStorage::new`] allocates (enough for the default 100
/// iterations and everything the tests run).
pub const DEFAULT_CURVE: usize = 1024;

/// Owned buffers for plans on maps of up to `cells` cells.
#[derive(Clone, Debug)]
pub struct HeapStorage {
    tau: Vec<[f32; 4]>,
    delta: Vec<[f32; 4]>,
    visited: Vec<u8>,
    moves: Vec<u8>,
    tours: [Vec<Dir>; 4],
    points: Vec<Point>,
    prev: Vec<u32>,
    curve: Vec<CurvePoint>,
}

impl HeapStorage {
    /// Storage for maps of up to `cells` cells and a curve of [`DEFAULT_CURVE`] iterations.
    pub fn new(cells: usize) -> Self {
        Self::with_curve(cells, DEFAULT_CURVE)
    }

    /// Storage for maps of up to `cells` cells and a curve of `curve` iterations.
    pub fn with_curve(cells: usize, curve: usize) -> Self {
        HeapStorage {
            tau: vec![[0.0; 4]; cells],
            delta: vec![[0.0; 4]; cells],
            visited: vec![0; cells],
            moves: vec![0; cells],
            tours: std::array::from_fn(|_| vec![0; cells]),
            points: vec![Point::default(); cells],
            prev: vec![0; cells],
            curve: vec![CurvePoint::default(); curve],
        }
    }

    /// Storage whose buffers hold arbitrary junk (a fixed pattern derived from `salt`), to check
    /// that a plan does not depend on what the workspace held before.
    pub fn dirty(cells: usize, salt: u32) -> Self {
        let mut s = Self::new(cells);
        let mut x = salt.wrapping_mul(0x9E37_79B9) | 1;
        let mut next = move || {
            // xorshift32
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        for t in s.tau.iter_mut().chain(s.delta.iter_mut()) {
            *t = std::array::from_fn(|_| (next() % 1000) as f32 / 7.0);
        }
        for b in s
            .visited
            .iter_mut()
            .chain(s.moves.iter_mut())
            .chain(s.tours.iter_mut().flatten())
        {
            *b = next() as u8;
        }
        for p in &mut s.points {
            *p = Point::new(next() as u16, next() as u16);
        }
        for p in &mut s.prev {
            *p = next();
        }
        s
    }

    /// The cell capacity.
    pub fn capacity(&self) -> usize {
        self.tau.len()
    }

    /// Borrow everything as a core workspace.
    pub fn workspace(&mut self) -> Workspace<'_> {
        let [t0, t1, t2, t3] = &mut self.tours;
        Workspace::from_slices(
            &mut self.tau,
            &mut self.delta,
            &mut self.visited,
            &mut self.moves,
            [t0, t1, t2, t3],
            &mut self.points,
            &mut self.prev,
            &mut self.curve,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capacity_is_cells() {
        let mut s = HeapStorage::new(37);
        assert_eq!(s.capacity(), 37);
        assert_eq!(s.workspace().capacity(), 37);
        let mut d = HeapStorage::dirty(5, 3);
        assert_eq!(d.workspace().capacity(), 5);
    }
}
