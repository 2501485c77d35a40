//! The coarse route on large maps: where the potential field pulls.
//!
//! The paper's goal attraction (eqs. 6-10) pulls every ant straight towards the goal. On a small
//! map that is what makes OHACA fast; on a large one it is the classic weakness of artificial
//! potential fields: the straight pull leads into every courtyard, dead-end street and U-shaped
//! wall that faces the goal, and a backtracking ant explores each of them before it finds the way
//! around (on a 256 x 256 city map an ant made ten times as many moves as its path has steps).
//!
//! On maps of more than 1,024 cells (those whose pheromone is kept in blocks), the map is cut into
//! at most [`GUIDE_BLOCKS`] square blocks (single cells on maps of at most [`GUIDE_BLOCKS`]
//! cells), and before any ant runs:
//!
//! 1. **Connectivity** ([`links`]): block `B` links to a neighbouring block `B'` when some live
//!    cell of `B` has an allowed move into a live cell of `B'` (pruned cells do not count). This
//!    over-approximates the map (a block's free cells need not be connected inside it), so a route
//!    exists on blocks whenever one exists on cells.
//! 2. **Distances** ([`search`]): an A* from the goal's block towards the start's over the links,
//!    10 per straight and 14 per diagonal block step, bounded by the plan: it closes the start's
//!    block and every block within a slack of the shortest block route, reading each closed
//!    block's links from the map as it closes it, and nothing else.
//! 3. **Sub-goals**: an ant in block `B` is pulled towards the centre of the block [`LOOKAHEAD`]
//!    links further down the route (or the goal itself once that is closer). The attraction is
//!    the paper's, unchanged (`a^(xi (d(j, T) - d(i, T)))` with the octile distance), with the
//!    sub-goal `T` in place of the goal `G`: a potential field that follows the coarse geodesic
//!    distance, so it has no local minimum larger than a block. A block the search did not reach
//!    has no next block: its ants are pulled at the goal ([`search`] says why).
//!
//! The ants still walk cells, with their tabu list and backtracking, so a wrong sub-goal (a block
//! whose free cells do not connect) costs moves, never a path. Memory: one `u32` per block (the
//! links, whether they are known, the next block and the search's key) plus scratch for the heap
//! (one `u32` per block).

use crate::colony::pheromone::Blocks;
use crate::map::grid::{Moves, Point, DX, DY};

pub mod heap;
pub mod links;
pub mod search;

pub use heap::RouteHeap;
pub use search::{Bound, Searched, Searching};

/// Most blocks of the route: a map with more cells than this is cut into blocks of `2^k x 2^k`
/// cells (the smallest `k` that gives at most this many), a smaller one routes on cells.
pub const GUIDE_BLOCKS: usize = 4096;

/// Blocks of `2^k x 2^k` cells with `k` below this (single cells, 2 x 2 and 4 x 4: maps of up to
/// 65,536 cells) have their links read for the whole map in one pass before the search
/// ([`links::links`], 32 cells a word), instead of one block at a time as the search closes
/// them ([`links::block`]). The route is the same bit for bit (the links are the same, and the
/// search reads nothing else: `small_blocks_route_as_the_lazy_search_does`); only the cost
/// moves. Why: on small blocks the bounded search closes most of the map anyway (a maze), and
/// a block's own read costs about as much as its share of the whole pass several times over
/// (measured on the device: Boston's setup 8.7 M before the bounded search, 13.0 M with it;
/// `docs/bench/lattice-issue36.md` has the figures with this rule).
pub const WHOLE_LINKS_BELOW: u8 = 3;

/// How many blocks ahead on the route an ant's sub-goal lies.
pub const LOOKAHEAD: u32 = 2;

/// Per-block word: bits 0-7 the links (bit `d`: the neighbour block in direction `d`), bit 8
/// whether they are known (read from the map: the search reads a block's links when it closes
/// it), bits 9-12 the next block's direction (`NONE`: the goal's block or no route), bits 13-31
/// the search's key, `g + h` ([`search`]; `UNREACHED`: not reached).
const LINKS: u32 = 0xFF;
const KNOWN: u32 = 1 << 8;
const NEXT_SHIFT: u32 = 9;
const NONE: u32 = 8;
const DIST_SHIFT: u32 = 13;
const UNREACHED: u32 = u32::MAX >> DIST_SHIFT;

/// A buffer was too short for the route: no route (every ant is pulled to the goal). Only a
/// workspace laid out without room for it gives this; the planner counts it
/// (`fmt::warn`) rather than falling back silently.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Short;

/// The coarse route of a run: the per-block words (or their [`pack`]ed next blocks) and what
/// reads them.
#[derive(Clone, Copy, Debug)]
pub struct Route<'a> {
    blocks: Blocks,
    words: &'a [u32],
    /// `words` holds four bits a block ([`pack`]), not a word.
    packed: bool,
    goal: Point,
    width: u16,
    height: u16,
}

impl<'a> Route<'a> {
    /// A route over the per-block words [`build`] wrote.
    pub fn new(blocks: Blocks, words: &'a [u32], goal: Point, width: u16, height: u16) -> Self {
        Route {
            blocks,
            words,
            packed: false,
            goal,
            width,
            height,
        }
    }

    /// A route over the next blocks [`pack`] kept of [`build`]'s words: the same targets.
    pub fn packed(
        blocks: Blocks,
        nibbles: &'a [u32],
        goal: Point,
        width: u16,
        height: u16,
    ) -> Self {
        Route {
            packed: true,
            ..Route::new(blocks, nibbles, goal, width, height)
        }
    }

    /// The block of cell `p`.
    #[inline]
    pub fn block(&self, p: Point) -> usize {
        self.blocks.block(p)
    }

    /// The point the potential field pulls towards from cell `p`.
    #[inline]
    pub fn target(&self, p: Point) -> Point {
        if self.packed {
            // Out of line: the word-a-block form below stays as the ants' loop inlines it.
            return self.target_packed(p);
        }
        self.target_by(p, |b| {
            self.words.get(b).map_or(NONE, |w| (w >> NEXT_SHIFT) & 15)
        })
    }

    /// [`Route::target`] on a [`pack`]ed route.
    #[inline(never)]
    fn target_packed(&self, p: Point) -> Point {
        self.target_by(p, |b| {
            let shift = ((b & 7) as u32).wrapping_mul(4);
            self.words.get(b >> 3).map_or(NONE, |w| (w >> shift) & 15)
        })
    }

    /// [`Route::target`] with `next(b)`: block `b`'s next block's direction (`NONE`: the goal's
    /// block or no route).
    #[inline(always)]
    fn target_by(&self, p: Point, next: impl Fn(usize) -> u32) -> Point {
        let s = self.blocks.shift();
        let (mut bx, mut by) = (i32::from(p.x >> s), i32::from(p.y >> s));
        let across = self.blocks.across();
        for _ in 0..LOOKAHEAD {
            // Block coordinates are below 2^16: the index fits.
            let b = (by as usize).wrapping_mul(across).wrapping_add(bx as usize);
            let next = next(b);
            if next >= NONE {
                return self.goal;
            }
            let d = next as usize & 7;
            bx = bx.wrapping_add(DX.get(d).copied().unwrap_or(0));
            by = by.wrapping_add(DY.get(d).copied().unwrap_or(0));
        }
        // The centre of that block, on the map (the last block of a row may be cut short).
        let half = (1i32 << s) >> 1;
        let cx = (bx << s)
            .wrapping_add(half)
            .min(i32::from(self.width).wrapping_sub(1));
        let cy = (by << s)
            .wrapping_add(half)
            .min(i32::from(self.height).wrapping_sub(1));
        Point::new(cx.max(0) as u16, cy.max(0) as u16)
    }
}

/// The block layout of the route of a `width x height` map.
pub fn blocks(width: u16, height: u16) -> Blocks {
    Blocks::with_budget(width, height, GUIDE_BLOCKS)
}

/// Build the route to `goal` for a plan from `start`: the links of the blocks it needs, the
/// distances and the next blocks, into `words` (one per block of `blocks`), by the search
/// bounded by the plan ([`search`], [`Bound::Plan`]). `dead` marks pruned cells (empty: none);
/// `heap` is scratch of one word per block.
pub fn build(
    moves: &Moves<'_>,
    blocks: Blocks,
    (start, goal): (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    bound: Bound,
) -> Result<Searched, Short> {
    let mut at = begin_build(moves, blocks, (start, goal), dead, words, heap)?;
    finish(
        moves,
        blocks,
        (start, goal),
        dead,
        words,
        heap,
        bound,
        &mut at,
    )
}

/// The route's words and heap of `blocks`: `words` and `heap` cut to one word a block, or
/// [`Short`].
fn cut<'w>(
    blocks: Blocks,
    words: &'w mut [u32],
    heap: &'w mut RouteHeap<'_>,
) -> Result<(&'w mut [u32], RouteHeap<'w>), Short> {
    let n = blocks.count();
    if n > usize::from(u16::MAX) {
        return Err(Short);
    }
    match (words.get_mut(..n), heap.cut(n)) {
        (Some(words), Some(heap)) => Ok((words, heap)),
        _ => Err(Short),
    }
}

/// [`build`] a piece at a time: prepare the words and start the search (a pass over the
/// words); then [`resume`] until it is done.
pub fn begin_build(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
) -> Result<Searching, Short> {
    let (words, mut heap) = cut(blocks, words, heap)?;
    words.fill(unsearched(0));
    let read = whole_links(moves, blocks, dead, words, None);
    let mut at = search::begin(blocks, ends, words, &mut heap);
    at.linked(read);
    Ok(at)
}

/// Go on with a route search started by [`begin_build`] or [`begin_repair`], closing at most
/// `limit` blocks (each reads its border cells' links once: a few thousand instructions):
/// `Ok(Some(_))` once the route is done, `Ok(None)` when it paused. Resume with the same
/// arguments; the pieces give the words of one [`build`] or [`repair`] bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn resume(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    bound: Bound,
    at: &mut Searching,
    limit: u32,
) -> Result<Option<Searched>, Short> {
    let (words, mut heap) = cut(blocks, words, heap)?;
    Ok(search::resume(
        moves, blocks, ends, dead, words, &mut heap, bound, at, limit,
    ))
}

/// [`resume`] to the end.
#[allow(clippy::too_many_arguments)]
fn finish(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    bound: Bound,
    at: &mut Searching,
) -> Result<Searched, Short> {
    loop {
        if let Some(done) = resume(moves, blocks, ends, dead, words, heap, bound, at, u32::MAX)? {
            return Ok(done);
        }
    }
}

/// On blocks smaller than [`WHOLE_LINKS_BELOW`]: read the links of the blocks in `region` (block
/// coordinates; `None`: every block) in one pass, and mark every block's links known (the
/// caller's words outside `region` must know theirs: a repair checks). Returns the blocks read
/// (0 on larger blocks, where the search reads each block as it closes it).
fn whole_links(
    moves: &Moves<'_>,
    blocks: Blocks,
    dead: &[u32],
    words: &mut [u32],
    region: Option<links::Region>,
) -> u32 {
    if blocks.shift() >= WHOLE_LINKS_BELOW {
        return 0;
    }
    // Only known words outside the region: otherwise the whole map.
    let region = region.filter(|r| {
        words.iter().enumerate().all(|(b, w)| {
            let (bx, by) = (
                b.checked_rem(blocks.across()).unwrap_or(0),
                b.checked_div(blocks.across()).unwrap_or(0),
            );
            w & KNOWN != 0 || r.holds(bx, by)
        })
    });
    let read = region.map_or(words.len(), |r| {
        if r.x0 > r.x1 || r.y0 > r.y1 {
            return 0;
        }
        r.x1.wrapping_sub(r.x0)
            .wrapping_add(1)
            .saturating_mul(r.y1.wrapping_sub(r.y0).wrapping_add(1))
    });
    links::links(moves, blocks, dead, words, region);
    for w in words.iter_mut() {
        *w = unsearched(*w | KNOWN);
    }
    u32::try_from(read).unwrap_or(u32::MAX)
}

/// A word before the search: the links and their flag `known`, no next block, not reached.
#[inline]
fn unsearched(known: u32) -> u32 {
    (known & (LINKS | KNOWN)) | (NONE << NEXT_SHIFT) | (UNREACHED << DIST_SHIFT)
}

/// Route again after the pruning marks or the map changed inside `area` only (`None`: no cell
/// changed), and the start moved: `words` hold the links of the route [`build`] (or `repair`)
/// made before, restored with [`unstash`]. The links of the blocks within one cell of `area`
/// are forgotten, the rest are kept, and the search runs again, reading the links it does not
/// know when it closes a block. The result is [`build`]'s on the map and marks as they are now
/// (a property test compares them: the same next blocks and keys everywhere, the same links
/// where both know them). Errors if a buffer is too short.
#[allow(clippy::too_many_arguments)]
pub fn repair(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    area: Option<(Point, Point)>,
    bound: Bound,
) -> Result<Searched, Short> {
    let mut at = begin_repair(moves, blocks, ends, dead, words, heap, area)?;
    finish(moves, blocks, ends, dead, words, heap, bound, &mut at)
}

/// [`repair`] a piece at a time: forget the links around `area` and start the search (a pass
/// over the words); then [`resume`] until it is done.
pub fn begin_repair(
    moves: &Moves<'_>,
    blocks: Blocks,
    ends: (Point, Point),
    dead: &[u32],
    words: &mut [u32],
    heap: &mut RouteHeap<'_>,
    area: Option<(Point, Point)>,
) -> Result<Searching, Short> {
    let (words, mut heap) = cut(blocks, words, heap)?;
    for w in words.iter_mut() {
        *w = unsearched(*w);
    }
    let grid = *moves.grid();
    let (w, h) = (grid.width(), grid.height());
    let mut region = None;
    if let (Some((lo, hi)), true) = (area, w > 0 && h > 0) {
        // A block's links read its border cells and the cells one move beyond them: the blocks
        // within one cell of `area`.
        let s = blocks.shift();
        let across = blocks.across();
        let (x0, y0) = (
            usize::from(lo.x.saturating_sub(1) >> s),
            usize::from(lo.y.saturating_sub(1) >> s),
        );
        let (x1, y1) = (
            usize::from(hi.x.saturating_add(1).min(w.wrapping_sub(1)) >> s),
            usize::from(hi.y.saturating_add(1).min(h.wrapping_sub(1)) >> s),
        );
        for by in y0..=y1 {
            let row = by.wrapping_mul(across);
            if let Some(ws) = words.get_mut(row.wrapping_add(x0)..=row.wrapping_add(x1)) {
                for w in ws {
                    *w &= !(LINKS | KNOWN);
                }
            }
        }
        region = Some(links::Region { x0, y0, x1, y1 });
    }
    // Small blocks: the forgotten blocks read again in one pass (a repair without an area, or
    // whose last run did not know every block, reads them all).
    let region = region.or(Some(links::Region {
        x0: 1,
        y0: 1,
        x1: 0,
        y1: 0,
    }));
    let read = whole_links(moves, blocks, dead, words, region);
    let mut at = search::begin(blocks, ends, words, &mut heap);
    at.linked(read);
    Ok(at)
}

/// Words [`pack`] needs for a route of `count` blocks: four bits a block.
pub const fn packed_words(count: usize) -> usize {
    count.div_ceil(8)
}

/// Keep of [`build`]'s `words` only what the ants read, each block's next block (four bits a
/// block, eight a word, block `b` in bits `4 (b % 8)` of word `b / 8`), in `out`: a route
/// ([`Route::packed`]) in an eighth of the words, whose full words (and heap) were scratch
/// (the compact arena builds them in its tabu bit set, idle before the first ant). The links
/// and distances are gone: such a route is built again, never [`repair`]ed. Returns false if
/// a buffer is too short.
pub fn pack(blocks: Blocks, words: &[u32], out: &mut [u32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(out)) = (words.get(..n), out.get_mut(..packed_words(n))) else {
        return false;
    };
    for (o, eight) in out.iter_mut().zip(words.chunks(8)) {
        *o = eight.iter().enumerate().fold(0, |acc, (k, w)| {
            acc | ((w >> NEXT_SHIFT) & 15).wrapping_shl((k as u32).wrapping_mul(4))
        });
    }
    true
}

/// `f32` slots [`stash`] needs for the links of `blocks`: two blocks a slot.
pub fn stash_len(blocks: Blocks) -> usize {
    blocks.count().div_ceil(2)
}

/// Keep the links of the route in `words` and whether they are known in `out` (at least
/// [`stash_len`] slots of a buffer that is free until the next run: the smoothing's unused
/// pheromone increments), two blocks' nine bits a slot as an integer below `2^18`, exact in an
/// `f32`. Returns false if `out` is too short.
pub fn stash(blocks: Blocks, words: &[u32], out: &mut [f32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(out)) = (words.get(..n), out.get_mut(..stash_len(blocks))) else {
        return false;
    };
    for (slot, pair) in out.iter_mut().zip(words.chunks(2)) {
        let lo = pair.first().map_or(0, |w| w & (LINKS | KNOWN));
        let hi = pair.get(1).map_or(0, |w| w & (LINKS | KNOWN));
        // Below 2^18: exact in an f32.
        *slot = (lo | hi << 9) as f32;
    }
    true
}

/// Put the links [`stash`] kept (and whether they are known) back into the low bits of `words`
/// (the rest of each word is cleared). Returns false if a buffer is too short.
pub fn unstash(blocks: Blocks, kept: &[f32], words: &mut [u32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(kept)) = (words.get_mut(..n), kept.get(..stash_len(blocks))) else {
        return false;
    };
    for (pair, slot) in words.chunks_mut(2).zip(kept) {
        // An integer below 2^18 (see `stash`): the cast is exact.
        let v = *slot as u32;
        for (w, bits) in pair.iter_mut().zip([v, v >> 9]) {
            *w = bits & (LINKS | KNOWN);
        }
    }
    true
}

fn dist(w: u32) -> u32 {
    w >> DIST_SHIFT
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::Grid;

    /// A 64 x 64 map (2 x 2 blocks would be 1024: the route uses single cells up to 4096 cells, so
    /// take 128 x 64 = 8192 cells: 2 x 2 blocks) with a wall between start and goal that has one
    /// gap at the bottom.
    fn walled() -> (Vec<u8>, u16, u16) {
        let (w, h) = (128u16, 64u16);
        let mut b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
        for y in 0..h - 4 {
            let i = usize::from(y) * usize::from(w) + 64;
            b[i / 8] |= 1 << (i % 8);
        }
        (b, w, h)
    }

    #[test]
    fn sub_goals_lead_around_the_wall() {
        let (b, w, h) = walled();
        let g = Grid::new(w, h, &b).unwrap();
        let blocks = blocks(w, h);
        assert_eq!(blocks.shift(), 1);
        let moves = Moves::new(g, &[]);
        let dead = vec![0u32; crate::map::bitmap::words(g.cells())];
        let mut words = vec![0u32; GUIDE_BLOCKS];
        let mut heap = vec![0u32; GUIDE_BLOCKS];
        let goal = Point::new(100, 2);
        let ends = (Point::new(20, 2), goal);
        build(
            &moves,
            blocks,
            ends,
            &dead,
            &mut words,
            &mut RouteHeap::new(&mut heap),
            Bound::Plan,
        )
        .unwrap();
        let route = Route::new(blocks, &words, goal, w, h);
        // From the top left the straight pull would hit the wall; the sub-goal leads down.
        let t = route.target(Point::new(20, 2));
        assert!(t.y > 2, "{t:?}");
        // Follow the sub-goals: they reach the goal through the gap.
        let mut p = Point::new(20, 2);
        for _ in 0..400 {
            let t = route.target(p);
            if t == goal {
                break;
            }
            assert!(t.x != 64 || t.y >= h - 4, "a sub-goal in the wall: {t:?}");
            p = t;
        }
        assert_eq!(route.target(p), goal);
        // Next to the goal, the goal itself.
        assert_eq!(route.target(Point::new(101, 3)), goal);
    }

    #[test]
    fn a_packed_route_pulls_where_its_words_do() {
        // Random maps and goals: every cell's target is the same from the packed next blocks
        // as from the words they were packed from, and a buffer one word short packs nothing.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(5);
        let mut routed = 0;
        for (w, h) in [(300u16, 200u16), (512, 64), (97, 131)] {
            for _ in 0..3 {
                let mut b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
                for byte in b.iter_mut() {
                    for bit in 0..8 {
                        if rng.next_unit() < 0.3 {
                            *byte |= 1 << bit;
                        }
                    }
                }
                let g = Grid::new(w, h, &b).unwrap();
                let blocks = blocks(w, h);
                let moves = Moves::new(g, &[]);
                let goal = Point::new(
                    (rng.next_unit() * f32::from(w - 1)) as u16,
                    (rng.next_unit() * f32::from(h - 1)) as u16,
                );
                let mut words = vec![0u32; GUIDE_BLOCKS];
                let mut heap = vec![0u32; GUIDE_BLOCKS];
                let start = Point::new(
                    (rng.next_unit() * f32::from(w - 1)) as u16,
                    (rng.next_unit() * f32::from(h - 1)) as u16,
                );
                let ends = (start, goal);
                build(
                    &moves,
                    blocks,
                    ends,
                    &[],
                    &mut words,
                    &mut RouteHeap::new(&mut heap),
                    Bound::Whole,
                )
                .unwrap();
                let mut nibbles = vec![0u32; packed_words(blocks.count())];
                assert!(!pack(blocks, &words, &mut nibbles[1..]));
                assert!(pack(blocks, &words, &mut nibbles));
                let full = Route::new(blocks, &words, goal, w, h);
                let packed = Route::packed(blocks, &nibbles, goal, w, h);
                for y in 0..h {
                    for x in 0..w {
                        let p = Point::new(x, y);
                        assert_eq!(packed.target(p), full.target(p), "{w}x{h} {p:?}");
                        routed += usize::from(full.target(p) != goal);
                    }
                }
            }
        }
        assert!(routed > 100_000, "{routed}");
    }

    #[test]
    fn distances_are_exact_on_blocks() {
        // An empty map: the distance of a block is the octile-like 10/14 distance to the goal's
        // (the key less the estimate to the start's block), on every block of the whole search
        // and on every block the bounded one reached.
        let g = Grid::new(128, 64, &[0u8; 1024]).unwrap();
        let blocks = blocks(128, 64);
        let moves = Moves::new(g, &[]);
        let dead = vec![0u32; crate::map::bitmap::words(g.cells())];
        let (start, goal) = (Point::new(127, 63), Point::new(0, 0));
        let s = blocks.shift();
        let (sx, sy) = (usize::from(start.x >> s), usize::from(start.y >> s));
        for bound in [Bound::Whole, Bound::Plan] {
            let mut words = vec![0u32; GUIDE_BLOCKS];
            let mut heap = vec![0u32; GUIDE_BLOCKS];
            let r = build(
                &moves,
                blocks,
                (start, goal),
                &dead,
                &mut words,
                &mut RouteHeap::new(&mut heap),
                bound,
            );
            assert_eq!(r.unwrap().length, Some(search::octile(0, 0, sx, sy)));
            for (b, w) in words.iter().take(blocks.count()).enumerate() {
                let (bx, by) = (b % blocks.across(), b / blocks.across());
                // Not closed (the heap's slot of a closed block is `u16::MAX`): a key not final.
                if !RouteHeap::new(&mut heap).closed(b) {
                    assert_eq!(bound, Bound::Plan);
                    continue;
                }
                let g = dist(*w) - search::octile(bx, by, sx, sy);
                assert_eq!(g, search::octile(bx, by, 0, 0), "block {b}");
            }
            // Too short a heap: no route.
            let mut short = vec![0u32; 10];
            let r = build(
                &moves,
                blocks,
                (start, goal),
                &dead,
                &mut words,
                &mut RouteHeap::new(&mut short),
                bound,
            );
            assert_eq!(r, Err(Short));
        }
    }

    #[test]
    fn repair_equals_build_on_random_maps_with_random_changes() {
        let mut x = 0x1234_5679u32;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let mut shifts = [0u32; 4];
        for round in 0..300 {
            let (w, h) = (20 + rnd() % 200, 20 + rnd() % 150);
            let cells = (w * h) as usize;
            let density = [5u32, 20, 35][round % 3];
            let mut b = vec![0u8; cells.div_ceil(8)];
            let mut dead = vec![0u32; crate::map::bitmap::words(cells)];
            for i in 0..cells {
                if rnd() % 100 < density {
                    b[i / 8] |= 1 << (i % 8);
                } else if rnd() % 100 < 15 {
                    crate::map::bitmap::set(&mut dead, i);
                }
            }
            let blocks = blocks(w as u16, h as u16);
            shifts[usize::from(blocks.shift()).min(3)] += 1;
            let goal = Point::new((rnd() % w) as u16, (rnd() % h) as u16);
            let start = Point::new((rnd() % w) as u16, (rnd() % h) as u16);
            // The robot moved: the next plan starts elsewhere (or at the same cell).
            let moved = if round % 5 == 0 {
                start
            } else {
                Point::new((rnd() % w) as u16, (rnd() % h) as u16)
            };
            let bound = if round % 4 == 0 {
                Bound::Whole
            } else {
                Bound::Plan
            };
            let g0 = Grid::new(w as u16, h as u16, &b).unwrap();
            let mut words = vec![0u32; GUIDE_BLOCKS];
            let mut heap = vec![0u32; GUIDE_BLOCKS];
            let ends = (start, goal);
            build(
                &Moves::new(g0, &[]),
                blocks,
                ends,
                &dead,
                &mut words,
                &mut RouteHeap::new(&mut heap),
                bound,
            )
            .unwrap();
            let mut kept = vec![0f32; stash_len(blocks)];
            assert!(stash(blocks, &words, &mut kept));
            // Scribble over the words, as the local search does with its scratch.
            words.fill(0xDEAD_BEEF);
            // Change the map and the marks inside a random rectangle (or nowhere).
            let area = (round % 7 != 0).then(|| {
                let (cw, ch) = (1 + rnd() % 9, 1 + rnd() % 9);
                let (x0, y0) = (rnd() % w, rnd() % h);
                let (x1, y1) = ((x0 + cw - 1).min(w - 1), (y0 + ch - 1).min(h - 1));
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = (y * w + x) as usize;
                        match rnd() % 4 {
                            0 => b[i / 8] |= 1 << (i % 8),
                            1 => b[i / 8] &= !(1 << (i % 8)),
                            2 => crate::map::bitmap::set(&mut dead, i),
                            _ => crate::map::bitmap::unset(&mut dead, i),
                        }
                    }
                }
                (
                    Point::new(x0 as u16, y0 as u16),
                    Point::new(x1 as u16, y1 as u16),
                )
            });
            let g1 = Grid::new(w as u16, h as u16, &b).unwrap();
            assert!(unstash(blocks, &kept, &mut words));
            let m1 = Moves::new(g1, &[]);
            let ends = (moved, goal);
            let r = repair(
                &m1,
                blocks,
                ends,
                &dead,
                &mut words,
                &mut RouteHeap::new(&mut heap),
                area,
                bound,
            )
            .unwrap();
            let mut fresh = vec![0u32; GUIDE_BLOCKS];
            let f = build(
                &m1,
                blocks,
                ends,
                &dead,
                &mut fresh,
                &mut RouteHeap::new(&mut heap),
                bound,
            )
            .unwrap();
            assert_eq!((r.closed, r.length), (f.closed, f.length), "round {round}");
            assert!(r.linked <= f.linked, "round {round}");
            let n = blocks.count();
            // The same next blocks and keys everywhere; the same links where both know them
            // (the repair knows the last run's too), and every block the fresh search read,
            // the repair knows.
            for (b, (&a, &f)) in words[..n].iter().zip(&fresh[..n]).enumerate() {
                let why = format!("round {round}: {w} x {h}, {area:?}, block {b}");
                assert_eq!(a >> NEXT_SHIFT, f >> NEXT_SHIFT, "{why}");
                assert!(a & KNOWN != 0 || f & KNOWN == 0, "{why}");
                if a & f & KNOWN != 0 {
                    assert_eq!(a & LINKS, f & LINKS, "{why}");
                }
                if a & KNOWN != 0 {
                    let (bx, by) = (b % blocks.across(), b / blocks.across());
                    let want = links::block_links(&m1, blocks, &dead, bx as u16, by as u16);
                    assert_eq!(a & LINKS, u32::from(want), "{why}: stale links");
                }
            }
        }
        assert!(
            shifts[0] > 20 && shifts[1] > 20 && shifts[2] > 10,
            "{shifts:?}"
        );
    }

    #[test]
    fn stash_keeps_the_links_only() {
        let blocks = blocks(256, 256);
        let words: Vec<u32> = (0..GUIDE_BLOCKS as u32)
            .map(|i| i.wrapping_mul(2654435761))
            .collect();
        let mut kept = vec![0f32; stash_len(blocks)];
        assert_eq!(kept.len(), 2048);
        assert!(stash(blocks, &words, &mut kept));
        assert!(!stash(blocks, &words, &mut kept[..2047]));
        let mut back = vec![u32::MAX; GUIDE_BLOCKS];
        assert!(unstash(blocks, &kept, &mut back));
        for (a, b) in words.iter().zip(&back) {
            assert_eq!(a & (LINKS | KNOWN), *b);
        }
    }

    #[test]
    fn small_blocks_route_as_the_lazy_search_does() {
        // Maps of 2 x 2 and 4 x 4 blocks read the whole map's links first (`WHOLE_LINKS_BELOW`);
        // the route (every block's next block and key, the search's closed count and length)
        // is the lazy search's bit for bit, and every block's links are the per-cell rule's.
        // Fails when the whole pass reads other links (other marks, a region off by a block).
        let mut rng = crate::rng::Xoshiro128pp::from_u64(36);
        for (round, (w, h)) in [(100u16, 90u16), (200, 150), (130, 70), (256, 256)]
            .into_iter()
            .cycle()
            .take(12)
            .enumerate()
        {
            let density = [0.1f32, 0.25, 0.35][round % 3];
            let b = crate::testutil::random_bits(&mut rng, w, h, density);
            let g = Grid::new(w, h, &b).unwrap();
            let cells = usize::from(w) * usize::from(h);
            let dead: Vec<u32> = (0..cells.div_ceil(32))
                .map(|_| rng.next_word() & rng.next_word() & rng.next_word())
                .collect();
            let moves = Moves::new(g, &[]);
            let blocks = blocks(w, h);
            assert!(blocks.shift() > 0 && blocks.shift() < WHOLE_LINKS_BELOW);
            let n = blocks.count();
            let free = |p: Point| g.is_free(p);
            let pick = |rng: &mut crate::rng::Xoshiro128pp| loop {
                let p = Point::new(
                    (rng.next_word() % u32::from(w)) as u16,
                    (rng.next_word() % u32::from(h)) as u16,
                );
                if free(p) {
                    return p;
                }
            };
            let ends = (pick(&mut rng), pick(&mut rng));
            let (mut words, mut heap) = (vec![0u32; n], vec![0u32; n]);
            let r = build(
                &moves,
                blocks,
                ends,
                &dead,
                &mut words,
                &mut RouteHeap::new(&mut heap),
                Bound::Plan,
            )
            .unwrap();
            let mut lazy = vec![unsearched(0); n];
            let l = search::search(
                &moves,
                blocks,
                ends,
                &dead,
                &mut lazy,
                &mut RouteHeap::new(&mut heap),
                Bound::Plan,
            );
            let why = format!("round {round}: {w} x {h}, {ends:?}");
            assert_eq!((r.closed, r.length), (l.closed, l.length), "{why}");
            assert_eq!(r.linked as usize, n, "{why}");
            for (i, (&a, &z)) in words.iter().zip(&lazy).enumerate() {
                assert_eq!(a >> NEXT_SHIFT, z >> NEXT_SHIFT, "{why}: block {i}");
                let (bx, by) = (i % blocks.across(), i / blocks.across());
                let want = links::block_links(&moves, blocks, &dead, bx as u16, by as u16);
                assert_eq!(
                    a & (LINKS | KNOWN),
                    u32::from(want) | KNOWN,
                    "{why}: block {i}"
                );
            }
        }
    }
}
