//! What each phase of a run borrows: one typed view of the workspace per phase, and the one
//! place where a buffer idle in that phase takes a second role, so two phases never write the
//! same words unknowingly.
//!
//! | view | phase | owns | borrows idle |
//! | --- | --- | --- | --- |
//! | [`Setting`] | setup (before the first ant) | the pruning marks, the coarse route ([`Guide`]) | [`Idle`]: the tabu set, the links, the path cells' words |
//! | [`Colony`] | the iterations | the pheromone and its increments, the tabu set, the tours; reads the marks, the moves and the route | tightening's index: the path cells and the links |
//! | [`Polishing`] | after the last iteration, and a reused answer's repair | the answer (best tour, path cells), the increments (distances, the route's stash) | [`Spent`]: the tabu set, the links, the route's words once stashed |
//!
//! Between plans a workspace keeps the pheromone, the answer (best tour and path cells, which
//! the firmware sends in parts and a replan reuses, [`super::Placed`]) and, for a warm start,
//! the pruning marks and the route's stashed links ([`super::Memory`]); everything else is
//! scratch. The route's two forms are two variants of [`Guide`], so a packed route can be
//! neither repaired nor stashed (there is no word a block to read), by type.
//!
//! Which buffer lends what:
//!
//! | phase | needs | lent from, in order of preference |
//! | --- | --- | --- |
//! | setup: the coarse route, full words (a [`route::Route::new`] workspace) | a heap of a word a block | the links, else the tabu bit set (free until the first ant) |
//! | setup: the coarse route, packed ([`route::pack`], the compact arena) | the route's words and its heap, a word a block each | the tabu bit set halved, else the tabu set and the links, else the links halved |
//! | colony: tightening ([`crate::colony::tighten`]) | a cell -> position index | the links (a per-cell array or a hash table), else the links and the path cells' words together (packed keys) |
//! | polish: the local search ([`crate::polish::refine`]) | two slices of [`super::run::REFINE_WORDS`] | the links and the route's words, the links and the tabu set, the tabu set and the route's words, the tabu set halved, the links halved |
//! | polish: the local search's memo ([`crate::polish::refine::Memo`]) | [`MEMO_RECORDS`] records | the front of the pheromone increments (the smoothing's ring later, the route's stash at the far end) |
//! | polish: the smoothing ([`crate::polish::smoothing`]) | `n` links for its shortest-path rule (fewer: the greedy rule) | the links, else the tabu set (free after the last ant and the local search) |
//! | a reused answer's repair ([`super::repair`]): the detour | two slices, as many words as it can get (its box is sized by what blocks the answer, up to what the slices hold; no memo) | the pair of the links, the route's words and the tabu set, or one of them halved, whose shorter slice is longest (the first such in that order on a tie) |
//! | a reused answer's repair: the smoothing | `n` links, as in the polish | as in the polish |
//!
//! Every choice depends only on the buffers' lengths (never on their contents or addresses), so
//! a host that lays out a device's arena plans exactly what the device plans, and a choice made
//! at the start of a phase is the same at each of its pieces. None of these buffers is kept
//! between runs except the answer's (`best`, `points`) and the pheromone: the tabu set, the links
//! and the route's words are scratch once the colony is done ([`super::Memory`] keeps nothing of
//! them, or stashes what it keeps in the pheromone increments first).

#[cfg(doc)]
use crate::colony::route;
use crate::map::grid::{Dir, Point};

pub(super) use super::workspace::Guide;
use super::workspace::Workspace;

/// Two slices of scratch words.
type Pair<'g> = (&'g mut [u32], &'g mut [u32]);

/// Windows the local search's memo remembers ([`crate::polish::refine::Memo`]): more than a pass
/// searches on the large maps' longest paths (at most 23 on `maze-128-128-2`'s 1,380 cells).
pub(super) const MEMO_RECORDS: usize = 32;

/// The local search's memo: the front of the pheromone increments, idle from the last ant to the
/// smoothing, before the `tail` words at their end (the route's stash). Empty when the increments
/// cannot hold [`MEMO_RECORDS`] records besides the tail (the search then runs without it).
pub(super) fn memo(delta: &mut [[f32; 4]], tail: usize) -> &mut [u32] {
    let words: &mut [u32] =
        bytemuck::try_cast_slice_mut(delta.as_flattened_mut()).unwrap_or_default();
    let want = crate::polish::refine::memo_words(MEMO_RECORDS);
    if words.len() >= want.saturating_add(tail) {
        words.get_mut(..want).unwrap_or_default()
    } else {
        &mut []
    }
}

/// What the setup borrows before the first ant: what it makes (the pruning marks, the coarse
/// route) and the buffers idle until the first ant that it makes them with.
pub(super) struct Setting<'w> {
    /// The pruning marks it writes.
    pub(super) dead: &'w mut [u32],
    /// The move table (empty: computed on the fly).
    pub(super) moves: &'w [u8],
    /// The coarse route it writes.
    pub(super) guide: Guide<'w>,
    /// Idle until the first ant.
    pub(super) idle: Idle<'w>,
}

/// The buffers idle before the first ant, lent to the setup by what it asks for.
pub(super) struct Idle<'w> {
    tabu: &'w mut [u32],
    links: &'w mut [u32],
    /// The path cells' words (empty when they are not word-aligned).
    cells: &'w mut [u32],
}

impl Idle<'_> {
    /// The flood fill's visited set and ring.
    pub(super) fn reach(&mut self) -> (&mut [u32], &mut [u32]) {
        (self.tabu, self.links)
    }

    /// The pruning's stack.
    pub(super) fn prune_stack(&mut self) -> &mut [u32] {
        self.links
    }

    /// A word-a-block route of `count` blocks: the words to write and the heap (the links if
    /// they hold `count` words, else the tabu set); `None` for a packed route.
    pub(super) fn route_words<'g>(
        &'g mut self,
        guide: &'g mut Guide<'_>,
        count: usize,
    ) -> Option<(&'g mut [u32], &'g mut [u32])> {
        let Guide::Words(words) = guide else {
            return None;
        };
        let heap = if self.links.len() >= count {
            &mut *self.links
        } else {
            &mut *self.tabu
        };
        Some((words, heap))
    }

    /// A packed route of `count` blocks: the words and heap to build it in ([`route`], the table
    /// above) and the words to pack it into; `None` for a word-a-block route or without room.
    pub(super) fn packed_route<'g>(
        &'g mut self,
        guide: &'g mut Guide<'_>,
        count: usize,
    ) -> Option<(Pair<'g>, &'g mut [u32])> {
        let Guide::Packed(out) = guide else {
            return None;
        };
        Some((route(self.tabu, self.cells, self.links, count)?, out))
    }
}

/// What the colony's iterations borrow: every buffer an ant reads or writes.
pub(super) struct Colony<'w> {
    pub(super) tau: &'w mut [[f32; 4]],
    pub(super) delta: &'w mut [[f32; 4]],
    /// The ant's tabu set (and tightening's filter).
    pub(super) tabu: &'w mut [u32],
    pub(super) dead: &'w [u32],
    pub(super) moves: &'w [u8],
    /// The ant's path, the iteration's best and worst (empty: walked again), the run's best.
    pub(super) tours: [&'w mut [Dir]; 4],
    /// Tightening's index ([`crate::colony::tighten::tighten`]): the path cells, then the links.
    pub(super) index: (&'w mut [Point], &'w mut [u32]),
    /// The coarse route the ants read.
    pub(super) guide: &'w Guide<'w>,
}

/// What the work after the last iteration borrows (and a reused answer's repair): the answer it
/// writes (the best tour, the path cells), the pheromone increments (the smoothing's distances,
/// and the stash of the route's links for the next warm start), the route (stashed, then
/// scratch) and the buffers idle after the last ant.
pub(super) struct Polishing<'w> {
    pub(super) best: &'w mut [Dir],
    pub(super) points: &'w mut [Point],
    pub(super) delta: &'w mut [[f32; 4]],
    /// The route, to stash before its words become scratch.
    pub(super) guide: Guide<'w>,
    /// Idle after the last ant.
    pub(super) idle: Spent<'w>,
}

/// The buffers idle after the last ant, lent to the polish by what it asks for.
pub(super) struct Spent<'w> {
    tabu: &'w mut [u32],
    links: &'w mut [u32],
}

impl Spent<'_> {
    /// The local search's two slices on a large map ([`refine`], the table above): the links,
    /// the route's words (`guide`, stashed first if kept) and the tabu set.
    pub(super) fn refine<'g>(
        &'g mut self,
        guide: &'g mut Guide<'_>,
        words: usize,
        fewest: usize,
    ) -> Option<(&'g mut [u32], &'g mut [u32])> {
        refine(
            self.links,
            guide.reborrow().scratch(),
            self.tabu,
            words,
            fewest,
        )
    }

    /// The local search's two slices on a small map: two slices of `words` of the links
    /// (shorter when they do not hold both: the search then leaves the path as it is).
    pub(super) fn halves_of_links(&mut self, words: usize) -> (&mut [u32], &mut [u32]) {
        let (a, rest) = self.links.split_at_mut(words.min(self.links.len()));
        (a, rest.get_mut(..words).unwrap_or_default())
    }

    /// The detour's scratch of a reused answer's repair ([`detour`], the table above): the
    /// longest two slices the links, the route's words (`guide`) and the tabu set give.
    pub(super) fn detour<'g>(&'g mut self, guide: &'g mut Guide<'_>) -> Pair<'g> {
        detour(self.links, guide.reborrow().scratch(), self.tabu)
    }

    /// The smoothing's links for a raw path of `n` cells ([`smoothing`]).
    pub(super) fn smoothing(&mut self, n: usize) -> &mut [u32] {
        smoothing(self.links, self.tabu, n)
    }

    /// The links (the corridor search's scratch on small maps).
    pub(super) fn links(&mut self) -> &mut [u32] {
        self.links
    }
}

impl<'a> Workspace<'a> {
    /// The setup's view.
    pub(super) fn setting(&mut self) -> Setting<'_> {
        Setting {
            dead: self.dead,
            moves: self.moves,
            guide: self.guide.reborrow(),
            idle: Idle {
                tabu: self.tabu,
                links: self.links,
                cells: bytemuck::try_cast_slice_mut(&mut *self.points).unwrap_or_default(),
            },
        }
    }

    /// The colony's view.
    pub(super) fn colony(&mut self) -> Colony<'_> {
        Colony {
            tau: self.tau,
            delta: self.delta,
            tabu: self.tabu,
            dead: self.dead,
            moves: self.moves,
            tours: [self.tour, self.iter_best, self.iter_worst, self.best],
            index: (self.points, self.links),
            guide: &self.guide,
        }
    }

    /// The polish's view (and a reused answer's repair's).
    pub(super) fn polishing(&mut self) -> Polishing<'_> {
        Polishing {
            best: self.best,
            points: self.points,
            delta: self.delta,
            guide: self.guide.reborrow(),
            idle: Spent {
                tabu: self.tabu,
                links: self.links,
            },
        }
    }
}

/// Two slices of `words` words from `a` and `b`: one of each, else both from `a`, else both
/// from `b`; `None` if neither way fits.
fn two<'x>(
    a: &'x mut [u32],
    b: &'x mut [u32],
    words: usize,
) -> Option<(&'x mut [u32], &'x mut [u32])> {
    if a.len() >= words && b.len() >= words {
        return Some((a.get_mut(..words)?, b.get_mut(..words)?));
    }
    let from = if a.len() >= words { a } else { b };
    let (x, y) = from.split_at_mut_checked(words)?;
    Some((x, y.get_mut(..words)?))
}

/// The local search's scratch after the last ant, two slices of `words` words (the table
/// above), else the tabu set halved when each half holds at least `fewest` words (a smaller
/// window, [`crate::polish::refine::Scratch::side`]); `None`: not enough.
pub(super) fn refine<'x>(
    links: &'x mut [u32],
    guide: &'x mut [u32],
    tabu: &'x mut [u32],
    words: usize,
    fewest: usize,
) -> Option<(&'x mut [u32], &'x mut [u32])> {
    let fits = |a: usize, b: usize| {
        a >= words && b >= words || a >= words.saturating_mul(2) || b >= words.saturating_mul(2)
    };
    match (links.len() >= words, guide.len() >= words) {
        (true, true) => return Some((links.get_mut(..words)?, guide.get_mut(..words)?)),
        (false, true) if tabu.len() >= words => {
            return Some((tabu.get_mut(..words)?, guide.get_mut(..words)?))
        }
        _ if fits(links.len(), tabu.len()) => return two(links, tabu, words),
        _ => {}
    }
    let half = tabu.len() / 2;
    if half < fewest {
        return None;
    }
    let (a, b) = tabu.split_at_mut_checked(half)?;
    Some((a, b.get_mut(..half)?))
}

/// A repair's detour scratch between plans, when the links, the route's words and the tabu set are
/// all idle: of the pairs (links, route), (links, tabu set), (tabu set, route) and of each of the
/// three halved, the one whose shorter slice is longest (the first in that order on a tie), both
/// slices cut to that length; two empty slices when every buffer is empty. It depends on the
/// three lengths only, so host and device lend the same.
pub(super) fn detour<'x>(
    links: &'x mut [u32],
    guide: &'x mut [u32],
    tabu: &'x mut [u32],
) -> Pair<'x> {
    let (l, g, t) = (links.len(), guide.len(), tabu.len());
    let sizes = [l.min(g), l.min(t), t.min(g), l / 2, t / 2, g / 2];
    let mut pick = 0usize;
    let mut words = 0usize;
    for (k, &w) in sizes.iter().enumerate() {
        if w > words {
            (pick, words) = (k, w);
        }
    }
    let cut = |x: &'x mut [u32]| -> &'x mut [u32] { x.get_mut(..words).unwrap_or_default() };
    let halves = |x: &'x mut [u32]| -> Pair<'x> {
        let (a, b) = x.split_at_mut(words.min(x.len()));
        (a, b.get_mut(..words).unwrap_or_default())
    };
    match pick {
        0 => (cut(links), cut(guide)),
        1 => (cut(links), cut(tabu)),
        2 => (cut(tabu), cut(guide)),
        3 => halves(links),
        4 => halves(tabu),
        _ => halves(guide),
    }
}

/// Words [`refine`] needs in the links beside a tabu set of `tabu` words (and a route of fewer
/// than `words` words).
pub(super) const fn refine_links(tabu: usize, words: usize, fewest: usize) -> usize {
    if tabu >= words.saturating_mul(2) || tabu / 2 >= fewest {
        0
    } else if tabu >= words {
        words
    } else {
        words.saturating_mul(2)
    }
}

/// The words and the heap of a packed route of `count` blocks, built before the first ant (the
/// table above), from the tabu set, the path cells' words (`points`, idle before the first ant)
/// and the links; `None`: not enough.
pub(super) fn route<'x>(
    tabu: &'x mut [u32],
    points: &'x mut [u32],
    links: &'x mut [u32],
    count: usize,
) -> Option<(&'x mut [u32], &'x mut [u32])> {
    let (t, p) = (tabu.len() >= count, points.len() >= count);
    if tabu.len() >= count.checked_mul(2)? {
        let (a, b) = tabu.split_at_mut_checked(count)?;
        return Some((a, b.get_mut(..count)?));
    }
    match (t, p) {
        (true, true) => Some((tabu.get_mut(..count)?, points.get_mut(..count)?)),
        (true, false) => Some((tabu.get_mut(..count)?, links.get_mut(..count)?)),
        (false, true) => Some((points.get_mut(..count)?, links.get_mut(..count)?)),
        (false, false) => {
            let (a, b) = links.split_at_mut_checked(count)?;
            Some((a, b.get_mut(..count)?))
        }
    }
}

/// Words [`route`] needs in the links beside a tabu set of `tabu` words and `points` words of
/// path cells for a route of `count` blocks.
pub(super) const fn route_links(tabu: usize, points: usize, count: usize) -> usize {
    let (t, p) = (tabu >= count, points >= count);
    if tabu >= count.saturating_mul(2) || t && p {
        0
    } else if t || p {
        count
    } else {
        count.saturating_mul(2)
    }
}

/// The smoothing's links for a raw path of `n` cells: the links when they hold `n`, else the
/// tabu set when it does, else the links (the greedy rule).
pub(super) fn smoothing<'x>(links: &'x mut [u32], tabu: &'x mut [u32], n: usize) -> &'x mut [u32] {
    if links.len() < n && tabu.len() >= n {
        tabu
    } else {
        links
    }
}

/// Words [`smoothing`] needs in the links beside a tabu set of `tabu` words for `n` cells.
pub(super) const fn smoothing_links(tabu: usize, n: usize) -> usize {
    if tabu >= n {
        0
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_lending_fits_what_its_size_says() {
        // For lengths around the boundaries, `route` and `refine` find their slices exactly
        // when the sizes say the links suffice, and never return overlapping or short slices.
        for tabu in [0usize, 10, 99, 100, 150, 199, 200, 500] {
            for links in [0usize, 50, 99, 100, 199, 200, 300] {
                let (mut t, mut l) = (vec![0u32; tabu], vec![0u32; links]);
                let need = route_links(tabu, 0, 100);
                let got = route(&mut t, &mut [], &mut l, 100);
                assert_eq!(got.is_some(), links >= need, "tabu {tabu} links {links}");
                if let Some((a, b)) = got {
                    assert_eq!((a.len(), b.len()), (100, 100));
                }
                let mut g = vec![0u32; 7];
                let got = refine(&mut l, &mut g, &mut t, 100, 60);
                assert_eq!(
                    got.is_some(),
                    links >= refine_links(tabu, 100, 60),
                    "{tabu} {links}"
                );
                let n = 120;
                let s = smoothing(&mut l, &mut t, n).len();
                assert_eq!(s >= n, links >= smoothing_links(tabu, n), "{tabu} {links}");
            }
        }
    }

    #[test]
    fn a_detour_gets_the_longest_pair_the_idle_buffers_give() {
        // Every pairing against a brute force over the six ways: both slices as long as the best
        // way's shorter one, and disjoint (two `&mut` borrows of one buffer cannot overlap).
        for l in [0usize, 1, 7, 100, 4056, 4096] {
            for g in [0usize, 512, 4096] {
                for t in [0usize, 2048, 5795, 8192] {
                    let (mut a, mut b, mut c) = (vec![0u32; l], vec![0u32; g], vec![0u32; t]);
                    let best = [l.min(g), l.min(t), t.min(g), l / 2, t / 2, g / 2]
                        .into_iter()
                        .max()
                        .unwrap();
                    let (x, y) = detour(&mut a, &mut b, &mut c);
                    assert_eq!((x.len(), y.len()), (best, best), "{l} {g} {t}");
                }
            }
        }
        // The F411's layouts: the full one (links and route words, 4,096 each) and the compact
        // one at 512 x 512 (its tabu set halved) and at Nav2's depot (the links and the tabu set).
        let sizes = |l, g, t| {
            let (mut a, mut b, mut c) = (vec![0u32; l], vec![0u32; g], vec![0u32; t]);
            detour(&mut a, &mut b, &mut c).0.len()
        };
        assert_eq!(sizes(4096, 4096, 2048), 4096);
        assert_eq!(sizes(2048, 512, 8192), 4096);
        assert_eq!(sizes(4056, 512, 5795), 4056);
    }
}
