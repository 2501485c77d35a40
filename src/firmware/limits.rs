//! What the device holds, from its board's description (`ohaca::board`, through
//! `super::board::BOARD`): the map's cells and sides, the map buffer's bytes, the longest ant
//! path. The state (`super::state`) and the buffers (`super::buffers`) both size themselves by
//! these.

use super::board::BOARD;

/// Most cells of a map the device holds and plans on, whatever its shape: the board's
/// `BOARD` (262,144 cells, 32 KiB at one bit a cell in the arena the planner's
/// buffers share, on the STM32F411 and the default QEMU board, so what QEMU proves holds on the
/// chip; 2,097,152 cells on the STM32H743 and its QEMU twin).
pub const MAX_CELLS: usize = BOARD.cells;
/// Longest side of a map the device takes (a 4096 x 64 corridor has as many cells as 512 x 512):
/// the board's.
pub const MAX_SIDE: u16 = BOARD.max_side;
/// Bytes of the map buffer.
pub const MAP_BYTES: usize = MAX_CELLS.div_ceil(8);
/// Most cells of a map the planner plans on: every map the device holds, at full resolution.
pub const PLAN_CELLS: usize = MAX_CELLS;
/// Longest ant path the planner keeps, in steps (a backtracking ant takes a cell beyond it for a
/// wall, a dying one is dropped, and a plan no ant finishes that way is `Error PathTooLong`): the
/// board's `BOARD`. A straight path across a 256 x 256 map has at most 255 steps, but a maze's or
/// a long corridor's (4096 x 16) can be far longer: the longest scenario of
/// `maps/large/maze-128-128-2` has 1,379 steps (BENCHMARKS.md, section 4), one of `maze512-1-0`
/// 4,000. The STM32F411 and the default QEMU board keep 4,095 (2,047 on maps of up to 68,256
/// cells, which get the arena's full layout: `ohaca::planner::arena::steps_for`), the STM32H743
/// and its twin 16,384.
pub const PLAN_STEPS: usize = BOARD.max_steps;
/// Bytes the board's receive buffer holds (the UART driver's ring, 1 KiB on every board): the
/// request bytes a host may have outstanding (`Capacity::window_bytes`). Within them nothing is
/// lost, however long the receiver is kept from reading (by a planner piece, or the map's lock),
/// at any baud rate; at 115,200 baud they are 89 ms of the line.
pub const RX_RING: usize = BOARD.rx_ring;
/// Requests a host may have outstanding (`Capacity::window`): the reply queue's depth.
pub const WINDOW: usize = BOARD.window;
