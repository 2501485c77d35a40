//! `--board f411|h743`: the host core planning exactly as a board's firmware does, bit for bit,
//! from the core's description of that board ([`ohaca::board`]): the same buffers, the same
//! layout, the same path bound.
//!
//! - **f411** (the STM32F411 and the default QEMU build): an arena of the board's length, laid
//!   out per map by [`ohaca::planner::arena::carve`] (every buffer on maps of up to 68,256
//!   cells and paths of up to 2,047 steps, the compact layout beyond: no pruning, 64 pheromone
//!   blocks, a packed coarse route, paths of up to 4,095 steps on every map it takes).
//! - **h743** (the STM32H743 and its QEMU twin): heap buffers of the board's shape: ant paths of
//!   up to 16,384 steps, 16,384 links, the move table on maps of up to 1,024 cells, the
//!   iteration's best and worst ants walked again.
//!
//! Without `--board`, `plan` and `render` plan in the host's own storage ([`HeapStorage`]: every
//! buffer for the map, paths as long as the map has cells), which gives the boards' paths
//! whenever the board plans the map in its full layout and no path is longer than the board's
//! bound ([`differs_from_host`]).

use ohaca::board::{Board, Layout, MapLayout, F411, H743};
use ohaca::heap::{AllocError, HeapStorage};
use ohaca::planner::{arena, Workspace};

/// Why a board's buffers cannot plan a map.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BoardError {
    /// The map has more cells than the board takes.
    #[error("the {board} board takes maps of up to {capacity} cells, not {cells}")]
    TooLarge {
        /// The board's name.
        board: &'static str,
        /// The map's cells.
        cells: usize,
        /// The board's most cells.
        capacity: usize,
    },
    /// The buffers could not be allocated.
    #[error(transparent)]
    Storage(#[from] AllocError),
    /// The core refused the layout (`ohaca::planner::arena::carve`).
    #[error("{0}")]
    Core(ohaca::Error),
}

impl From<ohaca::Error> for BoardError {
    fn from(e: ohaca::Error) -> Self {
        BoardError::Core(e)
    }
}

/// A `--board` value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BoardArg {
    /// The STM32F411 (and the default QEMU firmware): one 103,424-byte arena
    F411,
    /// The STM32H743 (and its QEMU twin): buffers over its RAM regions
    H743,
}

impl BoardArg {
    /// The core's description of the board.
    pub fn board(self) -> Board {
        match self {
            BoardArg::F411 => F411,
            BoardArg::H743 => H743,
        }
    }
}

/// The buffers of a board's firmware, on the host, for maps of one size.
#[derive(Debug)]
pub struct BoardStorage {
    board: Board,
    cells: usize,
    buffers: Buffers,
}

#[derive(Debug)]
enum Buffers {
    /// An arena of the board's length ([`Layout::Arena`]), carved for each run.
    Arena(Vec<u32>),
    /// Heap buffers of the board's shape ([`Layout::Separate`]), or with [`BoardStorage::lenient`]
    /// for a map larger than the arena.
    Heap(Box<HeapStorage>),
}

impl BoardStorage {
    /// `board`'s buffers for maps of `cells` cells; [`BoardError::TooLarge`] when the board does
    /// not take such a map.
    pub fn new(board: Board, cells: usize, iterations: usize) -> Result<Self, BoardError> {
        if board.plans(cells).is_none() {
            return Err(BoardError::TooLarge {
                board: board.name,
                cells,
                capacity: board.cells,
            });
        }
        let buffers = match board.layout {
            Layout::Arena { words } => Buffers::Arena(vec![0; words]),
            Layout::Separate { links, moves } => Buffers::Heap(Box::new(
                HeapStorage::with_steps(cells, board.max_steps, cells <= moves, iterations)?
                    .with_links(links)
                    .replaying(),
            )),
        };
        Ok(BoardStorage {
            board,
            cells,
            buffers,
        })
    }

    /// Like [`BoardStorage::new`], but a map the board does not take gets heap storage with the
    /// board's path bound instead of an error, as long as it fits the host (`ohaca replan` and
    /// `ohaca ros --host` without `--board`: the STM32F411's layout where it applies).
    pub fn lenient(board: Board, cells: usize, iterations: usize) -> Result<Self, BoardError> {
        let fits_arena = match board.layout {
            Layout::Arena { words } => cells <= arena::capacity(words),
            Layout::Separate { .. } => board.plans(cells).is_some(),
        };
        if fits_arena {
            let buffers = match board.layout {
                Layout::Arena { words } => Buffers::Arena(vec![0; words]),
                Layout::Separate { .. } => return Self::new(board, cells, iterations),
            };
            return Ok(BoardStorage {
                board,
                cells,
                buffers,
            });
        }
        Ok(BoardStorage {
            board,
            cells,
            buffers: Buffers::Heap(Box::new(HeapStorage::with_steps(
                cells,
                board.max_steps,
                true,
                iterations,
            )?)),
        })
    }

    /// The board.
    pub fn board(&self) -> Board {
        self.board
    }

    /// A workspace for a run on a map of the storage's size: the arena carved again (so what a
    /// previous run left in it, the colony of a warm start, stays where it was), or the heap
    /// buffers.
    pub fn workspace(&mut self) -> Result<Workspace<'_>, BoardError> {
        match &mut self.buffers {
            Buffers::Arena(words) => {
                Ok(arena::carve(words, self.cells, self.board.max_steps)?.workspace)
            }
            Buffers::Heap(h) => Ok(h.workspace()),
        }
    }

    /// A workspace for a map of `cells` cells: the storage made again for that size when it
    /// was for another.
    pub fn lend(&mut self, cells: usize, iterations: usize) -> Result<Workspace<'_>, BoardError> {
        if cells != self.cells {
            *self = BoardStorage::new(self.board, cells, iterations)?;
        }
        self.workspace()
    }
}

/// How `board` plans a map of `cells` cells, when that differs from the host's default storage
/// ([`HeapStorage`], every buffer): the arena's compact layout (no pruning, coarser pheromone,
/// fewer steps). `None`: the board plans it as the host does (up to its path bound), or does
/// not take it at all.
pub fn differs_from_host(board: &Board, cells: usize) -> Option<MapLayout> {
    board.plans(cells).filter(|l| l.compact)
}

/// A protocol capacity for `board`, as its firmware reports it in Hello (for the fitting that
/// `ohaca ros` does for a device).
pub fn capacity(board: &Board) -> ohaca::protocol::Capacity {
    ohaca::protocol::Capacity {
        cells: u32::try_from(board.cells).unwrap_or(u32::MAX),
        max_side: board.max_side,
        max_steps: u32::try_from(board.max_steps).unwrap_or(u32::MAX),
        max_chunk: u16::try_from(ohaca::protocol::MAX_CHUNK).unwrap_or(u16::MAX),
        max_request: u16::try_from(ohaca::protocol::MAX_REQUEST).unwrap_or(u16::MAX),
        plan_queue: 1,
        tick_hz: 1_000_000,
        window: u8::try_from(board.window).unwrap_or(u8::MAX),
        window_bytes: u16::try_from(board.rx_ring).unwrap_or(u16::MAX),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_board_refuses_maps_it_does_not_take() {
        let e = BoardStorage::new(F411, 512 * 513, 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the f411 board takes maps of up to 262144 cells, not 262656"
        );
        assert!(BoardStorage::new(F411, 512 * 512, 10).is_ok());
        // Lenient: the arena while it fits, the heap beyond.
        assert!(matches!(
            BoardStorage::lenient(F411, 512 * 513, 10).unwrap().buffers,
            Buffers::Arena(_)
        ));
        assert!(matches!(
            BoardStorage::lenient(F411, 1024 * 1024, 10)
                .unwrap()
                .buffers,
            Buffers::Heap(_)
        ));
    }

    #[test]
    fn the_f411_plans_large_maps_unlike_the_host() {
        assert_eq!(differs_from_host(&F411, 256 * 256), None);
        assert_eq!(
            differs_from_host(&F411, 604 * 307),
            Some(MapLayout {
                steps: F411.max_steps,
                compact: true
            })
        );
        assert_eq!(differs_from_host(&H743, 2048 * 1024), None);
    }
}
