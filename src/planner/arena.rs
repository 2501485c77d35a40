//! One arena of words for a map and the planner's buffers: how a board with little RAM plans
//! maps of very different sizes at full resolution ([`carve`]).
//!
//! A [`Storage`](super::Storage) sizes every buffer for the largest map it takes. On the
//! STM32F411 that is 65,536 cells: the map (8 KiB) plus two bits a cell (tabu list, pruning
//! marks), 32 KiB of pheromone, the coarse route and the links, 101 KiB in all. A map of
//! 262,144 cells (512 x 512) needs 32 KiB for its own bits and 32 KiB for the tabu list alone,
//! so it cannot have everything a 256 x 256 map has. The arena holds the map *and* the planner's
//! buffers, and [`carve`] lays them out for the map at hand:
//!
//! | layout | when | what | words at its largest map in an arena of 25,856 (the STM32F411's, [`crate::board::F411`]) |
//! | --- | --- | --- | --- |
//! | full | it fits with paths of up to [`FULL_STEPS`] (on the F411: maps of up to 68,256 cells) | the map, `tabu` and `dead` (1 bit a cell each), `tau` and `delta` ([`BLOCKS`] entries), the route's [`GUIDE_BLOCKS`] words, [`LINKS`] links, `steps + 1` path cells and two tours (the iteration's best and worst are walked again), the move table on maps of up to 1,024 cells | 25,856 (65,536 cells, 2,047 steps) |
//! | compact | the full one does not fit | the map, `tabu`; **no pruning marks** (the run does not prune), pheromone on at most [`COMPACT_BLOCKS`] blocks, the same route **packed** to four bits a block (512 words, [`crate::colony::route::pack`]), `steps + 1` path cells and two tours, and only the links no other buffer can lend (`planner::lend`; 2,048 at 512 x 512): paths of up to the caller's bound | 25,600 (262,144 cells, 4,095 steps) |
//!
//! The full layout gives a run exactly the buffers of a fixed `Storage<{ words(65536) }, 2048,
//! 4096, 1024, 0, 0>` (65,536 cells, 2,047-step paths), so its plans are that storage's bit for
//! bit; it keeps [`FULL_STEPS`] whatever the caller's bound, so a larger bound changes no plan of
//! a map it holds. The compact one plans like any workspace without pruning marks and with
//! coarser pheromone blocks. Why these and not other savings, measured on the 512 x 512 maps
//! (`BENCHMARKS.md`, section 1b, "Compact layout"): the route's block size decides the quality (a
//! route on 1,024 blocks instead of 4,096 took `NewYork_0_512` from 1.0019 to 1.0167 of the
//! optimum), the pheromone's does not (64 blocks instead of 1,024: the same means), and pruning
//! only saves moves.
//!
//! **Where a compact run's words go, phase by phase** (the F411 at 512 x 512: the map 8,192, the
//! tabu set 8,192, pheromone 512, route 512, path cells 4,096, tours 2,048, links 2,048, 256
//! unused). Each step of a path costs a word and a half it keeps (a path cell, two tour bytes)
//! and half a word of links; everything else a phase needs is lent by a buffer idle in that phase
//! (`planner::lend` has the whole table):
//!
//! | phase | what it uses beyond the map, pheromone and tours |
//! | --- | --- |
//! | setup | the coarse route's words and heap (a word a block each, 4,096 blocks): the tabu set halved, packed into the route's 512 words afterwards |
//! | colony | the tabu set; tightening's table of packed (cell, position) keys over the links and the path cells' words: 6,144 slots for a path of 4,096 cells, a load of 2/3 ([`crate::colony::tighten::keyed_words`]) |
//! | polish | the path cells (the raw path, then the waypoints); the local search's two slices of 4,056 words from the tabu set halved (two of at least 3,456 on maps of 221,184 to 259,583 cells: windows of 48 to 51 cells a side); the smoothing's links from the tabu set |
//! | between plans | the path cells and the best tour (the answer the firmware sends in parts, and a replan reuses) and the pheromone |
//!
//! Protocol 10's firmware had the route as a word a block and tightening's table of positions in
//! the links beside laid-out path cells: 1,876 steps at 512 x 512, where `maze512-1-0`'s
//! 4,000-step scenario got `PathTooLong` (the test
//! `the_f411s_arena_plans_a_4000_step_path_at_512_x_512` plans it at its optimum now).
//!
//! Guarantees: the layout depends only on the arena's length, the map's cells and the step
//! bound (a host that carves an arena of the device's length plans what the device plans); the
//! map always starts at the arena's first word (a receiver writes it there before any plan);
//! no panics and no `unsafe` (the casts are `bytemuck`'s checked ones).

use bytemuck::{try_cast_slice_mut, Pod};

use crate::colony::pheromone::BLOCKS;
use crate::colony::route::GUIDE_BLOCKS;
use crate::error::Error;
use crate::map::bitmap::words;
use crate::map::grid::{Dir, Point};

use crate::colony::route::packed_words;
use crate::colony::tighten::{hash_words, keyed_fits, keyed_words};

use super::needs;
use super::run::{REFINE_WORDS, SHORT_REFINE_WORDS};
use super::workspace::{Buffers, Workspace};

/// Most pheromone entries of the compact layout: 64 (on a 512 x 512 map, 64 blocks of 64 x 64
/// cells). Measured: `BENCHMARKS.md`, section 1b, "Compact layout".
pub const COMPACT_BLOCKS: usize = 64;
/// Links of the full layout: tightening's hash table (`2 (steps + 1)` slots), the coarse
/// route's heap, the flood fill's ring, the smoothing's links and one half of the local search's
/// scratch.
pub const LINKS: usize = 4096;
/// Longest path of the full layout: as many cells as its [`LINKS`] hold at a load of 1/2 in
/// tightening's table (the buffers of the `Storage` the STM32F411 had, 2,047 steps). A larger
/// step bound goes to the compact layout only, so a map that fits the full layout plans as it
/// always did.
pub const FULL_STEPS: usize = LINKS / 2 - 1;
/// Whether [`LINKS`] hold what every phase needs (`planner::needs`' `PHASES`) in the full
/// layout, beside its tabu set, its route's [`GUIDE_BLOCKS`] words and paths of [`FULL_STEPS`],
/// on every map: each map of up to 8,192 cells (where the route's blocks grow with the map), then
/// each tabu length up to 8,192 words (beyond that the tabu set lends every need's slices
/// itself). Checked at compile time: a need the full layout's links do not hold does not build.
const fn full_links_hold(links: usize) -> bool {
    let mut cells = 1usize;
    while cells <= 8192 * 32 {
        let idle = needs::Lengths {
            links: 0,
            tabu: words(cells),
            points: 0,
            guide: GUIDE_BLOCKS,
            weights: 0,
        };
        if needs::links(idle, ask(cells, FULL_STEPS, false)) > links {
            return false;
        }
        cells = if cells < 8192 {
            cells.saturating_add(1)
        } else {
            cells.saturating_add(32)
        };
    }
    true
}

const _: () = assert!(
    full_links_hold(LINKS),
    "a phase needs more links than the full layout has"
);

/// The fewest path steps a layout may leave: a map whose compact layout leaves fewer is too
/// large for the arena.
pub const MIN_STEPS: usize = 1023;
/// Maps of up to this many cells get the move table (as the F411's `Storage` did).
const MOVES: usize = 1024;

/// A map buffer and a workspace carved out of one arena ([`carve`]).
#[derive(Debug)]
pub struct Carved<'a> {
    /// The map's bits (the arena's first `words(cells)` words, as bytes): what
    /// [`crate::map::grid::Grid::new`] reads.
    pub map: &'a mut [u8],
    /// Every buffer of the run.
    pub workspace: Workspace<'a>,
    /// The compact layout (no pruning, coarser pheromone and route).
    pub compact: bool,
}

/// Every buffer's length in a layout, in the order [`lay`] takes them: written once, summed by
/// [`full_words`] and [`compact_words`], and taken by [`lay`], so the sizes an arena is checked
/// against are the ones it is cut into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Sizes {
    /// Words of the map's bits, and of the tabu set (a bit a cell each).
    map: usize,
    /// Words of the pruning marks (none in the compact layout).
    dead: usize,
    /// Pheromone entries, of `tau` and of `delta` each (four words an entry).
    blocks: usize,
    /// Words of the coarse route (a word a block, or packed).
    guide: usize,
    /// Links.
    links: usize,
    /// Path cells (a word each); the two tours take as many bytes each.
    cells: usize,
    /// Bytes of the move table.
    moves: usize,
}

impl Sizes {
    /// The layout of a map of `cells` cells with paths of `steps` steps (saturating).
    const fn of(cells: usize, steps: usize, compact: bool) -> Self {
        let w = words(cells);
        let n = steps.saturating_add(1);
        if compact {
            Self {
                map: w,
                dead: 0,
                blocks: COMPACT_BLOCKS,
                guide: packed_words(GUIDE_BLOCKS),
                links: compact_links(cells, steps),
                cells: n,
                moves: 0,
            }
        } else {
            Self {
                map: w,
                dead: w,
                blocks: if cells < BLOCKS { cells } else { BLOCKS },
                guide: GUIDE_BLOCKS,
                links: LINKS,
                cells: n,
                moves: if cells <= MOVES { cells } else { 0 },
            }
        }
    }

    /// Its words in all (saturating): each buffer rounded up to whole words, as [`take_as`]
    /// takes it.
    const fn words(self) -> usize {
        self.map
            .saturating_mul(2)
            .saturating_add(self.dead)
            .saturating_add(self.blocks.saturating_mul(8))
            .saturating_add(self.guide)
            .saturating_add(self.links)
            .saturating_add(self.cells)
            .saturating_add(self.cells.saturating_mul(2).div_ceil(4))
            .saturating_add(self.moves.div_ceil(4))
    }
}

/// Words the full layout takes for a map of `cells` cells and paths of `steps` steps (saturating).
pub const fn full_words(cells: usize, steps: usize) -> usize {
    Sizes::of(cells, steps, false).words()
}

/// Words the compact layout takes for a map of `cells` cells and paths of `steps` steps
/// (saturating).
pub const fn compact_words(cells: usize, steps: usize) -> usize {
    Sizes::of(cells, steps, true).words()
}

/// Links of the compact layout: the most any phase borrows beside the tabu set and the path
/// cells' words, read from the phases' needs (`planner::needs`' `PHASES`): tightening's keyed
/// table over the links and the path cells' words ([`keyed_words`]: `(steps + 1) / 2`;
/// [`hash_words`] on maps too large for its keys), the smoothing's `steps + 1` links where the
/// tabu set is shorter, the local search's two slices of [`REFINE_WORDS`] and the packed route's
/// words and heap (a word a block) as far as the tabu set does not hold them.
const fn compact_links(cells: usize, steps: usize) -> usize {
    needs::links(idle(cells, steps), ask(cells, steps, true))
}

/// What a layout asks of its links for a map of `cells` cells, paths of `steps` steps and a route
/// packed or not: the route's blocks ([`GUIDE_BLOCKS`] at most), tightening's table (packed keys
/// when a cell and a position fit a word, [`keyed_words`], else positions, [`hash_words`]) and
/// the local search's [`REFINE_WORDS`] (at least [`SHORT_REFINE_WORDS`]).
const fn ask(cells: usize, steps: usize, packed: bool) -> needs::Ask {
    let n = steps.saturating_add(1);
    let blocks = if cells < GUIDE_BLOCKS {
        cells
    } else {
        GUIDE_BLOCKS
    };
    let table = if keyed_fits(cells, n) {
        keyed_words(n)
    } else {
        hash_words(n)
    };
    needs::Ask {
        route: (blocks, packed),
        cells: n,
        table,
        refine: (REFINE_WORDS, SHORT_REFINE_WORDS),
        // No weight table in an arena: its walks compute their weights at each move.
        weights: 0,
    }
}

/// The idle buffers besides the links of the compact layout: the tabu set and the path cells'
/// words (the route, packed, lends nothing).
const fn idle(cells: usize, steps: usize) -> needs::Lengths {
    needs::Lengths {
        links: 0,
        tabu: words(cells),
        points: steps.saturating_add(1),
        guide: 0,
        weights: 0,
    }
}

/// The most cells an arena of `arena` words plans at full resolution: every map of at most this
/// many cells (a multiple of 32) has a layout leaving at least [`MIN_STEPS`] steps. 0 when not
/// even the compact layout fits the arena (small maps may still get the full layout there).
///
/// The compact layout's size grows with the map but for a few steps down: its links lend what a
/// short tabu set cannot (`planner::lend`), so a larger map may need fewer words than a smaller
/// one. Between those steps its size grows two words per 32 cells; the capacity is where it first
/// exceeds the arena.
pub const fn capacity(arena: usize) -> usize {
    // Tabu-set lengths go from piece to piece: [lo, next_cut(lo)).
    let end = usize::MAX / 64;
    let mut lo = 0usize;
    while lo < end {
        let hi = next_cut(lo);
        // The largest tabu length in [lo, hi) that fits, when the piece's last one does not.
        let last = hi.saturating_sub(1);
        if !fits_compact(arena, last) {
            if !fits_compact(arena, lo) {
                return lo.saturating_sub(1).saturating_mul(32);
            }
            // Bisection: fits at `a`, not at `b`.
            let (mut a, mut b) = (lo, last);
            while b.saturating_sub(a) > 1 {
                let m = a.saturating_add(b.saturating_sub(a) / 2);
                if fits_compact(arena, m) {
                    a = m;
                } else {
                    b = m;
                }
            }
            return a.saturating_mul(32);
        }
        lo = hi;
    }
    end.saturating_mul(32)
}

/// Whether a map with a tabu set of `w` words fits the compact layout with [`MIN_STEPS`].
const fn fits_compact(arena: usize, w: usize) -> bool {
    compact_words(w.saturating_mul(32), MIN_STEPS) <= arena
}

/// The smallest tabu-set length above `x` at which the compact layout's links change (what the
/// tabu set lends: the local search's slices, the route's words and heap, the smoothing's links):
/// the cuts of the phases' needs themselves ([`needs::next_cut`]), for paths of [`MIN_STEPS`] on
/// the largest route.
const fn next_cut(x: usize) -> usize {
    let cells = GUIDE_BLOCKS.saturating_mul(32);
    needs::next_cut(x, ask(cells, MIN_STEPS, true), usize::MAX / 64)
}

/// The longest path a map of `cells` cells gets in an arena of `arena` words with paths bounded
/// to `max_steps`, and whether its layout is the compact one; `None`: the map is too large.
pub const fn steps_for(arena: usize, cells: usize, max_steps: usize) -> Option<(usize, bool)> {
    let full = if max_steps < FULL_STEPS {
        max_steps
    } else {
        FULL_STEPS
    };
    if full_words(cells, full) <= arena {
        return Some((full, false));
    }
    // The compact layout's size grows with the steps: the most that fit, by bisection.
    if compact_words(cells, 0) > arena {
        return None;
    }
    let (mut a, mut b) = (0usize, max_steps);
    if compact_words(cells, b) <= arena {
        a = b;
    }
    while b > a.saturating_add(1) {
        let m = a.saturating_add(b.saturating_sub(a) / 2);
        if compact_words(cells, m) <= arena {
            a = m;
        } else {
            b = m;
        }
    }
    if a < MIN_STEPS && a < max_steps {
        return None;
    }
    Some((a, true))
}

/// Take the next `n` words of `rest`.
fn take<'a>(rest: &mut &'a mut [u32], n: usize) -> Option<&'a mut [u32]> {
    let (head, tail) = core::mem::take(rest).split_at_mut_checked(n)?;
    *rest = tail;
    Some(head)
}

/// Take the next `n` elements of type `T` (rounded up to a whole number of words) of `rest`.
fn take_as<'a, T: Pod>(rest: &mut &'a mut [u32], n: usize) -> Option<&'a mut [T]> {
    let bytes = n.checked_mul(core::mem::size_of::<T>())?;
    let w = take(rest, bytes.div_ceil(4))?;
    let all: &mut [T] = try_cast_slice_mut(w).ok()?;
    all.get_mut(..n)
}

/// Lay out the map of `cells` cells and a workspace for it, with paths of at most `max_steps`
/// steps, in `arena` (see the module docs for the two layouts). The map is the arena's first
/// `words(cells)` words whatever the layout. Fails with [`Error::MapTooLarge`] when neither
/// layout fits (the error's capacity is [`capacity`]`(arena.len())`).
pub fn carve(arena: &mut [u32], cells: usize, max_steps: usize) -> Result<Carved<'_>, Error> {
    // The capacity is worked out only for the error.
    let too_large = |words: usize| Error::MapTooLarge {
        cells: u32::try_from(cells).unwrap_or(u32::MAX),
        capacity: u32::try_from(capacity(words)).unwrap_or(u32::MAX),
    };
    let words = arena.len();
    let (steps, compact) = steps_for(words, cells, max_steps).ok_or_else(|| too_large(words))?;
    lay(arena, cells, steps, compact).ok_or_else(|| too_large(words))
}

/// [`carve`]'s layout, in the order of the module docs' table.
fn lay(mut rest: &mut [u32], cells: usize, steps: usize, compact: bool) -> Option<Carved<'_>> {
    let size = Sizes::of(cells, steps, compact);
    let map = take_as::<u8>(&mut rest, size.map.checked_mul(4)?)?;
    let tabu = take(&mut rest, size.map)?;
    let dead = take(&mut rest, size.dead)?;
    let tau = take_as::<[f32; 4]>(&mut rest, size.blocks)?;
    let delta = take_as::<[f32; 4]>(&mut rest, size.blocks)?;
    let guide = take(&mut rest, size.guide)?;
    let links = take(&mut rest, size.links)?;
    let points = take_as::<Point>(&mut rest, size.cells)?;
    let tours = take_as::<Dir>(&mut rest, size.cells.checked_mul(2)?)?;
    let (tour, best) = tours.split_at_mut_checked(size.cells)?;
    let moves = take_as::<u8>(&mut rest, size.moves)?;
    let ws = Workspace::new(Buffers {
        tau,
        delta,
        tabu,
        dead,
        moves,
        tours: [tour, &mut [], &mut [], best],
        points,
        links,
        curve: &mut [],
        guide,
    });
    Some(Carved {
        map,
        workspace: if compact { ws.with_packed_route() } else { ws },
        compact,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::Grid;
    use crate::planner::{plan, Params, Storage};
    use alloc::vec;
    use alloc::vec::Vec;

    /// An arena of the length of the STM32F411's: 103,424 bytes.
    const ARENA: usize = match crate::board::F411.layout {
        crate::board::Layout::Arena { words } => words,
        crate::board::Layout::Separate { .. } => 0,
    };

    #[test]
    fn every_map_up_to_the_capacity_fits_any_arena() {
        // Arena sizes around and far from the F411's, and every map size near the capacity and
        // near where the compact layout's links shrink (a tabu set of REFINE_WORDS words).
        let edge = REFINE_WORDS * 32;
        let mut with_cap = 0;
        for arena in (6_000..60_000).step_by(250).chain([ARENA]) {
            let cap = capacity(arena);
            if cap == 0 {
                continue;
            }
            with_cap += 1;
            let near = |c: usize| c.saturating_sub(64)..=c;
            for cells in near(cap)
                .chain(near(edge.min(cap)))
                .chain(near((edge + 32).min(cap)))
                .chain((1..=cap).step_by(cap / 97 + 1))
                .filter(|&c| c >= 1)
            {
                let fits = steps_for(arena, cells, 2047);
                assert!(
                    fits.is_some_and(|(s, _)| s >= MIN_STEPS),
                    "arena {arena}, capacity {cap}: {cells} cells: {fits:?}"
                );
            }
        }
        assert!(with_cap > 150, "{with_cap}");
    }

    #[test]
    fn the_full_layouts_links_are_what_the_phases_need() {
        // The compile-time check is tight: with a link fewer, the route's heap of 4,096 blocks
        // beside a tabu set of fewer words does not fit (the build then fails, `full_links_hold`).
        assert!(full_links_hold(LINKS));
        assert!(!full_links_hold(LINKS - 1));
    }

    /// A `w x h` map with random walls (`density`), its corners free.
    fn walls(w: u16, h: u16, density: f32, seed: u64) -> Vec<u8> {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(seed);
        let cells = usize::from(w) * usize::from(h);
        let mut b = vec![0u8; cells.div_ceil(8)];
        for i in 1..cells - 1 {
            if rng.next_unit() < density {
                b[i / 8] |= 1 << (i % 8);
            }
        }
        b
    }

    #[test]
    fn the_full_layout_plans_what_the_f411s_storage_planned() {
        type F411Storage = Storage<{ crate::map::bitmap::words(65_536) }, 2048, 4096, 1024, 0, 0>;
        let mut storage = alloc::boxed::Box::new(F411Storage::new());
        for (w, h, seed) in [
            (30u16, 30u16, 1u64),
            (256, 256, 2),
            (200, 150, 3),
            (31, 33, 4),
        ] {
            let bits = walls(w, h, 0.25, seed);
            let g = Grid::new(w, h, &bits).unwrap();
            let (s, goal) = (Point::new(0, 0), Point::new(w - 1, h - 1));
            let p = Params {
                seed,
                ..Params::default()
            };
            let a = plan(&g, s, goal, &p, storage.workspace())
                .map(|pl| (pl.directions().to_vec(), pl.waypoints().to_vec(), pl.moves));
            let mut arena = vec![0u32; ARENA];
            let c = carve(&mut arena, g.cells(), 2047).unwrap();
            assert!(!c.compact);
            let b = plan(&g, s, goal, &p, c.workspace).map(|pl| {
                assert!(pl.shortfalls.is_empty(), "{w} x {h}: {}", pl.shortfalls);
                (pl.directions().to_vec(), pl.waypoints().to_vec(), pl.moves)
            });
            assert_eq!(a, b, "{w} x {h}");
        }
    }

    #[test]
    fn the_f411_arena_plans_what_a_storage_keeping_every_tour_plans() {
        // The arena walks the iteration's best and worst ants again and tightens with its
        // half-word hash table (4,096 links, fewer than the map's cells); a storage that keeps the
        // two tours must plan the same, cold and warm (the pheromone kept in the arena).
        type Keeping = Storage<{ crate::map::bitmap::words(65_536) }, 2048, 4096, 1024, 0, 2048>;
        let mut storage = alloc::boxed::Box::new(Keeping::new());
        let mut arena = vec![0u32; ARENA];
        let (w, h) = (256u16, 256u16);
        let mut bits = walls(w, h, 0.25, 7);
        let (s, goal) = (Point::new(0, 0), Point::new(w - 1, h - 1));
        let (mut m1, mut m2) = (crate::planner::Memory::new(), crate::planner::Memory::new());
        let mut outcomes = Vec::new();
        for (round, warm) in [(0, false), (1, true), (2, true)] {
            if round > 0 {
                // Block a few cells away from the corners: the warm runs repair around them.
                for i in 0..6usize {
                    let c = (100 + 20 * round + i) * usize::from(w) + 90 + 7 * i;
                    bits[c / 8] |= 1 << (c % 8);
                    let p = Point::new((c % usize::from(w)) as u16, (c / usize::from(w)) as u16);
                    m1.changed(crate::planner::Area::cell(p), None);
                    m2.changed(crate::planner::Area::cell(p), None);
                }
            }
            let g = Grid::new(w, h, &bits).unwrap();
            let p = Params::default();
            let run = |ws, m: &mut crate::planner::Memory| {
                let mut r = if warm {
                    crate::planner::Run::warm(&g, s, goal, &p, ws, m)
                } else {
                    crate::planner::Run::cold(&g, s, goal, &p, ws, m)
                }
                .unwrap();
                while let crate::planner::Poll::Working(_) = r.poll() {}
                r.keep(m);
                r.finish().map(|pl| {
                    (
                        pl.directions().to_vec(),
                        pl.waypoints().to_vec(),
                        pl.moves,
                        pl.origin,
                    )
                })
            };
            let a = run(storage.workspace(), &mut m1);
            let c = carve(&mut arena, g.cells(), 2047).unwrap();
            assert!(!c.compact);
            let b = run(c.workspace, &mut m2);
            assert_eq!(a, b, "round {round}");
            outcomes.push(a.is_ok());
        }
        assert_eq!(outcomes, [true; 3]);
    }

    #[test]
    fn the_compact_layout_plans_valid_paths_near_the_full_ones() {
        // A 160 x 120 map in an arena too small for its full layout.
        let (w, h) = (160u16, 120u16);
        let cells = usize::from(w) * usize::from(h);
        let arena_words = compact_words(cells, 2047);
        assert!(full_words(cells, 2047) > arena_words);
        let (mut ratio, mut planned) = (0.0, 0);
        for seed in 1..=6u64 {
            let bits = walls(w, h, 0.15, seed);
            let g = Grid::new(w, h, &bits).unwrap();
            let (s, goal) = (Point::new(0, 0), Point::new(w - 1, h - 1));
            let p = Params {
                seed,
                ..Params::default()
            };
            let mut heap = crate::heap::HeapStorage::new(cells, 128).unwrap();
            let Ok(full) = plan(&g, s, goal, &p, heap.workspace()) else {
                continue;
            };
            let mut arena = vec![0u32; arena_words];
            assert_eq!(steps_for(arena_words, cells, 2047), Some((2047, true)));
            let c = carve(&mut arena, cells, 2047).unwrap();
            assert!(c.compact);
            assert_eq!(c.workspace.steps(), 2047);
            let compact = plan(&g, s, goal, &p, c.workspace).unwrap();
            assert_eq!(compact.pruned, 0);
            let raw: Vec<Point> = compact.raw().collect();
            assert_eq!((raw[0], *raw.last().unwrap()), (s, goal));
            for (pair, &d) in raw.windows(2).zip(compact.directions()) {
                assert_eq!(g.step(pair[0], d), Some(pair[1]));
            }
            ratio += f64::from(compact.raw_length / full.raw_length);
            planned += 1;
        }
        assert!(planned >= 4, "{planned} of 6 maps have a path");
        let ratio = ratio / f64::from(planned);
        assert!(ratio < 1.01, "{ratio}");
    }

    /// A Moving AI map (`@`, `T`, `O`, `W` blocked) as the core's bits.
    fn moving_ai(text: &str) -> (Vec<u8>, u16, u16) {
        let mut lines = text.lines();
        let (mut w, mut h) = (0u16, 0u16);
        for l in lines.by_ref() {
            if let Some(v) = l.strip_prefix("width ") {
                w = v.trim().parse().unwrap();
            } else if let Some(v) = l.strip_prefix("height ") {
                h = v.trim().parse().unwrap();
            } else if l.trim() == "map" {
                break;
            }
        }
        let mut b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
        for (y, row) in lines.take(usize::from(h)).enumerate() {
            for (x, c) in row.bytes().take(usize::from(w)).enumerate() {
                if matches!(c, b'@' | b'T' | b'O' | b'W') {
                    let i = y * usize::from(w) + x;
                    b[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (b, w, h)
    }

    #[test]
    fn the_f411s_arena_plans_a_4000_step_path_at_512_x_512() {
        // `maze512-1-0` (Moving AI: 512 x 512, corridors one cell wide), the scenario from
        // (40, 125) to (502, 437) whose optimum is 4,000 steps: in the STM32F411's arena the
        // compact layout keeps paths of 4,095 steps, and the plan is that optimum. Before the
        // packed route and the keyed table it kept 1,876: every ant was dropped.
        let (bits, w, h) = moving_ai(include_str!("../../maps/large/maze512-1-0.map"));
        let g = Grid::new(w, h, &bits).unwrap();
        let board = crate::board::F411;
        let mut arena = vec![0u32; ARENA];
        let c = carve(&mut arena, g.cells(), board.max_steps).unwrap();
        assert!(c.compact);
        assert_eq!(c.workspace.steps(), 4095);
        let (s, goal) = (Point::new(40, 125), Point::new(502, 437));
        let p = Params::default();
        let plan = plan(&g, s, goal, &p, c.workspace).unwrap();
        let raw: Vec<Point> = plan.raw().collect();
        assert_eq!((raw[0], *raw.last().unwrap()), (s, goal));
        for (pair, &d) in raw.windows(2).zip(plan.directions()) {
            assert_eq!(g.step(pair[0], d), Some(pair[1]));
        }
        assert_eq!(plan.directions().len(), 4000);
        // The compact layout lends every step all it asks for.
        assert!(plan.shortfalls.is_empty(), "{}", plan.shortfalls);
        assert!(
            (plan.raw_length - 4000.0).abs() < 1e-3,
            "{}",
            plan.raw_length
        );
        // With the bound of protocol 10's F411 (2,047 steps) no ant arrives.
        let mut arena = vec![0u32; ARENA];
        let c = carve(&mut arena, g.cells(), 2047).unwrap();
        assert!(matches!(
            crate::planner::plan(&g, s, goal, &p, c.workspace),
            Err(crate::Error::PathTooLong { .. })
        ));
    }
}
