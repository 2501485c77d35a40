//! Map uploads and cell updates as the device applies them: the run-length code of
//! [`super::Request::SetMapRle`] ([`RleEncoder`], [`RleDecoder`]), the upload state machine
//! shared by raw and run-length uploads ([`Upload`]), and in-place cell changes
//! ([`super::Request::SetRect`], [`super::Request::SetCells`]: [`check_rect`], [`set_rect`],
//! [`check_cells`], [`set_cells`]).
//!
//! Guarantees: nothing here panics or allocates, whatever a peer sends; every check runs before
//! the map buffer is touched, so a refused chunk header or cell update changes nothing; an upload
//! is complete only when exactly `width * height` cells were written (a partial or broken one is
//! never reported complete). The map buffer has [`crate::map::grid`]'s layout (row-major, LSB first,
//! `1` = blocked).
//!
//! Run-length code: the map's cells in row-major order as alternating runs, free first, each run
//! length an unsigned LEB128 varint (postcard's `u32`). A map that starts blocked starts with a
//! run of 0 free cells. The 4x3 map with one obstacle at `(1, 1)` (cell 5) is `05 01 06`.
//!
//! ```
//! use ohaca::protocol::{RleDecoder, RleEncoder};
//! let bits = [0x20u8, 0x00];                         // 4x3, cell 5 blocked
//! let code: Vec<u8> = RleEncoder::new(&bits, 12).collect();
//! assert_eq!(code, [5, 1, 6]);
//! let mut out = [0u8; 2];
//! let mut d = RleDecoder::new(12);
//! d.feed(&code, &mut out).unwrap();
//! assert!(d.is_complete());
//! assert_eq!(out[0] & 0x3f, 0x20);                 // the 12 cells match (unused bits aside)
//! ```

use super::{ErrorCode, ErrorReply, Waypoints, MAX_CHUNK};
use crate::map::grid::Point;

/// Most cells in one [`super::Request::SetCells`]: 4 bytes each, so the largest such request
/// (id `u32::MAX`) stays within [`super::MAX_REQUEST`].
pub const MAX_UPDATE_CELLS: usize = 60;

/// Cell `i`'s bit (free past the end): the layout is [`crate::map::bits`]'s.
fn bit(bits: &[u8], i: u32) -> bool {
    crate::map::bits::get(bits, i as usize).unwrap_or(false)
}

/// Set cell `i`'s bit to `value` (nothing past the end).
fn put_bit(bits: &mut [u8], i: u32, value: bool) {
    crate::map::bits::set(bits, i as usize, value);
}

/// Set cells `from .. from + len` to `value`.
fn fill_bits(bits: &mut [u8], from: u32, len: u32, value: bool) {
    crate::map::bits::fill(bits, from as usize, len as usize, value);
}

/// The run-length code of a packed map (see the module docs), one byte at a time: no buffer.
#[derive(Clone, Debug)]
pub struct RleEncoder<'a> {
    bits: &'a [u8],
    cells: u32,
    pos: u32,
    value: bool,
    /// The varint being sent: its bytes and how many are left.
    pending: [u8; 5],
    at: u8,
    len: u8,
    done: bool,
}

impl<'a> RleEncoder<'a> {
    /// The code of the first `cells` cells of `bits`.
    pub fn new(bits: &'a [u8], cells: u32) -> Self {
        RleEncoder {
            bits,
            cells,
            pos: 0,
            value: false,
            pending: [0; 5],
            at: 0,
            len: 0,
            done: false,
        }
    }

    /// The code's length in bytes (runs through a copy of the encoder).
    pub fn encoded_len(bits: &[u8], cells: u32) -> usize {
        RleEncoder::new(bits, cells).count()
    }

    /// Load the next run's varint; false at the end.
    fn next_run(&mut self) -> bool {
        if self.done || (self.pos >= self.cells && self.pos > 0) {
            return false;
        }
        let mut run = 0u32;
        while self.pos < self.cells && bit(self.bits, self.pos) == self.value {
            self.pos = self.pos.saturating_add(1);
            run = run.saturating_add(1);
        }
        // An empty map is one run of 0 cells.
        if self.cells == 0 {
            self.done = true;
        }
        self.value = !self.value;
        let mut n = 0u8;
        loop {
            let b = (run & 0x7F) as u8;
            run >>= 7;
            if let Some(slot) = self.pending.get_mut(n as usize) {
                *slot = if run == 0 { b } else { b | 0x80 };
            }
            n = n.saturating_add(1);
            if run == 0 {
                break;
            }
        }
        (self.at, self.len) = (0, n);
        true
    }
}

impl Iterator for RleEncoder<'_> {
    type Item = u8;
    fn next(&mut self) -> Option<u8> {
        if self.at >= self.len && !self.next_run() {
            return None;
        }
        let b = self.pending.get(self.at as usize).copied();
        self.at = self.at.saturating_add(1);
        b
    }
}

/// Why a run-length code was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RleError {
    /// A run goes past the map's last cell, or a varint does not fit a `u32`: `at` = cells
    /// decoded before it.
    Overrun {
        /// Cells decoded before the bad run.
        at: u32,
    },
}

/// Decodes a run-length code into a packed map, fed in pieces of any size (a run or a varint
/// may span chunks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RleDecoder {
    cells: u32,
    pos: u32,
    value: bool,
    acc: u32,
    shift: u8,
}

impl RleDecoder {
    /// A decoder for a map of `cells` cells.
    pub const fn new(cells: u32) -> Self {
        RleDecoder {
            cells,
            pos: 0,
            value: false,
            acc: 0,
            shift: 0,
        }
    }

    /// Cells written so far.
    pub fn decoded(&self) -> u32 {
        self.pos
    }

    /// True when every cell is written and no varint is half read.
    pub fn is_complete(&self) -> bool {
        self.pos == self.cells && self.shift == 0
    }

    /// Decode `code` into `bits`. On an error the decoder stays failed at the same place.
    pub fn feed(&mut self, code: &[u8], bits: &mut [u8]) -> Result<(), RleError> {
        for &b in code {
            let overrun = RleError::Overrun { at: self.pos };
            let low = u32::from(b & 0x7F);
            if self.shift > 28 || (self.shift == 28 && low > 0x0F) {
                self.shift = u8::MAX;
                return Err(overrun);
            }
            self.acc |= low.wrapping_shl(u32::from(self.shift));
            if b & 0x80 != 0 {
                self.shift = self.shift.saturating_add(7);
                continue;
            }
            let run = self.acc;
            (self.acc, self.shift) = (0, 0);
            let end = self.pos.saturating_add(run);
            if end > self.cells {
                // Leave the decoder where it failed: a later chunk cannot complete it.
                self.shift = u8::MAX;
                return Err(overrun);
            }
            fill_bits(bits, self.pos, run, self.value);
            self.pos = end;
            self.value = !self.value;
        }
        Ok(())
    }
}

/// How a map upload's bytes are coded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// [`super::Request::SetMap`]: the packed bits as they are.
    Raw,
    /// [`super::Request::SetMapRle`]: the run-length code of the module docs.
    Rle,
}

/// One chunk of a map upload, as [`super::Request::SetMap`] / [`super::Request::SetMapRle`]
/// carry it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapChunk<'a> {
    /// Raw or run-length.
    pub encoding: Encoding,
    /// Columns.
    pub width: u16,
    /// Rows.
    pub height: u16,
    /// Byte offset of `chunk` in the upload's byte stream.
    pub offset: u32,
    /// Bytes of the whole stream.
    pub total_len: u32,
    /// The bytes.
    pub chunk: &'a [u8],
}

/// The largest map a device holds: by cells, not by side, so any shape fits that has at most
/// `max_cells` cells and no side over `max_side` (a 604 x 307 depot is one map of 185,428 cells).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapLimits {
    /// Most cells (`width * height`).
    pub max_cells: u32,
    /// Longest side, in cells (columns or rows).
    pub max_side: u16,
}

impl MapLimits {
    /// Bytes of a buffer that holds the largest map.
    pub const fn bytes(&self) -> usize {
        (self.max_cells as usize).div_ceil(8)
    }

    /// `MapTooLarge` if a `width x height` map does not fit: a side over `max_side` (detail = that
    /// side, width first; limit = `max_side`), else more than `max_cells` cells (detail = cells,
    /// limit = `max_cells`).
    pub fn check(&self, width: u16, height: u16) -> Result<(), ErrorReply> {
        for side in [width, height] {
            if side > self.max_side {
                let (d, m) = (side.into(), self.max_side.into());
                return Err(err(ErrorCode::MapTooLarge, d, m));
            }
        }
        let cells = u32::from(width).saturating_mul(u32::from(height));
        if cells > self.max_cells {
            return Err(err(ErrorCode::MapTooLarge, cells, self.max_cells));
        }
        Ok(())
    }
}

/// An upload in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Open {
    encoding: Encoding,
    width: u16,
    height: u16,
    total_len: u32,
    received: u32,
    rle: RleDecoder,
}

/// The device's side of map uploads: which upload is open and how far it got. The caller owns
/// the map buffer; see [`Upload::accept`] and [`Upload::write`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Upload {
    open: Option<Open>,
}

fn err(code: ErrorCode, detail: u32, limit: u32) -> ErrorReply {
    ErrorReply::with(code, detail, limit)
}

impl Upload {
    /// No upload open.
    pub const fn new() -> Self {
        Upload { open: None }
    }

    /// True while an upload is open (started, not complete, not failed).
    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Check `c` without touching the map. `Ok(true)`: it starts a new upload (offset 0, a good
    /// header and a good chunk): the caller must stop using the active map before
    /// [`Upload::write`] overwrites it. `Ok(false)`: it continues the open upload.
    ///
    /// Errors, in this order (the first that applies is the answer):
    /// 1. `TooLarge`: a chunk of 0 bytes or of more than [`MAX_CHUNK`] (detail = its length,
    ///    limit = `MAX_CHUNK`);
    /// 2. at offset 0, the header: `BadMap` for a zero side (detail = `total_len`, limit = 0: no
    ///    map has 0 cells), `MapTooLarge` for a map over the limits ([`MapLimits::check`]),
    ///    `BadMap` for a wrong `total_len` (raw: detail = `total_len`, limit = `ceil(cells / 8)`;
    ///    run-length: `total_len` 0, detail 0, limit 1);
    /// 3. `BadChunk`: no upload open (0 / 0), or a chunk that does not continue it: other sides,
    ///    `total_len` or coding, `offset` past the bytes received, the chunk past `total_len`
    ///    (detail = bytes received, limit = `total_len`; for a new upload's first chunk past its
    ///    own `total_len`: 0 / `total_len`).
    ///
    /// **A refused chunk changes nothing**: an open upload stays open exactly as it was (a good
    /// offset-0 chunk replaces it, a refused one does not), and the map is untouched.
    pub fn accept(&mut self, c: &MapChunk<'_>, limits: MapLimits) -> Result<bool, ErrorReply> {
        let len = u32::try_from(c.chunk.len()).unwrap_or(u32::MAX);
        if c.chunk.is_empty() || c.chunk.len() > MAX_CHUNK {
            return Err(err(ErrorCode::TooLarge, len, MAX_CHUNK as u32));
        }
        if c.offset == 0 {
            let cells = u32::from(c.width).saturating_mul(u32::from(c.height));
            if cells == 0 {
                return Err(err(ErrorCode::BadMap, c.total_len, 0));
            }
            limits.check(c.width, c.height)?;
            let want = cells.div_ceil(8);
            match c.encoding {
                Encoding::Raw if c.total_len != want => {
                    return Err(err(ErrorCode::BadMap, c.total_len, want))
                }
                Encoding::Rle if c.total_len == 0 => return Err(err(ErrorCode::BadMap, 0, 1)),
                _ => {}
            }
            let new = Upload {
                open: Some(Open {
                    encoding: c.encoding,
                    width: c.width,
                    height: c.height,
                    total_len: c.total_len,
                    received: 0,
                    rle: RleDecoder::new(cells),
                }),
            };
            new.fits(c, len)?;
            *self = new;
            return Ok(true);
        }
        self.fits(c, len).map(|()| false)
    }

    /// `BadChunk` unless `c` continues the open upload.
    fn fits(&self, c: &MapChunk<'_>, len: u32) -> Result<(), ErrorReply> {
        let Some(o) = self.open else {
            return Err(err(ErrorCode::BadChunk, 0, 0));
        };
        let end = c.offset.saturating_add(len);
        let same = (c.encoding, c.width, c.height, c.total_len)
            == (o.encoding, o.width, o.height, o.total_len);
        if same && c.offset <= o.received && end <= o.total_len && len > 0 {
            Ok(())
        } else {
            Err(err(ErrorCode::BadChunk, o.received, o.total_len))
        }
    }

    /// Write an accepted chunk into `bits` (the map buffer, at least `ceil(width * height / 8)`
    /// bytes). Only bytes past those received so far count (a re-sent chunk overlaps them).
    /// `Ok(Some((width, height)))` when the map is complete (the upload closes), `Ok(None)` while
    /// more is to come. A run-length code that overruns the map, or ends (at `total_len`) short
    /// of it, is `BadRle` (detail = cells decoded, limit = cells): the upload closes and the
    /// buffer holds no map. `BadChunk` if `c` was not accepted.
    pub fn write(
        &mut self,
        c: &MapChunk<'_>,
        bits: &mut [u8],
    ) -> Result<Option<(u16, u16)>, ErrorReply> {
        let len = u32::try_from(c.chunk.len()).unwrap_or(u32::MAX);
        self.fits(c, len)?;
        let Some(o) = self.open.as_mut() else {
            return Err(err(ErrorCode::BadChunk, 0, 0));
        };
        let skip = o.received.saturating_sub(c.offset) as usize;
        let new = c.chunk.get(skip..).unwrap_or(&[]);
        let cells = u32::from(o.width).saturating_mul(u32::from(o.height));
        match o.encoding {
            Encoding::Raw => {
                let at = o.received as usize;
                let slot = bits.get_mut(at..at.saturating_add(new.len())).ok_or(err(
                    ErrorCode::BadChunk,
                    o.received,
                    o.total_len,
                ))?;
                // Same length by construction; a zip has no length check that could panic.
                for (d, b) in slot.iter_mut().zip(new) {
                    *d = *b;
                }
            }
            Encoding::Rle => {
                if let Err(RleError::Overrun { at }) = o.rle.feed(new, bits) {
                    self.open = None;
                    return Err(err(ErrorCode::BadRle, at, cells));
                }
            }
        }
        o.received = o
            .received
            .saturating_add(u32::try_from(new.len()).unwrap_or(u32::MAX));
        if o.received < o.total_len {
            return Ok(None);
        }
        let (w, h, rle) = (o.width, o.height, o.rle);
        self.open = None;
        if c.encoding == Encoding::Rle && !rle.is_complete() {
            return Err(err(ErrorCode::BadRle, rle.decoded(), cells));
        }
        Ok(Some((w, h)))
    }

    /// Drop the open upload (the buffer then holds no map until a new one completes).
    pub fn abort(&mut self) {
        self.open = None;
    }
}

/// Check a [`super::Request::SetRect`] against a `width x height` map: `OutsideMap` (detail = x,
/// limit = y of the first cell outside: the origin, else the far corner `(x + w - 1, y + h - 1)`,
/// saturating) unless the rectangle lies inside. A rectangle with a zero side changes nothing and
/// passes if its origin is inside.
pub fn check_rect(map: (u16, u16), x: u16, y: u16, w: u16, h: u16) -> Result<(), ErrorReply> {
    let (mw, mh) = map;
    if x >= mw || y >= mh {
        return Err(err(ErrorCode::OutsideMap, x.into(), y.into()));
    }
    let fx = u32::from(x).saturating_add(u32::from(w)).saturating_sub(1);
    let fy = u32::from(y).saturating_add(u32::from(h)).saturating_sub(1);
    if fx >= u32::from(mw) || fy >= u32::from(mh) {
        return Err(err(ErrorCode::OutsideMap, fx, fy));
    }
    Ok(())
}

/// Set (`blocked`) or clear every cell of the rectangle; [`check_rect`] first (nothing changes
/// when it fails).
pub fn set_rect(
    map: (u16, u16),
    bits: &mut [u8],
    (x, y, w, h): (u16, u16, u16, u16),
    blocked: bool,
) -> Result<(), ErrorReply> {
    check_rect(map, x, y, w, h)?;
    let mw = u32::from(map.0);
    for row in u32::from(y)..u32::from(y).saturating_add(u32::from(h)) {
        let from = row.saturating_mul(mw).saturating_add(u32::from(x));
        fill_bits(bits, from, u32::from(w), blocked);
    }
    Ok(())
}

/// Check a [`super::Request::SetCells`] list: `TooLarge` (detail = count, limit =
/// [`MAX_UPDATE_CELLS`]) if it is too long, `OutsideMap` (detail = x, limit = y) at the first
/// cell outside the map. An empty list passes.
pub fn check_cells(map: (u16, u16), cells: &Waypoints<'_>) -> Result<(), ErrorReply> {
    if cells.len() > MAX_UPDATE_CELLS {
        let n = u32::try_from(cells.len()).unwrap_or(u32::MAX);
        return Err(err(ErrorCode::TooLarge, n, MAX_UPDATE_CELLS as u32));
    }
    match cells.iter().find(|p| p.x >= map.0 || p.y >= map.1) {
        Some(p) => Err(err(ErrorCode::OutsideMap, p.x.into(), p.y.into())),
        None => Ok(()),
    }
}

/// Set (`blocked`) or clear every cell of the list; [`check_cells`] first (nothing changes when
/// it fails).
pub fn set_cells(
    map: (u16, u16),
    bits: &mut [u8],
    cells: &Waypoints<'_>,
    blocked: bool,
) -> Result<(), ErrorReply> {
    check_cells(map, cells)?;
    for Point { x, y } in cells.iter() {
        let i = u32::from(y)
            .saturating_mul(u32::from(map.0))
            .saturating_add(u32::from(x));
        put_bit(bits, i, blocked);
    }
    Ok(())
}
