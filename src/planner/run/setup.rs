//! The setup of a run before its first iteration, one piece at a time: the flood fill (is the
//! goal reachable at all?), dead-end pruning, the coarse route of a large map. The fill and the
//! pruning read the map (the default preset skips the fill; only the full layout prunes), the
//! route only the blocks its search closes ([`crate::colony::route::search`]); each is a piece of
//! [`Run::poll`].

use crate::colony::ant::DeadEnd;
use crate::colony::route;
use crate::map::grid::{Moves, Reach};
use crate::map::prune;

use super::{Area, End, Phase, Run, Setup, Shortfalls};

/// Blocks the coarse route's search closes in one piece of [`Run::poll`] (each reads its border
/// cells' links: a few thousand instructions a block). Measured under `-icount`
/// (`scripts/bench_pieces.py`): at 160 blocks a piece Sydney's route (H743 twin) took 1.24 M
/// instructions; at 112 the largest route piece is 0.57 M on NewYork, 0.59 M on the depot.
const ROUTE_BLOCKS: u32 = 112;

/// Cells the pruning from scratch tries in one piece of [`Run::poll`] (`prune::resume`: a
/// 32-cell window of the first pass counts as one; a few hundred instructions each, the settling
/// of a pruned cell's dead branch included). Measured under `-icount`
/// (`scripts/bench_pieces.py`): at 2,000 Sydney's largest pruning piece (H743 twin) was 1.035 M
/// instructions, at 1,600 it is 0.83 M.
const PRUNE_TRIES: u32 = 1_600;

impl Run<'_, '_> {
    /// The coarse route's search ended (`Ok(Some(_))`), was not wanted (`Ok(None)`) or found no
    /// room: the colony is next.
    fn routed(&mut self, routed: Result<Option<route::Searched>, route::Short>) {
        self.routed = match routed {
            Ok(Some(_searched)) => {
                crate::fmt::debug!(
                    "plan: route closed {} blocks, read {} blocks' links",
                    _searched.closed,
                    _searched.linked
                );
                true
            }
            Ok(None) => false,
            // A workspace laid out without room for the route (none the arena lays out): said,
            // not silent; the ants are pulled at the goal.
            Err(route::Short) => {
                crate::fmt::warning!("plan: no room for the coarse route");
                self.short.insert(Shortfalls::ROUTE);
                false
            }
        };
        crate::fmt::debug!("plan: {} cells pruned", self.pruned);
        self.phase = Phase::Colony(Default::default());
    }

    /// Do the piece `piece` of the setup and move to the next: the flood fill (a goal found
    /// unreachable ends the run: [`Run::finish`] gives [`crate::Error::NoPath`]), the dead-end
    /// pruning, the coarse route (then the colony). The flood fill and the pruning read the whole
    /// map once, the route only the blocks its bounded search closes.
    pub(super) fn setup_piece(&mut self, piece: Setup) {
        let grid = self.grid;
        let p = &self.params;
        // What the setup owns and the buffers it borrows until the first ant (`lend::Setting`).
        let mut ws = self.ws.setting();
        match piece {
            Setup::Reach => {
                // Backtracking ants skip the flood fill, cold or warm: if the goal is cut off,
                // the first ant backs out of every branch of the start's component and proves it
                // (`Lost::Exhausted`: the run ends with `NoPath`) for about what the flood fill
                // would have cost (both visit that component once); otherwise the fill is pure
                // overhead, a pass over every cell the plan could reach (4.6 M instructions of a
                // 90 M plan on Boston 256; issue 27). Only the paper's dying ants, which cannot
                // prove anything, still need it.
                let proved_by_ants = p.dead_end == DeadEnd::Backtrack;
                self.reach_checked = !proved_by_ants;
                if !proved_by_ants
                    && grid.reachable(self.start, self.goal, ws.idle.reach()) == Reach::No
                {
                    self.phase = Phase::Ended(End::NoPath);
                    return;
                }
                self.phase = Phase::Setup(Setup::Prune(None));
            }
            Setup::Prune(at) => {
                // A workspace without pruning marks (`dead` empty) plans without pruning.
                self.pruned = if p.prune && !ws.dead.is_empty() {
                    let moves = Moves::new(*grid, ws.moves);
                    self.marks = true;
                    match self.reuse {
                        // A warm start on the last run's marks: repair them around the changes
                        // and the two starts (the same marks as pruning again, `prune::repair`).
                        Some((changes, kept)) => {
                            let r = prune::repair(
                                &moves,
                                (kept.start, self.start, self.goal),
                                changes.map(Area::corners),
                                ws.dead,
                                ws.idle.prune_stack(),
                            );
                            let touched = r.touched.map(|(min, max)| Area { min, max });
                            self.touched = match (touched, changes) {
                                (Some(a), Some(b)) => Some(a.union(b)),
                                (a, b) => a.or(b),
                            };
                            // Relinking the whole map is building the route.
                            self.relinked &= !r.rebuilt;
                            r.pruned
                        }
                        // From scratch, at most `PRUNE_TRIES` cells tried a piece.
                        None => {
                            let mut at = at.unwrap_or_else(|| prune::begin(&moves, ws.dead));
                            let stack = ws.idle.prune_stack();
                            let (s, g) = (self.start, self.goal);
                            match prune::resume(&moves, s, g, ws.dead, stack, &mut at, PRUNE_TRIES)
                            {
                                Some(n) => n,
                                None => {
                                    self.phase = Phase::Setup(Setup::Prune(Some(at)));
                                    return;
                                }
                            }
                        }
                    }
                } else {
                    crate::map::bitmap::clear(ws.dead, grid.cells());
                    0
                };
                self.phase = Phase::Setup(Setup::Route(None));
            }
            Setup::Route(at) => {
                // Large maps: the potential field pulls along a coarse route (not for ACA, which
                // has no attraction), searched over the blocks the plan needs only
                // (`route::search`: from the goal's block until the start's block and every
                // block within the slack are closed; each block's links read as it closes), at
                // most `ROUTE_BLOCKS` blocks a piece.
                let wanted = self.blocks.shift() > 0 && p.algorithm.attracts();
                if !wanted {
                    self.routed(Ok(None));
                    return;
                }
                let (ends, blocks) = ((self.start, self.goal), self.guide_blocks);
                let moves = Moves::new(*grid, ws.moves);
                let count = blocks.count();
                let (relink, area) = (self.relinked && self.marks, self.touched.map(Area::corners));
                let packed = ws.guide.is_packed();
                // A packed route is built in words the tabu set, the path cells or the links lend
                // (idle until the first ant), then packed: built again each run, never repaired
                // (a packed route is kept only by workspaces without pruning marks).
                let bufs = if packed {
                    ws.idle
                        .packed_route(&mut ws.guide, count)
                        .map(|(pair, out)| (pair, Some(out)))
                } else {
                    ws.idle
                        .route_words(&mut ws.guide, count)
                        .map(|pair| (pair, None))
                };
                let Some(((words, mut heap), out)) = bufs else {
                    self.routed(Err(route::Short));
                    return;
                };
                let mut at = match at {
                    Some(at) => at,
                    // The last run's links, forgotten where the map or the marks changed.
                    None if relink && !packed => {
                        match route::begin_repair(
                            &moves, blocks, ends, ws.dead, words, &mut heap, area,
                        ) {
                            Ok(at) => at,
                            Err(e) => return self.routed(Err(e)),
                        }
                    }
                    None => {
                        match route::begin_build(&moves, blocks, ends, ws.dead, words, &mut heap) {
                            Ok(at) => at,
                            Err(e) => return self.routed(Err(e)),
                        }
                    }
                };
                let bound = route::Bound::Plan;
                let dead = &*ws.dead;
                let done = route::resume(
                    &moves,
                    blocks,
                    ends,
                    dead,
                    words,
                    &mut heap,
                    bound,
                    &mut at,
                    ROUTE_BLOCKS,
                );
                let routed = match (done, out) {
                    (Ok(None), _) => {
                        self.phase = Phase::Setup(Setup::Route(Some(at)));
                        return;
                    }
                    (Ok(Some(r)), Some(out)) => {
                        if route::pack(blocks, words, out) {
                            Ok(Some(r))
                        } else {
                            Err(route::Short)
                        }
                    }
                    (Ok(Some(r)), None) => Ok(Some(r)),
                    (Err(e), _) => Err(e),
                };
                self.routed(routed);
            }
        }
    }
}
