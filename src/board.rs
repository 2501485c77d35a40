//! What each board's firmware holds, described once: the most cells of a map, the longest ant
//! path and how the planner's buffers are laid out in its RAM ([`Board`]). The firmware's board
//! modules (`src/firmware/board/`) take their values from here, and the host tool plans "as that
//! board does" from the same description (`ohaca plan --board f411`), so a host and a device
//! can never disagree on a layout.
//!
//! | board | [`Board`] | cells | ant path | layout |
//! | --- | --- | ---: | ---: | --- |
//! | STM32F411 (and the default QEMU build, which copies it) | [`F411`] | 262,144 | 4,095 (2,047 on maps of up to 68,256 cells, which get the full layout) | one arena of 25,856 words, laid out per map by [`crate::planner::arena::carve`] |
//! | STM32H743 (and its QEMU twin, `twin-h743`) | [`H743`] | 2,097,152 | 16,384 | separate buffers over four RAM regions: every buffer for its largest map, 16,384 links, the move table on maps of up to 1,024 cells |
//!
//! The core's planner never names a board: [`crate::planner::arena`] takes an arena's length,
//! and a workspace takes whatever buffers it is given. The protocol's
//! [`MAX_STEPS`](crate::protocol) is the wire's bound (the longest path one reply carries), the
//! H743's `max_steps` today; every board's `max_steps` must be at most that.

use crate::colony::route::GUIDE_BLOCKS;
use crate::colony::tighten::hash_words;
use crate::planner::arena;

/// How a board lays out the map and the planner's buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One arena of `words` 32-bit words holding the map (first) and the planner's buffers,
    /// laid out for each map by [`arena::carve`]: every buffer while they fit (the *full*
    /// layout), the *compact* one beyond (no pruning marks, 64 pheromone blocks, fewer steps).
    Arena {
        /// The arena's length, in words.
        words: usize,
    },
    /// Every buffer a static of its own, sized for the board's largest map and longest path,
    /// with `links` links and the move table on maps of up to `moves` cells.
    Separate {
        /// Links: tightening's hash table, the coarse route's heap, the smoothing's links.
        links: usize,
        /// The move table covers maps of up to this many cells (none on larger maps).
        moves: usize,
    },
}

/// One board's firmware: see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Board {
    /// Short name: the host tool's `--board` value.
    pub name: &'static str,
    /// Most cells of a map, any shape (Hello's `capacity.cells`).
    pub cells: usize,
    /// Longest side of a map (Hello's `capacity.max_side`).
    pub max_side: u16,
    /// Longest ant path, in steps (Hello's `capacity.max_steps`); an [`Layout::Arena`] leaves
    /// fewer on maps too large for its full layout ([`Board::plans`]).
    pub max_steps: usize,
    /// Where the map and the planner's buffers go.
    pub layout: Layout,
    /// Bytes of its UART's receive buffer: the request bytes a host may have outstanding
    /// (Hello's `capacity.window_bytes`; within them nothing is lost, at any baud rate).
    pub rx_ring: usize,
    /// Requests a host may have outstanding (Hello's `capacity.window`): as many as its reply
    /// queue holds, so no reply is ever dropped within it.
    pub window: usize,
}

/// How a board plans one map: the longest ant path it keeps, and whether that is the arena's
/// compact layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapLayout {
    /// Longest ant path, in steps.
    pub steps: usize,
    /// The compact layout of [`arena::carve`] (no pruning marks, coarser pheromone).
    pub compact: bool,
}

/// The STM32F411 (128 KiB of RAM) and the default QEMU build: maps of up to 262,144 cells
/// (512 x 512, or Nav2's 604 x 307 depot at 5 cm), ant paths of up to 4,095 steps, in one arena
/// of 103,424 bytes (an 8 KiB map buffer and the 95,232-byte `Storage` it replaced): every
/// buffer and paths of up to 2,047 steps ([`arena::FULL_STEPS`]) on maps of up to 68,256 cells,
/// the compact layout beyond (4,095 steps on every map it takes, 512 x 512 included).
pub const F411: Board = Board {
    name: "f411",
    cells: 262_144,
    max_side: 4096,
    max_steps: 4095,
    layout: Layout::Arena { words: 25_856 },
    rx_ring: 1024,
    window: 8,
};

/// Longest path of the STM32H743.
const H743_STEPS: usize = 16_384;

/// The STM32H743 (1,056 KiB of RAM in four regions) and its QEMU twin: maps of up to 2,097,152
/// cells (2048 x 1024, or Nav2's 1006 x 1674 warehouse at 3 cm), ant paths of up to 16,384 steps,
/// every buffer a static of its own (`src/firmware/buffers.rs` places them): links are
/// tightening's smallest hash table for the longest path ([`hash_words`], 16,384 words, all of
/// SRAM4), and at least the coarse route's blocks.
pub const H743: Board = Board {
    name: "h743",
    cells: 2_097_152,
    max_side: 4096,
    max_steps: H743_STEPS,
    layout: Layout::Separate {
        links: links_for(H743_STEPS),
        moves: 1024,
    },
    rx_ring: 1024,
    window: 8,
};

/// Bytes of the STM32H743's SRAM4 (RM0433), the region that holds a [`Layout::Separate`]
/// board's links (`src/firmware/buffers.rs`): 64 KiB.
pub const H743_SRAM4_BYTES: usize = 64 * 1024;

/// Links of a [`Layout::Separate`] board with paths of up to `steps` steps: tightening's smallest
/// hash table for `steps + 1` cells, at least the coarse route's blocks.
const fn links_for(steps: usize) -> usize {
    let hash = hash_words(steps.saturating_add(1));
    if hash > GUIDE_BLOCKS {
        hash
    } else {
        GUIDE_BLOCKS
    }
}

/// Every board, by name.
pub const BOARDS: [Board; 2] = [F411, H743];

impl Board {
    /// Whether the board lays the map and the planner's buffers out in one arena
    /// ([`Layout::Arena`]) rather than as statics of their own ([`Layout::Separate`]).
    pub const fn is_arena(&self) -> bool {
        matches!(self.layout, Layout::Arena { .. })
    }

    /// The board called `name` (`f411`, `h743`; any case).
    pub fn named(name: &str) -> Option<Board> {
        BOARDS
            .into_iter()
            .find(|b| b.name.eq_ignore_ascii_case(name.trim()))
    }

    /// The board whose firmware reports this capacity in Hello (`cells`, `max_steps`): how a host
    /// learns a device's layout.
    pub fn with_capacity(cells: usize, max_steps: usize) -> Option<Board> {
        BOARDS
            .into_iter()
            .find(|b| b.cells == cells && b.max_steps == max_steps)
    }

    /// How the board plans a map of `cells` cells; `None`: the board does not take it.
    pub const fn plans(&self, cells: usize) -> Option<MapLayout> {
        if cells > self.cells {
            return None;
        }
        match self.layout {
            Layout::Arena { words } => match arena::steps_for(words, cells, self.max_steps) {
                Some((steps, compact)) => Some(MapLayout { steps, compact }),
                None => None,
            },
            Layout::Separate { .. } => Some(MapLayout {
                steps: self.max_steps,
                compact: false,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::arena::{capacity, carve, compact_words, full_words, steps_for, MIN_STEPS};
    use crate::Error;
    use alloc::vec;

    const WORDS: usize = match F411.layout {
        Layout::Arena { words } => words,
        Layout::Separate { .. } => 0,
    };

    #[test]
    fn the_layouts_of_the_f411s_arena() {
        // The former `Storage` had the 1,024-byte move table (256 words) whatever the map.
        assert_eq!(full_words(65_536, 2047) + 256, WORDS);
        assert_eq!(steps_for(WORDS, 65_536, 4095), Some((2047, false)));
        // Without the move table the full layout holds a little more; it keeps its 2,047 steps
        // (`FULL_STEPS`) whatever the bound, so those maps plan as they always did.
        assert_eq!(steps_for(WORDS, 68_256, 4095), Some((2047, false)));
        assert_eq!(steps_for(WORDS, 68_257, 4095), Some((4095, true)));
        assert_eq!(steps_for(WORDS, 604 * 307, 4095), Some((4095, true)));
        // Every compact map keeps 4,095 steps: the tabu set lends what the links do not hold
        // (the route's words and heap, the local search's scratch, the smoothing's links), and
        // tightening's keyed table takes the path cells' words. The largest map, 512 x 512:
        assert_eq!(steps_for(WORDS, 512 * 512, 4095), Some((4095, true)));
        assert_eq!(compact_words(512 * 512, 4095), 25_600);
        // Where the tabu set halved lends the local search a window of 48 to 51 cells a side.
        assert_eq!(steps_for(WORDS, 258_048, 4095), Some((4095, true)));
        assert_eq!(compact_words(258_048, 4095), 25_344);
        // One step more would not fit at 512 x 512 (the keyed table grows by half a word).
        assert!(compact_words(512 * 512, 4096 + 170) > WORDS);
        let cap = capacity(WORDS);
        assert_eq!(cap, 364_544);
        assert!(F411.cells <= cap);
        assert!(steps_for(WORDS, cap, 4095).is_some_and(|(s, c)| c && s >= MIN_STEPS));
        assert_eq!(steps_for(WORDS, cap + 32, 4095), None);
        // Every map size between: a layout that fits, the compact one leaving at least MIN_STEPS.
        for cells in (1..=cap).step_by(997) {
            let (s, compact) = steps_for(WORDS, cells, 4095).unwrap();
            let words = if compact {
                compact_words(cells, s)
            } else {
                full_words(cells, s)
            };
            assert!(words <= WORDS && s >= MIN_STEPS, "{cells}: {s} {compact}");
            let mut arena = vec![0u32; WORDS];
            let c = carve(&mut arena, cells, 4095).unwrap();
            assert_eq!((c.workspace.steps(), c.compact), (s, compact), "{cells}");
            // Up to the board's 262,144 cells, every compact map keeps the board's bound.
            assert!(!compact || cells > F411.cells || s == 4095, "{cells}: {s}");
            assert!(c.workspace.capacity() >= cells && c.map.len() * 8 >= cells);
        }
        let mut arena = vec![0u32; WORDS];
        assert_eq!(
            carve(&mut arena, cap + 32, 4095).unwrap_err(),
            Error::MapTooLarge {
                cells: 364_576,
                capacity: 364_544
            }
        );
    }

    #[test]
    fn each_board_says_how_it_plans_a_map() {
        let f = |cells| F411.plans(cells).map(|l| (l.steps, l.compact));
        assert_eq!(f(68_256), Some((2047, false)));
        assert_eq!(f(68_257), Some((4095, true)));
        assert_eq!(f(512 * 512), Some((4095, true)));
        assert_eq!(f(512 * 512 + 1), None, "more than the board takes");
        let h = |cells| H743.plans(cells).map(|l| (l.steps, l.compact));
        assert_eq!(h(512 * 512), Some((16_384, false)));
        assert_eq!(h(2_097_152), Some((16_384, false)));
        assert_eq!(h(2_097_153), None);
        assert_eq!(
            H743.layout,
            Layout::Separate {
                links: 16_384,
                moves: 1024
            }
        );
    }

    #[test]
    fn boards_by_name_and_by_capacity() {
        assert_eq!(Board::named("F411"), Some(F411));
        assert_eq!(Board::named("h743"), Some(H743));
        assert_eq!(Board::named("h7"), None);
        assert_eq!(Board::with_capacity(262_144, 4095), Some(F411));
        assert_eq!(
            Board::with_capacity(262_144, 2047),
            None,
            "protocol 10's F411 said 2,047"
        );
        assert_eq!(Board::with_capacity(2_097_152, 16_384), Some(H743));
        assert_eq!(Board::with_capacity(262_144, 16_384), None);
    }

    #[cfg(feature = "protocol")]
    #[test]
    fn every_path_a_board_plans_fits_one_reply() {
        for b in BOARDS {
            assert!(b.max_steps <= crate::protocol::MAX_STEPS, "{}", b.name);
        }
    }
}
