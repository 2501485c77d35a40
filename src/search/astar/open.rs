//! The exact A*'s open list: its entries ([`Entry`], 12 bytes, plain old data so a caller can
//! carve the list out of any word buffer) and their order (smaller `f`, then larger `g`), over
//! the crate's one binary heap ([`crate::search::heap`]), with the counts the search reports
//! (pushes, peak). A full list is [`AstarError::HeapFull`], never a panic.

use crate::search::heap::{Full, Heap, Keyed};

use super::AstarError;

/// One open-list entry: `!g` (so that a larger `g` ranks first), `f = g + h`, and the cell
/// (index `key >> 3`) with the direction it was reached by (`key & 7`), all in cost units. Plain
/// old data (`bytemuck::Pod`), so a caller can carve the open list out of a byte or word buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Entry {
    pub(super) ng: u32,
    pub(super) f: u32,
    pub(super) key: u32,
}

impl Entry {
    /// An entry to fill caller arrays with (`[Entry::EMPTY; N]`).
    pub const EMPTY: Entry = Entry {
        ng: 0,
        f: 0,
        key: 0,
    };
    /// Ranks after every real entry: "no entry".
    pub(super) const NONE: Entry = Entry {
        ng: u32::MAX,
        f: u32::MAX,
        key: 0,
    };

    /// The heap's order: smaller first (`f`, then larger `g`).
    #[inline(always)]
    pub(super) fn rank(&self) -> u64 {
        (u64::from(self.f) << 32) | u64::from(self.ng)
    }

    /// The entry's `g`.
    #[inline(always)]
    pub(super) fn g(&self) -> u32 {
        !self.ng
    }
}

impl Keyed for Entry {
    type Key = u64;
    #[inline(always)]
    fn key(&self) -> u64 {
        self.rank()
    }
}

/// The open list: the crate's binary min-heap ([`super::heap`]) of entries over the caller's
/// slice, and what the search reports of it.
pub(super) struct Open<'h> {
    pub(super) heap: Heap<'h, Entry>,
    pub(super) peak: usize,
    pub(super) pushes: u32,
}

impl Open<'_> {
    #[inline(never)]
    pub(super) fn push(&mut self, e: Entry) -> Result<(), AstarError> {
        self.heap
            .push(e)
            .map_err(|Full { capacity }| AstarError::HeapFull { capacity })?;
        if self.heap.len() > self.peak {
            self.peak = self.heap.len();
        }
        self.pushes = self.pushes.wrapping_add(1);
        Ok(())
    }

    /// The top entry ([`Entry::NONE`] if the heap is empty).
    #[inline(always)]
    pub(super) fn top(&self) -> Entry {
        self.heap.top().unwrap_or(Entry::NONE)
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<Entry> {
        self.heap.pop()
    }

    /// Pop the top and push `e` in one sift (the heap must not be empty).
    #[inline(always)]
    pub(super) fn replace_top(&mut self, e: Entry) -> Entry {
        self.pushes = self.pushes.wrapping_add(1);
        self.heap.replace_top(e).unwrap_or(Entry::NONE)
    }
}
