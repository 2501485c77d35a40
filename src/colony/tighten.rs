//! Path tightening (not in the paper): a finished ant path straightened in place before the
//! pheromone update, jumping from each cell to the furthest later path cell one allowed move away.
//!
//! Owns [`tighten`] and the cell -> path-position index it needs (a per-cell array, or an
//! open-addressing hash table over the path's cells when the workspace has fewer links than the
//! map has cells, of positions or, with fewer links still, of packed (cell, position) keys in
//! the links and the path cells' words; all give the same result). Like the rest of the core it has no panic path:
//! every index is checked, and a path it cannot index is returned unchanged.

use crate::colony::ant::Walk;
use crate::colony::tabu::TabuSet;
use crate::map::grid::{is_diagonal, neighbour, opposite, Dir, Moves, Point};

/// Straighten a finished walk in place: from each cell of the path, jump to the furthest later
/// path cell that is one allowed move away, dropping the detour in between. Returns the new walk.
/// The same as [`Tightening::begin`] and [`Tightening::resume`] without a budget.
///
/// This is not in the paper. A depth-first ant path is loop-free but can still bulge (go around
/// three sides of a square where one step would do). Cutting such bulges before the pheromone
/// update makes every ant deposit on a tighter path, which is what lets the colony settle on
/// near-optimal 8-connected paths within a few iterations (see `docs/ALGORITHM.md`). It costs at
/// most 8 lookups per path cell.
///
/// `cells` is scratch of at least `steps + 1` points. `pos` finds a cell's position on the path:
/// with one entry per map cell it is indexed by cell; shorter, it is an open-addressing hash
/// table over the path's cells, which needs a power of two of at least twice the path's cells as
/// slots, or if that does not fit, of at least one and a half times (load factor 2/3), two 16-bit
/// slots a word for paths of fewer than 65,535 cells ([`hash_words`]). When `pos` is shorter
/// still, the table holds packed (cell, position) keys over `pos` and `cells`' own words, which
/// then need not be laid out: at least `3 (steps + 1) / 2` slots together ([`keyed_words`], and
/// `cells` aligned to a word, as an arena's are). A path no index holds is returned
/// untightened. Every one gives the same result (the tests compare them).
///
/// `visited` is the walk's tabu set (every cell of the path is in it): a neighbour outside it is
/// not on the path and is not looked up. An empty set looks up every neighbour; same result.
pub fn tighten(
    moves: &Moves<'_>,
    start: Point,
    walk: Walk,
    tour: &mut [Dir],
    cells: &mut [Point],
    pos: &mut [u32],
    visited: &TabuSet<'_>,
) -> Walk {
    let Some(mut t) = Tightening::begin(moves, start, walk, tour, cells, pos) else {
        return walk;
    };
    let mut budget = u32::MAX;
    loop {
        if let Some(w) = t.resume(moves, start, tour, cells, pos, visited, &mut budget) {
            return w;
        }
        budget = u32::MAX;
    }
}

/// Work units of [`Tightening::resume`]: indexing a path cell, or a step of the pass over the
/// path where no neighbour but the path's previous and next cells is on it (about 90
/// instructions a unit on the device, measured on maze512's path).
pub const CELL_UNITS: u32 = 1;
/// Work units of a step of the pass that looks its neighbours up (up to eight, in the index):
/// `LOOK_UNITS` plus one a look-up.
pub const LOOK_UNITS: u32 = 2;

/// A walk's [`tighten`] in progress, a bounded amount of work at a time ([`Tightening::resume`]),
/// so a firmware can yield inside a long path's tightening: first every path cell goes into the
/// index, then the pass over the path writes the tightened steps to the front of the tour. The
/// index lives in the caller's `cells` and `pos`, the path in its tour; this holds where the work
/// stands (six words: a walk in progress holds it in place of its finished [`crate::colony::ant::Trail`],
/// no larger). However the work is cut, the result is [`tighten`]'s, bit for bit. The
/// caller passes the same buffers and the same `start` and tabu set to every call, and changes
/// none of them in between.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tightening {
    /// Steps of the walk's path (`tour[..steps]`).
    steps: usize,
    /// The walk's moves (tightening keeps them).
    moves: u32,
    /// Indexing: the next position to index; the pass: the position reached. Below `steps + 1`.
    i: usize,
    /// Steps of the tightened path written to the front of the tour (at most `i`), or
    /// [`INDEXING`] while the cells go into the index.
    out: usize,
    /// Diagonal steps among them.
    diagonal: u32,
    /// The cell at position `i`.
    at: Point,
}

/// [`Tightening::out`] while the cells go into the index (a flag of its own would make the state
/// a word larger than a walk's).
const INDEXING: usize = usize::MAX;

impl Tightening {
    /// Start tightening `walk` (its path is `tour[..walk.steps]`): clears the index (a hash table
    /// over `pos`, or over `pos` and `cells`' words) and does nothing else. `None` when no index
    /// fits the path: it stays as it is (see [`tighten`]).
    pub fn begin(
        moves: &Moves<'_>,
        start: Point,
        walk: Walk,
        tour: &[Dir],
        cells: &mut [Point],
        pos: &mut [u32],
    ) -> Option<Self> {
        let map = moves.grid().cells();
        // Cannot wrap for a real walk (steps < cells); were `steps` usize::MAX, `tour.get(..steps)`
        // below would fail and the walk come back unchanged.
        let n = walk.steps.wrapping_add(1);
        if cells.len() < n {
            return None;
        }
        tour.get(..walk.steps)?;
        if PathIndex::fits(pos.len(), map, n) {
            PathIndex::new(pos, map, n, true)?;
        } else {
            Keyed::new(pos, cells, map, n, true)?;
        }
        Some(Tightening {
            steps: walk.steps,
            moves: walk.moves,
            i: 0,
            out: INDEXING,
            diagonal: 0,
            at: start,
        })
    }

    /// Steps of the walk's path before tightening (the tightened path has at most as many).
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Go on for at most about `budget` work units ([`CELL_UNITS`], [`LOOK_UNITS`]), taking what
    /// it spends from `budget`: `Some(walk)` once the path is tightened (in `tour[..walk.steps]`),
    /// `None` while work is left (with `budget` at 0). A call with a budget below
    /// `LOOK_UNITS + 8` (a step that looks up all eight neighbours) makes no progress in the pass.
    /// Should the index not reopen in the buffers (not those of [`Tightening::begin`]), the path
    /// so far tightened is completed with the rest untightened: a valid path, never a panic.
    #[allow(clippy::too_many_arguments)]
    pub fn resume(
        &mut self,
        moves: &Moves<'_>,
        start: Point,
        tour: &mut [Dir],
        cells: &mut [Point],
        pos: &mut [u32],
        visited: &TabuSet<'_>,
        budget: &mut u32,
    ) -> Option<Walk> {
        let grid = moves.grid();
        let n = self.steps.wrapping_add(1);
        // The index: positions in `pos` (a per-cell array, or a hash table) checked against the
        // path laid out in `cells`, or, when `pos` is too short for that, a table of packed
        // (cell, position) keys over `pos` and `cells`' words together ([`Keyed`]).
        if PathIndex::fits(pos.len(), grid.cells(), n) {
            let (Some(mut ix), Some(laid)) = (
                PathIndex::new(pos, grid.cells(), n, false),
                cells.get_mut(..n),
            ) else {
                return Some(self.rest(tour));
            };
            // Lay the path out as cells and remember each cell's position on it.
            if !self.index(start, tour, budget, |i, p| {
                if let Some(slot) = laid.get_mut(i) {
                    *slot = p;
                }
                ix.insert(grid.index(p), i as u32);
            }) {
                return None;
            }
            let laid: &[Point] = laid;
            self.straighten(moves, tour, visited, budget, |cell| {
                ix.find(cell, |j| laid.get(j).map(|&q| grid.index(q)))
            })
        } else {
            let Some(mut k) = Keyed::new(pos, cells, grid.cells(), n, false) else {
                return Some(self.rest(tour));
            };
            if !self.index(start, tour, budget, |i, p| {
                k.insert(grid.index(p), i as u32)
            }) {
                return None;
            }
            self.straighten(moves, tour, visited, budget, |cell| k.find(cell))
        }
    }

    /// The index's part of [`Tightening::resume`]: `put(i, cell)` for the path's positions from
    /// `i` on, while `budget` lasts; `true` once every position is in (the pass then starts at
    /// the start).
    #[inline(always)]
    fn index(
        &mut self,
        start: Point,
        tour: &[Dir],
        budget: &mut u32,
        mut put: impl FnMut(usize, Point),
    ) -> bool {
        if self.out != INDEXING {
            return true;
        }
        let n = self.steps.wrapping_add(1);
        let path = tour.get(..self.steps).unwrap_or_default();
        let (mut i, mut p) = (self.i, self.at);
        while i < n {
            if *budget < CELL_UNITS {
                *budget = 0;
                (self.i, self.at) = (i, p);
                return false;
            }
            *budget = budget.wrapping_sub(CELL_UNITS);
            put(i, p);
            if let Some(&d) = path.get(i) {
                p = neighbour(p, d);
            }
            i = i.wrapping_add(1);
        }
        (self.i, self.out, self.at) = (0, 0, start);
        true
    }

    /// The rest of the path from position `i` on, untightened, after the steps written so far:
    /// `tour[i..steps]` still holds its original steps (the output, `tour[..out]`, never passes
    /// `i`).
    fn rest(&self, tour: &mut [Dir]) -> Walk {
        let (mut out, mut k) = match self.out {
            INDEXING => (0, 0),
            out => (out, self.i),
        };
        let mut diagonal = self.diagonal;
        while k < self.steps {
            let (Some(&d), true) = (tour.get(k), out <= k) else {
                break;
            };
            if let Some(slot) = tour.get_mut(out) {
                *slot = d;
            }
            diagonal = diagonal.wrapping_add(u32::from(is_diagonal(d)));
            out = out.wrapping_add(1);
            k = k.wrapping_add(1);
        }
        self.walk(out, diagonal)
    }

    /// The tightened walk of `out` steps, `diagonal` of them diagonal.
    fn walk(&self, out: usize, diagonal: u32) -> Walk {
        Walk {
            steps: out,
            straight: (out as u32).wrapping_sub(diagonal),
            diagonal,
            moves: self.moves,
            may_tighten: false,
        }
    }

    /// The pass of [`Tightening::resume`] over the path in `tour`, with `find(cell)`: the cell's
    /// position on it, from position `i` on while `budget` lasts. Generic over the index, so the
    /// look-ups of the inner loop branch on nothing else.
    #[inline(always)]
    fn straighten(
        &mut self,
        moves: &Moves<'_>,
        tour: &mut [Dir],
        visited: &TabuSet<'_>,
        budget: &mut u32,
        find: impl Fn(usize) -> Option<usize>,
    ) -> Option<Walk> {
        let grid = moves.grid();
        let n = self.steps.wrapping_add(1);
        let offsets = grid.offsets();
        let (mut i, mut out, mut diagonal) = (self.i, self.out, self.diagonal);
        let (width, height) = (usize::from(grid.width()), usize::from(grid.height()));
        // The cell at position `i`, followed along the path (a jump to `j` by move `d` lands on
        // the cell at `j`: that is how `j` was found).
        let mut cp = self.at;
        let mut left = *budget;
        // `i < n` throughout (it only ever becomes a valid position on the path), so no
        // `wrapping_` below wraps: `out <= i` and `diagonal <= out`.
        while i.wrapping_add(1) < n {
            if left < LOOK_UNITS.wrapping_add(8) {
                // Maybe not enough for the next step: the rest in the next call.
                *budget = 0;
                (self.i, self.out, self.diagonal, self.at) = (i, out, diagonal, cp);
                return None;
            }
            let ci = grid.index(cp);
            // Fast path, away from the map's border: when no neighbour but the path's previous
            // and next cells was visited, the next cell is the furthest. `tour[i]` still holds
            // the step from cell `i` to `i + 1` and `tour[i - 1]` the step into cell `i` (the
            // output so far ends at index `out - 1 < i`, and its last step, if at `i - 1`, is
            // that same step).
            if let Some(&next_d) = tour.get(i) {
                let (x, y) = (usize::from(cp.x), usize::from(cp.y));
                if x > 0 && y > 0 && x.wrapping_add(1) < width && y.wrapping_add(1) < height {
                    let mut others = visited.around(ci, width) & !(1u8 << (next_d & 7));
                    if let Some(&in_d) = i.checked_sub(1).and_then(|k| tour.get(k)) {
                        others &= !(1u8 << (opposite(in_d) & 7));
                    }
                    if others == 0 {
                        left = left.wrapping_sub(CELL_UNITS);
                        if let Some(slot) = tour.get_mut(out) {
                            *slot = next_d;
                        }
                        out = out.wrapping_add(1);
                        diagonal = diagonal.wrapping_add(u32::from(is_diagonal(next_d)));
                        i = i.wrapping_add(1);
                        cp = neighbour(cp, next_d);
                        continue;
                    }
                }
            }
            left = left.wrapping_sub(LOOK_UNITS);
            // The path's cells before and after this one are known without a look-up: `tour[i]`
            // is the step out of this cell and `tour[i - 1]` the step into it (see above).
            // (Index arithmetic: both are cells of the map, one move from this one.)
            let step = |d: Dir| offsets.get(usize::from(d & 7)).copied().unwrap_or(0);
            let prev = match i.checked_sub(1).and_then(|k| tour.get(k)) {
                Some(&d) => ci.wrapping_add_signed(step(d).wrapping_neg()),
                None => usize::MAX,
            };
            let next = tour
                .get(i)
                .map_or(usize::MAX, |&d| ci.wrapping_add_signed(step(d)));
            let mut mask = moves.at(ci, cp);
            // Furthest later path cell one allowed move away (the next cell always qualifies).
            let mut best = (i, 0u8);
            while mask != 0 {
                let d = mask.trailing_zeros() as u8;
                mask &= mask.wrapping_sub(1);
                let nb = ci.wrapping_add_signed(offsets.get(usize::from(d)).copied().unwrap_or(0));
                // Not visited: not on the path (a cell beyond the set reads as visited). The
                // previous cell cannot be the furthest; the next one is at `i + 1` (cells are
                // unique on a path).
                if !visited.contains(nb) || nb == prev {
                    continue;
                }
                if nb == next {
                    if i.wrapping_add(1) > best.0 {
                        best = (i.wrapping_add(1), d);
                    }
                    continue;
                }
                // At most eight look-ups a step: `left` was at least `LOOK_UNITS + 8`.
                left = left.saturating_sub(1);
                if let Some(j) = find(nb) {
                    if j > best.0 {
                        best = (j, d);
                    }
                }
            }
            let (j, d) = best;
            if j == i {
                // Cannot happen for a path made of allowed moves; stop rather than loop.
                break;
            }
            if let Some(slot) = tour.get_mut(out) {
                *slot = d;
            }
            out = out.wrapping_add(1);
            diagonal = diagonal.wrapping_add(u32::from(is_diagonal(d)));
            i = j;
            cp = neighbour(cp, d);
        }
        *budget = left;
        (self.i, self.out, self.diagonal, self.at) = (i, out, diagonal, cp);
        Some(self.walk(out, diagonal))
    }
}

/// Slots of the hash table [`tighten`] builds for a path of `n` cells in `words` words: the
/// smallest power of two of at least `2n` (load factor at most 1/2) when it fits, else half of
/// that if it still has at least `ceil(3n / 2)` slots (load factor at most 2/3), else `None` (the
/// path is left untightened). Two 16-bit slots a word for paths of fewer than 65,535 cells.
const fn hash_slots(n: usize, words: usize) -> Option<usize> {
    let Some(want) = table_slots(n) else {
        return None;
    };
    if words >= slot_words(want, n) {
        return Some(want);
    }
    // At least 3n/2 slots, rounded up (`n + ceil(n / 2) <= 2n`, which did not overflow).
    let fewer = want >> 1;
    if fewer >= n.wrapping_add(n.div_ceil(2)) && words >= slot_words(fewer, n) {
        Some(fewer)
    } else {
        None
    }
}

/// The slots of the smallest table of a load factor of at most 1/2 for `n` cells (a power of
/// two); `None` on overflow.
const fn table_slots(n: usize) -> Option<usize> {
    match n.checked_mul(2) {
        Some(twice) => twice.checked_next_power_of_two(),
        None => None,
    }
}

/// Words of a table of `slots` slots for paths of `n` cells: two 16-bit slots a word while the
/// positions fit 16 bits, else a word a slot.
const fn slot_words(slots: usize, n: usize) -> usize {
    if n < u16::MAX as usize {
        slots.div_ceil(2)
    } else {
        slots
    }
}

/// The fewest words of `pos` with which [`tighten`] tightens every path of up to `n` cells
/// (rather than leaving it unchanged) on a map of more cells: the fewest words `hash_slots`
/// accepts (the table half the smallest of load 1/2 when it stays at a load of at most 2/3,
/// else that one), derived from it rather than written again. `usize::MAX` if no table holds
/// `n` cells.
pub const fn hash_words(n: usize) -> usize {
    let Some(want) = table_slots(n) else {
        return usize::MAX;
    };
    let fewer = slot_words(want >> 1, n);
    if hash_slots(n, fewer).is_some() {
        fewer
    } else {
        slot_words(want, n)
    }
}

/// The fewest words of `pos` with which [`tighten`] tightens every path of up to `n` cells on a
/// map of up to 2^(32 - bits(n)) cells when `cells` lends its `n` words too: a table of packed
/// (cell, position) keys over both (`Keyed`), of at least `3n / 2` slots. The compact arena
/// ([`crate::planner::arena`]) sizes its links so: half the words of [`hash_words`].
pub const fn keyed_words(n: usize) -> usize {
    n.div_ceil(2)
}

/// Whether a [`keyed_words`] table holds paths of `n` cells on a map of `cells` cells: a cell
/// index and a position fit 32 bits together.
pub const fn keyed_fits(cells: usize, n: usize) -> bool {
    let bits = usize::BITS.saturating_sub(n.leading_zeros());
    let cell_bits = usize::BITS.saturating_sub(cells.saturating_sub(1).leading_zeros());
    bits < 32 && bits.saturating_add(cell_bits) <= 32
}

/// An open-addressing table of `(cell << bits) | (position + 1)` keys (0 = empty) over two
/// slices of words, slot `k` in the first while `k` is below its length, then in the second: the
/// links and the path cells' own words, which [`tighten`] does not need laid out when the key
/// carries the cell. Any number of slots (at least `3n / 2`, a load of at most 2/3): the home
/// slot is the Fibonacci hash scaled onto them (a multiply and a shift). Only when the cell
/// index and the position fit 32 bits together (`bits(cells - 1) + bits(n) <= 32`: 262,144
/// cells with paths of up to 16,383 steps).
struct Keyed<'a> {
    a: &'a mut [u32],
    b: &'a mut [u32],
    /// Slots in all: `a.len() + b.len()`, below 2^32.
    len: usize,
    /// Bits of `position + 1`.
    bits: u32,
}

impl<'a> Keyed<'a> {
    /// The table for a path of `n` cells, emptied when `clear` (a new path), else as the last
    /// call left it (a tightening resumed, [`Tightening::resume`]).
    fn new(
        a: &'a mut [u32],
        cells: &'a mut [Point],
        map_cells: usize,
        n: usize,
        clear: bool,
    ) -> Option<Self> {
        if !keyed_fits(map_cells, n) {
            return None;
        }
        let bits = usize::BITS.wrapping_sub(n.leading_zeros());
        let b: &mut [u32] = bytemuck::try_cast_slice_mut(cells).ok()?;
        // At most 2n slots (a load of 1/2): the table is cleared for every walk it indexes, and
        // more slots would only cost that.
        let most = n.checked_mul(2)?;
        let a = a.get_mut(..most.min(a.len()))?;
        let b = b.get_mut(..most.saturating_sub(a.len()).min(b.len()))?;
        let len = a.len().checked_add(b.len())?;
        if len < n.checked_add(n.div_ceil(2))? || u32::try_from(len).is_err() {
            return None;
        }
        if clear {
            a.fill(0);
            b.fill(0);
        }
        Some(Keyed { a, b, len, bits })
    }

    #[inline]
    fn home(&self, cell: usize) -> usize {
        // Fibonacci hashing, scaled onto `len` slots.
        let h = u64::from((cell as u32).wrapping_mul(0x9E37_79B9));
        (h.wrapping_mul(self.len as u64) >> 32) as usize
    }

    #[inline]
    fn slot(&self, k: usize) -> Option<u32> {
        match k.checked_sub(self.a.len()) {
            None => self.a.get(k).copied(),
            Some(j) => self.b.get(j).copied(),
        }
    }

    #[inline]
    fn next(&self, k: usize) -> usize {
        let k = k.wrapping_add(1);
        if k >= self.len {
            0
        } else {
            k
        }
    }

    fn insert(&mut self, cell: usize, i: u32) {
        // `bits < 32` (`new`: a position and a cell bit at least, or no path).
        let key = (cell as u32).wrapping_shl(self.bits) | i.wrapping_add(1);
        let mut k = self.home(cell);
        // At most n entries in at least 3n/2 slots: an empty slot is always found.
        for _ in 0..self.len {
            if self.slot(k) == Some(0) {
                let s = match k.checked_sub(self.a.len()) {
                    None => self.a.get_mut(k),
                    Some(j) => self.b.get_mut(j),
                };
                if let Some(s) = s {
                    *s = key;
                }
                return;
            }
            k = self.next(k);
        }
    }

    #[inline]
    fn find(&self, cell: usize) -> Option<usize> {
        let mut k = self.home(cell);
        for _ in 0..self.len {
            let v = self.slot(k)?;
            if v == 0 {
                return None;
            }
            if v.wrapping_shr(self.bits) as usize == cell {
                let mask = 1u32.wrapping_shl(self.bits).wrapping_sub(1);
                return Some((v & mask).wrapping_sub(1) as usize);
            }
            k = self.next(k);
        }
        None
    }
}

/// Cell -> position on a path: a per-cell array, or a hash table over the path's cells.
struct PathIndex<'a> {
    slots: &'a mut [u32],
    /// `Some(bits)`: hash table of `2^bits` slots holding `position + 1` (0 = empty), two 16-bit
    /// slots a word (paths of fewer than 65,535 cells) or one 32-bit slot a word.
    hash: Option<u32>,
    /// The hash table's slots are 16-bit halves of the words (slot `k`: word `k / 2`, the low
    /// half for even `k`).
    half: bool,
}

impl<'a> PathIndex<'a> {
    /// Whether [`PathIndex::new`] has room in `words` words for a path of `n` cells on a map of
    /// `cells` cells.
    fn fits(words: usize, cells: usize, n: usize) -> bool {
        words >= cells || hash_slots(n, words).is_some()
    }

    /// The index for a path of `n` cells on a map of `cells` cells; its hash table emptied when
    /// `clear` (a new path), else as the last call left it (a tightening resumed).
    fn new(pos: &'a mut [u32], cells: usize, n: usize, clear: bool) -> Option<Self> {
        if pos.len() >= cells {
            return Some(PathIndex {
                slots: pos,
                hash: None,
                half: false,
            });
        }
        // The smallest power of two of at least 2n slots (load factor <= 1/2), or when that does
        // not fit, half of it if that still has at least 3n/2 slots (load factor <= 2/3);
        // positions + 1 below 2^16 fit a half word, so the same words hold twice the slots.
        let slots = hash_slots(n, pos.len())?;
        let half = n < usize::from(u16::MAX);
        let table = pos.get_mut(..if half { slots.div_ceil(2) } else { slots })?;
        if clear {
            table.fill(0);
        }
        Some(PathIndex {
            slots: table,
            hash: Some(slots.trailing_zeros()),
            half,
        })
    }

    /// Slots of the hash table.
    #[inline]
    fn len(&self) -> usize {
        if self.half {
            self.slots.len().wrapping_mul(2) // a slice of words: far below usize::MAX / 2
        } else {
            self.slots.len()
        }
    }

    /// Hash slot `k` (`None` beyond the table).
    #[inline]
    fn slot(&self, k: usize) -> Option<u32> {
        if self.half {
            let w = *self.slots.get(k >> 1)?;
            Some(if k & 1 == 0 { w & 0xFFFF } else { w >> 16 })
        } else {
            self.slots.get(k).copied()
        }
    }

    /// Write `v` (below 2^16 in half slots) into hash slot `k`.
    #[inline]
    fn set_slot(&mut self, k: usize, v: u32) {
        if self.half {
            if let Some(w) = self.slots.get_mut(k >> 1) {
                *w = if k & 1 == 0 {
                    (*w & 0xFFFF_0000) | (v & 0xFFFF)
                } else {
                    (*w & 0xFFFF) | (v << 16)
                };
            }
        } else if let Some(s) = self.slots.get_mut(k) {
            *s = v;
        }
    }

    #[inline]
    fn home(bits: u32, cell: usize) -> usize {
        // Fibonacci hashing of the (32-bit) cell index onto `bits` bits (1 <= bits <= 32).
        ((cell as u32).wrapping_mul(0x9E37_79B9) >> (32u32.wrapping_sub(bits) & 31)) as usize
    }

    fn insert(&mut self, cell: usize, i: u32) {
        let Some(bits) = self.hash else {
            if let Some(s) = self.slots.get_mut(cell) {
                *s = i;
            }
            return;
        };
        let len = self.len();
        let mask = len.wrapping_sub(1);
        let mut h = Self::home(bits, cell) & mask;
        // At most n entries in at least 3n/2 slots: an empty slot is always found.
        for _ in 0..len {
            if self.slot(h) == Some(0) {
                self.set_slot(h, i.wrapping_add(1)); // i < n <= 2^31 (< 2^16 - 1 in half slots)
                return;
            }
            h = h.wrapping_add(1) & mask;
        }
    }

    /// The position of `cell`, checked against the path (`cell_at(j)` = the cell at position `j`):
    /// a per-cell array may hold stale positions from earlier walks.
    #[inline]
    fn find(&self, cell: usize, cell_at: impl Fn(usize) -> Option<usize>) -> Option<usize> {
        let Some(bits) = self.hash else {
            let j = *self.slots.get(cell)? as usize;
            return (cell_at(j) == Some(cell)).then_some(j);
        };
        let len = self.len();
        let mask = len.wrapping_sub(1);
        let mut h = Self::home(bits, cell) & mask;
        for _ in 0..len {
            let v = self.slot(h)?;
            if v == 0 {
                return None;
            }
            let j = v.wrapping_sub(1) as usize;
            if cell_at(j) == Some(cell) {
                return Some(j);
            }
            h = h.wrapping_add(1) & mask;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colony::ant::{Ant, DeadEnd};
    use crate::colony::heuristic::{Attraction, Heuristic};
    use crate::colony::pheromone::{Blocks, Table};
    use crate::map::grid::Grid;
    use crate::rng::Xoshiro128pp;

    /// A walk of [`wandering_walk`]: the map's bits, the walk, its tour and the tabu bits it left.
    struct Wandering {
        bits: Vec<u8>,
        walk: Walk,
        tour: Vec<Dir>,
        tabu: Vec<u32>,
    }

    /// A weakly guided walk from corner to corner of a `w x h` map with 20 % random obstacles
    /// (from `seed`): such walks wander and bulge. `None` when the goal is blocked or the ant is
    /// lost.
    fn wandering_walk(w: u16, h: u16, seed: u64) -> Option<Wandering> {
        let mut rng = Xoshiro128pp::from_u64(seed);
        let cells = usize::from(w) * usize::from(h);
        let mut bits = vec![0u8; cells.div_ceil(8)];
        for i in 0..cells {
            if i > 0 && i + 1 < cells && rng.next_unit() < 0.2 {
                bits[i / 8] |= 1 << (i % 8);
            }
        }
        let g = Grid::new(w, h, &bits).ok()?;
        let (start, goal) = (Point::new(0, 0), Point::new(w - 1, h - 1));
        if !g.is_free(goal) {
            return None;
        }
        let mut tau_buf = vec![[1.0f32; 4]; 1024];
        let tau = Table::new(Blocks::new(w, h), &mut tau_buf);
        let heur = Heuristic::new(goal, Some(Attraction { a: 0.3, xi: 1.0 }), 0.5);
        let moves = Moves::new(g, &[]);
        let ant = Ant {
            moves: &moves,
            start,
            goal,
            tau: &tau,
            heuristic: &heur,
            alpha: 1.0,
            dead_end: DeadEnd::Backtrack,
            dead: &[],
            route: None,
            weights: None,
            budget: u32::MAX,
        };
        let mut tabu = vec![0u32; crate::map::bitmap::words(cells)];
        let mut tour = vec![0u8; cells];
        let walk = ant
            .walk(&mut rng, &mut TabuSet::new(&mut tabu), &mut tour)
            .ok()?;
        Some(Wandering {
            bits,
            walk,
            tour,
            tabu,
        })
    }

    /// Tighten `walk` (its `tour`) on the map `bits` with `links` words of index: the walk and
    /// its path.
    fn tightened(
        (w, h, bits): (u16, u16, &[u8]),
        walk: Walk,
        tour: &[Dir],
        tabu: &[u32],
        links: usize,
    ) -> (Walk, Vec<Dir>) {
        let g = Grid::new(w, h, bits).unwrap();
        let moves = Moves::new(g, &[]);
        let mut t = tour.to_vec();
        let mut cells = vec![Point::default(); walk.steps + 1];
        let mut pos = vec![0u32; links];
        let out = tighten(
            &moves,
            Point::new(0, 0),
            walk,
            &mut t,
            &mut cells,
            &mut pos,
            &TabuSet::new(&mut tabu.to_vec()),
        );
        (out, t[..out.steps].to_vec())
    }

    /// Every wandering walk of `seeds` on each map size, with `run(links)`: it tightened with
    /// that many words of index.
    fn each_walk(
        sizes: &[(u16, u16)],
        seeds: core::ops::Range<u64>,
        mut f: impl FnMut((u16, u16, u64), &Wandering, &dyn Fn(usize) -> (Walk, Vec<Dir>)),
    ) {
        for &(w, h) in sizes {
            for seed in seeds.clone() {
                let Some(wd) = wandering_walk(w, h, seed) else {
                    continue;
                };
                let run =
                    |links: usize| tightened((w, h, &wd.bits), wd.walk, &wd.tour, &wd.tabu, links);
                f((w, h, seed), &wd, &run);
            }
        }
    }

    #[test]
    fn tightening_in_pieces_tightens_as_at_once() {
        // Wandering walks, each tightened with the per-cell index, the hash table and the keyed
        // table, at once and in pieces of a few work units (the least that makes progress, and
        // more): the same walk and path, bit for bit, and every piece but the last spends its
        // whole budget.
        let (mut split, mut shortened) = (0, 0);
        each_walk(&[(48, 40), (120, 90)], 0..16, |(w, h, seed), wd, run| {
            let n = wd.walk.steps + 1;
            let g = Grid::new(w, h, &wd.bits).unwrap();
            let moves = Moves::new(g, &[]);
            for links in [
                usize::from(w) * usize::from(h),
                hash_words(n),
                keyed_words(n),
            ] {
                let direct = run(links);
                shortened += usize::from(direct.0.steps < wd.walk.steps);
                for piece in [LOOK_UNITS + 8, 11, 37, 500] {
                    let mut t = wd.tour.clone();
                    let mut cells = vec![Point::default(); n];
                    let mut pos = vec![0u32; links];
                    let start = Point::new(0, 0);
                    let mut tg =
                        Tightening::begin(&moves, start, wd.walk, &t, &mut cells, &mut pos)
                            .expect("an index");
                    let mut calls = 0;
                    let out = loop {
                        let mut budget = piece;
                        calls += 1;
                        let done = tg.resume(
                            &moves,
                            start,
                            &mut t,
                            &mut cells,
                            &mut pos,
                            &TabuSet::new(&mut wd.tabu.clone()),
                            &mut budget,
                        );
                        if let Some(out) = done {
                            break out;
                        }
                        assert_eq!(budget, 0);
                        assert!(calls <= 2 * n, "{w}x{h} seed {seed}: no progress");
                    };
                    let got = (out, t[..out.steps].to_vec());
                    assert_eq!(
                        got, direct,
                        "{w}x{h} seed {seed} links {links} piece {piece}"
                    );
                    // At least the cells' indexing and a step a piece at this budget.
                    assert!(calls >= n / piece as usize, "{calls} {n} {piece}");
                    split += usize::from(calls > 2);
                }
            }
        });
        assert!(split >= 40 && shortened >= 10, "{split} {shortened}");
    }

    #[test]
    fn a_resumed_tightening_without_its_index_completes_the_path_untightened() {
        // The index gone between two pieces (buffers too short): the steps tightened so far and
        // the rest of the path as it was, a valid path of the same start and end.
        let mut checked = 0;
        each_walk(&[(120, 90)], 0..8, |(w, h, seed), wd, run| {
            let n = wd.walk.steps + 1;
            let g = Grid::new(w, h, &wd.bits).unwrap();
            let moves = Moves::new(g, &[]);
            let start = Point::new(0, 0);
            let mut t = wd.tour.clone();
            let mut cells = vec![Point::default(); n];
            let mut pos = vec![0u32; hash_words(n)];
            let mut tg = Tightening::begin(&moves, start, wd.walk, &t, &mut cells, &mut pos)
                .expect("an index");
            // Index every cell and a few steps of the pass.
            let mut budget = n as u32 + 40;
            let mut state = None;
            let first = tg.resume(
                &moves,
                start,
                &mut t,
                &mut cells,
                &mut pos,
                &TabuSet::new(&mut wd.tabu.clone()),
                &mut budget,
            );
            if first.is_none() {
                state = Some(tg);
            }
            let Some(mut tg) = state else { return };
            let mut none: Vec<u32> = Vec::new();
            let mut budget = u32::MAX;
            let out = tg
                .resume(
                    &moves,
                    start,
                    &mut t,
                    &mut cells,
                    &mut none,
                    &TabuSet::new(&mut wd.tabu.clone()),
                    &mut budget,
                )
                .expect("done at once");
            let end = t[..out.steps]
                .iter()
                .fold(start, |p, &d| crate::map::grid::neighbour(p, d));
            assert_eq!(end, Point::new(w - 1, h - 1), "seed {seed}");
            assert_eq!(out.straight + out.diagonal, out.steps as u32);
            assert!(out.steps >= run(usize::from(w) * usize::from(h)).0.steps);
            assert!(out.steps <= wd.walk.steps);
            checked += 1;
        });
        assert!(checked >= 3, "{checked}");
    }

    #[test]
    fn the_hash_tables_tighten_as_the_per_cell_index_does() {
        // Wandering walks on a 48 x 40 map; each is tightened with a per-cell index, with the
        // smallest hash table of 16-bit slots (half a word a slot) of a load factor of 1/2, and
        // with one word too few (tightened alike in the table half the size when that holds it,
        // else by the keyed table over the links and the cells' words), and with too few words
        // even for that (the walk comes back untightened).
        let (w, h) = (48u16, 40u16);
        let mut changed = 0;
        each_walk(&[(w, h)], 0..40, |(_, _, seed), wd, run| {
            let (walk, tour) = (wd.walk, &wd.tour);
            let n = walk.steps + 1;
            let cells = usize::from(w) * usize::from(h);
            let words = (2 * n).next_power_of_two() / 2;
            if words >= cells {
                // As many words as cells: the per-cell index, no hash table to test.
                return;
            }
            let direct = run(cells);
            assert_eq!(run(words), direct, "seed {seed}");
            if words < n + n.div_ceil(2) {
                assert_eq!(hash_words(n), words, "seed {seed}");
            } else {
                assert_eq!(hash_words(n), words / 2, "seed {seed}");
            }
            assert_eq!(run(words - 1), direct, "seed {seed}");
            assert_eq!(run(keyed_words(n)), direct, "seed {seed}");
            let (short, path) = run(keyed_words(n) - 1);
            assert_eq!((short, path.as_slice()), (walk, &tour[..walk.steps]));
            changed += usize::from(direct.0.steps < walk.steps);
        });
        assert!(changed >= 10, "{changed}");
    }

    #[test]
    fn the_two_thirds_table_tightens_as_the_per_cell_index_does() {
        // The same wandering walks, on maps of several sizes so that their lengths fall both
        // just above a power of two (where half the load-1/2 table still holds 3n/2 slots) and
        // below: with the words of that smaller table, each walk is tightened exactly as with the
        // per-cell index; with one word fewer, as the keyed table over links and cells does it.
        let (mut smaller, mut shortened) = (0, 0);
        let sizes = [(48u16, 40u16), (64, 24), (30, 30), (80, 60)];
        each_walk(&sizes, 0..40, |(w, h, seed), wd, run| {
            let n = wd.walk.steps + 1;
            let slots = (2 * n).next_power_of_two() / 2;
            if slots < n + n.div_ceil(2) {
                return;
            }
            let words = slots / 2;
            assert_eq!(hash_words(n), words);
            let direct = run(usize::from(w) * usize::from(h));
            assert_eq!(run(words), direct, "{w}x{h} seed {seed}");
            shortened += usize::from(direct.0.steps < wd.walk.steps);
            assert_eq!(run(words - 1), direct, "{w}x{h} seed {seed}");
            smaller += 1;
        });
        // Enough walks of such lengths, and enough of them shortened (a table that never finds a
        // cell would leave every walk as it was).
        assert!(smaller >= 20 && shortened >= 10, "{smaller} {shortened}");
    }

    #[test]
    fn the_two_thirds_table_holds_at_least_three_halves_of_the_cells() {
        // 10 cells: 16 slots >= 15 (8 words); 11 cells: 16 slots < 16.5, so 32 (16 words); the
        // same rounding at the H743's scale (10,923 cells: 16,384 slots would be a load over 2/3).
        assert_eq!((hash_words(10), hash_slots(10, 8)), (8, Some(16)));
        assert_eq!((hash_words(11), hash_slots(11, 15)), (16, None));
        assert_eq!(hash_words(10_922), 8_192);
        assert_eq!(
            (hash_words(10_923), hash_slots(10_923, 8_192)),
            (16_384, None)
        );
    }

    #[test]
    fn a_path_of_16385_cells_is_indexed_in_16384_words() {
        // The STM32H743's longest path (16,384 steps) in its 16,384 links: 32,768 half-word
        // slots, a load factor of 1/2 would need 65,536. Every cell is found at its position,
        // and cells not on the path are not.
        let n = 16_385;
        assert_eq!(hash_words(n), 16_384);
        let mut pos = vec![0u32; 16_384];
        let mut ix = PathIndex::new(&mut pos, 1 << 22, n, true).expect("a table");
        assert_eq!(ix.len(), 32_768);
        let cell = |i: usize| (i * 193 + 7) % (1 << 22);
        for i in 0..n {
            ix.insert(cell(i), i as u32);
        }
        let at = |j: usize| (j < n).then(|| cell(j));
        for i in 0..n {
            assert_eq!(ix.find(cell(i), at), Some(i));
        }
        for i in n..n + 1000 {
            assert_eq!(ix.find(cell(i), at), None);
        }
        let mut fewer = vec![0u32; 16_383];
        assert!(PathIndex::new(&mut fewer, 1 << 22, n, true).is_none());
    }

    #[test]
    fn the_keyed_table_finds_a_4096_cell_path_in_6144_words() {
        // The compact arena's longest path (4,095 steps) on a 512 x 512 map: its 2,048 links and
        // the path cells' 4,096 words hold 6,144 slots of packed keys (18 bits of cell, 13 of
        // position). Every cell is found at its position, cells not on the path are not, and a
        // map of 2^20 cells (20 + 13 bits) or one word fewer gets no table.
        let n = 4096;
        let map = 512 * 512;
        let cell = |i: usize| (i * 193 + 7) % map;
        let mut links = vec![0u32; keyed_words(n)];
        let mut cells = vec![Point::default(); n];
        let mut k = Keyed::new(&mut links, &mut cells, map, n, true).expect("a table");
        assert_eq!((k.len, k.bits), (6144, 13));
        for i in 0..n {
            k.insert(cell(i), i as u32);
        }
        for i in 0..n {
            assert_eq!(k.find(cell(i)), Some(i));
        }
        for i in n..n + 2000 {
            assert_eq!(k.find(cell(i)), None);
        }
        let mut links = vec![0u32; keyed_words(n) - 1];
        assert!(Keyed::new(&mut links, &mut cells, map, n, true).is_none());
        let mut links = vec![0u32; keyed_words(n)];
        assert!(Keyed::new(&mut links, &mut cells, 1 << 20, n, true).is_none());
    }

    #[test]
    fn the_keyed_table_tightens_long_walks_as_the_per_cell_index_does() {
        // Wandering walks on maps large enough for walks of hundreds of cells: the keyed table
        // with as few links as it needs, and with many more, tightens each as the per-cell index.
        let mut shortened = 0;
        each_walk(&[(120, 90), (200, 40)], 0..12, |(w, h, seed), wd, run| {
            let n = wd.walk.steps + 1;
            let direct = run(usize::from(w) * usize::from(h));
            assert_eq!(run(keyed_words(n)), direct, "{w}x{h} seed {seed}");
            assert_eq!(run(keyed_words(n) + 1), direct, "{w}x{h} seed {seed}");
            // Without the tabu set's filter every neighbour is looked up: the same path.
            let g = Grid::new(w, h, &wd.bits).unwrap();
            let mut t = wd.tour.clone();
            let mut cells = vec![Point::default(); n];
            let mut pos = vec![0u32; keyed_words(n)];
            let moves = Moves::new(g, &[]);
            let out = tighten(
                &moves,
                Point::new(0, 0),
                wd.walk,
                &mut t,
                &mut cells,
                &mut pos,
                &TabuSet::new(&mut []),
            );
            assert_eq!(
                (out, t[..out.steps].to_vec()),
                direct,
                "{w}x{h} seed {seed}"
            );
            shortened += usize::from(direct.0.steps < wd.walk.steps);
        });
        assert!(shortened >= 6, "{shortened}");
    }

    #[test]
    fn hash_words_is_the_fewest_words_hash_slots_takes() {
        // The sizing and the table agree: with `hash_words(n)` words the table is built, with
        // one word fewer it is not (and more words never hurt), across the 16-bit boundary.
        for n in (1..5_000).chain(65_000..65_600) {
            let w = hash_words(n);
            assert!(hash_slots(n, w).is_some(), "{n}");
            assert!(hash_slots(n, w - 1).is_none(), "{n}");
            assert!(hash_slots(n, w + 1).is_some(), "{n}");
        }
    }
}
