//! Planner storage on the heap (feature `alloc`), for hosts: the same buffers as
//! [`crate::Storage`], but as `Vec`s sized at run time instead of a compile-time capacity (a
//! `Storage` for a 512x512 map would be 14 MiB on the stack).
//!
//! [`HeapStorage`] owns the buffers and lends them to a run with [`Workspace::from_slices`]; it
//! is only that wrapper, so it follows whatever buffers the workspace takes. It can be reused for
//! many runs and grows on demand ([`HeapStorage::ensure`], never shrinking). Allocation uses
//! `try_reserve`, so a map too large for the machine's memory is an [`AllocError`], not an abort.

use alloc::collections::TryReserveError;
use alloc::vec::Vec;
use core::fmt;

use crate::grid::{Dir, Point};
use crate::planner::{CurvePoint, Params, Workspace};

/// The planner's buffers, on the heap. See the module docs.
#[derive(Clone, Debug, Default)]
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

/// The buffers could not be allocated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AllocError {
    /// Cells asked for.
    pub cells: usize,
    /// Curve entries asked for.
    pub iterations: usize,
    /// Bytes that would be needed (saturated at `usize::MAX`).
    pub bytes: usize,
}

impl fmt::Display for AllocError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot allocate planner storage for {} cells and {} iterations ({} bytes)",
            self.cells, self.iterations, self.bytes
        )
    }
}

impl core::error::Error for AllocError {}

/// Grow `v` to `n` entries of `fill`, failing instead of aborting when memory is short.
fn grow<T: Clone>(v: &mut Vec<T>, n: usize, fill: T) -> Result<(), TryReserveError> {
    if let Some(more) = n.checked_sub(v.len()) {
        v.try_reserve_exact(more)?;
        v.resize(n, fill);
    }
    Ok(())
}

impl HeapStorage {
    /// Storage for maps of up to `cells` cells and convergence curves of `iterations` entries.
    pub fn new(cells: usize, iterations: usize) -> Result<Self, AllocError> {
        let mut s = HeapStorage::default();
        s.ensure(cells, iterations)?;
        Ok(s)
    }

    /// Storage for one run on a map of `cells` cells with `params` (the curve holds every
    /// iteration).
    pub fn for_run(cells: usize, params: &Params) -> Result<Self, AllocError> {
        HeapStorage::new(cells, usize::from(params.iterations))
    }

    /// Bytes needed for `cells` cells and `iterations` curve entries, saturating.
    pub fn bytes_for(cells: usize, iterations: usize) -> usize {
        cells
            .saturating_mul(Workspace::BYTES_PER_CELL)
            .saturating_add(iterations.saturating_mul(core::mem::size_of::<CurvePoint>()))
    }

    /// Grow the buffers (never shrink) to hold at least `cells` cells and `iterations` curve
    /// entries.
    pub fn ensure(&mut self, cells: usize, iterations: usize) -> Result<(), AllocError> {
        let err = |_| AllocError {
            cells,
            iterations,
            bytes: HeapStorage::bytes_for(cells, iterations),
        };
        grow(&mut self.tau, cells, [0.0; 4]).map_err(err)?;
        grow(&mut self.delta, cells, [0.0; 4]).map_err(err)?;
        grow(&mut self.visited, cells, 0).map_err(err)?;
        grow(&mut self.moves, cells, 0).map_err(err)?;
        for t in &mut self.tours {
            grow(t, cells, 0).map_err(err)?;
        }
        grow(&mut self.points, cells, Point::default()).map_err(err)?;
        grow(&mut self.prev, cells, 0).map_err(err)?;
        grow(&mut self.curve, iterations, CurvePoint::default()).map_err(err)?;
        Ok(())
    }

    /// The largest map (in cells) the storage can plan on.
    pub fn cells(&self) -> usize {
        self.tau.len()
    }

    /// Curve entries (iterations recorded by [`crate::Plan::curve`]).
    pub fn curve_len(&self) -> usize {
        self.curve.len()
    }

    /// Fill every buffer with arbitrary values derived from `salt` (xorshift32), so a test can
    /// check that a plan does not depend on what the storage held before.
    pub fn scramble(&mut self, salt: u32) {
        let mut x = salt.wrapping_mul(0x9E37_79B9) | 1;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        // Pheromone-like values in [0, 143): whole numbers / 7.
        for t in self.tau.iter_mut().chain(self.delta.iter_mut()) {
            *t = core::array::from_fn(|_| (next() % 1000) as f32 / 7.0);
        }
        for b in self
            .visited
            .iter_mut()
            .chain(self.moves.iter_mut())
            .chain(self.tours.iter_mut().flatten())
        {
            *b = next() as u8;
        }
        for p in &mut self.points {
            *p = Point::new(next() as u16, next() as u16);
        }
        for p in &mut self.prev {
            *p = next();
        }
    }

    /// Borrow the buffers as a workspace for one run.
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
    fn sizes_and_growth() {
        let mut s = HeapStorage::new(100, 10).unwrap();
        assert_eq!(s.cells(), 100);
        assert_eq!(s.curve_len(), 10);
        assert_eq!(s.workspace().capacity(), 100);
        s.ensure(50, 5).unwrap();
        assert_eq!((s.cells(), s.curve_len()), (100, 10), "never shrinks");
        s.ensure(512 * 512, 100).unwrap();
        assert_eq!(s.workspace().capacity(), 512 * 512);
        s.scramble(3);
        assert_eq!(s.workspace().capacity(), 512 * 512);
    }

    #[test]
    fn impossible_size_is_an_error() {
        let e = HeapStorage::new(usize::MAX / 2, 1).unwrap_err();
        assert_eq!(e.bytes, usize::MAX);
        assert!(e.to_string().starts_with("cannot allocate planner storage"));
    }
}
