//! The smoothing's links over a raw path ([`PathLinks`]): for each position `j` of the path, the
//! position the shortest way to it comes from, in words a workspace lends (the links or the tabu
//! set, `planner::lend`).
//!
//! **What it owns.** A borrow of the words, one a path position. The DP
//! ([`crate::polish::smoothing`]) links each position to an earlier one ([`PathLinks::link`]),
//! reads them back ([`PathLinks::from`]), and at the end turns the chain from the goal into
//! forward links ([`PathLinks::reverse`], [`PathLinks::next`]). Those are its only operations,
//! so no caller reads a lent buffer's words as positions by hand.
//!
//! **Guarantees.** A position beyond the words has no link (reads `None`, writes are ignored):
//! the smoothing asks for links of the path's length ([`PathLinks::holds`]) and takes its
//! greedy rule without them. No panic.

/// No link (the end of the forward chain).
const END: u32 = u32::MAX;

/// The smoothing's links over a raw path, one word a position (see the module docs).
#[derive(Debug)]
pub struct PathLinks<'a> {
    words: &'a mut [u32],
}

impl<'a> PathLinks<'a> {
    /// The links over `words` (as many positions as words).
    #[inline]
    pub fn new(words: &'a mut [u32]) -> Self {
        Self { words }
    }

    /// The same links, borrowed for a shorter time.
    #[inline]
    pub fn reborrow(&mut self) -> PathLinks<'_> {
        PathLinks { words: self.words }
    }

    /// Whether it links a path of `n` positions.
    #[inline]
    pub fn holds(&self, n: usize) -> bool {
        self.words.len() >= n
    }

    /// Positions it links.
    #[inline]
    pub fn len(&self) -> usize {
        self.words.len()
    }

    /// Whether it links no position.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }

    /// Link position `j` to the earlier position `from` (ignored beyond the words).
    #[inline]
    pub fn link(&mut self, j: usize, from: usize) {
        if let Some(w) = self.words.get_mut(j) {
            *w = from as u32;
        }
    }

    /// The position `j` is linked from (`None` beyond the words).
    #[inline]
    pub fn from(&self, j: usize) -> Option<usize> {
        self.words.get(j).map(|&w| w as usize)
    }

    /// Turn the chain of links from `last` back to position 0 into forward links: afterwards
    /// [`PathLinks::next`] follows it from 0 to `last`.
    pub fn reverse(&mut self, last: usize) {
        let mut cur = last;
        let mut next = END;
        while let Some(slot) = self.words.get_mut(cur) {
            let p = *slot as usize;
            *slot = next;
            next = cur as u32;
            if cur == 0 {
                break;
            }
            cur = p;
        }
    }

    /// After [`PathLinks::reverse`]: the position after `i` on the chain (`None` at its end).
    #[inline]
    pub fn next(&self, i: usize) -> Option<usize> {
        match self.words.get(i) {
            Some(&nx) if nx != END => Some(nx as usize),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::PathLinks;

    #[test]
    fn links_beyond_the_words_are_refused_and_a_chain_reverses() {
        let mut words = [0u32; 5];
        let mut l = PathLinks::new(&mut words);
        // 0 <- 1 <- 3 <- 4 (2 is off the chain).
        for (j, from) in [(0, 0), (1, 0), (2, 1), (3, 1), (4, 3)] {
            l.link(j, from);
        }
        assert!(l.holds(5) && !l.holds(6));
        l.link(5, 2);
        assert_eq!(l.from(5), None);
        assert_eq!(l.from(4), Some(3));
        l.reverse(4);
        let mut chain = vec![0];
        while let Some(n) = l.next(*chain.last().unwrap()) {
            chain.push(n);
        }
        assert_eq!(chain, [0, 1, 3, 4]);
        assert_eq!(words[2], 1, "off the chain: left as it was");
    }
}
