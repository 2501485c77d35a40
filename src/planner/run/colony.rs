//! One iteration of the colony: every ant walks on the same pheromone and deposits into the
//! increment table, the wolves rule rewards the iteration's best path and punishes its worst, the
//! pheromone evaporates and takes the increments, and the run records its best path, the
//! convergence curve and whether to stop early.

use crate::colony::ant::{Ant, DeadEnd, Lost, Walk};
use crate::colony::pheromone::Table;
use crate::colony::tighten::tighten;
use crate::colony::update::{deposit, wolves, WolfPaths};
use crate::geometry::steps_length;
use crate::map::grid::{Dir, Moves, Point, Reach};
use crate::rng::Xoshiro128pp;

use crate::planner::lend::Colony;
use crate::planner::plan::CurvePoint;

use super::Run;

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
    point.arrived == ants && point.mean * REFINE_GAIN <= point.best
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

/// How to walk one ant of an iteration again: the generator's state before its walk and its move
/// budget. The pheromone, the pruning marks and the route do not change during an iteration (the
/// ants deposit into the increments), so the same state gives the same walk, bit for bit.
#[derive(Clone, Debug)]
pub(super) struct Replay {
    rng: Xoshiro128pp,
    budget: u32,
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
}

/// The iteration's best and worst paths for [`wolves`], each from where it is: `iter_best` and
/// `iter_worst` on a workspace that keeps them, else walked again from their ants' [`Replay`]s
/// (`again`: the replay, the path's steps, the buffer), the best into `best` when it is a new
/// run best (`record` wants it there: `placed`), else into `tour`, the worst into `tour` once the
/// best's deposit is done.
struct Paths<'p, F> {
    again: &'p mut F,
    it: &'p Iteration,
    /// Steps of the best and the worst path.
    steps: (usize, usize),
    /// `iter_best`, `iter_worst` where the workspace keeps them.
    kept: (Option<&'p [Dir]>, Option<&'p [Dir]>),
    best: &'p mut [Dir],
    tour: &'p mut [Dir],
    /// The iteration's best path is a new run best.
    new_best: bool,
    /// The best path was walked into `best`.
    placed: bool,
}

impl<F: FnMut(&Option<Replay>, usize, &mut [Dir]) -> bool> WolfPaths for Paths<'_, F> {
    fn best(&mut self) -> Option<&[Dir]> {
        let n = self.steps.0;
        if let Some(kept) = self.kept.0 {
            return kept.get(..n);
        }
        // A new run best is walked straight into `best`, where `record` wants it.
        let buf: &mut [Dir] = if self.new_best { self.best } else { self.tour };
        if (self.again)(&self.it.best_replay, n, buf) {
            self.placed = self.new_best;
            buf.get(..n)
        } else {
            None
        }
    }

    fn worst(&mut self) -> Option<&[Dir]> {
        let n = self.steps.1;
        if let Some(kept) = self.kept.1 {
            return kept.get(..n);
        }
        if (self.again)(&self.it.worst_replay, n, self.tour) {
            self.tour.get(..n)
        } else {
            None
        }
    }
}

/// One ant's walk, tightened ([`tighten`]) when `tight` and the walk may have a shortcut: the path
/// the ant deposits on, in `tour`.
#[allow(clippy::too_many_arguments)]
fn walk_tightened(
    ant: &Ant<'_, '_, '_>,
    tight: bool,
    rng: &mut Xoshiro128pp,
    tabu: &mut [u32],
    tour: &mut [Dir],
    points: &mut [Point],
    links: &mut [u32],
) -> Result<Walk, Lost> {
    let walk = ant.walk(rng, tabu, tour)?;
    Ok(if tight && walk.may_tighten {
        tighten(ant.moves, ant.start, walk, tour, points, links, tabu)
    } else {
        walk
    })
}

impl Run<'_, '_> {
    /// Every ant walks start -> goal on `tau(t)` and deposits `Q / L` into the increment table;
    /// then the wolves rule rewards the iteration's best path and punishes its worst (also into
    /// the increments), and a best path shorter than the run's becomes the run's (`best`).
    ///
    /// The best and worst paths are copied into `iter_best` and `iter_worst` as the ants find
    /// them, or, on a workspace without those buffers (empty), walked again from their ants'
    /// [`Replay`] once every ant has walked: two more walks an iteration for two tours fewer,
    /// the same increments and the same best path bit for bit (`docs/ALGORITHM.md`, "Memory").
    pub(super) fn walk_ants(&mut self, mut on_tour: impl FnMut(&[Dir])) -> Iteration {
        let p = self.params;
        // Every buffer an ant reads or writes (`lend::Colony`).
        let Colony {
            tau,
            delta,
            tabu,
            dead,
            moves,
            tours: [tour, iter_best, iter_worst, best],
            index: (points, links),
            guide,
        } = self.ws.colony();
        let moves = Moves::new(*self.grid, moves);
        let (width, height) = (self.grid.width(), self.grid.height());
        let route = guide.route(self.guide_blocks, self.goal, width, height);
        let tau = Table::new(self.blocks, tau);
        let mut delta = Table::new(self.blocks, delta);
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
            budget: u32::MAX,
        };
        let (keep_best, keep_worst) = (!iter_best.is_empty(), !iter_worst.is_empty());
        let mut it = Iteration::default();
        // The move budget (see `MOVE_BUDGET`): from the cheapest walk that arrived in this run.
        let bounded = self.iteration > 0 && self.refines && p.dead_end == DeadEnd::Backtrack;
        for _ in 0..p.ants {
            if let (true, Some(c)) = (bounded, self.cheapest) {
                ant.budget = c.saturating_mul(MOVE_BUDGET);
            }
            let before = (!keep_best || !keep_worst).then(|| Replay {
                rng: self.rng.clone(),
                budget: ant.budget,
            });
            let walk =
                match walk_tightened(&ant, p.tighten, &mut self.rng, tabu, tour, points, links) {
                    Ok(w) => w,
                    Err(Lost::Exhausted) => {
                        // The goal is not reachable, proved by this ant: backtracking ants run
                        // without the setup's flood fill (`setup.rs`).
                        self.no_path = true;
                        break;
                    }
                    Err(Lost::Died) => continue,
                    Err(Lost::Budget) => {
                        self.moves = self.moves.saturating_add(u64::from(ant.budget));
                        self.abandoned = self.abandoned.saturating_add(1);
                        continue;
                    }
                    Err(Lost::Overflow) => {
                        self.dropped = self.dropped.saturating_add(1);
                        // An ant that outgrew its tour proves nothing about reachability. Before
                        // any ant has arrived, the flood fill the setup skipped decides it now,
                        // once: an unreachable goal ends the run with `NoPath` instead of
                        // iterations of dropped ants ending in `PathTooLong`. The tabu set and
                        // the links are scratch between walks.
                        if self.best.is_none() && it.arrived == 0 && !self.reach_checked {
                            self.reach_checked = true;
                            let grid = self.grid;
                            if grid.reachable(self.start, self.goal, tabu, links) == Reach::No {
                                self.no_path = true;
                                break;
                            }
                        }
                        continue;
                    }
                };
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
        }
        // The iteration's best path becomes the run's when it is shorter (see `record`).
        let new_best = it
            .best
            .map(|(b, _)| b)
            .filter(|b| self.best.is_none_or(|g| b.length() < g.length()));
        // Walk the ant of `r` again into `buf`: the path it deposited on, `steps` long.
        let mut again = |r: &Option<Replay>, steps: usize, buf: &mut [Dir]| -> bool {
            let Some(r) = r else { return false };
            ant.budget = r.budget;
            let mut rng = r.rng.clone();
            matches!(
                walk_tightened(&ant, p.tighten, &mut rng, tabu, buf, points, links),
                Ok(w) if w.steps == steps
            )
        };
        let mut placed = false;
        if let (true, Some((b, nb)), Some((w, nw))) = (p.algorithm.wolves(), it.best, it.worst) {
            let mut paths = Paths {
                again: &mut again,
                it: &it,
                steps: (b.steps, w.steps),
                kept: (
                    keep_best.then_some(&*iter_best),
                    keep_worst.then_some(&*iter_worst),
                ),
                best,
                tour,
                new_best: new_best.is_some(),
                placed: false,
            };
            let lengths = ((b.length(), nb), (w.length(), nw));
            wolves(&mut delta, self.grid, self.start, p.q, lengths, &mut paths);
            placed = paths.placed;
        }
        if let (Some(b), false) = (new_best, placed) {
            if keep_best {
                if let Some(src) = iter_best.get(..b.steps) {
                    copy_tour(best, src);
                }
            } else {
                again(&it.best_replay, b.steps, best);
            }
        }
        it
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
        self.done = self.no_path || self.iteration >= p.iterations || early || agreed;
    }
}

fn copy_tour(dst: &mut [Dir], src: &[Dir]) {
    if let Some(d) = dst.get_mut(..src.len()) {
        d.copy_from_slice(src);
    }
}
