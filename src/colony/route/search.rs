//! The coarse route's search: an A* over the blocks from the goal's block towards the start's,
//! bounded by the plan.
//!
//! The ants read one thing of the route: in the block they stand in, the next block towards the
//! goal. They walk near the route's corridor, so the route needs to be right there and nowhere
//! else. The search is therefore an A* rooted at the goal's block (the route's distances are to
//! the goal), led by the octile block distance to the start's block (10 / 14 per straight /
//! diagonal block step, the coarse scale [`BLOCKS`] of `search::cost`, which says why not the
//! exact one: the steps' own costs, so the estimate is consistent and a closed block's
//! distance is exact), ties broken towards the straight line between the ends ([`Heap::tied_before`]).
//! It runs until it closes the start's block, at `F`, the length of the shortest block route;
//! by then it has closed every block whose shortest block route through it is shorter than `F`
//! (the blocks a detour round a wall passes) and some as short. Then it widens
//! ([`Bound::Plan`]): it goes on closing, in its own order, the blocks whose route through
//! them is at most [`SLACK`] longer than `F`, up to [`WIDEN`] times the blocks it had closed
//! (at least [`WIDEN_MIN`] more): first the ties nearest the line (a wider band), then the
//! corridors a few block steps longer, which a route on coarse blocks cannot tell from the
//! shortest one (without the widening, `w_woundedcoast` planned at 1.0042 of the optimum
//! instead of 1.0010, 20 scenarios x 2 seeds).
//!
//! A block's links ([`super::links`]) are read from the map's bits when the search closes the
//! block, never before, so the setup reads the border cells of the closed blocks only (a few
//! hundred instructions a block, where the whole map's links and a Dijkstra over every block
//! cost 5 M instructions on Nav2's depot). A property test compares every closed block's
//! distance with the search run to the end over every block ([`Bound::Whole`]), and the closed
//! set with the bound's.
//!
//! **Why not an ellipse** (every block within `(1 + eps) F`, the near-optimal corridors): in
//! the octile distance every block of the parallelogram between the ends of an open map lies
//! on a shortest block route, so `eps = 1/8` (and 30 more) closed 2,702 of the depot's 2,964
//! blocks for a corner-to-corner pair, and 3,301 of Boston's 4,096: no cheaper than the whole
//! map. The count bound keeps the widening to a multiple of what the route itself needed;
//! the colony still chooses the corridor at the cell level (the pheromone, the tour length and
//! the local search; the route only pulls).
//!
//! **An ant outside the closed blocks.** A block the search reached but did not close (the
//! ring around the closed band) keeps the next block it was reached from: a closed block, so the
//! ant is led back into the corridor, on a route to the goal that may not be the shortest. A
//! block the search never reached has no next block, and its ants are pulled straight at the
//! goal (the paper's attraction), as every ant is on a map without a route. Why not continue the
//! search on demand: the route must not change during an iteration (every ant of one reads the
//! same route, and the iteration's best and worst ants are walked again bit for bit), and an ant
//! two blocks off the corridor is one the tour length and the pheromone already discard; pulling
//! it at the goal costs moves, never a path (the ants walk cells with their tabu list and
//! backtracking).
//!
//! Memory: the route's words (one a block: links, a known flag, the next block, the key) and
//! scratch for the heap, one word a block.

use crate::colony::pheromone::Blocks;
use crate::map::grid::{Moves, Point, DX, DY};
use crate::search::cost::BLOCKS;
use crate::search::heap;

use super::{dist, RouteHeap, DIST_SHIFT, KNOWN, LINKS, NEXT_SHIFT};

/// After the start's block, the search closes the blocks whose key is at most `F + SLACK`
/// (four straight block steps: block routes are coarse, and a corridor whose cells are as short
/// may be a few block steps longer on blocks) ...
pub const SLACK: u32 = 4 * BLOCKS.straight;

/// ... up to `WIDEN` times the blocks it had closed by then (at least [`WIDEN_MIN`] more), in
/// the search's order: the ties at `F` nearest the straight line first (a wider band), then the
/// corridors a little longer.
pub const WIDEN: u32 = 2;

/// The fewest blocks the widening may add.
pub const WIDEN_MIN: u32 = 32;

/// How far the search runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// The default: stop once the start's block is closed and the widening is done.
    Plan,
    /// Close every block the goal's block reaches (a search over every block of the map: the
    /// reference the tests compare the bounded search with).
    Whole,
}

/// What a search did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Searched {
    /// Blocks closed (their distance exact).
    pub closed: u32,
    /// Blocks whose links were read from the map (the others were known: a warm start's).
    pub linked: u32,
    /// The length of the shortest block route from the start's block (`None`: the start's
    /// block is not reached: the ants prove whether the start is cut off).
    pub length: Option<u32>,
}

/// The octile block distance between blocks `(ax, ay)` and `(bx, by)` on the route's coarse
/// scale ([`BLOCKS`]: 10 a straight step, 14 a diagonal one).
#[inline]
pub(super) fn octile(ax: usize, ay: usize, bx: usize, by: usize) -> u32 {
    // Block coordinates are below 2^16.
    BLOCKS.octile(ax.abs_diff(bx) as u32, ay.abs_diff(by) as u32)
}

/// A* over the blocks from the goal's block, towards the start's block, as the module docs say
/// (until the start's block is closed, or over every block it reaches: `bound`).
/// `words` (one a block) hold each block's known links (bit [`KNOWN`]), the next block `NONE`
/// and the key `UNREACHED`; afterwards each block the search reached has its next block and its
/// key `g + h` (the distance to the goal's block plus the estimate to the start's block), and
/// each closed block its links. `heap` is scratch of one word a block; both are `blocks.count()`
/// long.
#[cfg(test)]
pub(super) fn search(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    bound: Bound,
) -> Searched {
    let mut at = begin(blocks, ends, words, heap);
    loop {
        if let Some(done) = resume(
            moves,
            blocks,
            ends,
            dead,
            words,
            heap,
            bound,
            &mut at,
            u32::MAX,
        ) {
            return done;
        }
    }
}

/// Where a search stands between two pieces ([`super::begin_build`], [`super::resume`]): the heap's length,
/// the widening's bounds and the counts so far; the words and the heap hold the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Searching {
    len: usize,
    /// Once the start's block is closed at `F`: the last key and the last count of blocks the
    /// search still closes (the widening, `Bound::Plan`).
    last_key: u32,
    last_count: u32,
    done: Searched,
}

impl Searching {
    /// Count `n` more blocks whose links were read before the search ([`Searched::linked`]).
    pub(super) fn linked(&mut self, n: u32) {
        self.done.linked = self.done.linked.wrapping_add(n);
    }
}

/// The heap over `heap` for a search between `start` and `goal` with `len` blocks queued.
fn heap_of<'h>(
    blocks: Blocks,
    (start, goal): (Point, Point),
    heap: &'h mut RouteHeap<'_>,
    len: usize,
) -> Heap<'h> {
    let s = blocks.shift();
    let start = (usize::from(start.x >> s), usize::from(start.y >> s));
    let goal = (usize::from(goal.x >> s), usize::from(goal.y >> s));
    // Block coordinates are below 2^16.
    let d = |a: usize, z: usize| (a as i32).wrapping_sub(z as i32);
    Heap {
        w: heap.words(),
        len,
        across: blocks.across().max(1),
        start,
        goal,
        line: (d(start.0, goal.0), d(start.1, goal.1)),
    }
}

/// Start a search (the A* above) to be done a piece at a time ([`resume`]): the heap cleared (a pass over
/// its words), the goal's block queued.
pub(super) fn begin(
    blocks: Blocks,
    ends: (Point, Point),
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
) -> Searching {
    heap.clear();
    let mut heap = heap_of(blocks, ends, heap, 0);
    let (sx, sy) = heap.start;
    let (gx, gy) = heap.goal;
    let goal_block = blocks.block(ends.1);
    if let Some(w) = words.get_mut(goal_block) {
        *w = (*w & (LINKS | KNOWN))
            | (super::NONE << NEXT_SHIFT)
            | (octile(gx, gy, sx, sy) << DIST_SHIFT);
        heap.push(words, goal_block);
    }
    Searching {
        len: heap.len,
        last_key: u32::MAX,
        last_count: u32::MAX,
        done: Searched::default(),
    }
}

/// Go on with the search at `at` ([`begin`]), closing at most `limit` blocks: `Some` once it is
/// done, `None` when it paused (resume with the same buffers). The pieces together close the
/// blocks of one search run to the end in its order, with the same words.
#[allow(clippy::too_many_arguments)]
pub(super) fn resume(
    moves: &Moves<'_>,
    blocks: Blocks,
    (start, goal): (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    bound: Bound,
    at: &mut Searching,
    limit: u32,
) -> Option<Searched> {
    let across = blocks.across().max(1);
    let n = words.len();
    let down = n.div_ceil(across);
    let start_block = blocks.block(start);
    let mut heap = heap_of(blocks, (start, goal), heap, at.len);
    let (sx, sy) = heap.start;
    let Searching {
        mut last_key,
        mut last_count,
        mut done,
        ..
    } = *at;
    let mut left = limit;
    while heap.len > 0 {
        let top = heap.block_at(0);
        if words.get(top).map_or(u32::MAX, |&w| dist(w)) > last_key || done.closed >= last_count {
            break;
        }
        if left == 0 {
            *at = Searching {
                len: heap.len,
                last_key,
                last_count,
                done,
            };
            return None;
        }
        left = left.wrapping_sub(1);
        let b = heap.pop(words);
        done.closed = done.closed.wrapping_add(1);
        let Some(&wb) = words.get(b) else { break };
        // `across >= 1`: the checked forms never fail.
        let bx = b.checked_rem(across).unwrap_or(0);
        let by = b.checked_div(across).unwrap_or(0);
        let g = dist(wb).wrapping_sub(octile(bx, by, sx, sy)); // f >= h: h is a lower bound
        if b == start_block {
            done.length = Some(g);
            if bound == Bound::Plan {
                last_key = g.saturating_add(SLACK);
                last_count = done
                    .closed
                    .saturating_mul(WIDEN)
                    .max(done.closed.saturating_add(WIDEN_MIN));
            }
        }
        // The links of a block are read when it is closed, and only then.
        let wb = if wb & KNOWN == 0 {
            let fresh = super::links::block(moves, blocks, dead, words, (bx, by));
            let wb = (wb & !LINKS) | fresh | KNOWN;
            if let Some(w) = words.get_mut(b) {
                *w = wb;
            }
            done.linked = done.linked.wrapping_add(1);
            wb
        } else {
            wb
        };
        let mut m = wb & LINKS;
        while m != 0 {
            let d = m.trailing_zeros() as usize & 7;
            m &= m.wrapping_sub(1);
            let nx = bx.wrapping_add_signed(DX.get(d).copied().unwrap_or(0) as isize);
            let ny = by.wrapping_add_signed(DY.get(d).copied().unwrap_or(0) as isize);
            if nx >= across || ny >= down {
                continue; // links never leave the map: a guard, not a case
            }
            let nb = ny.wrapping_mul(across).wrapping_add(nx);
            let Some(&wn) = words.get(nb) else { continue };
            if heap.slot(nb) == DONE {
                continue;
            }
            let step = BLOCKS.step(d as u8);
            let nf = g.wrapping_add(step).wrapping_add(octile(nx, ny, sx, sy));
            if nf < dist(wn) {
                // The neighbour's next block is `b`, the opposite direction of `d`.
                let back = (d as u32).wrapping_add(4) & 7;
                if let Some(w) = words.get_mut(nb) {
                    *w = (wn & (LINKS | KNOWN)) | (back << NEXT_SHIFT) | (nf << DIST_SHIFT);
                }
                heap.push(words, nb);
            } else if nf == dist(wn) && prefer(&heap, wn, (nx, ny), b) {
                let back = (d as u32).wrapping_add(4) & 7;
                if let Some(w) = words.get_mut(nb) {
                    *w = (wn & !(15 << NEXT_SHIFT)) | (back << NEXT_SHIFT);
                }
            }
        }
    }
    Some(done)
}

/// Whether block `(nx, ny)`, reached as short through its next block (in `wn`) as through the
/// closed block `b`, takes `b` instead: the one nearer the straight line between the ends
/// ([`Heap::tied_before`]), so that the next blocks do not depend on the order the search closed its
/// blocks in. Measured on the 20 longest scenarios x 3 seeds of four large maps against the
/// first block to reach it (`ht_chantry` 1.0033 -> 1.0017 of the optimum, `Paris_1_256`
/// 1.0005 -> 1.0011, the others the same) and against preferring a diagonal step as Dijkstra
/// from the goal did (one `ht_chantry` plan at 1.15).
fn prefer(heap: &Heap<'_>, wn: u32, (nx, ny): (usize, usize), b: usize) -> bool {
    let d = ((wn >> NEXT_SHIFT) & 7) as usize;
    let cx = nx.wrapping_add_signed(DX.get(d).copied().unwrap_or(0) as isize);
    let cy = ny.wrapping_add_signed(DY.get(d).copied().unwrap_or(0) as isize);
    let current = cy.wrapping_mul(heap.across).wrapping_add(cx);
    (wn >> NEXT_SHIFT) & 15 < 8 && heap.tied_before(b, current)
}

/// A closed block's slot in the heap.
const DONE: u32 = 0xFFFF;

/// An indexed binary min-heap of blocks by their key (`f`, the distance field of their word), in one word per block: the low half of word
/// `i` is the block in heap slot `i`, the high half of word `b` is block `b`'s slot + 1 (0: not
/// queued, `u16::MAX`: done). Blocks number at most `u16::MAX - 1`.
pub(super) struct Heap<'a> {
    w: &'a mut [u32],
    len: usize,
    /// Blocks a row, the start's block and the goal's: what breaks ties of the key.
    across: usize,
    start: (usize, usize),
    goal: (usize, usize),
    /// The start's block less the goal's: the line's direction (worked out once, not in every
    /// comparison).
    line: (i32, i32),
}

impl Heap<'_> {
    /// Whether block `a` comes before block `b`: the smaller key `f` (the distance field of
    /// their words), ties broken by [`Heap::tied_before`].
    #[inline]
    fn before(&self, words: &[u32], a: usize, b: usize) -> bool {
        let fa = words.get(a).map_or(u32::MAX, |&w| dist(w));
        let fb = words.get(b).map_or(u32::MAX, |&w| dist(w));
        fa < fb || fa == fb && self.tied_before(a, b)
    }

    /// Among blocks of the same `f`, whether `a` comes first: nearer the straight line between
    /// the goal's block and the start's, then the smaller estimate `h` (deeper first). On a map
    /// without walls every block of the parallelogram between the ends lies on a shortest block
    /// route in the octile distance; this order runs the search along the one nearest the
    /// straight line, so it closes a band about a block wide and the sub-goals lie along the
    /// line, where the paper's straight pull would lead (other orders gave routes along the
    /// parallelogram's sides, and the ants made twice the moves on Nav2's depot).
    ///
    /// The pair `(distance from the line, h)` compares as the one word `cross << 24 | h` did
    /// (`h` < 2^24; `tie_order_is_the_one_words`), in 32-bit arithmetic: both factors of each
    /// product are block coordinate differences, below `across` and `down`, whose product (the
    /// blocks) is below 2^16, so the products and their difference fit an `i32`; and `h` is
    /// worked out only when the two distances from the line are equal. The order runs in
    /// every comparison of the heap's sifts, and 64-bit products and shifts take several
    /// Cortex-M4 instructions each (the word's order cost 0.97 M of Boston_0_256's 16.9 M on
    /// the device, `docs/bench/boston-issue36.md`).
    #[inline]
    fn tied_before(&self, a: usize, b: usize) -> bool {
        let (ca, cb) = (self.cross(a), self.cross(b));
        ca < cb || ca == cb && self.h(a) < self.h(b)
    }

    /// Block `b`'s coordinates.
    #[inline(always)]
    fn xy(&self, b: usize) -> (usize, usize) {
        // `across >= 1`: the checked forms never fail.
        (
            b.checked_rem(self.across).unwrap_or(0),
            b.checked_div(self.across).unwrap_or(0),
        )
    }

    /// The first of [`Heap::tied_before`]'s pair: how far block `b` lies from the line (its cross
    /// product with the line's direction).
    #[inline(always)]
    fn cross(&self, b: usize) -> u32 {
        let (bx, by) = self.xy(b);
        let d = |a: usize, z: usize| (a as i32).wrapping_sub(z as i32); // coordinates < 2^16
        d(bx, self.goal.0)
            .wrapping_mul(self.line.1)
            .wrapping_sub(d(by, self.goal.1).wrapping_mul(self.line.0))
            .unsigned_abs()
    }

    /// The second of [`Heap::tied_before`]'s pair: block `b`'s estimate to the start's block.
    #[inline(always)]
    fn h(&self, b: usize) -> u32 {
        let (bx, by) = self.xy(b);
        octile(bx, by, self.start.0, self.start.1)
    }

    fn block_at(&self, i: usize) -> usize {
        self.w.get(i).map_or(0, |&v| (v & 0xFFFF) as usize)
    }
    fn set_block_at(&mut self, i: usize, b: usize) {
        if let Some(v) = self.w.get_mut(i) {
            *v = (*v & 0xFFFF_0000) | (b as u32 & 0xFFFF);
        }
    }
    pub(super) fn slot(&self, b: usize) -> u32 {
        self.w.get(b).map_or(0, |&v| v >> 16)
    }
    fn set_slot(&mut self, b: usize, s: u32) {
        if let Some(v) = self.w.get_mut(b) {
            *v = (*v & 0xFFFF) | (s << 16);
        }
    }
    /// Put the block of slot `i` there for good: record its slot.
    fn place(&mut self, i: usize, b: usize) {
        self.set_block_at(i, b);
        self.set_slot(b, (i as u32).wrapping_add(1)); // i < blocks < 2^16 - 1
    }

    /// The heap with the blocks' keys, as the crate's heap sees it (a copy of the fields, so
    /// that the sifts keep them in registers).
    #[inline(always)]
    fn keys<'k>(&'k mut self, words: &'k [u32]) -> Keys<'k> {
        Keys {
            heap: Heap {
                w: &mut *self.w,
                len: self.len,
                across: self.across,
                start: self.start,
                goal: self.goal,
                line: self.line,
            },
            words,
        }
    }

    /// Insert `b` or move it up after its distance dropped.
    fn push(&mut self, words: &[u32], b: usize) {
        let i = match self.slot(b) {
            0 => {
                let i = self.len;
                self.len = self.len.wrapping_add(1); // <= blocks
                i
            }
            0xFFFF => return, // done
            s => s.wrapping_sub(1) as usize,
        };
        heap::sift_up(&mut self.keys(words), i, b);
    }

    /// Remove and return the block of least distance (`len > 0`).
    fn pop(&mut self, words: &[u32]) -> usize {
        let top = self.block_at(0);
        self.set_slot(top, 0xFFFF);
        self.len = self.len.wrapping_sub(1);
        if self.len == 0 {
            return top;
        }
        let last = self.block_at(self.len);
        heap::sift_down(&mut self.keys(words), 0, last);
        top
    }
}

/// The route's heap as the crate's heap sees it ([`heap::Slots`]): its live slots, their
/// blocks' keys in `words`, and [`Heap::before`] as the order.
struct Keys<'k> {
    heap: Heap<'k>,
    words: &'k [u32],
}

impl heap::Slots for Keys<'_> {
    type Item = usize;
    #[inline(always)]
    fn at(&self, slot: usize) -> Option<usize> {
        (slot < self.heap.len).then(|| self.heap.block_at(slot))
    }
    #[inline(always)]
    fn put(&mut self, slot: usize, b: usize) {
        self.heap.place(slot, b);
    }
    #[inline(always)]
    fn before(&self, a: usize, b: usize) -> bool {
        self.heap.before(self.words, a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::super::links::block_links;
    use super::super::{build, Route, Short, NONE, UNREACHED};
    use super::*;
    use crate::map::grid::Grid;

    /// A random map of `w x h` cells, about `density` % blocked, and pruning marks (or none).
    fn random_map(
        pick: &mut impl FnMut(u32) -> u32,
        w: u16,
        h: u16,
        density: u32,
        marks: bool,
    ) -> (Vec<u8>, Vec<u32>) {
        let cells = usize::from(w) * usize::from(h);
        let mut b = vec![0u8; cells.div_ceil(8)];
        let mut dead = if marks {
            vec![0u32; crate::map::bitmap::words(cells)]
        } else {
            Vec::new()
        };
        for i in 0..cells {
            if pick(100) < density {
                b[i / 8] |= 1 << (i % 8);
            } else if marks && pick(100) < 10 {
                crate::map::bitmap::set(&mut dead, i);
            }
        }
        (b, dead)
    }

    fn closed(heap: &[u32], b: usize) -> bool {
        heap[b] >> 16 == DONE
    }

    /// The tie order as it was first written: one 64-bit word, the distance from the line
    /// (64-bit products) above `h`.
    fn one_word(across: usize, start: (usize, usize), goal: (usize, usize), b: usize) -> u64 {
        let (bx, by) = ((b % across) as i64, (b / across) as i64);
        let (sx, sy, gx, gy) = (start.0 as i64, start.1 as i64, goal.0 as i64, goal.1 as i64);
        let cross = ((bx - gx) * (sy - gy) - (by - gy) * (sx - gx)).unsigned_abs();
        cross << 24 | u64::from(octile(bx as usize, by as usize, start.0, start.1))
    }

    #[test]
    fn tie_order_is_the_one_words() {
        // Random block layouts up to the largest (blocks below 2^16, one side up to 4,096),
        // random ends and blocks: the 32-bit pair orders every two blocks as the word did
        // (breaking either half of the pair, or the lazy `h`, fails it).
        let mut rng = crate::rng::Xoshiro128pp::from_u64(3636);
        let mut pick = |n: u32| rng.next_word() % n.max(1);
        let mut buf = vec![0u32; 4];
        for case in 0..2_000 {
            let across = 1 + pick(if case % 2 == 0 { 64 } else { 4_096 }) as usize;
            let down = 1 + pick((65_000 / across as u32).min(4_096)) as usize;
            let blocks = across * down;
            let mut block = || pick(blocks as u32) as usize;
            let (s, g) = (block(), block());
            let start = (s % across, s / across);
            let goal = (g % across, g / across);
            let d = |a: usize, z: usize| a as i32 - z as i32;
            let heap = Heap {
                w: &mut buf,
                len: 0,
                across,
                start,
                goal,
                line: (d(start.0, goal.0), d(start.1, goal.1)),
            };
            for _ in 0..50 {
                let (a, b) = (block(), block());
                let want = one_word(across, start, goal, a) < one_word(across, start, goal, b);
                assert_eq!(heap.tied_before(a, b), want, "{across} x {down}, {a} {b}");
            }
        }
    }

    #[test]
    fn the_bounded_search_closes_the_blocks_shorter_than_the_route_with_the_whole_searchs_distances(
    ) {
        // Random maps, block sizes, starts and goals, with pruning marks or none: against the
        // search run over every block it reaches (`Bound::Whole`), the bounded search closes
        // every block whose distance plus estimate is below the shortest block route `F`, some
        // at `F`, none above (the bound holds), with the same key on each, links read on
        // exactly those but the start's (the per-cell rule's), a next block on a shortest route
        // for each, and for every block reached but not closed a next block that is closed.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(36);
        let mut pick = |n: u32| rng.next_word() % n.max(1);
        let (mut bounded, mut fewer) = (0u32, 0u32);
        for round in 0..400 {
            let (w, h) = (8 + pick(250) as u16, 8 + pick(200) as u16);
            let density = [5u32, 20, 35, 45][round % 4];
            let (b, dead) = random_map(&mut pick, w, h, density, round % 3 == 0);
            let g = Grid::new(w, h, &b).unwrap();
            let moves = Moves::new(g, &[]);
            let s = pick(4) as usize;
            let budget = usize::from(w).div_ceil(1 << s) * usize::from(h).div_ceil(1 << s);
            let blocks = Blocks::with_budget(w, h, budget);
            let (n, across) = (blocks.count(), blocks.across());
            let start = Point::new(pick(u32::from(w)) as u16, pick(u32::from(h)) as u16);
            let goal = Point::new(pick(u32::from(w)) as u16, pick(u32::from(h)) as u16);
            let sh = blocks.shift();
            let (sx, sy) = (usize::from(start.x >> sh), usize::from(start.y >> sh));
            let run = |bound: Bound| {
                let mut words = vec![super::super::unsearched(0); n];
                let mut heap = vec![0u32; n];
                let r = search(
                    &moves,
                    blocks,
                    (start, goal),
                    &dead,
                    &mut words,
                    &mut RouteHeap::new(&mut heap),
                    bound,
                );
                (r, words, heap)
            };
            let (rw, whole, wheap) = run(Bound::Whole);
            let (rp, plan, pheap) = run(Bound::Plan);
            assert_eq!(rw.length, rp.length, "round {round}");
            let found = u32::from(rp.length.is_some());
            assert_eq!(
                rp.closed, rp.linked,
                "round {round}: links read when closed"
            );
            let h_of = |b: usize| octile(b % across, b / across, sx, sy);
            let f_star = rp.length.unwrap_or(u32::MAX);
            let (mut count, mut at_most_f) = (0u32, 0u32);
            for b in 0..n {
                let why = format!("round {round}: {w} x {h}, shift {sh}, block {b}");
                let reached = dist(whole[b]) != UNREACHED;
                assert_eq!(reached, closed(&wheap, b), "{why}");
                let f = dist(whole[b]);
                if reached && f < f_star {
                    assert!(
                        closed(&pheap, b),
                        "{why}: shorter than the route, not closed"
                    );
                }
                if reached && f <= f_star {
                    at_most_f += 1;
                }
                if !closed(&pheap, b) {
                    assert_eq!(plan[b] & KNOWN, 0, "{why}: links read beyond the bound");
                    if dist(plan[b]) != UNREACHED {
                        // Reached, not closed: its next block is a closed one.
                        let d = ((plan[b] >> NEXT_SHIFT) & 15) as usize;
                        assert!(d < 8, "{why}");
                        let nx = (b % across).wrapping_add_signed(DX[d] as isize);
                        let ny = (b / across).wrapping_add_signed(DY[d] as isize);
                        assert!(closed(&pheap, ny * across + nx), "{why}: led outwards");
                    }
                    continue;
                }
                count += 1;
                let last = f_star.saturating_add(SLACK);
                assert!(f <= last, "{why}: closed beyond the slack");
                assert_eq!(dist(plan[b]), f, "{why}: the key");
                let (bx, by) = (b % across, b / across);
                let want = block_links(&moves, blocks, &dead, bx as u16, by as u16);
                assert_eq!(plan[b] & (LINKS | KNOWN), u32::from(want) | KNOWN, "{why}");
                // The next block is one step nearer the goal on a shortest block route.
                let d = ((plan[b] >> NEXT_SHIFT) & 15) as usize;
                let g = dist(plan[b]) - h_of(b);
                if d == NONE as usize {
                    assert_eq!(g, 0, "{why}: only the goal's block has no next block");
                    continue;
                }
                let nb = (by.wrapping_add_signed(DY[d] as isize)) * across
                    + bx.wrapping_add_signed(DX[d] as isize);
                let step = BLOCKS.step(d as u8);
                assert!(closed(&pheap, nb), "{why}");
                assert_eq!(
                    dist(plan[nb]) - h_of(nb) + step,
                    g,
                    "{why}: not a shortest step"
                );
            }
            assert_eq!(count, rp.closed, "round {round}");
            // The widening adds at most `WIDEN` times the blocks closed by the start's (all of
            // those within `F`), or `WIDEN_MIN`.
            if found == 1 {
                let most = (at_most_f * WIDEN).max(at_most_f + WIDEN_MIN);
                assert!(rp.closed <= most, "round {round}: {} > {most}", rp.closed);
            }
            bounded += found;
            fewer += u32::from(rp.closed < rw.closed);
        }
        // Most rounds reach the start's block, and the bound closes fewer blocks on most.
        assert!(bounded > 250 && fewer > 200, "{bounded} {fewer}");
    }

    #[test]
    fn a_short_plan_on_a_large_open_map_reads_a_few_blocks() {
        // 1,024 x 1,024 free cells (4,096 blocks of 16 x 16), start and goal five blocks apart:
        // the search closes the six blocks of the straight route and a band around them, and
        // reads their links only.
        // Breaking the bound (closing every block, as the whole search does) fails here.
        let (w, h) = (1024u16, 1024u16);
        let cells = usize::from(w) * usize::from(h);
        let b = vec![0u8; cells / 8];
        let g = Grid::new(w, h, &b).unwrap();
        let moves = Moves::new(g, &[]);
        let blocks = super::super::blocks(w, h);
        assert_eq!(blocks.count(), 4096);
        let (start, goal) = (Point::new(500, 500), Point::new(580, 500));
        let mut words = vec![0u32; 4096];
        let mut heap = vec![0u32; 4096];
        let r = build(
            &moves,
            blocks,
            (start, goal),
            &[],
            &mut words,
            &mut RouteHeap::new(&mut heap),
            Bound::Plan,
        );
        let r = r.unwrap();
        assert_eq!(r.length, Some(50));
        assert_eq!(r.closed, r.linked);
        // The six blocks of the straight route, and at most `WIDEN_MIN` more.
        assert!(r.closed <= 6 + WIDEN_MIN, "{r:?}");
        let known = words.iter().filter(|&&w| w & KNOWN != 0).count();
        assert_eq!(known, r.linked as usize);
        let all = build(
            &moves,
            blocks,
            (start, goal),
            &[],
            &mut words,
            &mut RouteHeap::new(&mut heap),
            Bound::Whole,
        );
        assert_eq!(all.unwrap().closed, 4096);
    }

    #[test]
    fn an_ant_outside_the_closed_blocks_is_led_back_or_pulled_at_the_goal() {
        // An open map: a block the search never reached pulls at the goal; a block it reached
        // but did not close (the ring round the band) leads into a block it closed.
        let (w, h) = (1024u16, 1024u16);
        let b = vec![0u8; usize::from(w) * usize::from(h) / 8];
        let g = Grid::new(w, h, &b).unwrap();
        let moves = Moves::new(g, &[]);
        let blocks = super::super::blocks(w, h);
        let (start, goal) = (Point::new(500, 500), Point::new(580, 500));
        let mut words = vec![0u32; 4096];
        let mut heap = vec![0u32; 4096];
        build(
            &moves,
            blocks,
            (start, goal),
            &[],
            &mut words,
            &mut RouteHeap::new(&mut heap),
            Bound::Plan,
        )
        .unwrap();
        let route = Route::new(blocks, &words, goal, w, h);
        // Far away, unreached: the goal.
        let far = Point::new(10, 1000);
        assert_eq!(dist(words[blocks.block(far)]), UNREACHED);
        assert_eq!(route.target(far), goal);
        // Every block reached but not closed leads into a closed one.
        let mut ring = 0;
        for (bi, &wd) in words.iter().enumerate() {
            if dist(wd) == UNREACHED || closed(&heap, bi) {
                continue;
            }
            ring += 1;
            let p = Point::new(((bi % 64) * 16 + 8) as u16, ((bi / 64) * 16 + 8) as u16);
            // Its sub-goal lies down the route from a closed block (or is the goal, next to the
            // goal's block): not the straight pull of an unreached block.
            let t = route.target(p);
            assert!(
                t == goal || dist(words[blocks.block(t)]) != UNREACHED,
                "block {bi}"
            );
            // The block one link ahead is closed.
            let d = ((wd >> NEXT_SHIFT) & 15) as usize;
            let nb = (bi / 64).wrapping_add_signed(DY[d] as isize) * 64
                + (bi % 64).wrapping_add_signed(DX[d] as isize);
            assert!(closed(&heap, nb), "block {bi}");
        }
        assert!(ring >= 10, "{ring}");
    }

    #[test]
    fn a_start_cut_off_on_blocks_closes_the_goals_component() {
        // A wall splits the map: the start's block is never reached, the search closes what the
        // goal's block reaches and says so (`length: None`); too short a buffer is `Short`.
        let (w, h) = (256u16, 64u16);
        let mut b = vec![0u8; usize::from(w) * usize::from(h) / 8];
        for y in 0..usize::from(h) {
            let i = y * usize::from(w) + 128;
            b[i / 8] |= 1 << (i % 8);
        }
        let g = Grid::new(w, h, &b).unwrap();
        let moves = Moves::new(g, &[]);
        let blocks = super::super::blocks(w, h);
        let (start, goal) = (Point::new(10, 10), Point::new(250, 10));
        let mut words = vec![0u32; 4096];
        let mut heap = vec![0u32; 4096];
        let r = build(
            &moves,
            blocks,
            (start, goal),
            &[],
            &mut words,
            &mut RouteHeap::new(&mut heap),
            Bound::Plan,
        );
        let r = r.unwrap();
        assert_eq!(r.length, None);
        assert_eq!(r.closed as usize, blocks.count() / 2);
        let r = build(
            &moves,
            blocks,
            (start, goal),
            &[],
            &mut words[..10],
            &mut RouteHeap::new(&mut heap),
            Bound::Plan,
        );
        assert_eq!(r, Err(Short));
    }
}
