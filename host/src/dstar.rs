//! D* Lite: the incremental exact baseline for replanning (issue 28, "replans that cost what
//! changed"). Koenig, S. and Likhachev, M., "D* Lite", Proceedings of the AAAI Conference on
//! Artificial Intelligence (AAAI), 2002, pp. 476-483: the optimized version (the paper's
//! Figure 4), with the key modifier `km` for a robot that moves between replans.
//!
//! **What it owns.** One persistent search from a moving start (the robot) to a fixed goal on a
//! copy of an occupancy grid that changes between replans: [`DStarLite::new`] takes the map, the
//! start and the goal; [`DStarLite::plan`] searches (the first call is the initial search, a
//! backward A* from the goal; every later call repairs only what the changes since the previous
//! call made inconsistent); [`DStarLite::move_robot`] and [`DStarLite::update_cells`] tell it
//! what happened in between. [`replay`] runs it along a recorded [`Drive`] of `ohaca replan`: the
//! same map states, robot cells and goal, one D* Lite object across the drive's plans, each plan
//! checked against the project's exact A* ([`ohaca::astar`]) on the same problem.
//!
//! **The graph is the core's.** The same 8-connected model as [`ohaca::astar`] and
//! [`ohaca::Grid::step`]: the eight king moves between free cells, a diagonal only when both
//! orthogonally adjacent cells are free (no corner is ever cut), read with
//! [`ohaca::Grid::mask_at`]. The edges are symmetric, so a vertex's predecessors are its
//! successors. Costs are the exact scale of [`ohaca::search::cost`], as in [`ohaca::astar`]:
//! [`STRAIGHT`] = 33,461 units a straight step, [`cost::DIAGONAL`] = 47,321 a diagonal one, and the heuristic is the octile distance
//! in those units (consistent: `STRAIGHT <= DIAGONAL <= 2 STRAIGHT`). A `g` or `rhs` above
//! [`MAX_LENGTH`]` * STRAIGHT` is stored as infinite, so within that bound every comparison is
//! exact in the reals (the proof is `ohaca::astar`'s) and the path found is a shortest path, with
//! the same step counts (hence bit for bit the same length) as the exact A*'s; a goal farther
//! than `MAX_LENGTH` is reported as no path (`ohaca::astar` says `TooFar`).
//!
//! **Changes.** A cell that flips changes the cost of every edge it ends or whose corner it is;
//! every vertex with such an out-edge lies in the flipped cell's 3 x 3 block, and
//! [`DStarLite::update_cells`] recomputes their `rhs` from its definition (the minimum over
//! successors of edge cost plus `g`) and updates their queue membership. This is the paper's
//! per-edge update loop (lines 34'-41' of Figure 4) with the `rhs` of every endpoint recomputed
//! rather than patched: the same values, since `rhs` is by definition that minimum.
//!
//! **Order.** The queue orders vertices by the key `[min(g, rhs) + h(start, s) + km;
//! min(g, rhs)]` lexicographically (the paper's), then by cell index, so every run is
//! deterministic. On a tie of `f` the paper's key prefers the smaller `g`, so on an open map the
//! initial search expands more than [`ohaca::astar`], which prefers the deeper vertex.
//!
//! **What it keeps, counted in [`Stats::memory_bytes`].** Three 4-byte words a cell for as long
//! as it lives: `g`, `rhs`, and the vertex's position in the queue (an indexed binary heap, so a
//! vertex's key can be updated or removed in place, as the paper's queue operations require);
//! and the queue itself, 16 bytes an entry (`k1` in 64 bits, `k2` and the cell in 32 each),
//! counted at the most entries it ever held (it persists between replans). Its own copy of the
//! map (one bit a cell) is not counted, as `ohaca::astar` does not count the map it reads.
//!
//! **Guarantees.** Exact (above) and incremental: every [`DStarLite::plan`] returns a shortest
//! path on the map as it is then (its cost the robot's `rhs`; the optimized search may stop
//! before lowering the robot's own `g`), checked against the exact A* by the tests after random
//! sequences of changes and moves, and by [`replay`] on every plan. Errors are values
//! ([`DStarError`]): a cell off the map, a blocked start or goal (as [`ohaca::astar`]'s
//! `BadCell`), a map too large; nothing panics and every table access is checked.

use ohaca::astar::{self, AstarError, End, Entry, MAX_LENGTH, STRAIGHT};
use ohaca::geometry::steps_length;
use ohaca::grid::{is_diagonal, neighbour};
use ohaca::search::{cost, heap};
use ohaca::{Grid, Point};

use crate::map::Map;
use crate::replan::Drive;

/// "Infinite" `g` or `rhs`: not reachable within [`MAX_LENGTH`].
const INF: u32 = u32::MAX;
/// The largest finite `g` or `rhs` (larger is stored as [`INF`]).
const LIMIT: u32 = MAX_LENGTH * STRAIGHT;
/// Queue position of a vertex not in the queue.
const NOT_OPEN: u32 = u32::MAX;

/// Largest map the search accepts (`ohaca::astar`'s bound, so that cell indices and queue
/// positions fit 32 bits).
pub const MAX_CELLS: usize = astar::MAX_CELLS;

/// Bytes the search keeps a cell: `g`, `rhs` and the queue position.
pub const CELL_BYTES: usize = 3 * core::mem::size_of::<u32>();

/// Bytes of one queue entry.
pub const ENTRY_BYTES: usize = core::mem::size_of::<Node>();

/// Everything that can stop D* Lite.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DStarError {
    /// A cell given is outside the map.
    #[error("cell ({}, {}) is outside the map", .0.x, .0.y)]
    OffMap(Point),
    /// The start or the goal is blocked (or off the map).
    #[error("{} is off the map or blocked", if *.0 == End::Start { "start" } else { "goal" })]
    BadCell(End),
    /// The map has more than [`MAX_CELLS`] cells, or its bits are too short.
    #[error("map of {cells} cells: too large or its bits too short")]
    BadMap {
        /// Cells of the map.
        cells: usize,
    },
    /// The tables could not be allocated.
    #[error("no memory for the tables of {cells} cells")]
    OutOfMemory {
        /// Cells of the map.
        cells: usize,
    },
    /// [`replay`]: a map of the drive is not the first one's size.
    #[error("plan {plan}: the map changed size")]
    MapSize {
        /// The plan's index in the drive.
        plan: usize,
    },
    /// [`replay`]: the exact A* failed on a plan's problem for another reason than no path.
    #[error("plan {plan}: exact A*: {error}")]
    Astar {
        /// The plan's index in the drive.
        plan: usize,
        /// What A* said.
        error: String,
    },
    /// [`replay`]: D* Lite and the exact A* disagree on a plan's optimum (straight and diagonal
    /// steps, `None` = no path). Never expected: a bug in one of them.
    #[error("plan {plan}: D* Lite found {dstar:?} (straight, diagonal) steps, exact A* {astar:?}")]
    Disagree {
        /// The plan's index in the drive.
        plan: usize,
        /// D* Lite's step counts.
        dstar: Option<(u32, u32)>,
        /// A*'s step counts.
        astar: Option<(u32, u32)>,
    },
}

/// What one [`DStarLite::plan`] cost: the work since the previous call (the cell updates of
/// [`DStarLite::update_cells`] included) and the memory the search keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Vertex expansions: vertices taken off the queue and made consistent (overconsistent:
    /// `g` lowered to `rhs`; underconsistent: `g` raised to infinity), the paper's count.
    pub expanded: u64,
    /// Queue tops whose key had grown with `km` and were put back with their new key (no
    /// expansion).
    pub requeued: u64,
    /// Vertex updates (the paper's `UpdateVertex`): a vertex whose `rhs` may have changed had its
    /// queue membership and key settled, by an expansion of a neighbour or a changed cell.
    pub updated: u64,
    /// Cells whose state changed (blocked or freed) since the previous plan.
    pub cells_changed: u64,
    /// Most entries the queue held during this call.
    pub open_peak: usize,
    /// Entries left in the queue (kept for the next replan).
    pub open_len: usize,
    /// Bytes the search keeps: [`CELL_BYTES`] a cell plus [`ENTRY_BYTES`] for each entry of
    /// the queue at the most it ever held (since [`DStarLite::new`]).
    pub memory_bytes: usize,
}

/// A shortest path.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    /// Every cell, the robot's first and the goal last.
    pub cells: Vec<Point>,
    /// Straight steps.
    pub straight: u32,
    /// Diagonal steps.
    pub diagonal: u32,
    /// Length in cost units (`straight STRAIGHT + diagonal DIAGONAL`), the robot's `rhs`.
    pub cost: u32,
    /// Length in cells ([`steps_length`], the core's formula: comparable bit for bit).
    pub length: f32,
}

/// What [`DStarLite::plan`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Planned {
    /// A shortest path, or `None`: the goal is not reachable within [`MAX_LENGTH`].
    pub path: Option<Path>,
    /// What the call cost.
    pub stats: Stats,
}

/// The queue's key: `[min(g, rhs) + h + km; min(g, rhs)]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Key {
    k1: u64,
    k2: u32,
}

impl Key {
    /// The key of a vertex with `g = rhs = infinity`: after every real key.
    const INFINITE: Key = Key {
        k1: u64::MAX,
        k2: u32::MAX,
    };
}

/// One queue entry: the key's two parts, then the cell index (the tie-break), ordered in that
/// order; flat, so that it packs in 16 bytes (a nested [`Key`] would pad it to 24).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Node {
    k1: u64,
    k2: u32,
    cell: u32,
}

impl Node {
    fn new(cell: usize, key: Key) -> Node {
        // `cell < cells <= MAX_CELLS < 2^32`.
        Node {
            k1: key.k1,
            k2: key.k2,
            cell: cell as u32,
        }
    }

    fn key(&self) -> Key {
        Key {
            k1: self.k1,
            k2: self.k2,
        }
    }
}

const _: () = assert!(ENTRY_BYTES == 16);

/// The queue: an indexed binary min-heap, the core's ([`heap`]), over the entries' vector (a
/// vertex's position in `pos`, [`NOT_OPEN`] if it is not in the queue).
#[derive(Clone, Debug)]
struct Open {
    heap: Vec<Node>,
    pos: Vec<u32>,
    /// Most entries ever held.
    peak: usize,
    /// Most entries held since the last [`Open::reset_peak`].
    call_peak: usize,
}

impl Open {
    fn contains(&self, c: usize) -> bool {
        self.pos.get(c).is_some_and(|&p| p != NOT_OPEN)
    }

    fn top(&self) -> Option<Node> {
        self.heap.first().copied()
    }

    fn len(&self) -> usize {
        self.heap.len()
    }

    fn reset_peak(&mut self) {
        self.call_peak = self.heap.len();
    }

    /// The queue as the core's heap sees it ([`heap::Slots`]).
    fn slots(&mut self) -> Slots<'_> {
        Slots {
            heap: &mut self.heap,
            pos: &mut self.pos,
        }
    }

    fn insert(&mut self, cell: usize, key: Key) {
        let i = self.heap.len();
        let n = Node::new(cell, key);
        self.heap.push(n);
        self.peak = self.peak.max(self.heap.len());
        self.call_peak = self.call_peak.max(self.heap.len());
        heap::sift_up(&mut self.slots(), i, n);
    }

    fn update(&mut self, cell: usize, key: Key) {
        let Some(&i) = self.pos.get(cell) else { return };
        let i = i as usize;
        let Some(old) = self.heap.get(i).map(Node::key) else {
            return;
        };
        let n = Node::new(cell, key);
        if key < old {
            heap::sift_up(&mut self.slots(), i, n);
        } else {
            heap::sift_down(&mut self.slots(), i, n);
        }
    }

    fn remove(&mut self, cell: usize) {
        let Some(p) = self.pos.get_mut(cell) else {
            return;
        };
        let i = *p as usize;
        *p = NOT_OPEN;
        let Some(last) = self.heap.pop() else { return };
        if i < self.heap.len() && heap::sift_up(&mut self.slots(), i, last) == i {
            heap::sift_down(&mut self.slots(), i, last);
        }
    }
}

/// The queue's entries and positions as the core's heap sees them: a slice of [`Node`]s in
/// their own order, each one's slot recorded in `pos`.
struct Slots<'a> {
    heap: &'a mut [Node],
    pos: &'a mut [u32],
}

impl heap::Slots for Slots<'_> {
    type Item = Node;
    fn at(&self, slot: usize) -> Option<Node> {
        self.heap.get(slot).copied()
    }
    /// Put `n` at heap slot `i` and record its position.
    fn put(&mut self, i: usize, n: Node) {
        if let Some(slot) = self.heap.get_mut(i) {
            *slot = n;
        }
        if let Some(p) = self.pos.get_mut(n.cell as usize) {
            // `i < heap.len() <= cells <= MAX_CELLS < 2^32`.
            *p = i as u32;
        }
    }
    fn before(&self, a: Node, b: Node) -> bool {
        a < b
    }
}

/// The search's state (everything but the map, so that a borrowed [`Grid`] over the map and the
/// state can be used together).
#[derive(Clone, Debug)]
struct State {
    g: Vec<u32>,
    rhs: Vec<u32>,
    open: Open,
    start: Point,
    /// Where the robot was when `km` was last brought up to date.
    last: Point,
    goal: Point,
    km: u64,
    /// Work since the last plan.
    stats: Stats,
}

/// The octile distance between `a` and `b` in cost units (exact in u32 for u16 coordinates).
fn octile(a: Point, b: Point) -> u64 {
    u64::from(cost::EXACT.octile(u32::from(a.x.abs_diff(b.x)), u32::from(a.y.abs_diff(b.y))))
}

/// The moves from `p` (bit `d` set iff [`Grid::step`] allows move `d`; 0 at a blocked cell):
/// its successors, and as the edges are symmetric, its predecessors.
fn moves(grid: &Grid<'_>, p: Point) -> u8 {
    grid.mask_at(p)
}

/// `a + b`, infinite above [`LIMIT`].
fn add(a: u32, b: u32) -> u32 {
    match a.checked_add(b) {
        Some(s) if s <= LIMIT => s,
        _ => INF,
    }
}

/// A vector of `n` copies of `v`, or an error if it cannot be allocated.
fn filled(n: usize, v: u32) -> Result<Vec<u32>, DStarError> {
    let mut out = Vec::new();
    out.try_reserve_exact(n)
        .map_err(|_| DStarError::OutOfMemory { cells: n })?;
    out.resize(n, v);
    Ok(out)
}

impl State {
    fn g(&self, i: usize) -> u32 {
        self.g.get(i).copied().unwrap_or(INF)
    }

    fn rhs(&self, i: usize) -> u32 {
        self.rhs.get(i).copied().unwrap_or(INF)
    }

    fn key(&self, grid: &Grid<'_>, i: usize) -> Key {
        let m = self.g(i).min(self.rhs(i));
        if m == INF {
            return Key::INFINITE;
        }
        Key {
            k1: u64::from(m) + octile(self.start, grid.point(i)) + self.km,
            k2: m,
        }
    }

    /// The paper's `UpdateVertex`: `u` in the queue with its current key iff it is
    /// inconsistent.
    fn update_vertex(&mut self, grid: &Grid<'_>, u: usize) {
        self.stats.updated += 1;
        let inconsistent = self.g(u) != self.rhs(u);
        match (inconsistent, self.open.contains(u)) {
            (true, true) => self.open.update(u, self.key(grid, u)),
            (true, false) => self.open.insert(u, self.key(grid, u)),
            (false, true) => self.open.remove(u),
            (false, false) => {}
        }
    }

    /// `rhs(u)` from its definition: the cheapest move to a successor plus its `g` (0 at the
    /// goal, infinite at a blocked cell).
    fn best_rhs(&self, grid: &Grid<'_>, u: usize) -> u32 {
        let p = grid.point(u);
        if p == self.goal {
            return 0;
        }
        let m = moves(grid, p);
        (0..8u8)
            .filter(|d| m & (1 << d) != 0)
            .map(|d| add(cost::step(d), self.g(grid.index(neighbour(p, d)))))
            .min()
            .unwrap_or(INF)
    }

    fn set_rhs(&mut self, u: usize, v: u32) {
        if let Some(r) = self.rhs.get_mut(u) {
            *r = v;
        }
    }

    fn set_g(&mut self, u: usize, v: u32) {
        if let Some(g) = self.g.get_mut(u) {
            *g = v;
        }
    }

    /// Bring `km` up to date with the robot's moves since the last call (the paper's
    /// `km = km + h(s_last, s_start); s_last = s_start`).
    fn sync_start(&mut self) {
        if self.start != self.last {
            self.km += octile(self.last, self.start);
            self.last = self.start;
        }
    }

    /// The paper's `ComputeShortestPath` (optimized, Figure 4).
    fn compute(&mut self, grid: &Grid<'_>) {
        let s = grid.index(self.start);
        while let Some(top) = self.open.top() {
            if top.key() >= self.key(grid, s) && self.rhs(s) <= self.g(s) {
                break;
            }
            let u = top.cell as usize;
            let k_new = self.key(grid, u);
            let p = grid.point(u);
            let (g_u, rhs_u) = (self.g(u), self.rhs(u));
            if top.key() < k_new {
                self.stats.requeued += 1;
                self.open.update(u, k_new);
            } else if g_u > rhs_u {
                // Overconsistent: settle it and offer it to its predecessors.
                self.stats.expanded += 1;
                self.set_g(u, rhs_u);
                self.open.remove(u);
                let m = moves(grid, p);
                for d in (0..8u8).filter(|d| m & (1 << d) != 0) {
                    let q = neighbour(p, d);
                    let qi = grid.index(q);
                    if q != self.goal {
                        let via = add(cost::step(d), rhs_u);
                        if via < self.rhs(qi) {
                            self.set_rhs(qi, via);
                        }
                    }
                    self.update_vertex(grid, qi);
                }
            } else {
                // Underconsistent: forget its g; predecessors that relied on it look again.
                self.stats.expanded += 1;
                self.set_g(u, INF);
                let m = moves(grid, p);
                for d in (0..8u8).filter(|d| m & (1 << d) != 0) {
                    let q = neighbour(p, d);
                    let qi = grid.index(q);
                    if q != self.goal && self.rhs(qi) == add(cost::step(d), g_u) {
                        let r = self.best_rhs(grid, qi);
                        self.set_rhs(qi, r);
                    }
                    self.update_vertex(grid, qi);
                }
                // `u` itself: no self-loop, so its rhs stands; requeue or drop it.
                self.update_vertex(grid, u);
            }
        }
    }

    /// Follow the cheapest successor (edge cost plus `g`) from the robot to the goal. The
    /// optimized `ComputeShortestPath` may stop with the robot's vertex overconsistent (its `g`
    /// not lowered yet): its distance is its `rhs`, as in the paper's main loop.
    fn path(&self, grid: &Grid<'_>) -> Option<Path> {
        let cost = self.rhs(grid.index(self.start));
        if cost == INF {
            return None;
        }
        let mut cells = vec![self.start];
        let (mut straight, mut diagonal) = (0u32, 0u32);
        let mut p = self.start;
        while p != self.goal {
            if cells.len() > grid.cells() {
                return None;
            }
            let m = moves(grid, p);
            let (d, q, c) = (0..8u8)
                .filter(|d| m & (1 << d) != 0)
                .map(|d| {
                    let q = neighbour(p, d);
                    (d, q, add(cost::step(d), self.g(grid.index(q))))
                })
                .min_by_key(|&(_, _, c)| c)?;
            if c == INF {
                return None;
            }
            if is_diagonal(d) {
                diagonal += 1;
            } else {
                straight += 1;
            }
            cells.push(q);
            p = q;
        }
        Some(Path {
            cells,
            straight,
            diagonal,
            cost,
            length: steps_length(straight, diagonal),
        })
    }
}

/// D* Lite on an 8-connected grid (see the module docs).
#[derive(Clone, Debug)]
pub struct DStarLite {
    width: u16,
    height: u16,
    /// The map as it is now (one bit a cell, `ohaca::grid`'s layout).
    bits: Vec<u8>,
    state: State,
}

impl DStarLite {
    /// A search on a copy of `grid` from `start` to `goal`, initialized (the paper's
    /// `Initialize`: every `g` and `rhs` infinite but the goal's `rhs`, the goal queued); no
    /// search yet ([`DStarLite::plan`]). Either end may be blocked for now, not off the map.
    pub fn new(grid: &Grid<'_>, start: Point, goal: Point) -> Result<DStarLite, DStarError> {
        let cells = grid.cells();
        if cells > MAX_CELLS {
            return Err(DStarError::BadMap { cells });
        }
        for p in [start, goal] {
            if !grid.contains(p) {
                return Err(DStarError::OffMap(p));
            }
        }
        let bits = grid
            .bits()
            .get(..ohaca::grid::bytes_for(cells))
            .ok_or(DStarError::BadMap { cells })?
            .to_vec();
        let mut state = State {
            g: filled(cells, INF)?,
            rhs: filled(cells, INF)?,
            open: Open {
                heap: Vec::new(),
                pos: filled(cells, NOT_OPEN)?,
                peak: 0,
                call_peak: 0,
            },
            start,
            last: start,
            goal,
            km: 0,
            stats: Stats::default(),
        };
        let gi = grid.index(goal);
        state.set_rhs(gi, 0);
        state.open.insert(
            gi,
            Key {
                k1: octile(start, goal),
                k2: 0,
            },
        );
        Ok(DStarLite {
            width: grid.width(),
            height: grid.height(),
            bits,
            state,
        })
    }

    /// The map as the search sees it now.
    pub fn grid(&self) -> Result<Grid<'_>, DStarError> {
        Grid::new(self.width, self.height, &self.bits).map_err(|_| DStarError::BadMap {
            cells: usize::from(self.width) * usize::from(self.height),
        })
    }

    /// The robot's cell.
    pub fn start(&self) -> Point {
        self.state.start
    }

    /// The goal.
    pub fn goal(&self) -> Point {
        self.state.goal
    }

    /// The robot is now at `to` (any cell of the map; normally a step or more along its path).
    /// Nothing is searched until the next [`DStarLite::plan`].
    pub fn move_robot(&mut self, to: Point) -> Result<(), DStarError> {
        if !self.grid()?.contains(to) {
            return Err(DStarError::OffMap(to));
        }
        self.state.start = to;
        Ok(())
    }

    /// Cells became blocked (`true`) or free: apply them to the map and update every vertex
    /// whose outgoing edges changed (no search yet: [`DStarLite::plan`]). Cells given in their
    /// current state are skipped; returns how many flipped. On an error (a cell off the map)
    /// nothing changes.
    pub fn update_cells(&mut self, changed: &[(Point, bool)]) -> Result<usize, DStarError> {
        let (w, h) = (self.width, self.height);
        if let Some(&(p, _)) = changed.iter().find(|(p, _)| p.x >= w || p.y >= h) {
            return Err(DStarError::OffMap(p));
        }
        self.state.sync_start();
        let mut flipped = Vec::new();
        for &(p, blocked) in changed {
            let i = usize::from(p.y) * usize::from(w) + usize::from(p.x);
            if ohaca::map::bits::get(&self.bits, i).is_some_and(|was| was != blocked) {
                ohaca::map::bits::set(&mut self.bits, i, blocked);
                flipped.push(p);
            }
        }
        // Every vertex with an out-edge that changed: the flipped cells' 3 x 3 blocks.
        let mut touched: Vec<usize> = Vec::with_capacity(9 * flipped.len());
        for p in &flipped {
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (x, y) = (i32::from(p.x) + dx, i32::from(p.y) + dy);
                    if x >= 0 && y >= 0 && x < i32::from(w) && y < i32::from(h) {
                        touched.push(y as usize * usize::from(w) + x as usize);
                    }
                }
            }
        }
        touched.sort_unstable();
        touched.dedup();
        let grid = Grid::new(w, h, &self.bits).map_err(|_| DStarError::BadMap {
            cells: usize::from(w) * usize::from(h),
        })?;
        let st = &mut self.state;
        for u in touched {
            let r = st.best_rhs(&grid, u);
            st.set_rhs(u, r);
            st.update_vertex(&grid, u);
        }
        st.stats.cells_changed += flipped.len() as u64;
        Ok(flipped.len())
    }

    /// Search (the first call) or repair (every later one) and return a shortest path from the
    /// robot to the goal, with what the call cost since the previous one. A blocked start or
    /// goal is [`DStarError::BadCell`] (the search's state stays valid: clear the cell and plan
    /// again).
    pub fn plan(&mut self) -> Result<Planned, DStarError> {
        let grid =
            Grid::new(self.width, self.height, &self.bits).map_err(|_| DStarError::BadMap {
                cells: usize::from(self.width) * usize::from(self.height),
            })?;
        let st = &mut self.state;
        if !grid.is_free(st.start) {
            return Err(DStarError::BadCell(End::Start));
        }
        if !grid.is_free(st.goal) {
            return Err(DStarError::BadCell(End::Goal));
        }
        st.sync_start();
        st.compute(&grid);
        let path = st.path(&grid);
        let mut stats = core::mem::take(&mut st.stats);
        stats.open_peak = st.open.call_peak;
        stats.open_len = st.open.len();
        stats.memory_bytes = grid
            .cells()
            .saturating_mul(CELL_BYTES)
            .saturating_add(st.open.peak.saturating_mul(ENTRY_BYTES));
        st.open.reset_peak();
        Ok(Planned { path, stats })
    }
}

/// The exact A*'s answer to one problem ([`ohaca::astar::search`], the 4-bit variant, from
/// scratch), for comparison.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AstarCost {
    /// Straight and diagonal steps of its path (`None`: no path).
    pub steps: Option<(u32, u32)>,
    /// Its expansions.
    pub expanded: u32,
    /// Bytes it used ([`ohaca::astar::Search::ram_bytes`]).
    pub memory_bytes: usize,
}

/// Run the exact A* ([`ohaca::astar::search`]) from `start` to `goal` on `grid`.
pub fn astar_cost(grid: &Grid<'_>, start: Point, goal: Point) -> Result<AstarCost, AstarError> {
    let n = grid.cells();
    let mut nib = vec![0u8; astar::nibble_bytes(n)];
    let mut heap = vec![Entry::EMPTY; 8 * n + 8];
    match astar::search(grid, start, goal, &mut nib, &mut heap) {
        Ok(s) => Ok(AstarCost {
            steps: Some((s.straight, s.diagonal)),
            expanded: s.expansions,
            memory_bytes: s.ram_bytes(),
        }),
        Err(AstarError::NoPath | AstarError::TooFar) => Ok(AstarCost {
            steps: None,
            expanded: 0,
            memory_bytes: 0,
        }),
        Err(e) => Err(e),
    }
}

/// One plan of a drive, replayed.
#[derive(Clone, Debug, PartialEq)]
pub struct Replayed {
    /// The plan's index in the drive.
    pub plan: usize,
    /// The robot's cell.
    pub robot: Point,
    /// D* Lite's path length in cells (`None`: no path).
    pub length: Option<f32>,
    /// D* Lite's cost (the work since the previous plan: the changed cells' updates and the
    /// search).
    pub dstar: Stats,
    /// The exact A* from scratch on the same problem.
    pub astar: AstarCost,
}

/// The cells whose state differs between `a` and `b` (maps of one size), with `b`'s state.
fn diff(a: &Map, b: &Map) -> Vec<(Point, bool)> {
    let mut out = Vec::new();
    let w = usize::from(b.width);
    for (k, (x, y)) in a.bits.iter().zip(&b.bits).enumerate() {
        let mut d = x ^ y;
        while d != 0 {
            let bit = d.trailing_zeros() as usize;
            d &= d - 1;
            let i = 8 * k + bit;
            if i < b.cells() {
                let p = Point::new((i % w) as u16, (i / w) as u16);
                out.push((p, y & (1 << bit) != 0));
            }
        }
    }
    out
}

/// Replay `drive` (to `goal`) into one D* Lite object: the first plan's map, robot cell and goal
/// start it and it plans; before every later plan the robot moves to that plan's cell and the
/// cells that differ between the two plans' maps change, and it replans. Every plan is also
/// solved from scratch by the exact A*, and the two must find the same optimum (same straight
/// and diagonal steps) or [`DStarError::Disagree`].
pub fn replay(drive: &Drive, goal: Point) -> Result<Vec<Replayed>, DStarError> {
    let mut out = Vec::with_capacity(drive.steps.len());
    let mut dstar: Option<DStarLite> = None;
    let mut prev: Option<&Map> = None;
    for (i, step) in drive.steps.iter().enumerate() {
        let grid = step.map.grid().map_err(|_| DStarError::BadMap {
            cells: step.map.cells(),
        })?;
        let d = match (dstar.as_mut(), prev) {
            (Some(d), Some(prev)) => {
                if (prev.width, prev.height) != (step.map.width, step.map.height) {
                    return Err(DStarError::MapSize { plan: i });
                }
                d.move_robot(step.robot)?;
                d.update_cells(&diff(prev, &step.map))?;
                d
            }
            _ => dstar.insert(DStarLite::new(&grid, step.robot, goal)?),
        };
        let planned = d.plan()?;
        let a = astar_cost(&grid, step.robot, goal).map_err(|e| DStarError::Astar {
            plan: i,
            error: e.to_string(),
        })?;
        let steps = planned.path.as_ref().map(|p| (p.straight, p.diagonal));
        if steps != a.steps {
            return Err(DStarError::Disagree {
                plan: i,
                dstar: steps,
                astar: a.steps,
            });
        }
        out.push(Replayed {
            plan: i,
            robot: step.robot,
            length: planned.path.map(|p| p.length),
            dstar: planned.stats,
            astar: a,
        });
        prev = Some(&step.map);
    }
    Ok(out)
}
