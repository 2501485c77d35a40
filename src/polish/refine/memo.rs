//! The windows a refinement has searched, so that a later window asking the same question is
//! answered without a search.
//!
//! **What it owns.** A record per searched window, in words the caller lends (the planner lends
//! the front of its pheromone increments, idle between the last iteration and the smoothing):
//! the window's two ends, its box and the exact cost the search found. A ring: when it is full
//! the oldest record goes.
//!
//! **What it guarantees (the proof that a skipped window is a window that could not improve).**
//! A window's search ([`super::window::search`]) is a function of the map, the box and the two
//! ends only: it starts from cleared scratch, reads the map inside the box, and returns the exact
//! shortest cost between the ends inside the box (integer costs, a total order on the open list:
//! `super`'s module docs). The map does not change during a refinement. So a window whose ends
//! and box equal a record's would find the record's cost; it replaces its piece only when that
//! cost is below the piece's own (`cost < old`). When it is not, the window keeps its piece and
//! commits exactly as the searched window would have: the refined path is the same, bit for bit,
//! with or without the memo (`a_memo_changes_no_path`, which fails when the key leaves out the
//! box or an end). Only the search is skipped, never a decision. A window whose record says it
//! would improve is searched (the path is read back from the search's scratch).
//!
//! Where it pays: every pass after the first repeats the windows of the last pass that landed
//! on the same ends and box, and a pass that changes nothing is what ends the refinement
//! (measured in `docs/ALGORITHM.md`, "Local search").
//!
//! Panic-free: every index is checked; a memo too short for one record remembers nothing.

use crate::map::grid::Point;

use super::window::Box2;

/// Words a record takes: the two ends, the box's corner, its size, the cost.
pub const RECORD_WORDS: usize = 5;
/// Words before the first record: the next slot of the ring and the records held.
const HEADER: usize = 2;

/// Words a memo of `records` records takes.
pub const fn words(records: usize) -> usize {
    records.saturating_mul(RECORD_WORDS).saturating_add(HEADER)
}

/// A search's question: its ends and its box, packed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Key([u32; RECORD_WORDS - 1]);

/// A cell as one word (`x` low, `y` high).
fn pack(x: u16, y: u16) -> u32 {
    u32::from(x) | (u32::from(y) << 16)
}

impl Key {
    pub(super) fn new(from: Point, to: Point, bbox: &Box2) -> Self {
        // Box sides are at most `MAX_SIDE` = 255: they fit 16 bits.
        let side = |v: usize| u16::try_from(v).unwrap_or(u16::MAX);
        Key([
            pack(from.x, from.y),
            pack(to.x, to.y),
            pack(bbox.x0, bbox.y0),
            pack(side(bbox.w), side(bbox.h)),
        ])
    }
}

/// The records, over lent words (see the module docs).
#[derive(Debug)]
pub struct Memo<'a> {
    words: &'a mut [u32],
}

impl<'a> Memo<'a> {
    /// An empty memo over `words` (its contents do not matter).
    pub fn clear(words: &'a mut [u32]) -> Self {
        for w in words.iter_mut().take(HEADER) {
            *w = 0;
        }
        Memo { words }
    }

    /// The memo [`Memo::clear`] started in `words`, with every record since (words written by
    /// anything else in between make it a memo of wrong answers: the caller lends the same
    /// words, untouched, for one refinement).
    pub fn reopen(words: &'a mut [u32]) -> Self {
        Memo { words }
    }

    /// Records it can hold.
    pub fn capacity(&self) -> usize {
        self.words.len().saturating_sub(HEADER) / RECORD_WORDS
    }

    fn header(&self) -> (usize, usize) {
        let at = |i: usize| self.words.get(i).map_or(0, |&w| w as usize);
        (at(0), at(1))
    }

    /// The cost a search with this key found, if remembered.
    pub(super) fn find(&self, key: Key) -> Option<u32> {
        let (_, held) = self.header();
        let records = self.words.get(HEADER..).unwrap_or_default();
        records
            .chunks_exact(RECORD_WORDS)
            .take(held)
            .find(|r| r.get(..RECORD_WORDS - 1) == Some(&key.0[..]))
            .and_then(|r| r.last().copied())
    }

    /// Remember that a search with this key found `cost`.
    pub(super) fn put(&mut self, key: Key, cost: u32) {
        let cap = self.capacity();
        if cap == 0 {
            return;
        }
        let (next, held) = self.header();
        let slot = next.min(cap.saturating_sub(1));
        let at = HEADER.saturating_add(slot.saturating_mul(RECORD_WORDS));
        if let Some(r) = self.words.get_mut(at..at.saturating_add(RECORD_WORDS)) {
            for (w, &k) in r
                .iter_mut()
                .zip(key.0.iter().chain(core::iter::once(&cost)))
            {
                *w = k;
            }
        }
        let next = if slot.saturating_add(1) >= cap {
            0
        } else {
            slot.saturating_add(1)
        };
        // Both below the capacity, which is below the slice's length: they fit a word.
        if let Some(w) = self.words.get_mut(0) {
            *w = next as u32;
        }
        if let Some(w) = self.words.get_mut(1) {
            *w = held.saturating_add(1).min(cap) as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(i: u16) -> Key {
        let b = Box2 {
            x0: i,
            y0: 1,
            w: 10,
            h: 12,
        };
        Key::new(Point::new(i, 2), Point::new(3, i), &b)
    }

    #[test]
    fn remembers_until_the_ring_wraps() {
        let mut words = [7u32; words(3)];
        let mut m = Memo::clear(&mut words);
        assert_eq!(m.capacity(), 3);
        assert_eq!(m.find(key(1)), None);
        for i in 1..=3 {
            m.put(key(i), u32::from(i) * 100);
        }
        assert_eq!(m.find(key(2)), Some(200));
        m.put(key(4), 400); // overwrites the oldest, key(1)
        assert_eq!(m.find(key(1)), None);
        assert_eq!(m.find(key(4)), Some(400));
        assert_eq!(m.find(key(3)), Some(300));
        let m = Memo::reopen(&mut words);
        assert_eq!(m.find(key(3)), Some(300));
    }

    #[test]
    fn too_short_remembers_nothing() {
        let mut words = [0u32; 4];
        let mut m = Memo::clear(&mut words);
        m.put(key(1), 5);
        assert_eq!(m.find(key(1)), None);
        let mut m = Memo::clear(&mut []);
        m.put(key(1), 5);
        assert_eq!(m.find(key(1)), None);
    }
}
