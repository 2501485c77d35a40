//! The one binary min-heap of the crate: the open lists of the exact A* ([`super::astar`]), the
//! coarse route's block search (`colony::route::search`), the refine window's A*
//! (`polish::refine::window`) and the host's D* Lite.
//!
//! **What it owns.** The heap's order and nothing else: which slot holds which item while an
//! item goes up or down (slot 0 is the root, the children of slot `i` are `2 i + 1` and
//! `2 i + 2`). The slots, the items, the key and its ties are the caller's, through [`Slots`]:
//! a slice of items ordered by a key ([`ByKey`], under the plain value heap [`Heap`]), or a
//! caller's own layout, such as an indexed heap that records each item's slot in
//! [`Slots::put`] (decrease-key in place) or keeps its keys in another table. The number of live
//! slots is the [`Slots`]' too: [`Slots::at`] is `None` past the heap's end.
//!
//! **Ties.** The steps compare in a fixed sequence, stated on each function, and an item moves
//! only past one that it comes strictly [`Slots::before`]. So, for an order that is not total
//! (equal keys), the items leave in the same order on every platform and on every build: the
//! searches' paths depend on it bit for bit.
//!
//! **Guarantees.** No allocation and no panic: every slot access goes through [`Slots`] (the
//! slice implementations use `get`), and slot arithmetic stays below twice the number of
//! slots, far from `usize::MAX`. A push into a full [`Heap`] is an error value ([`Full`]).

/// The slots of a binary min-heap, as the caller lays them out, and its order.
pub trait Slots {
    /// What a slot holds (a value, or an index into the caller's key tables).
    type Item: Copy;
    /// The item in `slot`, or `None` past the heap's last live slot.
    fn at(&self, slot: usize) -> Option<Self::Item>;
    /// Put `item` in `slot` (an indexed heap also records the item's slot here).
    fn put(&mut self, slot: usize, item: Self::Item);
    /// Whether `a` leaves the heap before `b` (a strict order: false for equal keys).
    fn before(&self, a: Self::Item, b: Self::Item) -> bool;
    /// The two siblings in slots `c` and `c + 1`, both live (a layout may read them at once).
    #[inline(always)]
    fn pair(&self, c: usize) -> Option<(Self::Item, Self::Item)> {
        Some((self.at(c)?, self.at(c.wrapping_add(1))?))
    }
}

/// Put `item` into the hole at `hole`, moving it up past every parent it comes strictly before;
/// returns the slot it ends in.
#[inline(always)]
pub fn sift_up<S: Slots + ?Sized>(s: &mut S, mut hole: usize, item: S::Item) -> usize {
    while hole > 0 {
        let parent = hole.wrapping_sub(1) >> 1;
        let Some(p) = s.at(parent) else { break };
        if !s.before(item, p) {
            break;
        }
        s.put(hole, p);
        hole = parent;
    }
    s.put(hole, item);
    hole
}

/// Put `item` into the hole at `hole`, moving it down: at each level the right child is taken
/// only if it comes strictly before the left one, and moves up only if it comes strictly before
/// `item`.
#[inline]
pub fn sift_down<S: Slots + ?Sized>(s: &mut S, mut hole: usize, item: S::Item) {
    loop {
        let c = hole.wrapping_mul(2).wrapping_add(1);
        let Some(left) = s.at(c) else { break };
        let (c, child) = match s.at(c.wrapping_add(1)) {
            Some(right) if s.before(right, left) => (c.wrapping_add(1), right),
            _ => (c, left),
        };
        if !s.before(child, item) {
            break;
        }
        s.put(hole, child);
        hole = c;
    }
    s.put(hole, item);
}

/// Fill the root's hole with `item` (a pop's last item, or a replacement of the top): walk the
/// hole down to a leaf along the children that come first (the right one only if it comes
/// strictly before the left; one comparison a level), then [`sift_up`] `item` from there
/// (usually a step or none). Out of line, so that a search loop keeps its registers.
#[inline(never)]
pub fn settle<S: Slots + ?Sized>(s: &mut S, item: S::Item) {
    let mut hole = 0usize;
    let mut c = 1usize;
    while let Some((left, right)) = s.pair(c) {
        let (child, cs) = if s.before(right, left) {
            (right, c.wrapping_add(1))
        } else {
            (left, c)
        };
        s.put(hole, child);
        hole = cs;
        c = cs.wrapping_mul(2).wrapping_add(1);
    }
    // A last, lone left child.
    if let Some(left) = s.at(c) {
        s.put(hole, left);
        hole = c;
    }
    sift_up(s, hole, item);
}

/// An item that carries its own key: what [`Heap`] orders by.
pub trait Keyed: Copy {
    /// The key: smaller leaves first.
    type Key: Ord + Copy;
    /// The item's key.
    fn key(&self) -> Self::Key;
}

/// A slice of [`Keyed`] items as heap slots, every one of them live.
pub struct ByKey<'a, T>(pub &'a mut [T]);

impl<T: Keyed> Slots for ByKey<'_, T> {
    type Item = T;
    #[inline(always)]
    fn at(&self, slot: usize) -> Option<T> {
        self.0.get(slot).copied()
    }
    #[inline(always)]
    fn put(&mut self, slot: usize, item: T) {
        if let Some(s) = self.0.get_mut(slot) {
            *s = item;
        }
    }
    #[inline(always)]
    fn before(&self, a: T, b: T) -> bool {
        a.key() < b.key()
    }
    #[inline(always)]
    fn pair(&self, c: usize) -> Option<(T, T)> {
        match self.0.get(c..c.wrapping_add(2)) {
            Some(&[l, r]) => Some((l, r)),
            _ => None,
        }
    }
}

/// A push into a full [`Heap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Full {
    /// Items the heap's slice holds.
    pub capacity: usize,
}

impl core::fmt::Display for Full {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "heap full at {} items", self.capacity)
    }
}

/// A binary min-heap of [`Keyed`] values over the caller's slice (its capacity).
pub struct Heap<'a, T> {
    slots: &'a mut [T],
    len: usize,
}

impl<'a, T: Keyed> Heap<'a, T> {
    /// An empty heap over `slots`.
    pub fn new(slots: &'a mut [T]) -> Self {
        Heap { slots, len: 0 }
    }

    /// Items held.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if the heap holds nothing.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Items the slice holds.
    pub fn capacity(&self) -> usize {
        self.slots.len()
    }

    /// The first item, if any.
    #[inline(always)]
    pub fn top(&self) -> Option<T> {
        match self.slots.first() {
            Some(&t) if self.len > 0 => Some(t),
            _ => None,
        }
    }

    /// Add `item` ([`sift_up`] from the new last slot). Inlined: a search that wants it out of
    /// line (its loop's registers) wraps it in a function of its own.
    #[inline(always)]
    pub fn push(&mut self, item: T) -> Result<(), Full> {
        let len = self.len;
        // `len <= slots.len()` always, so `len + 1` cannot wrap.
        let Some(live) = self.slots.get_mut(..len.wrapping_add(1)) else {
            return Err(Full {
                capacity: self.slots.len(),
            });
        };
        self.len = len.wrapping_add(1);
        sift_up(&mut ByKey(live), len, item);
        Ok(())
    }

    /// Take the first item out (the last one [`settle`]s into the root's hole).
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        let n = self.len.checked_sub(1)?;
        // `n < len <= slots.len()`: the split never fails.
        let (&mut last, live) = self.slots.get_mut(..=n)?.split_last_mut()?;
        // The root, or the last item itself when it was the only one.
        let top = live.first().copied().unwrap_or(last);
        self.len = n;
        settle(&mut ByKey(live), last);
        Some(top)
    }

    /// Take the first item out and add `item` in one [`settle`] (`None`, and nothing added, if
    /// the heap is empty).
    #[inline(always)]
    pub fn replace_top(&mut self, item: T) -> Option<T> {
        let top = self.top()?;
        if let Some(live) = self.slots.get_mut(..self.len) {
            settle(&mut ByKey(live), item);
        }
        Some(top)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value with a key and a tag that the order does not see (to watch ties).
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    struct Item {
        key: u8,
        tag: u16,
    }

    impl Keyed for Item {
        type Key = u8;
        fn key(&self) -> u8 {
            self.key
        }
    }

    fn next(x: &mut u32) -> u32 {
        *x ^= *x << 13;
        *x ^= *x >> 17;
        *x ^= *x << 5;
        *x
    }

    #[test]
    fn pops_in_key_order_and_a_full_heap_says_so() {
        let mut x = 0x9E37_79B9u32;
        for round in 0..300 {
            let cap = 1 + next(&mut x) as usize % 64;
            let mut slots = vec![Item { key: 0, tag: 0 }; cap];
            let mut heap = Heap::new(&mut slots);
            let mut model: Vec<u8> = Vec::new();
            for step in 0..400u16 {
                match next(&mut x) % 5 {
                    0 | 1 => {
                        let it = Item {
                            key: (next(&mut x) % 8) as u8,
                            tag: step,
                        };
                        let r = heap.push(it);
                        if model.len() < cap {
                            assert_eq!(r, Ok(()));
                            model.push(it.key);
                        } else {
                            assert_eq!(r, Err(Full { capacity: cap }), "round {round}");
                        }
                    }
                    2 => {
                        let it = Item {
                            key: (next(&mut x) % 8) as u8,
                            tag: step,
                        };
                        let got = heap.replace_top(it).map(|t| t.key);
                        model.sort_unstable();
                        assert_eq!(got, model.first().copied(), "round {round}");
                        if !model.is_empty() {
                            model[0] = it.key;
                        }
                    }
                    _ => {
                        model.sort_unstable();
                        let want = (!model.is_empty()).then(|| model.remove(0));
                        assert_eq!(heap.pop().map(|t| t.key), want, "round {round}");
                    }
                }
                assert_eq!(heap.len(), model.len());
            }
        }
    }

    /// The order among equal keys is the rule's: pushes and pops of a fixed sequence leave the
    /// tags in exactly this order. Taking the right child on a tie (`!before(left, right)`), or
    /// moving an item past an equal parent, fails here.
    #[test]
    fn ties_leave_in_the_fixed_order() {
        let mut slots = [Item { key: 0, tag: 0 }; 16];
        let mut heap = Heap::new(&mut slots);
        let keys = [3u8, 1, 1, 2, 1, 3, 2, 1, 2, 3, 1, 2];
        for (tag, &key) in keys.iter().enumerate() {
            heap.push(Item {
                key,
                tag: tag as u16,
            })
            .unwrap();
        }
        let mut tags = Vec::new();
        while let Some(t) = heap.pop() {
            tags.push(t.tag);
        }
        assert_eq!(tags, [1, 4, 7, 10, 2, 8, 3, 6, 11, 0, 5, 9]);
    }

    /// An indexed heap as the searches lay one out: items are indices into a key table, each
    /// one's slot recorded in `pos`; a decreased key moves up with [`sift_up`] from its slot,
    /// an increased one down with [`sift_down`].
    struct Indexed<'a> {
        heap: &'a mut [u16],
        len: usize,
        pos: &'a mut [usize],
        keys: &'a [u32],
    }

    impl Slots for Indexed<'_> {
        type Item = u16;
        fn at(&self, slot: usize) -> Option<u16> {
            if slot < self.len {
                self.heap.get(slot).copied()
            } else {
                None
            }
        }
        fn put(&mut self, slot: usize, i: u16) {
            self.heap[slot] = i;
            self.pos[usize::from(i)] = slot;
        }
        fn before(&self, a: u16, b: u16) -> bool {
            (self.keys[usize::from(a)], a) < (self.keys[usize::from(b)], b)
        }
    }

    #[test]
    fn an_indexed_heap_keeps_positions_through_updates() {
        let mut x = 0x1234_5678u32;
        for _ in 0..100 {
            let n = 1 + next(&mut x) as usize % 100;
            let mut keys: Vec<u32> = (0..n).map(|_| next(&mut x) % 50).collect();
            let mut heap = vec![0u16; n];
            let mut pos = vec![0usize; n];
            let mut len = 0;
            for i in 0..n {
                let mut h = Indexed {
                    heap: &mut heap,
                    len: len + 1,
                    pos: &mut pos,
                    keys: &keys,
                };
                sift_up(&mut h, len, i as u16);
                len += 1;
            }
            for _ in 0..n {
                let i = next(&mut x) as usize % n;
                let old = keys[i];
                keys[i] = next(&mut x) % 50;
                let at = pos[i];
                let mut h = Indexed {
                    heap: &mut heap,
                    len,
                    pos: &mut pos,
                    keys: &keys,
                };
                if keys[i] < old {
                    sift_up(&mut h, at, i as u16);
                } else {
                    sift_down(&mut h, at, i as u16);
                }
            }
            let mut want: Vec<(u32, u16)> = (0..n).map(|i| (keys[i], i as u16)).collect();
            want.sort_unstable();
            for &(_, i) in &want {
                let mut h = Indexed {
                    heap: &mut heap,
                    len,
                    pos: &mut pos,
                    keys: &keys,
                };
                assert_eq!(h.at(0), Some(i));
                assert_eq!(h.pos[usize::from(i)], 0);
                len -= 1;
                let last = h.heap[len];
                h.len = len;
                if len > 0 {
                    sift_down(&mut h, 0, last);
                }
            }
        }
    }
}
