//! A planning run as a state machine: [`Run::new`] validates and prepares, [`Run::setup_step`]
//! does the setup a piece at a time, [`Run::step`] runs one iteration (walk every ant, update the
//! pheromone, record the iteration), [`Run::polish_step`] refines and smooths the best path a
//! piece at a time, and [`Run::finish`] turns it into a [`Plan`].
//!
//! The firmware yields to its executor between pieces, so it can answer other requests and cancel
//! a plan by dropping (or finishing) the run. How the work is cut never changes the result:
//! `step` and `finish` alone do every piece that is left.
//!
//! | file | owns |
//! | --- | --- |
//! | `mod.rs` | [`Run`]'s state, its constructors (cold, warm), the accessors, `step` and `finish` |
//! | `setup.rs` | the setup before the first iteration: flood fill, pruning, the coarse route |
//! | `colony.rs` | one iteration: every ant's walk, the pheromone update, the record and early stop |
//! | `polish.rs` | the work after the last iteration: the local search and the smoothing |

mod colony;
mod polish;
mod setup;

pub use colony::{settled, REFINE_GAIN};
pub(crate) use polish::{REFINE_WORDS, SHORT_REFINE_WORDS};

use crate::colony::heuristic::Heuristic;
use crate::colony::pheromone::{Blocks, Table};
use crate::colony::route;
use crate::error::{Endpoint, Error};
use crate::geometry::{polyline_length, turns};
use crate::map::grid::{Dir, Grid, Moves, Point};
use crate::polish::smoothing::SmoothingKind;
use crate::rng::Xoshiro128pp;

use super::lend::Guide;
use super::params::{Algorithm, Params};
use super::plan::Origin;
use super::plan::{CurvePoint, Plan};
use super::warm::{self, Answer, Area, Kept, Memory};
use super::workspace::Workspace;
use colony::Best;
use polish::{Polish, SMALL_REFINE_WORDS};

/// A warm start whose changed cells' bounding box holds more than `1 / REBUILD_SHARE` of the
/// map's cells prunes and routes from scratch instead of repairing the last run's marks and
/// route: the repair re-examines every cell of the box and its cascade, about four times what a
/// fresh pruning costs a cell (on a 256 x 256 city, a whole-map box cost 20-30 M instructions
/// of repair against 7.8 M of setup from scratch; `BENCHMARKS.md` 4b). Both give the same marks
/// and route bit for bit, so this moves cost, never a path.
pub const REBUILD_SHARE: usize = 8;

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
    /// The best's length when a stale streak last ended (see `colony::REFINE_GAIN`).
    mark: Option<f32>,
    stale: u16,
    moves: u64,
    pruned: u32,
    routed: bool,
    warm: bool,
    /// A warm start's changes since the last run, and what that run kept (see [`Run::keep`]).
    reuse: Option<(Option<Area>, Kept)>,
    /// The coarse route's links of the last run are back in `guide` ([`route::unstash`]).
    relinked: bool,
    /// The cells whose pruning mark or map cell may differ from the last run's, after a local
    /// repair of the marks (the coarse route repairs its links there).
    touched: Option<Area>,
    /// This run's pruning marks are in `dead` (the setup pruned them).
    marks: bool,
    /// This run's coarse route's links are stashed in `delta` ([`route::stash`]).
    stashed: bool,
    setup: Setup,
    refines: bool,
    polish: Polish,
    /// The colony's best path length, kept when the local search replaces the best path.
    colony: Option<Best>,
    no_path: bool,
    /// The flood fill has decided reachability in this run (or could not): it runs in the setup
    /// for dying ants only, and for backtracking ones once an ant outgrew its tour before any
    /// arrived (`colony.rs`), the one case where the ants cannot prove an unreachable goal.
    reach_checked: bool,
    /// Ants dropped so far because their paths outgrew the workspace ([`Error::PathTooLong`]).
    dropped: u32,
    /// Ants abandoned so far for their moves ([`colony::MOVE_BUDGET`]).
    abandoned: u32,
    /// The fewest moves any ant of this run made to arrive.
    cheapest: Option<u32>,
    done: bool,
}

/// The setup still to do before the first iteration, in order: the firmware yields between the
/// pieces ([`Run::setup_step`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Setup {
    /// The flood fill (is the goal reachable at all?), for dying ants only: backtracking ants
    /// prove an unreachable goal themselves (`setup.rs`).
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
    /// to `tau0`. The rest of the setup (with [`crate::DeadEnd::Die`], a flood fill: is the goal
    /// reachable at all?; pruning the cells no shortest path needs, [`Params::prune`]; the coarse
    /// route of a large map) runs in the first [`Run::step`], or piecewise through
    /// [`Run::setup_step`]; an unreachable goal ends the run there (or, with backtracking ants,
    /// in the first ant's walk), and [`Run::finish`] fails with [`Error::NoPath`].
    pub fn new(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
    ) -> Result<Self, Error> {
        Self::prepare(grid, start, goal, params, ws, None)
    }

    /// Record in `memory` what this run leaves in the workspace for the next [`Run::warm`] to
    /// repair locally instead of rebuilding: its pruning marks (once the setup made them) and
    /// its coarse route's links (once [`Run::polish_step`] started: they are stashed then, before
    /// the local search takes the route's words as scratch), and its answer once the polish is
    /// done (for [`super::reuse`]). Call it with the `memory` this run
    /// was started with ([`Run::warm`], [`Run::cold`]), after the run (before [`Run::finish`]),
    /// and before another run uses the workspace; the firmware calls it once the run's polish is
    /// done. Without the call the next warm start rebuilds both, with the same result.
    pub fn keep(&self, memory: &mut Memory) {
        if !memory.is_warm_for(self.grid.width(), self.grid.height(), self.goal) {
            return;
        }
        if self.marks {
            memory.keep(Kept {
                start: self.start,
                route: self.stashed,
            });
        }
        // The answer, once the polish laid out its waypoints, for a replan to reuse
        // ([`super::reuse`]).
        if let (Some(best), Polish::Done { waypoints }, false) =
            (self.best, self.polish, self.no_path)
        {
            memory.answer = Some(Answer {
                start: self.start,
                from: 0,
                steps: u32::try_from(best.steps).unwrap_or(0),
                first: 0,
                end: u32::try_from(waypoints).unwrap_or(0),
                params: Params {
                    seed: 0,
                    ..self.params
                },
            });
        }
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
            .then(|| (memory.changes(), memory.kept()));
        let run = Self::prepare(grid, start, goal, params, ws, warm)?;
        memory.planned(grid.width(), grid.height(), goal);
        Ok(run)
    }

    /// [`Run::new`] (`warm` = `None`) and [`Run::warm`] (`Some((changes since, what the last
    /// run kept))`).
    fn prepare(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
        warm: Option<(Option<Area>, Option<Kept>)>,
    ) -> Result<Self, Error> {
        params.validate()?;
        let cells = grid.cells();
        let (width, height) = (grid.width(), grid.height());
        let blocks = Blocks::with_budget(width, height, ws.pheromone_budget());
        let mut ws = ws.fit(cells, blocks)?;
        for (p, e) in [(start, Endpoint::Start), (goal, Endpoint::Goal)] {
            if !grid.contains(p) {
                return Err(Error::OutOfBounds(e));
            }
            if !grid.is_free(p) {
                return Err(Error::Blocked(e));
            }
        }
        Moves::fill(grid, ws.moves);
        let guide_blocks = match ws.guide.len() {
            // A packed route keeps four bits a block: the finest route in an eighth of the words.
            _ if ws.guide.is_packed() => route::blocks(width, height),
            // A workspace with fewer route words than `GUIDE_BLOCKS` routes on larger blocks.
            n @ 1..route::GUIDE_BLOCKS => Blocks::with_budget(width, height, n),
            _ => route::blocks(width, height),
        };
        match warm {
            None => ws.tau.fill([params.tau0; 4]),
            Some((changes, _)) => {
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
        // The last run's pruning marks are reused (repaired locally) when it kept them and this
        // run prunes too; its route's links too when it stashed them in `delta` (restored here,
        // before `delta` is cleared). Not when the changes span more than [`REBUILD_SHARE`] of
        // the map: the repair then costs more than pruning and routing from scratch, which give
        // the same marks and route bit for bit.
        let local = |c: Option<Area>| c.is_none_or(|a| a.cells() <= (cells / REBUILD_SHARE) as u64);
        let reuse = match warm {
            Some((changes, Some(kept))) if params.prune && local(changes) => Some((changes, kept)),
            _ => None,
        };
        let relinked = reuse.is_some_and(|(_, k)| k.route)
            && match &mut ws.guide {
                Guide::Words(words) => {
                    let kept = ws.delta.as_flattened();
                    let n = route::stash_len(guide_blocks);
                    kept.len() >= n
                        && route::unstash(
                            guide_blocks,
                            kept.get(kept.len().wrapping_sub(n)..).unwrap_or_default(),
                            words,
                        )
                }
                // A packed route keeps no links.
                Guide::Packed(_) => false,
            };
        ws.delta.fill([0.0; 4]);
        let heuristic = Heuristic::new(goal, params.attraction(), params.beta);
        // The local search: OHACA on every map, when the workspace can lend its scratch (every
        // `Storage` with at least 4,096 links, and `HeapStorage`; on large maps like the coarse
        // route, on small ones from the links alone).
        let scratch = {
            let mut v = ws.polishing();
            if blocks.shift() > 0 {
                v.idle
                    .refine(&mut v.guide, REFINE_WORDS, SHORT_REFINE_WORDS)
                    .is_some()
            } else {
                v.idle.halves_of_links(SMALL_REFINE_WORDS).1.len() == SMALL_REFINE_WORDS
            }
        };
        let refines = params.refine && params.algorithm == Algorithm::Ohaca && scratch;
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
            mark: None,
            stale: 0,
            moves: 0,
            pruned: 0,
            routed: false,
            warm: warm.is_some(),
            reuse,
            relinked,
            touched: None,
            marks: false,
            stashed: false,
            setup: Setup::Reach,
            refines,
            polish: Polish::Start,
            colony: None,
            no_path: false,
            reach_checked: false,
            dropped: 0,
            abandoned: 0,
            cheapest: None,
            done: false,
        })
    }

    /// Ant moves made so far.
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Ants abandoned so far because they made more moves than the run's move budget allows
    /// (runs with the local search only; see `docs/ALGORITHM.md`, "Move budget").
    pub fn abandoned(&self) -> u32 {
        self.abandoned
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
        self.update();
        self.record(&it);
        !self.done
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
            origin: if warm { Origin::Warm } else { Origin::Cold },
            curve,
            params,
        })
    }
}
