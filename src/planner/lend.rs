//! What each phase of a run borrows: one typed view of the workspace per phase, and the one
//! place where a buffer idle in that phase takes a second role, so two phases never write the
//! same words unknowingly.
//!
//! | view | phase | owns | borrows idle |
//! | --- | --- | --- | --- |
//! | [`Setting`] | setup (before the first ant) | the pruning marks, the coarse route ([`Guide`]) | [`Idle`]: the tabu set, the links, the path cells' words |
//! | [`Colony`] | the iterations | the pheromone and its increments, the tabu set, the tours, the weight table (`crate::colony::weights`, a buffer of its own, feature `alloc`); reads the marks, the moves and the route | tightening's index: the path cells and the links |
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
//! | colony: the weight table (`crate::colony::weights`), where the walks read one (an entry a cell, no route) | 10 words a cell | its own buffer, whole, when it holds them (`needs::lend_weights`); else none: the walks compute their weights at each move |
//! | colony: the tabu set's rows layout ([`TabuSet::with_rows`]: a map at most 30 cells wide, read by the loop with a table) | `2 (height + 2)` words | the weight buffer's words beyond the table's, when they hold them; else the tabu set stays linear in its own words |
//! | polish: the local search ([`crate::polish::refine`]) | two slices of [`super::run::REFINE_WORDS`] | the links and the route's words, the links and the tabu set, the tabu set and the route's words, the tabu set halved, the links halved |
//! | polish: the local search's memo ([`crate::polish::refine::Memo`]) | [`MEMO_RECORDS`] records | the front of the pheromone increments (the smoothing's ring later, the route's stash at the far end) |
//! | polish: the smoothing ([`crate::polish::smoothing`]) | `n` links for its shortest-path rule (fewer: the greedy rule) | the links, else the tabu set (free after the last ant and the local search) |
//! | a reused answer's repair ([`super::repair`]): the detour | two slices, as many words as it can get (its box is sized by what blocks the answer, up to what the slices hold; no memo) | the pair of the links, the route's words and the tabu set, or one of them halved, whose shorter slice is longest (the first such in that order on a tie) |
//! | a reused answer's repair: the smoothing | `n` links, as in the polish | as in the polish |
//!
//! **Needs, declared once per phase** (`planner::needs`): each phase's buffer needs are a const
//! list there, with the lending rules; the views here lend by them ([`Need::take`], then
//! [`Lent::take`]), and the arena lays out and sizes from the same list.
//!
//! **Typed views.** A lent buffer reaches the phase as its own type, which owns the operations
//! the phase needs, so no call site does word arithmetic on a buffer of another role: the ant's
//! [`TabuSet`], the route search's [`RouteHeap`], the smoothing's [`PathLinks`], the local
//! search's [`crate::polish::refine::Scratch`].
//!
//! Every choice depends only on the buffers' lengths (never on their contents), so a host that
//! lays out a device's arena plans exactly what the device plans (one exception, which no arena
//! meets: tightening's keyed index reads the path cells as words, so path cells that a workspace
//! laid by hand leaves unaligned lend none, and a walk left untightened is counted,
//! `Shortfalls::TIGHTEN`; `carve` and every board's storage align them), and a choice made
//! at the start of a phase is the same at each of its pieces. None of these buffers is kept
//! between runs except the answer's (`best`, `points`) and the pheromone: the tabu set, the links
//! and the route's words are scratch once the colony is done ([`super::Memory`] keeps nothing of
//! them, or stashes what it keeps in the pheromone increments first).

#[cfg(doc)]
use crate::colony::route;
use crate::colony::route::RouteHeap;
use crate::colony::tabu::TabuSet;
#[cfg(any(feature = "alloc", test))]
use crate::colony::weights::{self, WeightTable};
use crate::map::grid::{Dir, FillScratch, Point};
use crate::polish::links::PathLinks;

#[cfg(any(feature = "alloc", test))]
use super::needs::lend_weights;
use super::needs::{detour_take, Ask, Lent, Need, Pair};
#[cfg(doc)]
use super::needs::{refine_take, route_take, smoothing_take, Take};

pub(super) use super::workspace::Guide;
use super::workspace::Workspace;

/// A route's words and its search's heap.
type Routing<'g> = (&'g mut [u32], RouteHeap<'g>);

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
    /// The flood fill's scratch: the tabu set's words as its marks, the links as its ring.
    pub(super) fn reach(&mut self) -> FillScratch<'_> {
        FillScratch::new(self.tabu, self.links)
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
    ) -> Option<Routing<'g>> {
        let Guide::Words(words) = guide else {
            return None;
        };
        let lent = Lent::new(self.links, self.tabu, &mut [], &mut []);
        let ask = Ask::route(count, false);
        let take = Need::Route.take(lent.lengths(), ask)?;
        let (heap, _) = lent.take(take)?;
        Some((words, RouteHeap::new(heap)))
    }

    /// A packed route of `count` blocks: the words and heap to build it in ([`route_take`], the table
    /// above) and the words to pack it into; `None` for a word-a-block route or without room.
    pub(super) fn packed_route<'g>(
        &'g mut self,
        guide: &'g mut Guide<'_>,
        count: usize,
    ) -> Option<(Routing<'g>, &'g mut [u32])> {
        let Guide::Packed(out) = guide else {
            return None;
        };
        let lent = Lent::new(self.links, self.tabu, self.cells, &mut []);
        let ask = Ask::route(count, true);
        let take = Need::Route.take(lent.lengths(), ask)?;
        let (words, heap) = lent.take(take)?;
        Some(((words, RouteHeap::new(heap)), out))
    }
}

/// What the colony's iterations borrow: every buffer an ant reads or writes.
pub(super) struct Colony<'w> {
    pub(super) tau: &'w mut [[f32; 4]],
    pub(super) delta: &'w mut [[f32; 4]],
    /// The ant's tabu set (and tightening's filter).
    pub(super) tabu: TabuSet<'w>,
    pub(super) dead: &'w [u32],
    pub(super) moves: &'w [u8],
    /// The ant's path, the iteration's best and worst (empty: walked again), the run's best.
    pub(super) tours: [&'w mut [Dir]; 4],
    /// Tightening's index ([`crate::colony::tighten::tighten`]): the path cells, then the links.
    pub(super) index: (&'w mut [Point], &'w mut [u32]),
    /// The coarse route the ants read.
    pub(super) guide: &'w Guide<'w>,
    /// The iteration's weight table ([`Need::Weights`]), when the walks read one and the
    /// workspace has room for it; `None`: the walks compute their weights at each move.
    #[cfg(any(feature = "alloc", test))]
    pub(super) weights: Option<WeightTable<'w>>,
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
    /// The local search's two slices on a large map ([`refine_take`], the table above): the links,
    /// the route's words (`guide`, stashed first if kept) and the tabu set.
    pub(super) fn refine<'g>(
        &'g mut self,
        guide: &'g mut Guide<'_>,
        words: usize,
        fewest: usize,
    ) -> Option<(&'g mut [u32], &'g mut [u32])> {
        let lent = Lent::new(self.links, self.tabu, &mut [], guide.reborrow().scratch());
        let ask = Ask::refine(words, fewest);
        let take = Need::Refine.take(lent.lengths(), ask)?;
        lent.take(take)
    }

    /// The local search's two slices on a small map: two slices of `words` of the links
    /// (shorter when they do not hold both: the search then leaves the path as it is).
    pub(super) fn halves_of_links(&mut self, words: usize) -> (&mut [u32], &mut [u32]) {
        let (a, rest) = self.links.split_at_mut(words.min(self.links.len()));
        (a, rest.get_mut(..words).unwrap_or_default())
    }

    /// The detour's scratch of a reused answer's repair ([`detour_take`], the table above): the
    /// longest two slices the links, the route's words (`guide`) and the tabu set give.
    pub(super) fn detour<'g>(&'g mut self, guide: &'g mut Guide<'_>) -> Pair<'g> {
        let lent = Lent::new(self.links, self.tabu, &mut [], guide.reborrow().scratch());
        let take = detour_take(lent.lengths());
        lent.take(take).unwrap_or_default()
    }

    /// The smoothing's links for a raw path of `n` cells ([`smoothing_take`]).
    pub(super) fn smoothing(&mut self, n: usize) -> PathLinks<'_> {
        let lent = Lent::new(self.links, self.tabu, &mut [], &mut []);
        let ask = Ask::smoothing(n);
        let take = Need::Smoothing.take(lent.lengths(), ask);
        let links = take.and_then(|t| lent.take(t));
        PathLinks::new(links.map_or(&mut [], |(links, _)| links))
    }

    /// The links (the corridor search's scratch on small maps).
    pub(super) fn links(&mut self) -> &mut [u32] {
        self.links
    }
}

/// The colony's weight table over `words` for a map of `cells` cells, lent by
/// [`Need::Weights`]'s rule ([`lend_weights`]). Not inlined: the colony's frame, on the device's
/// deepest path, keeps its size (the device has no table).
/// The words beyond the table's ([`weights::words`]`(cells)`) come back beside it: the tabu
/// set's rows layout takes them ([`TabuSet::with_rows`]; empty when there is no table).
#[cfg(any(feature = "alloc", test))]
#[inline(never)]
fn weight_table(
    words: &mut [u32],
    ask: Ask,
    cells: usize,
) -> (Option<WeightTable<'_>>, &mut [u32]) {
    let Some(lent) = lend_weights(words, ask) else {
        return (None, &mut []);
    };
    let (table, spare) = lent.split_at_mut(weights::words(cells).min(lent.len()));
    match WeightTable::of(table, cells) {
        Some(t) => (Some(t), spare),
        None => (None, &mut []),
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

    /// The colony's view; `table`: the map's width and height when its walks read a weight
    /// table (the loop for an entry a cell, [`crate::colony::ant`]), lent when the workspace
    /// holds one for them, with the tabu set in the rows layout in the weight buffer's words
    /// beyond the table where they hold it ([`TabuSet::with_rows`]: a map at most
    /// [`crate::colony::tabu::ROWS_WIDTH`] wide). The same choice at every piece: it depends
    /// only on the map and the buffers' lengths.
    pub(super) fn colony(&mut self, table: Option<(usize, usize)>) -> Colony<'_> {
        #[cfg(any(feature = "alloc", test))]
        let (weights, tabu) = {
            let (width, height) = table.unwrap_or((0, 0));
            let cells = width.saturating_mul(height);
            let words = table.map_or(0, |_| weights::words(cells));
            let (weights, spare) = weight_table(self.weights, Ask::weights(words), cells);
            let tabu = TabuSet::new(self.tabu);
            let tabu = if weights.is_some() {
                tabu.with_rows(spare, width, height, self.dead)
            } else {
                tabu
            };
            (weights, tabu)
        };
        #[cfg(not(any(feature = "alloc", test)))]
        let (tabu, _) = (TabuSet::new(self.tabu), table);
        Colony {
            #[cfg(any(feature = "alloc", test))]
            weights,
            tau: self.tau,
            delta: self.delta,
            tabu,
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
