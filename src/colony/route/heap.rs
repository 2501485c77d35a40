//! The route search's heap over lent words ([`RouteHeap`]): what a workspace lends the coarse
//! route's search (the links, the tabu set or a half of one, `planner::lend`), as its own type.
//!
//! **What it owns.** A borrow of the words, a word a block: each holds a block of the heap's
//! slot in its low half and, in its high half, the slot of the block of its own index (0: never
//! queued, `u16::MAX`: closed). Only the search ([`super::search`]) reads and writes them;
//! everyone else hands the view on, so no other code does word arithmetic on a buffer lent as the
//! heap, and a buffer of another role is never read as one.
//!
//! **Guarantees.** A heap shorter than the blocks is refused before the search starts
//! ([`RouteHeap::cut`], the route's [`super::Short`]); the search's accesses are bounds-checked
//! besides. No panic.

/// The coarse route search's heap over lent words, a word a block (see the module docs).
#[derive(Debug)]
pub struct RouteHeap<'a> {
    words: &'a mut [u32],
}

impl<'a> RouteHeap<'a> {
    /// The heap over `words` (as many blocks as words).
    #[inline]
    pub fn new(words: &'a mut [u32]) -> Self {
        Self { words }
    }

    /// Blocks it can hold.
    #[inline]
    pub fn blocks(&self) -> usize {
        self.words.len()
    }

    /// The heap of `blocks` blocks in its first words; `None` (refused) when it holds fewer.
    #[inline]
    pub fn cut(&mut self, blocks: usize) -> Option<RouteHeap<'_>> {
        Some(RouteHeap {
            words: self.words.get_mut(..blocks)?,
        })
    }

    /// Empty: no block queued or closed (a pass over the words).
    #[inline]
    pub(super) fn clear(&mut self) {
        self.words.fill(0);
    }

    /// The words, to the search's own layout ([`super::search`]).
    #[inline]
    pub(super) fn words(&mut self) -> &mut [u32] {
        self.words
    }

    /// Whether block `b` is closed (its key final), for the tests' checks.
    #[cfg(test)]
    pub(super) fn closed(&self, b: usize) -> bool {
        self.words.get(b).is_some_and(|&w| w >> 16 == 0xFFFF)
    }
}

#[cfg(test)]
mod tests {
    use super::RouteHeap;

    #[test]
    fn a_heap_shorter_than_the_blocks_is_refused() {
        let mut words = [7u32; 5];
        assert!(RouteHeap::new(&mut words).cut(6).is_none());
        let mut heap = RouteHeap::new(&mut words);
        assert_eq!(heap.blocks(), 5);
        let mut cut = heap.cut(4).expect("four of five");
        assert_eq!(cut.blocks(), 4);
        cut.clear();
        assert!(!cut.closed(0));
        // Only its blocks' words are written.
        assert_eq!(words, [0, 0, 0, 0, 7]);
    }
}
