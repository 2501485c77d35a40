//! One iteration of the colony: every ant walks on the same pheromone and deposits into the
//! increment table, the wolves rule rewards the iteration's best path and punishes its worst, the
//! pheromone evaporates and takes the increments, and the run records its best path, the
//! convergence curve and whether to stop early.

use crate::colony::ant::{Ant, DeadEnd, Lost, Walk};
use crate::colony::pheromone::Table;
use crate::colony::update::{deposit, wolves_amounts};
use crate::geometry::steps_length;
use crate::map::grid::{Dir, FillScratch, Filling, Moves, Reach};
use crate::rng::Xoshiro128pp;

use crate::planner::lend::Colony;
use crate::planner::plan::CurvePoint;

use super::walk::{again, charge, go, start_cost, Going, Replay, FILL_CELLS, MOVES_A_PIECE};
use super::{Phase, Run};

/// From its second iteration on, an ant of a run with the local search may make at most this many
/// times the moves (forward and back) of the cheapest walk that arrived so far in the run; one
/// that needs more is abandoned ([`Lost::Budget`]). Not in the paper, and off without the local
/// search (the paper preset).
///
/// Why: a backtracking ant is a randomised depth-first search. In an open area (a 10-wide maze
/// corridor, a room) the potential field can lead it to wall itself in with its own trail; it
/// then backs out through every unvisited cell reachable from its path before it finds the way
/// on. Measured on `maze-128-128-10` (20 ants on `tau0`, the longest scenario): 15 of 20 ants make
/// 1.0-1.01 moves a path step, 5 make 4-35 (one visited 12,740 of the maze's cells), and those 5
/// are 90 % of all moves. Their paths are long detours (the iteration's worst, punished by the
/// wolves rule); with the local search they add nothing the run needs. A budget of 3 times the
/// cheapest arrived walk leaves every ant that goes more or less straight (detours included)
/// alone and stops the walled-in ones early (a budget in path steps instead abandoned 49 of 50
/// ants on `ht_chantry`, where every ant backtracks a lot). The first iteration has no budget, so
/// a run always has its first paths as before; `BENCHMARKS.md` and `docs/ALGORITHM.md` have the
/// figures.
pub(super) const MOVE_BUDGET: u32 = 3;

/// How much shorter a new best must be to end a stale streak in a run that refines its result
/// ([`crate::Params::refine`]): below `REFINE_GAIN` times the best of the iteration that last
/// ended one. A smaller gain still becomes the run's best (its path is kept), but counts as a
/// stale iteration for `refine_patience`.
///
/// Why: the local search replaces every piece of the best path by the exact shortest path in a
/// window around it, so the colony's slow gains (a corner cut, a wiggle straightened: 0.1-0.5 %
/// an iteration in a wide corridor) are what the local search does anyway. What the colony alone
/// finds is another way round an obstacle, which on the maps measured gains more. Measured on
/// `maze-128-128-10` (the longest scenario): the best fell 468.1 -> 459.5 over 13 iterations,
/// 0.1-0.7 % at a time, and the local search makes every one of those paths the same optimum
/// (453.9); `BENCHMARKS.md` 1b has the quality of all large maps with this rule.
pub const REFINE_GAIN: f32 = 0.99;

/// Whether an iteration of a run that refines settled its corridor: every ant of it arrived and
/// their mean length is within [`REFINE_GAIN`] of the iteration's best (`mean * REFINE_GAIN <=
/// best`, on the iteration's [`CurvePoint`], so the plan's curve replays it). Such a run stops
/// there, whatever its patience, on a map of more than [`crate::colony::pheromone::BLOCKS`] cells (the
/// pheromone in blocks, the local search in windows). Not in the paper, and off without the local
/// search (the paper preset).
///
/// Why: with the local search the colony only has to choose the corridor, and the next
/// iteration counts as progress only if it gains more than 1 % ([`REFINE_GAIN`]). When this
/// iteration's ants, drawn independently, all arrived and agree to within that on average, none
/// of them found a way that much shorter than the rest, and the next iteration's ants, drawn
/// from the pheromone those ants laid on that corridor, are less likely still to; the local
/// search then makes the path inside it. Where the choice is real the ants disagree and the
/// run goes on as before (`ht_chantry`'s plans are unchanged). Measured
/// (`docs/bench/colony-issue36.md`, `docs/ALGORITHM.md`): ant moves a plan halve on the mazes
/// and drop by a third on the cities and the depot, and the mean raw length over the 20 large
/// maps is 1.0009 against 1.0008 (1.0009 both with seeds 1-4).
pub fn settled(point: &CurvePoint, ants: u16) -> bool {
    point.walked == ants && point.arrived == ants && point.mean * REFINE_GAIN <= point.best
        || crate::planner::quorum::ended(point, ants)
}

/// The best path of an iteration or of the run, as step counts (exact length comparison).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Best {
    pub(super) steps: usize,
    pub(super) straight: u32,
    pub(super) diagonal: u32,
}

impl Best {
    pub(super) fn of(w: &Walk) -> Self {
        Best {
            steps: w.steps,
            straight: w.straight,
            diagonal: w.diagonal,
        }
    }
    pub(super) fn length(&self) -> f32 {
        steps_length(self.straight, self.diagonal)
    }
    pub(super) fn same_length(&self, o: &Best) -> bool {
        self.straight == o.straight && self.diagonal == o.diagonal
    }
}

/// What the ants of one iteration found: the shortest and the longest path (with how many ants
/// took a path of that length) and the sum of the lengths, for the update and the record.
#[derive(Clone, Debug, Default)]
pub(super) struct Iteration {
    best: Option<(Best, u32)>,
    worst: Option<(Best, u32)>,
    /// The best path's ant, on a workspace without `iter_best` (walked again at the update).
    best_replay: Option<Replay>,
    /// The worst path's ant, on a workspace without `iter_worst`.
    worst_replay: Option<Replay>,
    sum: f32,
    arrived: u32,
    /// An ant of this iteration proved the goal unreachable (the run ends with `NoPath`).
    no_path: bool,
    /// Ants walked (all of them unless the quorum ended the iteration, [`crate::planner::quorum`]).
    walked: u16,
}

/// Where the colony's iteration stands between two pieces ([`Run::poll`]).
#[derive(Clone, Debug, Default)]
pub(super) struct Walking {
    /// What the ants that walked found.
    it: Iteration,
    /// Ants whose walk ended.
    ant: u16,
    /// The walk in progress: where it (or its tightening) stands, the generator's state before
    /// it (for a [`Replay`]) and its move budget.
    now: Option<(Going, Option<Replay>, u32)>,
    /// After the ants: what is left of the iteration.
    close: Close,
    /// A walk again in progress (a [`Replay`]): where it (or its tightening) stands and its
    /// generator.
    again: Option<(Going, Xoshiro128pp)>,
    /// The best path was walked again into `best` for the wolves rule.
    placed: bool,
    /// The flood fill an ant that outgrew its tour started (see `Lost::Overflow` below), where it
    /// paused; it ends before the next ant walks (it uses the tabu set and the links).
    filling: Option<Filling>,
}

impl Walking {
    /// Whether this iteration has begun (an ant walked or walks).
    pub(super) fn started(&self) -> bool {
        self.ant > 0 || self.now.is_some() || self.close != Close::Ants || self.filling.is_some()
    }

    /// The name of the next piece ([`Run::piece`]).
    pub(super) fn piece(&self) -> &'static str {
        match self.close {
            Close::Ants => "walk",
            Close::Best | Close::Worst => "wolves",
            Close::Place => "place",
            Close::Update => "update",
        }
    }
}

/// The steps of an iteration after its ants, in order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Close {
    /// The ants walk.
    #[default]
    Ants,
    /// The wolves rule's reward on the iteration's best path (walked again if not kept).
    Best,
    /// The wolves rule's punishment on its worst path (walked again if not kept).
    Worst,
    /// A new run best into `best` (walked again if not kept and not walked for the wolves).
    Place,
    /// The pheromone update and the record.
    Update,
}

impl Run<'_, '_> {
    /// One piece of the colony's iteration: the ants walk start -> goal on `tau(t)` (at most
    /// [`MOVES_A_PIECE`] moves a piece, an ant's walk split over pieces as needed) and each
    /// deposits `Q / L` into the increment table; then the wolves rule rewards the iteration's
    /// best path and punishes its worst (also into the increments), a best path shorter than the
    /// run's becomes the run's (`best`), and the update and the record end the iteration.
    ///
    /// The best and worst paths are copied into `iter_best` and `iter_worst` as the ants find
    /// them, or, on a workspace without those buffers (empty), walked again from their ants'
    /// [`Replay`] once every ant has walked: two more walks an iteration for two tours fewer,
    /// the same increments and the same best path bit for bit (`docs/ALGORITHM.md`, "Memory").
    /// The ants walk in the same order with the same draws however the pieces cut them.
    pub(super) fn colony_piece(&mut self, mut w: Walking, on_tour: &mut dyn FnMut(&[Dir])) {
        let p = self.params;
        // The walks read a weight table where they walk by the loop for an entry a cell (the
        // pheromone's block shift 0, no route: `Ant::resume`).
        let table = (self.blocks.shift() == 0 && !self.routed).then_some((
            usize::from(self.grid.width()),
            usize::from(self.grid.height()),
        ));
        // Every buffer an ant reads or writes (`lend::Colony`).
        let Colony {
            tau,
            delta,
            mut tabu,
            dead,
            moves,
            tours: [tour, iter_best, iter_worst, best],
            index: (points, links),
            guide,
            #[cfg(any(feature = "alloc", test))]
            weights,
        } = self.ws.colony(table);
        let moves = Moves::new(*self.grid, moves);
        let (width, height) = (self.grid.width(), self.grid.height());
        let route = guide.route(self.guide_blocks, self.goal, width, height);
        let tau = Table::new(self.blocks, tau);
        let mut delta = Table::new(self.blocks, delta);
        #[cfg(any(feature = "alloc", test))]
        if let (Some(t), false) = (&weights, w.started()) {
            // A new iteration (the pheromone changed at the update before it, or the run began):
            // every row is filled again from it.
            t.clear();
        }
        let mut ant = Ant {
            moves: &moves,
            start: self.start,
            goal: self.goal,
            tau: &tau,
            heuristic: &self.heuristic,
            alpha: p.alpha,
            dead_end: p.dead_end,
            dead,
            route: self.routed.then_some(&route),
            #[cfg(any(feature = "alloc", test))]
            weights: weights.as_ref(),
            budget: u32::MAX,
        };
        let (keep_best, keep_worst) = (!iter_best.is_empty(), !iter_worst.is_empty());
        // The move budget (see `MOVE_BUDGET`): from the cheapest walk that arrived in this run.
        let bounded = self.iteration > 0 && self.refines && p.dead_end == DeadEnd::Backtrack;
        let cells = self.grid.cells();
        let mut left = MOVES_A_PIECE;
        // The iteration's best path becomes the run's when it is shorter (see `record`); the
        // run's best changes only in `record`.
        let new_best = |it: &Iteration, run_best: Option<Best>| {
            it.best
                .map(|(b, _)| b)
                .filter(|b| run_best.is_none_or(|g| b.length() < g.length()))
        };
        let tight = p.tighten;
        // Before the run has a best path, `best` is free, and the iteration's best (if any ant
        // arrives) becomes the run's: a workspace without `iter_best` keeps it there as the ants
        // find it instead of walking its ant again (the same path bit for bit, see `Replay`).
        let best_free = !keep_best && self.best.is_none() && !best.is_empty();
        // The quorum where `settled` applies (see `record`).
        let quorum = self.refines && self.blocks.shift() > 0;
        while left > 0 {
            match w.close {
                Close::Ants => {
                    if let Some(mut fill) = w.filling.take() {
                        let cells = (left as usize).saturating_mul(FILL_CELLS);
                        let grid = self.grid;
                        let mut scratch = FillScratch::new(tabu.lend(), links);
                        match grid.reach_resume(self.goal, &mut scratch, &mut fill, cells) {
                            None => {
                                w.filling = Some(fill);
                                left = 0;
                            }
                            Some(reach) => {
                                left = left.saturating_sub(1);
                                w.it.no_path |= reach == Reach::No;
                            }
                        }
                        continue;
                    }
                    let (mut going, before, budget) = match w.now.take() {
                        Some(now) => now,
                        None if w.ant < p.ants && !w.it.no_path => {
                            let budget = match (bounded, self.cheapest) {
                                (true, Some(c)) => c.saturating_mul(MOVE_BUDGET),
                                _ => u32::MAX,
                            };
                            let before = (!keep_best || !keep_worst).then(|| Replay {
                                rng: self.rng.clone(),
                                budget,
                            });
                            left = left.saturating_sub(start_cost(cells));
                            w.it.walked = w.ant.saturating_add(1);
                            (Going::Walk(ant.begin(&mut tabu, tour)), before, budget)
                        }
                        None => {
                            w.close = Close::Best;
                            continue;
                        }
                    };
                    ant.budget = budget;
                    let idx = (&mut *points, &mut *links);
                    let rng = &mut self.rng;
                    let short = &mut self.short;
                    let walk = match go(
                        &ant, tight, &mut going, rng, &mut tabu, tour, idx, &mut left, short,
                    ) {
                        Ok(None) => {
                            w.now = Some((going, before, budget));
                            continue;
                        }
                        Ok(Some(walk)) => {
                            charge(&mut left, walk.steps);
                            walk
                        }
                        Err(lost) => {
                            w.ant = w.ant.saturating_add(1);
                            match lost {
                                Lost::Exhausted => {
                                    // The goal is not reachable, proved by this ant: backtracking
                                    // ants run without the setup's flood fill (`setup.rs`).
                                    w.it.no_path = true;
                                }
                                Lost::Died => {}
                                Lost::Budget => {
                                    self.moves = self.moves.saturating_add(u64::from(budget));
                                    self.abandoned = self.abandoned.saturating_add(1);
                                }
                                Lost::Overflow => {
                                    self.dropped = self.dropped.saturating_add(1);
                                    // An ant that outgrew its tour proves nothing about
                                    // reachability. Before any ant has arrived, the flood fill
                                    // the setup skipped decides it now, once: an unreachable goal
                                    // ends the run with `NoPath` instead of iterations of dropped
                                    // ants ending in `PathTooLong`. The tabu set and the links
                                    // are scratch between walks.
                                    if self.best.is_none()
                                        && w.it.arrived == 0
                                        && !self.reach_checked
                                    {
                                        self.reach_checked = true;
                                        // A piece at a time, before the next ant.
                                        let grid = self.grid;
                                        let mut scratch = FillScratch::new(tabu.lend(), links);
                                        match grid.reach_begin(self.start, self.goal, &mut scratch)
                                        {
                                            Ok(fill) => w.filling = Some(fill),
                                            Err(reach) => w.it.no_path |= reach == Reach::No,
                                        }
                                    }
                                }
                            }
                            continue;
                        }
                    };
                    w.ant = w.ant.saturating_add(1);
                    let it = &mut w.it;
                    // Tightening keeps the walk's moves.
                    self.moves = self.moves.saturating_add(u64::from(walk.moves));
                    self.cheapest = Some(self.cheapest.map_or(walk.moves, |c| c.min(walk.moves)));
                    let Some(path) = tour.get(..walk.steps) else {
                        continue;
                    };
                    on_tour(path);
                    let b = Best::of(&walk);
                    let len = b.length();
                    it.sum += len;
                    it.arrived = it.arrived.saturating_add(1);
                    deposit(&mut delta, self.grid, self.start, path, p.q / len);
                    match &mut it.best {
                        Some((cur, n)) if cur.same_length(&b) => *n = n.saturating_add(1),
                        Some((cur, _)) if len >= cur.length() => {}
                        _ => {
                            if keep_best {
                                copy_tour(iter_best, path);
                            } else if best_free {
                                copy_tour(best, path);
                            } else {
                                it.best_replay.clone_from(&before);
                            }
                            it.best = Some((b, 1));
                        }
                    }
                    match &mut it.worst {
                        Some((cur, n)) if cur.same_length(&b) => *n = n.saturating_add(1),
                        Some((cur, _)) if len <= cur.length() => {}
                        _ => {
                            if keep_worst {
                                copy_tour(iter_worst, path);
                            } else {
                                it.worst_replay.clone_from(&before);
                            }
                            it.worst = Some((b, 1));
                        }
                    }
                    if quorum {
                        let b = it.best.map_or(f32::INFINITY, |(b, _)| b.length());
                        if crate::planner::quorum::reached(w.ant, p.ants, it.arrived, it.sum, b) {
                            w.close = Close::Best;
                        }
                    }
                }
                Close::Best | Close::Worst => {
                    let amounts = match (p.algorithm.wolves(), w.it.best, w.it.worst) {
                        (true, Some((b, nb)), Some((x, nx))) => {
                            wolves_amounts(p.q, (b.length(), nb), (x.length(), nx))
                                .map(|a| (a, b.steps, x.steps))
                        }
                        _ => None,
                    };
                    let Some(((reward, punish), best_steps, worst_steps)) = amounts else {
                        w.close = Close::Place;
                        continue;
                    };
                    let is_best = w.close == Close::Best;
                    let (n, amount) = if is_best {
                        (best_steps, reward)
                    } else {
                        (worst_steps, punish)
                    };
                    let kept = if is_best {
                        // `best` when it was free: the ants left the path there.
                        if keep_best {
                            Some(&*iter_best)
                        } else if best_free {
                            Some(&*best)
                        } else {
                            None
                        }
                    } else {
                        keep_worst.then_some(&*iter_worst)
                    };
                    let path: Option<&[Dir]> = match kept {
                        Some(k) => k.get(..n),
                        None => {
                            // A new run best is walked straight into `best`, where `record`
                            // wants it; everything else into `tour`.
                            let into_best = is_best && new_best(&w.it, self.best).is_some();
                            let buf: &mut [Dir] = if into_best { best } else { tour };
                            let r = if is_best {
                                &w.it.best_replay
                            } else {
                                &w.it.worst_replay
                            };
                            let idx = (&mut *points, &mut *links);
                            match again(
                                &mut ant,
                                tight,
                                r,
                                n,
                                &mut w.again,
                                &mut tabu,
                                buf,
                                idx,
                                &mut left,
                            ) {
                                None => continue,
                                Some(true) => {
                                    w.placed |= into_best;
                                    let buf: &[Dir] = if into_best { best } else { tour };
                                    buf.get(..n)
                                }
                                Some(false) => None,
                            }
                        }
                    };
                    if let Some(t) = path {
                        charge(&mut left, t.len());
                        deposit(&mut delta, self.grid, self.start, t, amount);
                    }
                    w.close = if is_best { Close::Worst } else { Close::Place };
                }
                Close::Place => {
                    if let (Some(b), false) = (new_best(&w.it, self.best), w.placed || best_free) {
                        if keep_best {
                            if let Some(src) = iter_best.get(..b.steps) {
                                copy_tour(best, src);
                            }
                        } else {
                            let idx = (&mut *points, &mut *links);
                            let done = again(
                                &mut ant,
                                tight,
                                &w.it.best_replay,
                                b.steps,
                                &mut w.again,
                                &mut tabu,
                                best,
                                idx,
                                &mut left,
                            );
                            if done.is_none() {
                                continue;
                            }
                        }
                    }
                    w.close = Close::Update;
                }
                Close::Update => break,
            }
        }
        if w.close != Close::Update {
            self.phase = Phase::Colony(w);
            return;
        }
        self.update();
        self.record(&w.it);
    }

    /// `tau = clamp((1 - rho) tau + delta)` (the wolves terms are in `delta` already).
    pub(super) fn update(&mut self) {
        let p = self.params;
        let ws = &mut self.ws;
        let mut tau = Table::new(self.blocks, ws.tau);
        let mut delta = Table::new(self.blocks, ws.delta);
        tau.evaporate_and_merge(&mut delta, p.rho, p.tau_min, p.tau_max);
    }

    /// Track the run's best, append to the curve, decide whether to stop.
    pub(super) fn record(&mut self, it: &Iteration) {
        let improved = match (it.best, self.best) {
            (Some((b, _)), None) => Some(b),
            (Some((b, _)), Some(g)) if b.length() < g.length() => Some(b),
            _ => None,
        };
        // In a run that refines, only a gain of more than `REFINE_GAIN` ends a stale streak.
        let significant = |b: &Best, mark: f32| !self.refines || b.length() < mark * REFINE_GAIN;
        if let Some(b) = improved {
            // Its path is in `best` already (`walk_ants`).
            self.best = Some(b);
            self.best_iteration = self.iteration;
            if self.mark.is_none_or(|m| significant(&b, m)) {
                self.mark = Some(b.length());
                self.stale = 0;
            } else {
                self.stale = self.stale.saturating_add(1);
            }
        } else {
            self.stale = self.stale.saturating_add(1);
        }
        let inf = f32::INFINITY;
        let point = CurvePoint {
            best: it.best.map_or(inf, |(b, _)| b.length()),
            mean: if it.arrived > 0 {
                it.sum / it.arrived as f32
            } else {
                inf
            },
            best_so_far: self.best.map_or(inf, |b| b.length()),
            arrived: u16::try_from(it.arrived).unwrap_or(u16::MAX),
            walked: it.walked,
        };
        if let Some(slot) = self.ws.curve.get_mut(usize::from(self.iteration)) {
            *slot = point;
        }
        self.iteration = self.iteration.saturating_add(1);
        let p = &self.params;
        let patience = if self.warm && p.warm_patience > 0 {
            p.warm_patience
        } else if self.refines && p.refine_patience > 0 {
            p.refine_patience
        } else {
            p.patience
        };
        let early = patience > 0 && self.best.is_some() && self.stale >= patience;
        // Fewer ants where the corridor is settled (see `settled`): on maps whose local search
        // works in windows along the path (on a small map it is one exact search of the whole
        // map, and the colony's corridor does not matter at all).
        let agreed = self.refines && self.blocks.shift() > 0 && settled(&point, p.ants);
        self.phase = if it.no_path || self.iteration >= p.iterations || early || agreed {
            self.after_colony(it.no_path)
        } else {
            Phase::Colony(Walking::default())
        };
    }
}

fn copy_tour(dst: &mut [Dir], src: &[Dir]) {
    if let Some(d) = dst.get_mut(..src.len()) {
        d.copy_from_slice(src);
    }
}
