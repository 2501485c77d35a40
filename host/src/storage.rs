//! Planner storage on the heap.
//!
//! The core never allocates: a run borrows every buffer through an [`ohaca::Workspace`]. On the
//! device those buffers are a fixed-size `static` [`ohaca::Storage`]; on the host a `Storage` for
//! a 512x512 map would be 14 MiB on the stack. [`HeapStorage`] owns the same buffers as `Vec`s
//! sized at run time and lends them with [`ohaca::Workspace::from_slices`]. It can be reused for
//! many runs (and grows on demand with [`HeapStorage::ensure`]), which the experiment and bench
//! commands rely on.
//!
//! Allocation uses `try_reserve`, so a map too large for the machine's memory is an error, not an
//! abort.

use std::collections::TryReserveError;

use ohaca::grid::Dir;
use ohaca::planner::CurvePoint;
use ohaca::{Point, Workspace};

/// The planner's buffers, on the heap. See the module docs.
#[derive(Debug, Default)]
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
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "cannot allocate planner storage for {cells} cells and {iterations} iterations ({bytes} bytes)"
)]
pub struct StorageError {
    /// Cells asked for.
    pub cells: usize,
    /// Curve entries asked for.
    pub iterations: usize,
    /// Bytes that would be needed (saturated at `usize::MAX`).
    pub bytes: usize,
}

/// Grow `v` to `n` entries of `fill`, failing instead of aborting when memory is short.
fn grow<T: Clone>(v: &mut Vec<T>, n: usize, fill: T) -> Result<(), TryReserveError> {
    if v.len() < n {
        v.try_reserve_exact(n - v.len())?;
        v.resize(n, fill);
    }
    Ok(())
}

impl HeapStorage {
    /// Storage for maps of up to `cells` cells and convergence curves of `iterations` entries.
    pub fn new(cells: usize, iterations: usize) -> Result<Self, StorageError> {
        let mut s = HeapStorage::default();
        s.ensure(cells, iterations)?;
        Ok(s)
    }

    /// Storage for one run on a map of `cells` cells with `params` (the curve holds every
    /// iteration).
    pub fn for_run(cells: usize, params: &ohaca::Params) -> Result<Self, StorageError> {
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
    pub fn ensure(&mut self, cells: usize, iterations: usize) -> Result<(), StorageError> {
        let err = |_| StorageError {
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

    /// Curve entries (iterations recorded by [`ohaca::Plan::curve`]).
    pub fn curve_len(&self) -> usize {
        self.curve.len()
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
    }

    #[test]
    fn impossible_size_is_an_error() {
        let e = HeapStorage::new(usize::MAX / 2, 1).unwrap_err();
        assert_eq!(e.bytes, usize::MAX);
    }
}
