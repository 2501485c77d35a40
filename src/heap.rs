//! Planner storage on the heap (feature `alloc`), for hosts: the same buffers as
//! [`crate::Storage`], but as `Vec`s sized at run time instead of a compile-time capacity (a
//! `Storage` for a 512x512 map would be 14 MiB on the stack).
//!
//! [`HeapStorage`] holds the buffers in the same `OwnedBuffers` as [`crate::Storage`] (`Vec`s
//! where that has arrays), which lends them to a run as a [`Workspace`]; so it follows whatever
//! buffers the workspace takes. It gives ant paths room for every cell and the move table, so
//! nothing is ever cut short (the device's [`crate::Storage`] bounds the paths;
//! [`HeapStorage::with_steps`] gives the same bound on the host). It can be reused for many runs
//! and grows on demand ([`HeapStorage::ensure`], never shrinking). Allocation uses
//! `try_reserve`, so a map too large for the machine's memory is an [`AllocError`], not an abort.

use alloc::collections::TryReserveError;
use alloc::vec::Vec;
use core::fmt;

use crate::colony::pheromone::BLOCKS;
use crate::colony::route::GUIDE_BLOCKS;
use crate::map::bitmap::words;
use crate::map::grid::{Dir, Point};
use crate::planner::{CurvePoint, OwnedBuffers, Params, Workspace};

/// The buffers, each a `Vec`.
type Vecs = OwnedBuffers<
    Vec<[f32; 4]>,
    Vec<u32>,
    Vec<u8>,
    Vec<Dir>,
    Vec<Dir>,
    Vec<Point>,
    Vec<u32>,
    Vec<CurvePoint>,
    Vec<u32>,
    Vec<u32>,
>;

/// The planner's buffers, on the heap. See the module docs.
#[derive(Clone, Debug, Default)]
pub struct HeapStorage {
    cells: usize,
    /// No buffers for the iteration's best and worst paths ([`HeapStorage::replaying`]).
    replay: bool,
    /// No weight table ([`HeapStorage::unweighted`]).
    unweighted: bool,
    buffers: Vecs,
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
        if cells > usize::MAX / 64 || iterations > usize::MAX / 64 {
            return usize::MAX;
        }
        Workspace::bytes(cells, cells, true, iterations)
            .saturating_add(Workspace::weight_words(cells).saturating_mul(4))
    }

    /// Storage like [`HeapStorage::new`] whose ant paths are bounded to `steps` steps (the
    /// device's bound), with or without the move table: for host runs that must match a device
    /// bit for bit.
    pub fn with_steps(
        cells: usize,
        steps: usize,
        moves: bool,
        iterations: usize,
    ) -> Result<Self, AllocError> {
        let mut s = HeapStorage::new(cells, iterations)?;
        let steps = steps.max(1);
        for t in s.buffers.tours.iter_mut().chain(&mut s.buffers.kept) {
            t.truncate(steps);
        }
        s.buffers.points.truncate(steps.saturating_add(1));
        if cells > steps.saturating_add(1).saturating_mul(2) {
            let links = steps
                .saturating_add(1)
                .saturating_mul(2)
                .checked_next_power_of_two()
                .unwrap_or(usize::MAX)
                .max(GUIDE_BLOCKS);
            s.buffers.links.truncate(links);
        }
        if !moves {
            s.buffers.moves.clear();
        }
        Ok(s)
    }

    /// The same storage with at most `links` links: for a device that has fewer than
    /// [`HeapStorage::with_steps`] gives (the STM32H743 keeps paths of 16,384 steps with
    /// tightening's smallest table, `crate::colony::tighten::hash_words`). [`HeapStorage::ensure`]
    /// grows them again.
    pub fn with_links(mut self, links: usize) -> Self {
        self.buffers.links.truncate(links);
        self
    }

    /// Drop the buffers of the iteration's best and worst paths, as a device's storage may
    /// ([`crate::Storage`]'s `KEPT` = 0): runs walk those two ants again instead, with the same
    /// paths bit for bit.
    pub fn replaying(mut self) -> Self {
        self.replay = true;
        for t in &mut self.buffers.kept {
            *t = Vec::new();
        }
        self
    }

    /// Drop the colony's weight table, as the device's storages have none
    /// ([`Workspace::with_weights`]): the walks compute their weights at each move instead, with
    /// the same paths bit for bit.
    pub fn unweighted(mut self) -> Self {
        self.unweighted = true;
        self.buffers.weights = Vec::new();
        self
    }

    /// Grow the buffers (never shrink) to hold at least `cells` cells and `iterations` curve
    /// entries.
    pub fn ensure(&mut self, cells: usize, iterations: usize) -> Result<(), AllocError> {
        let err = |_: ()| AllocError {
            cells,
            iterations,
            bytes: HeapStorage::bytes_for(cells, iterations),
        };
        if cells > usize::MAX / 64 {
            return Err(err(()));
        }
        let e = |_: TryReserveError| err(());
        self.cells = self.cells.max(cells);
        let cells = self.cells;
        let b = &mut self.buffers;
        grow(&mut b.tau, cells.min(BLOCKS), [0.0; 4]).map_err(e)?;
        grow(&mut b.delta, cells.min(BLOCKS), [0.0; 4]).map_err(e)?;
        grow(&mut b.tabu, words(cells), 0).map_err(e)?;
        grow(&mut b.dead, words(cells), 0).map_err(e)?;
        grow(&mut b.moves, cells, 0).map_err(e)?;
        let steps = cells.max(1);
        for t in &mut b.tours {
            grow(t, steps, 0).map_err(e)?;
        }
        if !self.replay {
            for t in &mut b.kept {
                grow(t, steps, 0).map_err(e)?;
            }
        }
        grow(&mut b.points, steps.saturating_add(1), Point::default()).map_err(e)?;
        grow(&mut b.links, cells.max(GUIDE_BLOCKS), 0).map_err(e)?;
        grow(&mut b.curve, iterations, CurvePoint::default()).map_err(e)?;
        if cells > BLOCKS {
            grow(&mut b.guide, GUIDE_BLOCKS, 0).map_err(e)?;
        }
        if !self.unweighted {
            grow(&mut b.weights, Workspace::weight_words(cells), 0).map_err(e)?;
        }
        Ok(())
    }

    /// The largest map (in cells) the storage can plan on.
    pub fn cells(&self) -> usize {
        self.cells
    }

    /// Curve entries (iterations recorded by [`crate::Plan::curve`]).
    pub fn curve_len(&self) -> usize {
        self.buffers.curve.len()
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
        let b = &mut self.buffers;
        // Pheromone-like values in [0, 143): whole numbers / 7.
        for t in b.tau.iter_mut().chain(b.delta.iter_mut()) {
            *t = core::array::from_fn(|_| (next() % 1000) as f32 / 7.0);
        }
        let tours = b.tours.iter_mut().chain(&mut b.kept).flatten();
        for byte in b.moves.iter_mut().chain(tours) {
            *byte = next() as u8;
        }
        for p in &mut b.points {
            *p = Point::new(next() as u16, next() as u16);
        }
        for w in b
            .tabu
            .iter_mut()
            .chain(b.dead.iter_mut())
            .chain(b.links.iter_mut())
            .chain(b.guide.iter_mut())
            .chain(b.weights.iter_mut())
        {
            *w = next();
        }
    }

    /// Borrow the buffers as a workspace for one run.
    pub fn workspace(&mut self) -> Workspace<'_> {
        self.buffers.workspace()
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
        assert_eq!(s.cells(), 512 * 512);
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
