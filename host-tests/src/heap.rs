//! A heap-backed workspace: every buffer the core's [`Workspace`] borrows, as `Vec`s sized for any
//! cell count (the core's [`ohaca::Storage`] needs its capacity at compile time).

use ohaca::bitmap::words;
use ohaca::grid::Dir;
use ohaca::pheromone::BLOCKS;
use ohaca::route::GUIDE_BLOCKS;
use ohaca::{Buffers, CurvePoint, Point, Workspace};

/// Convergence-curve entries [`HeapStorage::new`] allocates (enough for the default 100
/// iterations and everything the tests run).
pub const DEFAULT_CURVE: usize = 1024;

/// Owned buffers for plans on maps of up to `cells` cells.
#[derive(Clone, Debug)]
pub struct HeapStorage {
    tau: Vec<[f32; 4]>,
    delta: Vec<[f32; 4]>,
    tabu: Vec<u32>,
    dead: Vec<u32>,
    moves: Vec<u8>,
    tours: [Vec<Dir>; 4],
    points: Vec<Point>,
    links: Vec<u32>,
    curve: Vec<CurvePoint>,
    guide: Vec<u32>,
}

impl HeapStorage {
    /// Storage for maps of up to `cells` cells and a curve of [`DEFAULT_CURVE`] iterations, with
    /// room for ant paths through every cell and the move table (nothing is ever cut short).
    pub fn new(cells: usize) -> Self {
        Self::with_capacities(cells, cells, true, DEFAULT_CURVE)
    }

    /// Storage for maps of up to `cells` cells and a curve of `curve` iterations.
    pub fn with_curve(cells: usize, curve: usize) -> Self {
        Self::with_capacities(cells, cells, true, curve)
    }

    /// Storage with explicit capacities: maps of up to `cells` cells, ant paths of up to `steps`
    /// steps, the move table or not, `curve` iterations. `links` is what the device uses: one
    /// per cell if `cells` is at most twice the path cells, else twice the path cells.
    pub fn with_capacities(cells: usize, steps: usize, moves: bool, curve: usize) -> Self {
        let steps = steps.max(1);
        let links = if cells <= 2 * (steps + 1) {
            cells
        } else {
            (2 * (steps + 1)).next_power_of_two().max(GUIDE_BLOCKS)
        };
        HeapStorage {
            tau: vec![[0.0; 4]; cells.min(BLOCKS)],
            delta: vec![[0.0; 4]; cells.min(BLOCKS)],
            tabu: vec![0; words(cells)],
            dead: vec![0; words(cells)],
            moves: vec![0; if moves { cells } else { 0 }],
            tours: std::array::from_fn(|_| vec![0; steps]),
            points: vec![Point::default(); steps + 1],
            links: vec![0; links],
            curve: vec![CurvePoint::default(); curve],
            guide: vec![0; if cells > BLOCKS { GUIDE_BLOCKS } else { 0 }],
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
        for b in s.moves.iter_mut().chain(s.tours.iter_mut().flatten()) {
            *b = next() as u8;
        }
        for w in s
            .tabu
            .iter_mut()
            .chain(s.dead.iter_mut())
            .chain(s.links.iter_mut())
        {
            *w = next();
        }
        for p in &mut s.points {
            *p = Point::new(next() as u16, next() as u16);
        }
        s
    }

    /// The cell capacity.
    pub fn capacity(&self) -> usize {
        self.tabu.len() * 32
    }

    /// Borrow everything as a core workspace.
    pub fn workspace(&mut self) -> Workspace<'_> {
        let [t0, t1, t2, t3] = &mut self.tours;
        Workspace::new(Buffers {
            tau: &mut self.tau,
            delta: &mut self.delta,
            tabu: &mut self.tabu,
            dead: &mut self.dead,
            moves: &mut self.moves,
            tours: [t0, t1, t2, t3],
            points: &mut self.points,
            links: &mut self.links,
            curve: &mut self.curve,
            guide: &mut self.guide,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capacity_is_cells_rounded_to_words() {
        let mut s = HeapStorage::new(37);
        assert_eq!(s.capacity(), 64);
        assert_eq!(s.workspace().capacity(), 37);
        let mut d = HeapStorage::dirty(5, 3);
        assert_eq!(d.workspace().capacity(), 5);
    }
}
