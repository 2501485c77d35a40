//! What each phase borrows of the buffers idle in it, declared once: the lending rules (a [`Take`]
//! of the idle buffers, chosen from their [`Lengths`] alone), the phases' needs ([`SETUP`],
//! [`COLONY`], [`POLISH`], all of them in [`PHASES`]) and the lending itself ([`Lent`]).
//! `planner::lend`'s views lend by these rules, `planner::arena` lays out and sizes from them.
//!
//! What a phase borrows of the idle buffers is a const list of
//! [`Need`]s: [`SETUP`], [`COLONY`], [`POLISH`], all of them in [`PHASES`]. A need is one lending
//! rule (the `*_take` functions below: a [`Take`] from the buffers' lengths alone) and how much of
//! it is enough ([`Need::enough`]). Everything else is read from that list: the slices a view
//! lends ([`Need::take`], then [`Lent::take`]), the links the compact arena lays out beside the
//! tabu set ([`links`]: the most any need asks), the tabu lengths at which that changes
//! ([`next_cut`], what `arena::capacity` walks), and the compile-time check that the full
//! layout's fixed links hold every need (`arena::full_links_hold`). To add a phase or a need: a
//! [`Need`] variant with its rule, its `wants`, `steps` and `cuts`, and an entry in its phase's
//! list; the tests here (`the_links_change_only_at_the_cuts`, `a_short_buffer_is_not_enough`)
//! fail when the cuts or the sizes do not follow the rule. A buffer a phase finds
//! short is a counted shortfall ([`super::Shortfalls`]: the route, its stash, tightening's index,
//! the local search, the smoothing, the corridor), never a silent fallback; the arena and the
//! boards' storages have none.
//!
//! Guarantees: every choice depends only on the buffers' lengths, never on their contents (the
//! path cells' words are lent only when aligned, which every arena and board storage is: see
//! [`super::lend`]); two slices lent at once never overlap (by type: each buffer is handed out at most
//! once, [`Lent`]); no panics (the const fns walk their lists by slice patterns).

/// Two slices of scratch words.
pub(super) type Pair<'g> = (&'g mut [u32], &'g mut [u32]);

/// A buffer a phase borrows while it is idle.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Buf {
    /// The links.
    Links,
    /// The tabu bit set.
    Tabu,
    /// The path cells' words (idle before the first ant).
    Points,
    /// The route's words (scratch after the colony).
    Guide,
    /// The weight table's words (the colony's alone; none in the arenas).
    Weights,
}

/// The lengths, in words, of the idle buffers a rule chooses among.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) struct Lengths {
    pub(super) links: usize,
    pub(super) tabu: usize,
    pub(super) points: usize,
    pub(super) guide: usize,
    pub(super) weights: usize,
}

/// What a phase takes of the idle buffers: each lending rule below chooses one from the
/// buffers' lengths alone, and [`Take::fits`] says whether those lengths hold it. The rule is
/// written once: the slices a phase gets ([`Lent::take`]) and the links an arena must lay out
/// for it ([`Need::links`]) are both derived from it.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Take {
    /// The first `words` words of each of two buffers.
    Pair(Buf, Buf, usize),
    /// Two slices of `words` words one after the other in one buffer.
    Halves(Buf, usize),
    /// One buffer, whole (the second slice empty).
    Whole(Buf),
}

impl Lengths {
    const fn of(self, b: Buf) -> usize {
        match b {
            Buf::Links => self.links,
            Buf::Tabu => self.tabu,
            Buf::Points => self.points,
            Buf::Guide => self.guide,
            Buf::Weights => self.weights,
        }
    }
}

impl Take {
    /// Whether buffers of these lengths hold it.
    pub(super) const fn fits(self, l: Lengths) -> bool {
        match self {
            Take::Pair(a, b, words) => {
                !matches!(
                    (a, b),
                    (Buf::Links, Buf::Links)
                        | (Buf::Tabu, Buf::Tabu)
                        | (Buf::Points, Buf::Points)
                        | (Buf::Guide, Buf::Guide)
                        | (Buf::Weights, Buf::Weights)
                ) && l.of(a) >= words
                    && l.of(b) >= words
            }
            Take::Halves(a, words) => l.of(a) >= words.saturating_mul(2),
            Take::Whole(_) => true,
        }
    }

    /// Words of its shorter slice.
    pub(super) const fn words(self, l: Lengths) -> usize {
        match self {
            Take::Pair(_, _, words) | Take::Halves(_, words) => words,
            Take::Whole(b) => l.of(b),
        }
    }

    /// `Some(self)` when buffers of these lengths hold it.
    const fn within(self, l: Lengths) -> Option<Take> {
        if self.fits(l) {
            Some(self)
        } else {
            None
        }
    }
}

/// The idle buffers themselves, to lend what a [`Take`] says.
pub(super) struct Lent<'x> {
    /// Indexed by [`Buf`]: each is handed out at most once.
    bufs: [Option<&'x mut [u32]>; 4],
}

impl<'x> Lent<'x> {
    pub(super) fn new(
        links: &'x mut [u32],
        tabu: &'x mut [u32],
        points: &'x mut [u32],
        guide: &'x mut [u32],
    ) -> Self {
        Self {
            bufs: [Some(links), Some(tabu), Some(points), Some(guide)],
        }
    }

    /// Their lengths.
    pub(super) fn lengths(&self) -> Lengths {
        let len = |b: Buf| {
            self.bufs
                .get(b as usize)
                .and_then(|x| x.as_ref())
                .map_or(0, |x| x.len())
        };
        Lengths {
            links: len(Buf::Links),
            tabu: len(Buf::Tabu),
            points: len(Buf::Points),
            guide: len(Buf::Guide),
            // The weight table's words are lent by `lend_weights` alone.
            weights: 0,
        }
    }

    fn buf(&mut self, b: Buf) -> Option<&'x mut [u32]> {
        self.bufs.get_mut(b as usize)?.take()
    }

    /// The slices `take` names; `None` when the buffers do not hold it.
    pub(super) fn take(mut self, take: Take) -> Option<Pair<'x>> {
        match take {
            Take::Pair(a, b, words) => {
                let x = self.buf(a)?.get_mut(..words)?;
                Some((x, self.buf(b)?.get_mut(..words)?))
            }
            Take::Halves(a, words) => {
                let (x, y) = self.buf(a)?.split_at_mut_checked(words)?;
                Some((x, y.get_mut(..words)?))
            }
            Take::Whole(a) => Some((self.buf(a)?, &mut [])),
        }
    }
}

/// The local search's scratch after the last ant, two slices of `words` words (the table
/// above): the links and the route's words, the tabu set and the route's words, the links and
/// the tabu set (one of each, else both from one), else the tabu set halved when each half
/// holds at least `fewest` words (a smaller window,
/// [`crate::polish::refine::Scratch::side`]); `None`: not enough. Reads the links, the tabu set
/// and the route's words.
pub(super) const fn refine_take(l: Lengths, words: usize, fewest: usize) -> Option<Take> {
    if l.links >= words && l.guide >= words {
        return Some(Take::Pair(Buf::Links, Buf::Guide, words));
    }
    if l.links < words && l.guide >= words && l.tabu >= words {
        return Some(Take::Pair(Buf::Tabu, Buf::Guide, words));
    }
    if l.links >= words && l.tabu >= words
        || l.links >= words.saturating_mul(2)
        || l.tabu >= words.saturating_mul(2)
    {
        return if l.links >= words && l.tabu >= words {
            Some(Take::Pair(Buf::Links, Buf::Tabu, words))
        } else if l.links >= words {
            Some(Take::Halves(Buf::Links, words))
        } else {
            Some(Take::Halves(Buf::Tabu, words))
        };
    }
    let half = l.tabu / 2;
    if half < fewest {
        None
    } else {
        Some(Take::Halves(Buf::Tabu, half))
    }
}

/// A repair's detour scratch between plans, when the links, the route's words and the tabu set are
/// all idle: of the pairs (links, route), (links, tabu set), (tabu set, route) and of each of the
/// three halved, the one whose shorter slice is longest (the first in that order on a tie), both
/// slices cut to that length (empty when every buffer is).
pub(super) const fn detour_take(l: Lengths) -> Take {
    let ways = [
        Take::Pair(Buf::Links, Buf::Guide, min(l.links, l.guide)),
        Take::Pair(Buf::Links, Buf::Tabu, min(l.links, l.tabu)),
        Take::Pair(Buf::Tabu, Buf::Guide, min(l.tabu, l.guide)),
        Take::Halves(Buf::Links, l.links / 2),
        Take::Halves(Buf::Tabu, l.tabu / 2),
        Take::Halves(Buf::Guide, l.guide / 2),
    ];
    let mut best = Take::Pair(Buf::Links, Buf::Guide, 0);
    let mut rest: &[Take] = &ways;
    while let [way, tail @ ..] = rest {
        if way.words(l) > best.words(l) {
            best = *way;
        }
        rest = tail;
    }
    best
}

const fn min(a: usize, b: usize) -> usize {
    if a < b {
        a
    } else {
        b
    }
}

/// The words and the heap of a packed route of `count` blocks, built before the first ant (the
/// table above): the tabu set halved, else the tabu set and the path cells' words, else either
/// of them and the links, else the links halved; `None`: not enough.
pub(super) const fn route_take(l: Lengths, count: usize) -> Option<Take> {
    let take = match (l.tabu >= count, l.points >= count) {
        _ if l.tabu >= count.saturating_mul(2) => Take::Halves(Buf::Tabu, count),
        (true, true) => Take::Pair(Buf::Tabu, Buf::Points, count),
        (true, false) => Take::Pair(Buf::Tabu, Buf::Links, count),
        (false, true) => Take::Pair(Buf::Points, Buf::Links, count),
        (false, false) => Take::Halves(Buf::Links, count),
    };
    take.within(l)
}

/// The heap of a word-a-block route of `count` blocks (the full layout): the links when they hold
/// `count` words, else the tabu set.
pub(super) const fn heap_take(l: Lengths, count: usize) -> Take {
    if l.links >= count {
        Take::Whole(Buf::Links)
    } else {
        Take::Whole(Buf::Tabu)
    }
}

/// The smoothing's links for a raw path of `n` cells: the links when they hold `n`, else the
/// tabu set when it does, else the links (the greedy rule).
pub(super) const fn smoothing_take(l: Lengths, n: usize) -> Take {
    if l.links < n && l.tabu >= n {
        Take::Whole(Buf::Tabu)
    } else {
        Take::Whole(Buf::Links)
    }
}

/// The colony's weight table for a map whose walks read one ([`Ask::weights`] words,
/// [`crate::colony::weights::words`]; 0: the walks read none): the weight table's words whole
/// when they hold that many; `None`: none (the walks compute their weights at each move).
pub(super) const fn weights_take(l: Lengths, words: usize) -> Option<Take> {
    if words > 0 && l.weights >= words {
        Some(Take::Whole(Buf::Weights))
    } else {
        None
    }
}

/// The weight table's `words`, lent by [`Need::Weights`]'s rule ([`weights_take`]) for
/// [`Ask::weights`]: all of them, or `None`. Apart from [`Lent`], which lends the idle buffers of
/// the other needs: the table is a buffer of its own, and the views that lend those (on the
/// device's deepest frames) keep their size.
#[cfg(any(feature = "alloc", test))]
pub(super) fn lend_weights(words: &mut [u32], a: Ask) -> Option<&mut [u32]> {
    let l = Lengths {
        links: 0,
        tabu: 0,
        points: 0,
        guide: 0,
        weights: words.len(),
    };
    match Need::Weights.take(l, a)? {
        Take::Whole(Buf::Weights) => Some(words),
        _ => None,
    }
}

/// One buffer need of a phase: what it borrows of the idle buffers, by which lending rule, and
/// how much of it is enough. A phase's needs are a const list ([`SETUP`], [`COLONY`], [`POLISH`],
/// all of them in [`PHASES`]); the slices a view lends ([`Need::take`], through [`Lent::take`]),
/// the links an arena lays out for them ([`links`]) and the tabu lengths at which that changes
/// ([`next_cut`], what the arena's capacity search walks) are all read from that list, so a new
/// phase or a new need is one entry here and its rule.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Need {
    /// The coarse route's heap, a word a block ([`heap_take`]), or a packed route's words and
    /// heap ([`route_take`]), by [`Ask::route`].
    Route,
    /// Tightening's index over the links: [`Ask::table`] words of them (the path cells' words
    /// beside them when its keys are packed); not lent by a rule (the colony's view holds the
    /// links whole), but laid out.
    Tighten,
    /// The local search's two slices ([`Ask::refine`]: of its words, at least its fewest, [`refine_take`]).
    Refine,
    /// The smoothing's links for [`Ask::cells`] path cells ([`smoothing_take`]).
    Smoothing,
    /// The iteration's weight table, [`Ask::weights`] words ([`weights_take`]): a buffer of its
    /// own, never the links (a walk without it computes its weights at each move, the same
    /// walk), so it asks the arena for nothing.
    Weights,
}

/// The setup's needs (before the first ant): the coarse route. (Its flood fill and pruning
/// stack take the tabu set and the links whole, whatever their lengths.)
pub(super) const SETUP: &[Need] = &[Need::Route];
/// The colony's needs: tightening's index, the weight table.
pub(super) const COLONY: &[Need] = &[Need::Tighten, Need::Weights];
/// The polish's needs: the local search's slices, the smoothing's links. (A repair's detour
/// takes what it gets: [`detour_take`].)
pub(super) const POLISH: &[Need] = &[Need::Refine, Need::Smoothing];
/// Every phase's needs: what an arena must lay out besides the tabu set.
pub(super) const PHASES: [&[Need]; 3] = [SETUP, COLONY, POLISH];

/// The figures the needs are functions of (each need reads its own).
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default)]
pub(super) struct Ask {
    /// The route's blocks (a word each of words and of heap), and whether it is packed (its
    /// words lent, not laid out).
    pub(super) route: (usize, bool),
    /// Cells of the longest path (`steps + 1`).
    pub(super) cells: usize,
    /// Words of tightening's table in the links.
    pub(super) table: usize,
    /// Words of each of the local search's slices, and the fewest it takes.
    pub(super) refine: (usize, usize),
    /// Words of the colony's weight table (0: its walks read none).
    pub(super) weights: usize,
}

impl Ask {
    /// A route of `blocks` blocks, packed or not.
    pub(super) const fn route(blocks: usize, packed: bool) -> Self {
        Self {
            route: (blocks, packed),
            cells: 0,
            table: 0,
            refine: (0, 0),
            weights: 0,
        }
    }

    /// The colony's weight table of `words` words (0: none).
    #[cfg(any(feature = "alloc", test))]
    pub(super) const fn weights(words: usize) -> Self {
        Self {
            weights: words,
            ..Self::route(0, false)
        }
    }

    /// The local search's slices of `words` (at least `fewest`).
    pub(super) const fn refine(words: usize, fewest: usize) -> Self {
        Self {
            refine: (words, fewest),
            ..Self::route(0, false)
        }
    }

    /// The smoothing's links for `cells` path cells.
    pub(super) const fn smoothing(cells: usize) -> Self {
        Self {
            cells,
            ..Self::route(0, false)
        }
    }
}

impl Need {
    /// What it takes of buffers of lengths `l` (its rule), `None`: they do not hold it.
    pub(super) const fn take(self, l: Lengths, a: Ask) -> Option<Take> {
        match self {
            Need::Route if a.route.1 => route_take(l, a.route.0),
            Need::Route => Some(heap_take(l, a.route.0)),
            Need::Tighten => Some(Take::Whole(Buf::Links)),
            Need::Refine => refine_take(l, a.refine.0, a.refine.1),
            Need::Smoothing => Some(smoothing_take(l, a.cells)),
            Need::Weights => weights_take(l, a.weights),
        }
    }

    /// Words of its shorter slice that are enough.
    const fn wants(self, a: Ask) -> usize {
        match self {
            Need::Route => a.route.0,
            Need::Tighten => a.table,
            Need::Refine => a.refine.1,
            Need::Smoothing => a.cells,
            Need::Weights => a.weights,
        }
    }

    /// Whether buffers of lengths `l` give it enough.
    pub(super) const fn enough(self, l: Lengths, a: Ask) -> bool {
        match self.take(l, a) {
            Some(t) => t.fits(l) && t.words(l) >= self.wants(a),
            None => false,
        }
    }

    /// The lengths of links it may ask for, fewest first.
    const fn steps(self, a: Ask) -> [usize; 3] {
        let w = self.wants(a);
        match self {
            Need::Route if a.route.1 => [0, w, w.saturating_mul(2)],
            Need::Route | Need::Smoothing => [0, w, w],
            Need::Tighten => [w, w, w],
            Need::Refine => [0, a.refine.0, a.refine.0.saturating_mul(2)],
            Need::Weights => [0, 0, 0],
        }
    }

    /// Words it needs in the links beside the other idle buffers of `l` (`l.links` unread): the
    /// fewest of its [`Need::steps`] that are enough.
    pub(super) const fn links(self, l: Lengths, a: Ask) -> usize {
        let [x, y, z] = self.steps(a);
        if self.enough(Lengths { links: x, ..l }, a) {
            x
        } else if self.enough(Lengths { links: y, ..l }, a) {
            y
        } else {
            z
        }
    }

    /// The tabu-set lengths at which [`Need::links`] may change (0: none).
    const fn cuts(self, a: Ask) -> [usize; 3] {
        let w = self.wants(a);
        match self {
            Need::Route if a.route.1 => [w, w.saturating_mul(2), 0],
            Need::Route | Need::Smoothing => [w, 0, 0],
            Need::Tighten | Need::Weights => [0, 0, 0],
            Need::Refine => [
                a.refine.0,
                a.refine.0.saturating_mul(2),
                a.refine.1.saturating_mul(2),
            ],
        }
    }
}

/// Words every phase of [`PHASES`] needs in the links beside the other idle buffers of `l`: the
/// most any of their needs asks for.
pub(super) const fn links(l: Lengths, a: Ask) -> usize {
    let mut most = 0;
    let mut phases: &[&[Need]] = &PHASES;
    while let [needs, rest @ ..] = phases {
        let mut needs: &[Need] = needs;
        while let [need, tail @ ..] = needs {
            most = max(most, need.links(l, a));
            needs = tail;
        }
        phases = rest;
    }
    most
}

/// The smallest tabu-set length above `x` at which [`links`] may change (for the same other
/// buffers), at most `end`: between two of them it is the same ([`super::arena::capacity`]
/// walks the tabu lengths piece by piece).
pub(super) const fn next_cut(x: usize, a: Ask, end: usize) -> usize {
    let mut best = end;
    let mut phases: &[&[Need]] = &PHASES;
    while let [needs, rest @ ..] = phases {
        let mut needs: &[Need] = needs;
        while let [need, tail @ ..] = needs {
            let mut cuts: &[usize] = &need.cuts(a);
            while let [c, more @ ..] = cuts {
                if *c > x && *c < best {
                    best = *c;
                }
                cuts = more;
            }
            needs = tail;
        }
        phases = rest;
    }
    best
}

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lengths(links: usize, tabu: usize, points: usize, guide: usize) -> Lengths {
        Lengths {
            links,
            tabu,
            points,
            guide,
            weights: 0,
        }
    }

    /// Lend `take` from fresh buffers of these lengths: the two slices' lengths.
    fn lend(l: Lengths, take: Take) -> Option<(usize, usize)> {
        let (mut a, mut b, mut c, mut d) = (
            vec![0u32; l.links],
            vec![0u32; l.tabu],
            vec![0u32; l.points],
            vec![0u32; l.guide],
        );
        let lent = Lent::new(&mut a, &mut b, &mut c, &mut d);
        assert_eq!(lent.lengths(), Lengths { weights: 0, ..l });
        lent.take(take).map(|(x, y)| (x.len(), y.len()))
    }

    /// What the tests ask: a packed route of `blocks`, the local search's `words` (at least
    /// `fewest`), `cells` path cells.
    fn ask(blocks: usize, words: usize, fewest: usize, cells: usize) -> Ask {
        Ask {
            route: (blocks, true),
            cells,
            table: 0,
            refine: (words, fewest),
            weights: 0,
        }
    }

    #[test]
    fn every_lending_fits_what_its_size_says() {
        // For lengths around the boundaries, the route and the local search find their slices
        // exactly when the needs say the links suffice, and the slices lent are as long as the
        // rule says (two `&mut` slices never overlap, by type).
        let a = ask(100, 100, 60, 120);
        for tabu in [0usize, 10, 99, 100, 150, 199, 200, 500] {
            for links in [0usize, 50, 99, 100, 199, 200, 300] {
                let l = lengths(links, tabu, 0, 7);
                let need = |n: Need| links >= n.links(l, a);
                let got = Need::Route.take(l, a);
                assert_eq!(got.is_some(), need(Need::Route), "{tabu} {links}");
                if let Some(take) = got {
                    assert_eq!(lend(l, take), Some((100, 100)));
                }
                let got = Need::Refine.take(l, a);
                assert_eq!(got.is_some(), need(Need::Refine), "{tabu} {links}");
                if let Some(take) = got {
                    let w = take.words(l);
                    assert!(w == 100 || w >= 60 && w == tabu / 2, "{take:?}");
                    assert_eq!(lend(l, take), Some((w, w)));
                }
                let take = Need::Smoothing.take(l, a).unwrap();
                let s = lend(l, take).map_or(0, |(x, _)| x);
                assert_eq!(s >= 120, need(Need::Smoothing), "{tabu} {links}");
            }
        }
        // A pair of one buffer with itself is never lent.
        let l = lengths(10, 10, 10, 10);
        assert!(!Take::Pair(Buf::Links, Buf::Links, 1).fits(l));
        assert_eq!(lend(l, Take::Pair(Buf::Tabu, Buf::Tabu, 1)), None);
        assert_eq!(lend(l, Take::Halves(Buf::Tabu, 6)), None);
    }

    #[test]
    fn a_short_buffer_is_not_enough() {
        // Each need says when the idle buffers fall short: then the arena lays out more links,
        // or the phase counts a shortfall (`planner::Shortfalls`).
        let a = Ask {
            table: 50,
            ..ask(100, 100, 60, 120)
        };
        let l = lengths(0, 0, 0, 0);
        for need in [Need::Route, Need::Tighten, Need::Refine, Need::Smoothing] {
            assert!(!need.enough(l, a), "{need:?}");
            let links = need.links(l, a);
            assert!(need.enough(lengths(links, 0, 0, 0), a), "{need:?}");
            assert!(!need.enough(lengths(links - 1, 0, 0, 0), a), "{need:?}");
        }
        // The arena's links are the most any phase's need asks: with a tabu set of 200 words,
        // which lends the route, the local search and the smoothing theirs, tightening's table.
        assert_eq!(links(l, a), 200);
        assert_eq!(links(lengths(0, 200, 0, 0), a), 50);
    }

    #[test]
    fn the_weight_table_is_lent_whole_or_not_at_all() {
        // Its own words, whole, when they hold the table; never when the walks read none; and
        // it asks the arena for no links (the arenas have no table: their walks compute the
        // weights at each move).
        let a = Ask::weights(322);
        for w in [0usize, 1, 321, 322, 500] {
            let l = Lengths {
                weights: w,
                ..lengths(1000, 1000, 1000, 1000)
            };
            let take = Need::Weights.take(l, a);
            assert_eq!(take.is_some(), w >= 322, "{w}");
            assert_eq!(Need::Weights.enough(l, a), w >= 322, "{w}");
            assert_eq!(take, (w >= 322).then_some(Take::Whole(Buf::Weights)));
            let mut words = vec![0u32; w];
            let lent = lend_weights(&mut words, a).map(|x| x.len());
            assert_eq!(lent, (w >= 322).then_some(w));
            assert_eq!(lend_weights(&mut words, Ask::weights(0)), None);
            assert_eq!(Need::Weights.links(l, a), 0);
            assert_eq!(Need::Weights.take(l, Ask::weights(0)), None);
        }
        assert_eq!(links(lengths(0, 0, 0, 0), a), 0);
    }

    #[test]
    fn the_links_change_only_at_the_cuts() {
        // Between two tabu lengths of `next_cut`, the links every phase needs are the same: the
        // arena's capacity search relies on it. A rule whose threshold is not a cut fails here.
        for (words, fewest, count, n) in
            [(100, 60, 70, 300), (4056, 3456, 4096, 4096), (8, 3, 20, 9)]
        {
            let a = ask(count, words, fewest, n);
            let sizes = |tabu| {
                let l = lengths(0, tabu, n, 0);
                [Need::Route, Need::Refine, Need::Smoothing].map(|need| need.links(l, a))
            };
            for tabu in 1..3 * (words + count + n) {
                if next_cut(tabu - 1, a, usize::MAX) != tabu {
                    assert_eq!(sizes(tabu), sizes(tabu - 1), "{tabu}");
                }
            }
        }
    }

    #[test]
    fn a_detour_gets_the_longest_pair_the_idle_buffers_give() {
        // Every pairing against a brute force over the six ways: both slices as long as the best
        // way's shorter one.
        for l in [0usize, 1, 7, 100, 4056, 4096] {
            for g in [0usize, 512, 4096] {
                for t in [0usize, 2048, 5795, 8192] {
                    let best = [l.min(g), l.min(t), t.min(g), l / 2, t / 2, g / 2]
                        .into_iter()
                        .max()
                        .unwrap();
                    let len = lengths(l, t, 0, g);
                    assert_eq!(
                        lend(len, detour_take(len)),
                        Some((best, best)),
                        "{l} {g} {t}"
                    );
                }
            }
        }
        // The F411's layouts: the full one (links and route words, 4,096 each) and the compact
        // one at 512 x 512 (its tabu set halved) and at Nav2's depot (the links and the tabu set).
        let words = |l, g, t| detour_take(lengths(l, t, 0, g)).words(lengths(l, t, 0, g));
        assert_eq!(words(4096, 4096, 2048), 4096);
        assert_eq!(words(2048, 512, 8192), 4096);
        assert_eq!(words(4056, 512, 5795), 4056);
    }
}
