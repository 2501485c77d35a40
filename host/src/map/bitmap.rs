//! [`Map`]: an owned occupancy map in the core's layout, whatever file it came from.

use std::fmt::Write as _;

use ohaca::{Grid, Point};

/// The largest side a map may have (the core addresses cells with `u16` coordinates).
pub const MAX_SIDE: usize = u16::MAX as usize;

/// An owned occupancy map in the core's layout: `width x height` cells, row-major, one bit per
/// cell, least significant bit first, `1` = blocked (see [`ohaca::grid`]).
///
/// The fields are public so a map can be built from any source; [`Map::grid`] checks that they
/// agree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Map {
    /// Columns.
    pub width: u16,
    /// Rows.
    pub height: u16,
    /// `ceil(width * height / 8)` bytes of cell bits.
    pub bits: Vec<u8>,
}

impl Map {
    /// A `width x height` map whose cell `(x, y)` is blocked iff `blocked(x, y)`. Sides of 0
    /// give a map that [`Map::grid`] rejects.
    pub fn from_fn(width: u16, height: u16, mut blocked: impl FnMut(u16, u16) -> bool) -> Map {
        let cells = usize::from(width) * usize::from(height);
        let mut bits = vec![0u8; ohaca::map::bits::bytes(cells)];
        for y in 0..height {
            for x in 0..width {
                if blocked(x, y) {
                    let i = usize::from(y) * usize::from(width) + usize::from(x);
                    ohaca::map::bits::set(&mut bits, i, true);
                }
            }
        }
        Map {
            width,
            height,
            bits,
        }
    }

    /// The core's view of this map. Fails with [`ohaca::Error::BadMap`] if a side is 0 or
    /// `bits` is too short (possible only for a hand-built `Map`; loaded maps are always valid).
    pub fn grid(&self) -> Result<Grid<'_>, ohaca::Error> {
        Grid::new(self.width, self.height, &self.bits)
    }

    /// `width * height`.
    pub fn cells(&self) -> usize {
        usize::from(self.width) * usize::from(self.height)
    }

    /// True if `p` is outside the map or blocked.
    pub fn is_blocked(&self, p: Point) -> bool {
        if p.x >= self.width || p.y >= self.height {
            return true;
        }
        let i = usize::from(p.y) * usize::from(self.width) + usize::from(p.x);
        ohaca::map::bits::get(&self.bits, i).unwrap_or(true)
    }

    /// Block (`blocked`) or clear cell `p`, with the device's own cell writer
    /// ([`ohaca::protocol::set_rect`], one cell). Fails with the protocol's `OutsideMap` when `p`
    /// is off the map.
    pub fn set(&mut self, p: Point, blocked: bool) -> Result<(), ohaca::protocol::ErrorReply> {
        let size = (self.width, self.height);
        ohaca::protocol::set_rect(size, &mut self.bits, (p.x, p.y, 1, 1), blocked)
    }

    /// The map as a text grid (`.` free, `#` blocked, one row per line), which
    /// [`Map::parse`] with [`Format::Text`] reads back unchanged.
    pub fn to_text(&self) -> String {
        let mut s = String::with_capacity((usize::from(self.width) + 1) * usize::from(self.height));
        for y in 0..self.height {
            for x in 0..self.width {
                s.push(if self.is_blocked(Point::new(x, y)) {
                    '#'
                } else {
                    '.'
                });
            }
            s.push('\n');
        }
        s
    }

    /// The map as a Moving AI `.map` file (`.` free, `@` blocked).
    pub fn to_moving_ai(&self) -> String {
        let mut s = String::new();
        let _ = write!(
            s,
            "type octile\nheight {}\nwidth {}\nmap\n",
            self.height, self.width
        );
        for line in self.to_text().lines() {
            s.extend(line.chars().map(|c| if c == '#' { '@' } else { c }));
            s.push('\n');
        }
        s
    }
}
