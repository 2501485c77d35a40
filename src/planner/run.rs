//! A planning run as a state machine: [`Run::new`] validates and prepares, [`Run::setup_step`]
//! does the setup a piece at a time, [`Run::step`] runs one iteration (walk every ant, update the
//! pheromone, record the iteration), [`Run::polish_step`] refines and smooths the best path a
//! piece at a time, and [`Run::finish`] turns it into a [`Plan`].
//!
//! The firmware yields to its executor between pieces, so it can answer other requests and cancel
//! a plan by dropping (or finishing) the run. How the work is cut never changes the result:
//! `step` and `finish` alone do every piece that is left.

use crate::ant::{Ant, DeadEnd, Lost, Walk};
use crate::error::{Endpoint, Error};
use crate::geometry::{polyline_length, steps_length, turns};
use crate::grid::{direction, is_diagonal, Dir, Grid, Moves, Point, Reach};
use crate::heuristic::Heuristic;
use crate::pheromone::{Blocks, Table};
use crate::prune::prune;
use crate::refine::{self, Budget, Refiner, Scratch};
use crate::rng::Xoshiro128pp;
use crate::route::{self, Route, GUIDE_BLOCKS};
use crate::smoothing::{Smoother, SmoothingKind};
use crate::tighten::tighten;
use crate::update::{deposit, wolves};

use super::params::{Algorithm, Params};
use super::plan::{CurvePoint, Plan, RawPath};
use super::warm::{self, Area, Memory};
use super::workspace::Workspace;

/// The best path of an iteration or of the run, as step counts (exact length comparison).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Best {
    steps: usize,
    straight: u32,
    diagonal: u32,
}

impl Best {
    fn of(w: &Walk) -> Self {
        Best {
            steps: w.steps,
            straight: w.straight,
            diagonal: w.diagonal,
        }
    }
    fn length(&self) -> f32 {
        steps_length(self.straight, self.diagonal)
    }
    fn same_length(&self, o: &Best) -> bool {
        self.straight == o.straight && self.diagonal == o.diagonal
    }
}

/// What the ants of one iteration found: the shortest and the longest path (with how many ants
/// took a path of that length) and the sum of the lengths, for the update and the record.
#[derive(Clone, Copy, Debug, Default)]
struct Iteration {
    best: Option<(Best, u32)>,
    worst: Option<(Best, u32)>,
    sum: f32,
    arrived: u32,
}

/// Window side of the local search ([`Params::refine`]). Its scratch is the links and the coarse
/// route's words, free after the last iteration: two slices of [`Scratch::words`]`(52)` = 4,056
/// words each, which the device's and the host's storage both lend (at least [`GUIDE_BLOCKS`]
/// words each on maps with a route). Measured on the 20 longest scenarios of the 20 large Moving
/// AI maps (`refine_large` example): mean raw/opt8 1.0009 at 52, 1.0011 at 48, 1.0007 at 64.
pub const REFINE_SIDE: usize = 52;
const REFINE_WORDS: usize = Scratch::words(REFINE_SIDE);
const _: () = assert!(REFINE_WORDS <= GUIDE_BLOCKS);
/// Cells the local search expands between two yields of [`Run::polish_step`] (a window expands
/// at most `REFINE_SIDE^2` = 2,704).
const REFINE_SLICE: u64 = 8192;
/// Raw cells of the smoothing DP between two yields of [`Run::polish_step`] (each tests at most
/// [`crate::smoothing::LOOKBACK`] segments).
const SMOOTH_SLICE: usize = 48;

/// The work after the last iteration, in order ([`Run::polish_step`]).
#[derive(Clone, Copy, Debug)]
enum Polish {
    /// Not started: the best path is only the best tour's directions.
    Start,
    /// The local search on the raw path in `points`, a budget at a time.
    Refine(Refiner),
    /// The smoothing of the raw path in `points`, a stretch at a time.
    Smooth(Smoother),
    /// Done: `points[..waypoints]` are the waypoints.
    Done { waypoints: usize },
}

/// A planning run in progress. See the module docs.
pub struct Run<'g, 'a> {
    grid: &'g Grid<'g>,
    start: Point,
    goal: Point,
    params: Params,
    heuristic: Heuristic,
    blocks: Blocks,
    guide_blocks: Blocks,
    rng: Xoshiro128pp,
    ws: Workspace<'a>,
    iteration: u16,
    best: Option<Best>,
    best_iteration: u16,
    stale: u16,
    moves: u64,
    pruned: u32,
    routed: bool,
    warm: bool,
    setup: Setup,
    refines: bool,
    polish: Polish,
    /// The colony's best path length, kept when the local search replaces the best path.
    colony: Option<Best>,
    no_path: bool,
    /// Ants dropped so far because their paths outgrew the workspace ([`Error::PathTooLong`]).
    dropped: u32,
    done: bool,
}

/// The setup still to do before the first iteration, in order. Each piece reads the whole map
/// once, so the firmware yields between them ([`Run::setup_step`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Setup {
    /// The flood fill (is the goal reachable at all?).
    Reach,
    /// Dead-end pruning ([`Params::prune`]).
    Prune,
    /// The coarse route on large maps.
    Route,
    /// Nothing: the ants can walk.
    Done,
}

impl<'g, 'a> Run<'g, 'a> {
    /// Validate everything and prepare a run: fails at once on bad parameters, a map larger than
    /// the workspace, or a start or goal off the map or on an obstacle; sets every pheromone entry
    /// to `tau0`. The rest of the setup (a flood fill: is the goal reachable at all?; pruning the
    /// cells no shortest path needs, [`Params::prune`]; the coarse route of a large map) runs in
    /// the first [`Run::step`], or piecewise through [`Run::setup_step`]; an unreachable goal
    /// ends the run there, and [`Run::finish`] fails with [`Error::NoPath`].
    pub fn new(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
    ) -> Result<Self, Error> {
        Self::prepare(grid, start, goal, params, ws, None)
    }

    /// [`Run::new`], keeping the colony of the previous run to the same goal when `memory` says
    /// the workspace holds it (same map size and goal): its pheromone is kept, reset to `tau0` near
    /// the cells changed since ([`crate::planner::REPAIR_RADIUS`]), and the run stops after
    /// [`Params::warm_patience`] stale iterations. Otherwise this is exactly [`Run::new`] (a cold
    /// start). On success `memory` records this run (also when its first step then finds the goal
    /// unreachable: the pheromone is then this run's); on failure nothing changed.
    ///
    /// The caller keeps `memory` beside the storage, calls [`Memory::changed`] for every map
    /// update and [`Memory::forget`] for a new map. See [`crate::planner`]'s `warm` module docs.
    pub fn warm(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
        memory: &mut Memory,
    ) -> Result<Self, Error> {
        Self::remembered(grid, (start, goal), params, ws, memory, true)
    }

    /// [`Run::new`] (a cold start, always) that records itself in `memory` on success, so a
    /// later [`Run::warm`] to the same goal can keep its colony. On failure nothing changed.
    pub fn cold(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
        memory: &mut Memory,
    ) -> Result<Self, Error> {
        Self::remembered(grid, (start, goal), params, ws, memory, false)
    }

    /// [`Run::warm`] (`warm`) or [`Run::cold`].
    fn remembered(
        grid: &'g Grid<'g>,
        (start, goal): (Point, Point),
        params: &Params,
        ws: Workspace<'a>,
        memory: &mut Memory,
        warm: bool,
    ) -> Result<Self, Error> {
        let warm = (warm && memory.is_warm_for(grid.width(), grid.height(), goal))
            .then(|| memory.changes());
        let run = Self::prepare(grid, start, goal, params, ws, warm)?;
        memory.planned(grid.width(), grid.height(), goal);
        Ok(run)
    }

    /// [`Run::new`] (`warm` = `None`) and [`Run::warm`] (`Some(changes since)`).
    fn prepare(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
        warm: Option<Option<Area>>,
    ) -> Result<Self, Error> {
        params.validate()?;
        let cells = grid.cells();
        let blocks = Blocks::new(grid.width(), grid.height());
        let ws = ws.fit(cells, blocks)?;
        for (p, e) in [(start, Endpoint::Start), (goal, Endpoint::Goal)] {
            if !grid.contains(p) {
                return Err(Error::OutOfBounds(e));
            }
            if !grid.is_free(p) {
                return Err(Error::Blocked(e));
            }
        }
        Moves::fill(grid, ws.moves);
        let guide_blocks = route::blocks(grid.width(), grid.height());
        match warm {
            None => ws.tau.fill([params.tau0; 4]),
            Some(changes) => {
                let mut tau = Table::new(blocks, ws.tau);
                let _reset = warm::repair(
                    &mut tau,
                    changes,
                    params.tau0,
                    params.tau_min,
                    params.tau_max,
                );
                crate::fmt::debug!("plan: warm start, {} pheromone entries reset", _reset);
            }
        }
        ws.delta.fill([0.0; 4]);
        let heuristic = Heuristic::new(goal, params.attraction(), params.beta);
        // The local search: OHACA on large maps, when the workspace can lend its scratch (every
        // `Storage` with at least 4,096 links, and `HeapStorage`; like the coarse route).
        let refines = params.refine
            && params.algorithm == Algorithm::Ohaca
            && blocks.shift() > 0
            && ws.links.len() >= REFINE_WORDS
            && ws.guide.len() >= REFINE_WORDS;
        crate::fmt::debug!(
            "plan: {} cells, ants {}, iterations {}",
            cells,
            params.ants,
            params.iterations
        );
        Ok(Run {
            grid,
            start,
            goal,
            params: *params,
            heuristic,
            blocks,
            guide_blocks,
            rng: Xoshiro128pp::from_u64(params.seed),
            ws,
            iteration: 0,
            best: None,
            best_iteration: 0,
            stale: 0,
            moves: 0,
            pruned: 0,
            routed: false,
            warm: warm.is_some(),
            setup: Setup::Reach,
            refines,
            polish: Polish::Start,
            colony: None,
            no_path: false,
            dropped: 0,
            done: false,
        })
    }

    /// Do the next piece of the setup, if any is left: the flood fill (a goal found unreachable
    /// ends the run: [`Run::finish`] gives [`Error::NoPath`]), the dead-end pruning, the coarse
    /// route. Returns `true` while setup remains. Each piece reads the whole map once (on a
    /// 256 x 256 map about as long as an iteration), so the firmware yields between them;
    /// [`Run::step`] does whatever setup is left itself, so other callers never need this.
    pub fn setup_step(&mut self) -> bool {
        let grid = self.grid;
        let p = &self.params;
        let ws = &mut self.ws;
        match self.setup {
            Setup::Reach => {
                // A warm start with backtracking ants skips the flood fill: if a change cut the
                // goal off, the first ant backs out of every branch and proves it
                // (`Lost::Exhausted`, the run ends with `NoPath`) for about what the flood fill
                // would have cost; otherwise the fill is pure overhead on a replan (4.6 M of 75 M
                // instructions on Boston 256).
                let proved_by_ants = self.warm && p.dead_end == DeadEnd::Backtrack;
                if !proved_by_ants
                    && grid.reachable(self.start, self.goal, ws.tabu, ws.links) == Reach::No
                {
                    self.no_path = true;
                    self.done = true;
                    self.setup = Setup::Done;
                    return false;
                }
                self.setup = Setup::Prune;
            }
            Setup::Prune => {
                self.pruned = if p.prune {
                    let moves = Moves::new(*grid, ws.moves);
                    prune(&moves, self.start, self.goal, ws.dead, ws.links)
                } else {
                    crate::bitmap::clear(ws.dead, grid.cells());
                    0
                };
                self.setup = Setup::Route;
            }
            Setup::Route => {
                // Large maps: the potential field pulls along a coarse route (not for ACA, which
                // has no attraction).
                self.routed = self.blocks.shift() > 0 && p.algorithm.attracts() && {
                    let moves = Moves::new(*grid, ws.moves);
                    route::build(
                        &moves,
                        self.guide_blocks,
                        self.goal,
                        ws.dead,
                        ws.guide,
                        ws.links,
                    )
                };
                crate::fmt::debug!("plan: {} cells pruned", self.pruned);
                self.setup = Setup::Done;
            }
            Setup::Done => {}
        }
        self.setup != Setup::Done
    }

    /// Ant moves made so far.
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Cells pruned before the ants ran.
    pub fn pruned(&self) -> u32 {
        self.pruned
    }

    /// Iteration (0-based) in which the best path so far was found, if any ant has arrived.
    pub fn best_iteration(&self) -> Option<u16> {
        self.best.map(|_| self.best_iteration)
    }

    /// Length of the best raw path found so far.
    pub fn best_length(&self) -> Option<f32> {
        self.best.map(|b| b.length())
    }

    /// True if this run kept the previous run's colony ([`Run::warm`]).
    pub fn is_warm(&self) -> bool {
        self.warm
    }

    /// Iterations run so far.
    pub fn iteration(&self) -> u16 {
        self.iteration
    }

    /// True once the run has stopped (iteration limit or early stop).
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Run one iteration (all ants, then the pheromone update). Returns `true` while there is more
    /// to do.
    pub fn step(&mut self) -> bool {
        self.step_observed(|_| {})
    }

    /// [`Run::step`], calling `on_tour` with the path of every ant that arrived, in ant order,
    /// as directions from the start: exactly the path the ant deposits on (after tightening).
    /// With these, the iteration's pheromone update (eq. 11-13) can be recomputed by hand; the
    /// tests do.
    pub fn step_observed(&mut self, on_tour: impl FnMut(&[Dir])) -> bool {
        while self.setup_step() {}
        if self.done {
            return false;
        }
        let it = self.walk_ants(on_tour);
        self.update(&it);
        self.record(&it);
        !self.done
    }

    /// Every ant walks start -> goal on `tau(t)` and deposits `Q / L` into the increment table;
    /// the iteration's best and worst paths are kept for the wolves rule.
    fn walk_ants(&mut self, mut on_tour: impl FnMut(&[Dir])) -> Iteration {
        let p = self.params;
        let Workspace {
            tau,
            delta,
            tabu,
            dead,
            moves,
            tour,
            iter_best,
            iter_worst,
            points,
            links,
            guide,
            ..
        } = &mut self.ws;
        let moves = Moves::new(*self.grid, moves);
        let route = Route::new(
            self.guide_blocks,
            guide,
            self.goal,
            self.grid.width(),
            self.grid.height(),
        );
        let tau = Table::new(self.blocks, tau);
        let mut delta = Table::new(self.blocks, delta);
        let ant = Ant {
            moves: &moves,
            start: self.start,
            goal: self.goal,
            tau: &tau,
            heuristic: &self.heuristic,
            alpha: p.alpha,
            dead_end: p.dead_end,
            dead,
            route: self.routed.then_some(&route),
        };
        let mut it = Iteration::default();
        for _ in 0..p.ants {
            let walk = match ant.walk(&mut self.rng, tabu, tour) {
                Ok(w) => w,
                Err(Lost::Exhausted) => {
                    // Only possible when the flood fill could not decide: now it is decided.
                    self.no_path = true;
                    break;
                }
                Err(Lost::Died) => continue,
                Err(Lost::Overflow) => {
                    self.dropped = self.dropped.saturating_add(1);
                    continue;
                }
            };
            self.moves = self.moves.saturating_add(u64::from(walk.moves));
            let walk = if p.tighten && walk.may_tighten {
                tighten(&moves, self.start, walk, tour, points, links, tabu)
            } else {
                walk
            };
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
                    copy_tour(iter_best, path);
                    it.best = Some((b, 1));
                }
            }
            match &mut it.worst {
                Some((cur, n)) if cur.same_length(&b) => *n = n.saturating_add(1),
                Some((cur, _)) if len <= cur.length() => {}
                _ => {
                    copy_tour(iter_worst, path);
                    it.worst = Some((b, 1));
                }
            }
        }
        it
    }

    /// The wolves rule (HACA, OHACA), then `tau = clamp((1 - rho) tau + delta)`.
    fn update(&mut self, it: &Iteration) {
        let p = self.params;
        let ws = &mut self.ws;
        let mut tau = Table::new(self.blocks, ws.tau);
        let mut delta = Table::new(self.blocks, ws.delta);
        if let (true, Some((b, nb)), Some((w, nw))) = (p.algorithm.wolves(), it.best, it.worst) {
            if let (Some(bt), Some(wt)) =
                (ws.iter_best.get(..b.steps), ws.iter_worst.get(..w.steps))
            {
                wolves(
                    &mut delta,
                    self.grid,
                    self.start,
                    p.q,
                    (bt, b.length(), nb),
                    (wt, w.length(), nw),
                );
            }
        }
        tau.evaporate_and_merge(&mut delta, p.rho, p.tau_min, p.tau_max);
    }

    /// Track the run's best, append to the curve, decide whether to stop.
    fn record(&mut self, it: &Iteration) {
        let improved = match (it.best, self.best) {
            (Some((b, _)), None) => Some(b),
            (Some((b, _)), Some(g)) if b.length() < g.length() => Some(b),
            _ => None,
        };
        if let Some(b) = improved {
            if let Some(src) = self.ws.iter_best.get(..b.steps) {
                copy_tour(self.ws.best, src);
            }
            self.best = Some(b);
            self.best_iteration = self.iteration;
            self.stale = 0;
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
        self.done = self.no_path || self.iteration >= p.iterations || early;
    }

    /// Do the next piece of the work after the last iteration, if any is left: lay the best path
    /// out as cells, the local search ([`Params::refine`], large maps) on at most 8,192 expanded
    /// cells, the smoothing DP on at most 48 raw cells. Returns `true` while work remains; does
    /// nothing before the run is done ([`Run::is_done`]) or when it found no path. On a
    /// 256 x 256 map each piece costs a fraction of an iteration, so the firmware yields between
    /// them; [`Run::finish`] does whatever is left itself.
    pub fn polish_step(&mut self) -> bool {
        let Some(best) = self.best else {
            return false;
        };
        if !self.done || self.no_path {
            return false;
        }
        let grid = self.grid;
        let ws = &mut self.ws;
        let kind = if self.params.algorithm == Algorithm::Ohaca {
            self.params.smoothing
        } else {
            SmoothingKind::None
        };
        let dist = ws.delta.as_flattened_mut();
        self.polish = match self.polish {
            Polish::Start => {
                // Expand the tour into cells.
                let n = best.steps.saturating_add(1);
                let tour = ws.best.get(..best.steps).unwrap_or_default();
                for (slot, p) in ws.points.iter_mut().zip(RawPath::new(self.start, tour)) {
                    *slot = p;
                }
                let refiner = self
                    .refines
                    .then(|| Refiner::in_place(grid, ws.points, n, refine::DEFAULT_PASSES).ok())
                    .flatten();
                match refiner {
                    Some(r) => Polish::Refine(r),
                    None => Polish::Smooth(Smoother::new(kind, n, dist, ws.links)),
                }
            }
            Polish::Refine(mut r) => {
                let a = ws.links.get_mut(..REFINE_WORDS).unwrap_or_default();
                let b = ws.guide.get_mut(..REFINE_WORDS).unwrap_or_default();
                let mut budget = Budget::new(REFINE_SLICE);
                if r.resume(grid, ws.points, &mut Scratch::new(a, b), &mut budget) {
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
                    Polish::Smooth(Smoother::new(kind, n, dist, ws.links))
                } else {
                    Polish::Refine(r)
                }
            }
            Polish::Smooth(mut sm) => {
                if sm.resume(grid, ws.points, dist, ws.links, SMOOTH_SLICE) {
                    Polish::Smooth(sm)
                } else {
                    Polish::Done {
                        waypoints: sm.finish(grid, ws.points, dist, ws.links),
                    }
                }
            }
            done @ Polish::Done { .. } => done,
        };
        !matches!(self.polish, Polish::Done { .. })
    }

    /// The error of a run no ant finished: [`Error::PathTooLong`] when ants were dropped for
    /// their length (the likelier cause, and the one a caller can act on), else
    /// [`Error::NoAntArrived`].
    fn no_arrival(&self) -> Error {
        if self.dropped == 0 {
            return Error::NoAntArrived;
        }
        Error::PathTooLong {
            ants: self.dropped,
            limit: u32::try_from(self.ws.steps()).unwrap_or(u32::MAX),
        }
    }

    /// Stop now and turn the best path found so far into the result: refined (large maps) and
    /// smoothed for OHACA, doing whatever [`Run::polish_step`] left. Fails with
    /// [`Error::NoAntArrived`] if no ant has reached the goal (only possible with
    /// [`crate::DeadEnd::Die`], or before the first iteration), with [`Error::PathTooLong`] instead
    /// if ants were dropped for paths longer than the workspace keeps, and with [`Error::NoPath`]
    /// if an unreachable goal ended the run.
    pub fn finish(mut self) -> Result<Plan<'a>, Error> {
        if self.no_path {
            return Err(Error::NoPath);
        }
        if self.best.is_none() {
            return Err(self.no_arrival());
        }
        self.done = true;
        while self.polish_step() {}
        let Run {
            start,
            params,
            ws,
            best,
            best_iteration,
            iteration,
            moves,
            pruned,
            warm,
            polish,
            colony,
            ..
        } = self;
        let best = best.ok_or(Error::NoAntArrived)?;
        let Polish::Done { waypoints: k } = polish else {
            return Err(Error::NoPath);
        };
        let Workspace {
            best: best_tour,
            points,
            curve,
            ..
        } = ws;
        let tour: &'a [Dir] = best_tour.get(..best.steps).ok_or(Error::NoPath)?;
        let pts: &'a [Point] = points;
        let waypoints = pts.get(..k).ok_or(Error::NoPath)?;
        let kind = if params.algorithm == Algorithm::Ohaca {
            params.smoothing
        } else {
            SmoothingKind::None
        };
        // Without smoothing the waypoints are the raw path's corners: report the exact step-count
        // length rather than re-summing it (which can differ in the last bit).
        let length = if kind == SmoothingKind::None {
            best.length()
        } else {
            polyline_length(waypoints)
        };
        let curve: &'a [CurvePoint] = curve;
        let curve = curve
            .get(..usize::from(iteration).min(curve.len()))
            .unwrap_or(&[]);
        Ok(Plan {
            start,
            tour,
            waypoints,
            raw_length: best.length(),
            colony_length: colony.unwrap_or(best).length(),
            length,
            turns: turns(waypoints),
            iterations: iteration,
            best_iteration,
            moves,
            pruned,
            warm,
            curve,
            params,
        })
    }
}

fn copy_tour(dst: &mut [Dir], src: &[Dir]) {
    if let Some(d) = dst.get_mut(..src.len()) {
        d.copy_from_slice(src);
    }
}
