//! The eight moves: direction codes, their offsets, diagonal or straight, and their opposite.
//!
//! This is the one place the moves are defined. [`crate::map::grid`] (which re-exports them) builds the
//! map's move rules on them, and [`crate::map::bitmap`] its neighbourhood masks, so neither of those
//! modules depends on the other for them. Everything here is `const` and cannot fail.

/// One of the eight moves, `0..8` clockwise from east (with `y` pointing down): E, SE, S, SW, W,
/// NW, N, NE. Odd directions are diagonal.
pub type Dir = u8;

/// Column offset of each direction.
pub const DX: [i32; 8] = [1, 1, 0, -1, -1, -1, 0, 1];
/// Row offset of each direction.
pub const DY: [i32; 8] = [0, 1, 1, 1, 0, -1, -1, -1];

/// True for the four diagonal directions.
#[inline]
pub const fn is_diagonal(d: Dir) -> bool {
    d & 1 == 1
}

/// The direction that undoes `d`.
#[inline]
pub const fn opposite(d: Dir) -> Dir {
    d.wrapping_add(4) & 7
}
