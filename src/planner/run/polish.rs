//! The work after the last iteration, a piece at a time: the best tour laid out as cells, the
//! local search on large maps ([`Params::refine`]) a budget of expanded cells at a time, then the
//! smoothing a stretch of raw cells at a time, then the corridor search: each a piece of
//! [`Run::poll`].

use crate::colony::route::{self, GUIDE_BLOCKS};
use crate::map::grid::{direction, is_diagonal};
use crate::polish::refine::{self, Budget, Memo, Refiner, Scratch};
use crate::polish::smoothing::{Smoother, SmoothingKind, LOOKBACK};

use crate::planner::params::Algorithm;
#[cfg(doc)]
use crate::planner::params::Params;
use crate::planner::plan::RawPath;

use super::colony::Best;
use super::{End, Phase, Run, Shortfalls};
use crate::planner::lend::{self, Guide};

/// Window side of the local search ([`Params::refine`]). Its scratch is the links and the coarse
/// route's words, free after the last iteration: two slices of [`Scratch::words`]`(52)` = 4,056
/// words each, which the device's and the host's storage both lend (at least [`GUIDE_BLOCKS`]
/// words each on maps with a route). Measured on the 20 longest scenarios of the 20 large Moving
/// AI maps (`refine_large` example): mean raw/opt8 1.0009 at 52, 1.0011 at 48, 1.0007 at 64.
pub const REFINE_SIDE: usize = 52;
pub(crate) const REFINE_WORDS: usize = Scratch::words(REFINE_SIDE);
/// The smallest window side the local search takes on a large map when the workspace cannot
/// lend two slices of [`REFINE_WORDS`] but its tabu set halved gives two of at least
/// [`Scratch::words`]`(48)` (the compact arena on maps of 221,184 to 259,583 cells,
/// [`crate::planner::arena`]): 48, measured at 1.0011 of the optimum against 1.0009 at 52
/// (`REFINE_SIDE`).
pub const SHORT_REFINE_SIDE: usize = 48;
pub(crate) const SHORT_REFINE_WORDS: usize = Scratch::words(SHORT_REFINE_SIDE);
const _: () = assert!(REFINE_WORDS <= GUIDE_BLOCKS);
/// Window side of the local search on small maps (at most [`crate::colony::pheromone::BLOCKS`] = 1,024
/// cells, which have no coarse route to lend): 32, a window of 1,024 cells, as large as the map.
/// Its two slices of [`Scratch::words`]`(32)` = 1,536 words both come from the links, so a
/// workspace needs 3,072 links for it (the device's 4,096 and `HeapStorage`'s at least
/// [`GUIDE_BLOCKS`] have them; a smaller one keeps the colony's path, as before).
pub const SMALL_REFINE_SIDE: usize = 32;
pub(super) const SMALL_REFINE_WORDS: usize = Scratch::words(SMALL_REFINE_SIDE);
/// The local search's budget of expanded cells in one piece of [`Run::poll`]. It is checked
/// before each window, so 1 is one window a piece (at most `REFINE_SIDE^2` = 2,704 expanded
/// cells; the largest measured under `-icount`, `BENCHMARKS.md` 4d: 0.8 M instructions on
/// Sydney, 0.5 M on NewYork; 8,192 cells a piece were 2.6 M).
const REFINE_SLICE: u64 = 1;
/// Raw cells of the smoothing DP in one piece of [`Run::poll`] (each tests at most
/// [`crate::polish::smoothing::LOOKBACK`] segments, or the bounded scan's fewer; 48 were up to 2.8 M
/// instructions on maze512's 4,000-cell path, 4 keep the DP's pieces under 0.4 M).
const SMOOTH_SLICE: usize = 4;
/// Work units of the smoothing's tail ([`Smoother::finish_piece`]: the trace, the merge and the
/// taut pull; about a segment test's row each) in one piece of [`Run::poll`].
const TAIL_UNITS: u32 = 8192;

/// Words at the end of the pheromone increments that the route's stash holds (the local
/// `sm`, with [`Shortfalls::SMOOTHING`] noted in `short` when it smooths with a cheaper rule
/// than `kind` (its links were short).
fn noted(sm: Smoother, kind: SmoothingKind, short: &mut Shortfalls) -> Smoother {
    if sm.kind() != kind {
        short.insert(Shortfalls::SMOOTHING);
    }
    sm
}

/// search's memo stays before them).
fn stash_tail(stashed: bool, blocks: crate::colony::pheromone::Blocks) -> usize {
    if stashed {
        route::stash_len(blocks)
    } else {
        0
    }
}

/// The work after the last iteration, in order: one piece a [`Run::poll`]; the end is
/// [`End::Path`].
#[derive(Clone, Copy, Debug)]
pub(super) enum Polish {
    /// Not started: the best path is only the best tour's directions.
    Start,
    /// The local search on the raw path in `points`, a budget at a time.
    Refine(Refiner),
    /// The smoothing of the raw path in `points`, a stretch at a time.
    Smooth(Smoother),
    /// The smoothing's steps after its DP ([`Smoother::finish_piece`]), then the corridor.
    Tail(Smoother),
}

impl Run<'_, '_> {
    /// Do the piece `piece` of the work after the last iteration and move to the next: lay the
    /// best path out as cells, the local search ([`Params::refine`], large maps) on at most 8,192
    /// expanded cells, the smoothing DP on at most 48 raw cells (its last piece also the corridor
    /// search), then the end ([`End::Path`]).
    pub(super) fn polish_piece(&mut self, piece: Polish) {
        let Some(best) = self.best else {
            self.phase = Phase::Ended(End::NoArrival);
            return;
        };
        let grid = self.grid;
        // The answer, the increments, the route and the buffers idle after the last ant
        // (`lend::Polishing`).
        let mut ws = self.ws.polishing();
        let kind = if self.params.algorithm == Algorithm::Ohaca {
            self.params.smoothing
        } else {
            SmoothingKind::None
        };
        // The exact corridor search of small maps ([`crate::polish::corridor`]): OHACA's default smoothing
        // on maps whose pheromone increments lend one entry a cell.
        let corridor = kind == SmoothingKind::Shortest && self.blocks.shift() == 0;
        self.phase = match piece {
            Polish::Start => {
                // Expand the tour into cells.
                let n = best.steps.saturating_add(1);
                let tour = ws.best.get(..best.steps).unwrap_or_default();
                for (slot, p) in ws.points.iter_mut().zip(RawPath::new(self.start, tour)) {
                    *slot = p;
                }
                // Stash the coarse route's links for the next warm start ([`Run::keep`])
                // before the local search takes the route's words as scratch: in the last
                // slots of the pheromone increments, which the smoothing leaves alone (it uses
                // a ring of at most `LOOKBACK + 1` from the front).
                if let (true, Guide::Words(words)) = (self.routed, &ws.guide) {
                    let dist = ws.delta.as_flattened_mut();
                    let n = route::stash_len(self.guide_blocks);
                    let room = dist.len().saturating_sub(LOOKBACK.wrapping_add(1));
                    self.stashed = n <= room && {
                        let at = dist.len().wrapping_sub(n);
                        let out = dist.get_mut(at..).unwrap_or_default();
                        route::stash(self.guide_blocks, words, out)
                    };
                    if !self.stashed {
                        self.short.insert(Shortfalls::STASH);
                    }
                }
                let refiner = self
                    .refines
                    .then(|| Refiner::in_place(grid, ws.points, n, refine::DEFAULT_PASSES).ok())
                    .flatten();
                if refiner.is_some() {
                    Memo::clear(lend::memo(
                        ws.delta,
                        stash_tail(self.stashed, self.guide_blocks),
                    ));
                }
                Phase::Polish(match refiner {
                    Some(r) => Polish::Refine(r),
                    None => Polish::Smooth(noted(
                        Smoother::new(
                            kind,
                            n,
                            ws.delta.as_flattened_mut(),
                            &mut ws.idle.smoothing(n),
                        ),
                        kind,
                        &mut self.short,
                    )),
                })
            }
            Polish::Refine(mut r) => {
                // Large maps: the links and the coarse route's words; small maps: two halves of
                // the links (see `SMALL_REFINE_SIDE`).
                let (a, b) = if self.blocks.shift() > 0 {
                    let lent = ws
                        .idle
                        .refine(&mut ws.guide, REFINE_WORDS, SHORT_REFINE_WORDS);
                    if lent.is_none() {
                        self.short.insert(Shortfalls::REFINE);
                    }
                    lent.unwrap_or((&mut [], &mut []))
                } else {
                    let (a, b) = ws.idle.halves_of_links(SMALL_REFINE_WORDS);
                    if b.len() < SMALL_REFINE_WORDS {
                        self.short.insert(Shortfalls::REFINE);
                    }
                    (a, b)
                };
                let mut budget = Budget::new(REFINE_SLICE);
                let tail = stash_tail(self.stashed, self.guide_blocks);
                let memo = Memo::reopen(lend::memo(ws.delta, tail));
                let mut scratch = Scratch::new(a, b).with_memo(memo);
                if r.resume(grid, ws.points, &mut scratch, &mut budget) {
                    let n = r.finish(ws.points);
                    // The refined path becomes the run's raw path: its directions replace the
                    // best tour (never longer, at most as many cells as `points` holds).
                    let raw = ws.points.get(..n).unwrap_or_default();
                    let (mut straight, mut diagonal) = (0u32, 0u32);
                    for (slot, pair) in ws.best.iter_mut().zip(raw.windows(2)) {
                        if let (Some(&p), Some(&q)) = (pair.first(), pair.get(1)) {
                            let d = direction(p, q).unwrap_or(0);
                            *slot = d;
                            if is_diagonal(d) {
                                diagonal = diagonal.saturating_add(1);
                            } else {
                                straight = straight.saturating_add(1);
                            }
                        }
                    }
                    self.colony = Some(best);
                    self.best = Some(Best {
                        steps: n.saturating_sub(1).min(ws.best.len()),
                        straight,
                        diagonal,
                    });
                    // The refined path is locally shortest: the smoothing's bounded scan.
                    let sm = Smoother::new(
                        kind,
                        n,
                        ws.delta.as_flattened_mut(),
                        &mut ws.idle.smoothing(n),
                    );
                    Phase::Polish(Polish::Smooth(noted(sm, kind, &mut self.short).bounded()))
                } else {
                    Phase::Polish(Polish::Refine(r))
                }
            }
            Polish::Smooth(mut sm) => {
                let dist = ws.delta.as_flattened_mut();
                let mut links = ws.idle.smoothing(sm.cells());
                if sm.resume(grid, ws.points, dist, &mut links, SMOOTH_SLICE) {
                    Phase::Polish(Polish::Smooth(sm))
                } else {
                    Phase::Polish(Polish::Tail(sm))
                }
            }
            Polish::Tail(mut sm) => {
                let dist = ws.delta.as_flattened_mut();
                let mut links = ws.idle.smoothing(sm.cells());
                match sm.finish_piece(grid, ws.points, dist, &mut links, TAIL_UNITS) {
                    None => Phase::Polish(Polish::Tail(sm)),
                    Some(k) => {
                        let waypoints = if corridor {
                            crate::polish::corridor::try_shortest(
                                grid,
                                ws.points,
                                k,
                                crate::polish::corridor::RADIUS,
                                ws.delta,
                                ws.idle.links(),
                            )
                            .unwrap_or_else(|_| {
                                // The smoothed path stays as it is.
                                self.short.insert(Shortfalls::CORRIDOR);
                                k.min(ws.points.len())
                            })
                        } else {
                            k
                        };
                        Phase::Ended(End::Path { waypoints })
                    }
                }
            }
        };
    }
}
