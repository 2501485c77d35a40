//! Every buffer a run needs, borrowed from the caller ([`Workspace`]) or owned with compile-time
//! capacities ([`Storage`], for a `static` on the device). Nothing is allocated.
//!
//! What scales with what:
//!
//! | buffer | entries | bytes | what for |
//! | --- | --- | --- | --- |
//! | `tabu`, `dead` | `words(cells)` each | 1 bit a cell each | the ant's tabu list; pruned cells |
//! | `tau`, `delta` | [`BLOCKS`] (fewer on maps of fewer cells) | 16 each | pheromone and its increment |
//! | `moves` | `cells`, or none | 1 | allowed-move masks (computed on the fly without it) |
//! | 2 tours | `steps` each | 1 | the ant's path, the best so far |
//! | 2 more tours, or none | `steps` each | 1 | the iteration's best and worst paths |
//! | `points` | `steps + 1` | 4 | the best path as cells, tightening scratch |
//! | `links` | `cells`, or at least tightening's table ([`crate::colony::tighten::hash_words`]`(steps + 1)`: `2 (steps + 1)` half-word slots at a load of 1/2, down to `3 (steps + 1) / 2` at 2/3; fewer leave walks untightened), `steps + 1` (the smoothing's shortest-path rule; fewer: its greedy rule) and [`GUIDE_BLOCKS`] | 4 | path positions (tightening), flood-fill ring, pruning stack, route heap, smoothing links |
//! | `curve` | iterations recorded | 16 | the convergence curve |
//! | `guide` | [`GUIDE_BLOCKS`] on maps of more than [`BLOCKS`] cells, else none; an eighth of that packed ([`Workspace::with_packed_route`]) | 4 | the coarse route ([`crate::colony::route`]) |
//! | `weights`, or none | 12 a cell and 4 on maps of at most [`BLOCKS`] cells ([`Workspace::weight_words`]; feature `alloc`: the heap storage gives it, a device's storages none) | 4 | the iteration's weights by cell and direction ([`crate::colony::weights`]; without it the walks compute them at each move, the same walks), and the tabu set's rows layout beside them ([`crate::colony::tabu`]) |
//!
//! A buffer idle in a phase lends itself to another role there (the links above, the tabu set to
//! the route's heap and the local search, the path cells to tightening's keyed table); each phase
//! borrows the workspace through its own typed view, which decides that in one place
//! (`planner::lend`: `Setting`, `Colony`, `Polishing`).
//!
//! So the colony's memory is a fixed budget (pheromone) plus what the longest ant path needs
//! (`steps`), plus two bits a map cell. The map itself (one bit a cell) is the caller's.
//! An ant whose path grows beyond `steps` is dropped; `links` shorter than `cells` switches
//! tightening to a hash table. Neither changes a path that fits.
//!
//! **The iteration's best and worst paths** are kept in `iter_best` and `iter_worst`, or, when
//! those are empty, walked again: the run keeps each one's ant (the generator's state before its
//! walk and its move budget) and walks it again after the iteration, before the update. Nothing
//! an ant reads changes during an iteration (the ants deposit into `delta`; `tau`, the marks and
//! the route change only at the update), so the second walk is the first, bit for bit: the same
//! increments, the same best path, the same plan (a test compares every algorithm and dead-end
//! rule both ways). It costs two walks an iteration (about 4 % of an iteration's moves with 50
//! ants) and saves two bytes a path step: on the STM32F411 that is what paths of 2,047 steps fit in
//! (its arena's full layout; the compact one keeps 4,095, [`super::arena`]).

use crate::colony::pheromone::{Blocks, BLOCKS};
use crate::colony::route::{Route, GUIDE_BLOCKS};
use crate::error::Error;
use crate::map::bitmap::words;
use crate::map::grid::{Dir, Point};

use super::plan::CurvePoint;

/// Every buffer a run needs, borrowed from the caller (see the module docs for the sizes).
#[derive(Debug)]
pub struct Workspace<'a> {
    pub(super) tau: &'a mut [[f32; 4]],
    pub(super) delta: &'a mut [[f32; 4]],
    pub(super) tabu: &'a mut [u32],
    pub(super) dead: &'a mut [u32],
    pub(super) moves: &'a mut [u8],
    pub(super) tour: &'a mut [Dir],
    pub(super) iter_best: &'a mut [Dir],
    pub(super) iter_worst: &'a mut [Dir],
    pub(super) best: &'a mut [Dir],
    pub(super) points: &'a mut [Point],
    pub(super) links: &'a mut [u32],
    pub(super) curve: &'a mut [CurvePoint],
    /// The coarse route: a word a block, or packed ([`Workspace::with_packed_route`]).
    pub(super) guide: Guide<'a>,
    /// The colony's weight table ([`Workspace::with_weights`]; empty: none). Only where a heap
    /// storage can give one (feature `alloc`): a device's workspaces keep their size.
    #[cfg(any(feature = "alloc", test))]
    pub(super) weights: &'a mut [u32],
}

/// The caller's buffers, by name, for [`Workspace::new`].
#[derive(Debug)]
pub struct Buffers<'a> {
    /// Pheromone: [`BLOCKS`] entries (or as many as the largest map's [`Blocks::count`]).
    pub tau: &'a mut [[f32; 4]],
    /// Pheromone increments: as many as `tau`.
    pub delta: &'a mut [[f32; 4]],
    /// Tabu bit set: [`words`]`(cells)` words.
    pub tabu: &'a mut [u32],
    /// Pruned-cell bit set: as many as `tabu`.
    pub dead: &'a mut [u32],
    /// Allowed-move masks: `cells` bytes, or empty to compute them on the fly.
    pub moves: &'a mut [u8],
    /// The four tours, `steps` entries each (the longest ant path the run keeps): the ant's
    /// path, the iteration's best, its worst, the run's best. The second and third may be empty:
    /// those paths are then walked again instead of kept (see the module docs).
    pub tours: [&'a mut [Dir]; 4],
    /// Path cells: `steps + 1`.
    pub points: &'a mut [Point],
    /// Links: `cells`, or at least tightening's hash table, `steps + 1` and [`GUIDE_BLOCKS`] (see
    /// the module docs).
    pub links: &'a mut [u32],
    /// Convergence curve: one entry per iteration recorded.
    pub curve: &'a mut [CurvePoint],
    /// The coarse route on large maps ([`crate::colony::route`]): [`GUIDE_BLOCKS`] entries (none needed on
    /// maps of at most [`BLOCKS`] cells).
    pub guide: &'a mut [u32],
}

impl<'a> Workspace<'a> {
    /// Bytes a workspace needs for maps of `cells` cells and ant paths of up to `steps` steps, with
    /// or without the move table and with a curve of `curve` iterations (saturating).
    #[allow(clippy::arithmetic_side_effects)] // saturating below; const fn cannot use the methods' closures
    pub const fn bytes(cells: usize, steps: usize, moves: bool, curve: usize) -> usize {
        if cells > usize::MAX / 64 || steps > usize::MAX / 64 || curve > usize::MAX / 64 {
            return usize::MAX;
        }
        let bits = 2 * 4 * words(cells);
        let pheromone = 2 * 16 * if cells < BLOCKS { cells } else { BLOCKS };
        let moves = if moves { cells } else { 0 };
        let links = 4 * if cells < 2 * (steps + 1) {
            cells
        } else {
            2 * (steps + 1)
        };
        let guide = if cells > BLOCKS { 4 * GUIDE_BLOCKS } else { 0 };
        bits + pheromone + moves + 4 * steps + 4 * (steps + 1) + links + 16 * curve + guide
    }

    /// [`Workspace::bytes`] for a workspace without the iteration's best and worst paths
    /// (`iter_best` and `iter_worst` empty: those two ants are walked again, the module docs).
    pub const fn bytes_walking_again(
        cells: usize,
        steps: usize,
        moves: bool,
        curve: usize,
    ) -> usize {
        Self::bytes(cells, steps, moves, curve).saturating_sub(steps.saturating_mul(2))
    }

    /// A workspace over the caller's buffers.
    pub fn new(b: Buffers<'a>) -> Self {
        let [tour, iter_best, iter_worst, best] = b.tours;
        Workspace {
            tau: b.tau,
            delta: b.delta,
            tabu: b.tabu,
            dead: b.dead,
            moves: b.moves,
            tour,
            iter_best,
            iter_worst,
            best,
            points: b.points,
            links: b.links,
            curve: b.curve,
            guide: Guide::Words(b.guide),
            #[cfg(any(feature = "alloc", test))]
            weights: &mut [],
        }
    }

    /// Words of the colony's weight table ([`Workspace::with_weights`]) for maps of up to `cells`
    /// cells: [`crate::colony::weights::words`] (10 a cell) for the maps whose walks read one (at most
    /// [`BLOCKS`] cells: the pheromone has an entry a cell), none for larger ones, and beside
    /// the table the tabu set's rows layout on maps at most
    /// [`crate::colony::tabu::ROWS_WIDTH`] wide ([`crate::colony::tabu::rows_words`]: 2 a cell
    /// and 4; saturating).
    pub const fn weight_words(cells: usize) -> usize {
        let c = if cells < BLOCKS { cells } else { BLOCKS };
        crate::colony::weights::words(c).saturating_add(crate::colony::tabu::rows_words(c))
    }

    /// The same workspace with a weight table in `weights` ([`crate::colony::weights`]: the
    /// iteration's `tau^alpha * eta^beta` by cell and direction, filled as the ants first stand on
    /// a cell): the walks on a map of at most [`BLOCKS`] cells read their weights from it when it
    /// holds [`Workspace::weight_words`]`(cells)` words, at fewer instructions a move; otherwise
    /// they compute them at each move. The same plan bit for bit either way. The heap storage
    /// gives one; the device arenas none.
    #[cfg(any(feature = "alloc", test))]
    pub fn with_weights(self, weights: &'a mut [u32]) -> Self {
        Workspace { weights, ..self }
    }

    /// The same workspace keeping its coarse route packed in `guide`, four bits a block
    /// ([`crate::colony::route::pack`]): [`GUIDE_BLOCKS`]` / 8` words for the finest route, its words
    /// and heap built in the tabu set or the links before the first ant (`planner::lend`).
    pub fn with_packed_route(self) -> Self {
        let guide = Guide::Packed(self.guide.scratch());
        Workspace { guide, ..self }
    }

    /// The same workspace recording the convergence curve in `curve` (one entry an iteration;
    /// [`crate::planner::arena::carve`]'s workspaces have none).
    pub fn with_curve(self, curve: &'a mut [CurvePoint]) -> Self {
        Workspace { curve, ..self }
    }

    /// The largest map (in cells) this workspace can plan on: as many as its bit sets hold, and
    /// with fewer than [`BLOCKS`] pheromone entries at most that many, except on a workspace
    /// without pruning marks (`dead` empty, [`crate::planner::arena::carve`]'s compact layout), where a map
    /// of more cells than `tau` has entries gets blocks of cells
    /// ([`Workspace::pheromone_budget`]).
    pub fn capacity(&self) -> usize {
        let blocks = self.pheromone_budget();
        if self.dead.is_empty() {
            return if blocks == 0 {
                0
            } else {
                self.tabu.len().saturating_mul(32)
            };
        }
        let bits = self.tabu.len().min(self.dead.len()).saturating_mul(32);
        // Maps of up to `blocks` cells fit whatever the bits say beyond; larger maps need the
        // whole pheromone budget.
        if blocks >= BLOCKS {
            bits
        } else {
            bits.min(blocks)
        }
    }

    /// Most pheromone entries a run on this workspace uses: [`BLOCKS`], or fewer if `tau` and
    /// `delta` are shorter (a map of more cells than that gets blocks of cells: coarser pheromone,
    /// the same rule as on every map of more than [`BLOCKS`] cells).
    pub fn pheromone_budget(&self) -> usize {
        self.tau.len().min(self.delta.len()).min(BLOCKS)
    }

    /// The longest ant path (in steps) this workspace keeps.
    pub fn steps(&self) -> usize {
        // An empty `iter_best` or `iter_worst` is not a bound: that path is walked again instead
        // of kept (the module docs).
        let kept = |t: &[Dir]| if t.is_empty() { usize::MAX } else { t.len() };
        [
            self.tour.len(),
            kept(self.iter_best),
            kept(self.iter_worst),
            self.best.len(),
            self.points.len().saturating_sub(1),
        ]
        .into_iter()
        .min()
        .unwrap_or(0)
    }

    /// Cut every buffer to what a `cells`-cell map with pheromone layout `blocks` uses, or fail
    /// with [`Error::MapTooLarge`].
    pub(super) fn fit(self, cells: usize, blocks: Blocks) -> Result<Self, Error> {
        let capacity = self.capacity();
        let too_large = || Error::MapTooLarge {
            cells: u32::try_from(cells).unwrap_or(u32::MAX),
            capacity: u32::try_from(capacity).unwrap_or(u32::MAX),
        };
        if cells > capacity || self.steps() == 0 && cells > 1 {
            return Err(too_large());
        }
        let w = words(cells);
        let n = blocks.count();
        let steps = self.steps();
        let moves_len = if self.moves.len() >= cells { cells } else { 0 };
        let cut = |s: &'a mut [u32], n: usize| s.split_at_mut(n.min(s.len())).0;
        let Workspace {
            tau,
            delta,
            tabu,
            dead,
            moves,
            tour,
            iter_best,
            iter_worst,
            best,
            points,
            links,
            curve,
            guide,
            #[cfg(any(feature = "alloc", test))]
            weights,
        } = self;
        let (tau, _) = tau.split_at_mut(n.min(tau.len()));
        let (delta, _) = delta.split_at_mut(n.min(delta.len()));
        if tau.len() < n || delta.len() < n {
            return Err(too_large());
        }
        Ok(Workspace {
            tau,
            delta,
            tabu: cut(tabu, w),
            dead: cut(dead, w),
            moves: moves.split_at_mut(moves_len.min(moves.len())).0,
            tour: tour.split_at_mut(steps.min(tour.len())).0,
            iter_best: iter_best.split_at_mut(steps.min(iter_best.len())).0,
            iter_worst: iter_worst.split_at_mut(steps.min(iter_worst.len())).0,
            best: best.split_at_mut(steps.min(best.len())).0,
            points: points
                .split_at_mut(steps.saturating_add(1).min(points.len()))
                .0,
            links,
            curve,
            guide,
            #[cfg(any(feature = "alloc", test))]
            weights,
        })
    }

    /// The pheromone of the last run (`[E, SE, S, SW]` per entry, row-major; see
    /// [`crate::colony::pheromone::Blocks`] for how a map's cells map onto entries).
    pub fn pheromone(&self) -> &[[f32; 4]] {
        self.tau
    }
}

/// The buffers of a run, owned: as arrays of compile-time capacities by [`Storage`], as `Vec`s
/// sized at run time by `heap::HeapStorage`. The one place that lends them to a [`Workspace`],
/// so both storages follow whatever buffers the workspace takes.
#[derive(Clone, Debug, Default)]
pub(crate) struct OwnedBuffers<Tau, Bits, Moves, Tour, Kept, Points, Links, Curve, Guide, Weights> {
    pub(crate) tau: Tau,
    pub(crate) delta: Tau,
    pub(crate) tabu: Bits,
    pub(crate) dead: Bits,
    pub(crate) moves: Moves,
    /// The ant's path and the run's best.
    pub(crate) tours: [Tour; 2],
    /// The iteration's best and worst paths (empty: walked again, see the module docs).
    pub(crate) kept: [Kept; 2],
    pub(crate) points: Points,
    pub(crate) links: Links,
    pub(crate) curve: Curve,
    pub(crate) guide: Guide,
    /// The colony's weight table (empty: none; lent only where a heap storage can give one,
    /// feature `alloc`).
    #[cfg_attr(not(any(feature = "alloc", test)), allow(dead_code))]
    pub(crate) weights: Weights,
}

impl<Tau, Bits, Moves, Tour, Kept, Points, Links, Curve, Guide, Weights>
    OwnedBuffers<Tau, Bits, Moves, Tour, Kept, Points, Links, Curve, Guide, Weights>
where
    Tau: AsMut<[[f32; 4]]>,
    Bits: AsMut<[u32]>,
    Moves: AsMut<[u8]>,
    Tour: AsMut<[Dir]>,
    Kept: AsMut<[Dir]>,
    Points: AsMut<[Point]>,
    Links: AsMut<[u32]>,
    Curve: AsMut<[CurvePoint]>,
    Guide: AsMut<[u32]>,
    Weights: AsMut<[u32]>,
{
    /// Borrow the buffers as a workspace for one run.
    pub(crate) fn workspace(&mut self) -> Workspace<'_> {
        let [tour, best] = &mut self.tours;
        let [iter_best, iter_worst] = &mut self.kept;
        let ws = Workspace::new(Buffers {
            tau: self.tau.as_mut(),
            delta: self.delta.as_mut(),
            tabu: self.tabu.as_mut(),
            dead: self.dead.as_mut(),
            moves: self.moves.as_mut(),
            tours: [
                tour.as_mut(),
                iter_best.as_mut(),
                iter_worst.as_mut(),
                best.as_mut(),
            ],
            points: self.points.as_mut(),
            links: self.links.as_mut(),
            curve: self.curve.as_mut(),
            guide: self.guide.as_mut(),
        });
        #[cfg(any(feature = "alloc", test))]
        let ws = ws.with_weights(self.weights.as_mut());
        ws
    }
}

/// Fixed-capacity storage for a [`Workspace`]: bit sets of `WORDS` words (maps of up to
/// `32 * WORDS` cells), ant paths of up to `STEPS - 1` steps, `LINKS` links, a move table for maps
/// of up to `MOVES` cells (0: none), a curve of `CURVE` iterations (0: none recorded), and
/// `KEPT` entries for each of the iteration's best and worst paths: `STEPS` keeps them, 0 (the
/// default) walks those two ants again at the update instead (`2 * STEPS` bytes less for two
/// more walks an iteration; the same paths bit for bit). Put it in a `static` on the device; its
/// size is [`Storage::BYTES`].
///
/// ```
/// use ohaca::bitmap::words;
/// use ohaca::planner::Storage;
/// // 256 x 256 maps, paths of up to 2047 steps, the move table for small maps, no curve.
/// type Device = Storage<{ words(65536) }, 2048, 4096, 1024, 0>;
/// assert_eq!(Device::BYTES, 93 * 1024);
/// // The same keeping the iteration's two paths: 4 KiB more.
/// type Kept = Storage<{ words(65536) }, 2048, 4096, 1024, 0, 2048>;
/// assert_eq!(Kept::BYTES, Device::BYTES + 2 * 2048);
/// ```
#[derive(Debug)]
pub struct Storage<
    const WORDS: usize,
    const STEPS: usize,
    const LINKS: usize,
    const MOVES: usize = 0,
    const CURVE: usize = 128,
    const KEPT: usize = 0,
> {
    buffers: Arrays<WORDS, STEPS, LINKS, MOVES, CURVE, KEPT>,
}

/// The buffers of a [`Storage`], each an array.
type Arrays<
    const WORDS: usize,
    const STEPS: usize,
    const LINKS: usize,
    const MOVES: usize,
    const CURVE: usize,
    const KEPT: usize,
> = OwnedBuffers<
    [[f32; 4]; BLOCKS],
    [u32; WORDS],
    [u8; MOVES],
    [Dir; STEPS],
    [Dir; KEPT],
    [Point; STEPS],
    [u32; LINKS],
    [CurvePoint; CURVE],
    [u32; GUIDE_BLOCKS],
    [u32; 0],
>;

impl<
        const WORDS: usize,
        const STEPS: usize,
        const LINKS: usize,
        const MOVES: usize,
        const CURVE: usize,
        const KEPT: usize,
    > Storage<WORDS, STEPS, LINKS, MOVES, CURVE, KEPT>
{
    /// Size in bytes.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// Zeroed storage (a `const fn`, so it can initialise a `static`).
    pub const fn new() -> Self {
        Storage {
            buffers: OwnedBuffers {
                tau: [[0.0; 4]; BLOCKS],
                delta: [[0.0; 4]; BLOCKS],
                tabu: [0; WORDS],
                dead: [0; WORDS],
                moves: [0; MOVES],
                tours: [[0; STEPS]; 2],
                kept: [[0; KEPT]; 2],
                points: [Point::new(0, 0); STEPS],
                links: [0; LINKS],
                curve: [CurvePoint {
                    best: 0.0,
                    mean: 0.0,
                    best_so_far: 0.0,
                    arrived: 0,
                    walked: 0,
                }; CURVE],
                guide: [0; GUIDE_BLOCKS],
                weights: [],
            },
        }
    }

    /// Borrow the storage as a [`Workspace`].
    pub fn workspace(&mut self) -> Workspace<'_> {
        self.buffers.workspace()
    }
}

impl<
        const WORDS: usize,
        const STEPS: usize,
        const LINKS: usize,
        const MOVES: usize,
        const CURVE: usize,
        const KEPT: usize,
    > Default for Storage<WORDS, STEPS, LINKS, MOVES, CURVE, KEPT>
{
    fn default() -> Self {
        Self::new()
    }
}

/// The coarse route's words, by what they hold: the role is in the type, not in a flag beside a
/// slice.
#[derive(Debug)]
pub(super) enum Guide<'a> {
    /// A word a block ([`route::build`]: links and whether they are known, next block, the
    /// search's key): a warm start repairs it.
    Words(&'a mut [u32]),
    /// Four bits a block, the next block only ([`route::pack`]): built again every run, its
    /// words and heap lent by the setup (`planner::lend`).
    Packed(&'a mut [u32]),
}

impl<'a> Guide<'a> {
    /// Its words, whatever they hold.
    pub(super) fn len(&self) -> usize {
        match self {
            Guide::Words(w) | Guide::Packed(w) => w.len(),
        }
    }

    /// Four bits a block.
    pub(super) fn is_packed(&self) -> bool {
        matches!(self, Guide::Packed(_))
    }

    /// The same role over a shorter borrow.
    pub(super) fn reborrow(&mut self) -> Guide<'_> {
        match self {
            Guide::Words(w) => Guide::Words(w),
            Guide::Packed(w) => Guide::Packed(w),
        }
    }

    /// Its words as scratch (after the colony, when no ant reads the route).
    pub(super) fn scratch(self) -> &'a mut [u32] {
        match self {
            Guide::Words(w) | Guide::Packed(w) => w,
        }
    }

    /// The route the ants read from it.
    pub(super) fn route(&self, blocks: Blocks, goal: Point, width: u16, height: u16) -> Route<'_> {
        match self {
            Guide::Words(w) => Route::new(blocks, w, goal, width, height),
            Guide::Packed(w) => Route::packed(blocks, w, goal, width, height),
        }
    }
}
