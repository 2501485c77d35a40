//! A planning run as a state machine. [`Run::new`] (or [`Run::warm`], [`Run::cold`]) validates
//! and prepares; [`Run::poll`] then does one bounded piece of work and says what it did; once it
//! answers [`Poll::Done`], [`Run::finish`] turns the run into a [`Plan`]. Every driver is the
//! same loop, the firmware's with a yield and a cancel check in its body:
//!
//! ```ignore
//! while let Poll::Working(_) = run.poll() {
//!     yield_now().await;            // the firmware; a host loop has an empty body
//!     if cancelled() { return Err(Cancelled); }
//! }
//! let plan = run.finish()?;
//! ```
//!
//! The run's [`Phase`] is one value: the setup (flood fill, pruning, coarse route), the colony
//! (iterations of walking ants, the pheromone update, the record), the polish (the local search,
//! the smoothing, the corridor search) and the end (the waypoints, or why there are none). A poll
//! does one piece of the current phase and moves to the next phase when its last piece is done,
//! like smoltcp's `Interface::poll` or embassy-net's `Runner`: the caller owns the loop, the run
//! owns the state. A poll that does the last piece still answers [`Poll::Working`]; the next one
//! answers [`Poll::Done`] and does nothing.
//!
//! How the work is cut never changes the result: the same pieces in the same order, whoever
//! drives them; [`Run::finish`] polls whatever is left itself, and [`Run::step`] (tests and
//! callers that observe iterations) polls to the end of the next iteration.
//!
//! | file | owns |
//! | --- | --- |
//! | `mod.rs` | [`Run`]'s state and [`Phase`], its constructors (cold, warm), the accessors, [`Run::poll`] and `finish` |
//! | `setup.rs` | the setup before the first iteration: flood fill, pruning, the coarse route |
//! | `colony.rs` | one iteration: every ant's walk, the pheromone update, the record and early stop |
//! | `walk.rs` | a walk within the pieces' budget: the budget, the walk in progress and its tightening, the walk again for the wolves rule |
//! | `polish.rs` | the work after the last iteration: the local search and the smoothing |

mod colony;
mod polish;
mod setup;
mod walk;

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
use super::short::Shortfalls;
use super::warm::{self, Answer, Area, Kept, Memory};
use super::workspace::Workspace;
use colony::{Best, Walking};
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
    /// The steps that ran short of scratch so far ([`crate::planner::Shortfalls`]).
    short: Shortfalls,
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
    /// Where the run is: see [`Phase`].
    phase: Phase,
    refines: bool,
    /// The colony's best path length, kept when the local search replaces the best path.
    colony: Option<Best>,
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
}

/// What a [`Run::poll`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Poll {
    /// It did one piece of this stage; more may be left: poll again.
    Working(Stage),
    /// Nothing is left (and this poll did nothing): [`Run::finish`] gives the result.
    Done,
}

/// The stage of a run a [`Poll::Working`] piece belonged to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The setup before the first ant: flood fill, pruning, the coarse route.
    Setup,
    /// The colony: the ants' walks, the pheromone update, the record of an iteration.
    Colony,
    /// The work after the last iteration: the local search, the smoothing, the corridor.
    Polish,
}

impl Stage {
    /// The stage's name, for logs.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Setup => "setup",
            Stage::Colony => "colony",
            Stage::Polish => "polish",
        }
    }
}

/// Where a run is: the one value that says which piece [`Run::poll`] does next.
// The colony's variant is the largest (its iteration's replays: about 260 bytes); the core has no
// heap to box it in, and a run holds one phase.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Phase {
    /// The setup, at this piece.
    Setup(Setup),
    /// The colony's iterations, the current one where it stands.
    Colony(Walking),
    /// The work after the last iteration, at this piece.
    Polish(Polish),
    /// Nothing left: how the run ended.
    Ended(End),
}

/// How a run ended ([`Phase::Ended`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    /// The polished path: `points[..waypoints]` are its waypoints.
    Path { waypoints: usize },
    /// The goal is not reachable (the flood fill or a backtracking ant proved it).
    NoPath,
    /// The colony stopped and no ant had arrived ([`Run::no_arrival`] says why).
    NoArrival,
}

/// The setup still to do before the first iteration, in order: one piece a [`Run::poll`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Setup {
    /// The flood fill (is the goal reachable at all?), for dying ants only: backtracking ants
    /// prove an unreachable goal themselves (`setup.rs`).
    Reach,
    /// Dead-end pruning ([`Params::prune`]): where it paused (`None`: not started).
    Prune(Option<crate::map::prune::Pruning>),
    /// The coarse route on large maps: its search where it paused (`None`: not started).
    Route(Option<route::Searching>),
}

impl<'g, 'a> Run<'g, 'a> {
    /// Validate everything and prepare a run: fails at once on bad parameters, a map larger than
    /// the workspace, or a start or goal off the map or on an obstacle; sets every pheromone entry
    /// to `tau0`. The rest of the setup (with [`crate::DeadEnd::Die`], a flood fill: is the goal
    /// reachable at all?; pruning the cells no shortest path needs, [`Params::prune`]; the coarse
    /// route of a large map) runs in the first polls ([`Run::poll`]); an unreachable goal ends
    /// the run there (or, with backtracking ants, in the first ant's walk), and [`Run::finish`]
    /// fails with [`Error::NoPath`].
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
    /// its coarse route's links (once the polish started: they are stashed then, before
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
        if let (Some(best), &Phase::Ended(End::Path { waypoints })) = (self.best, &self.phase) {
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
            short: Shortfalls::NONE,
            routed: false,
            warm: warm.is_some(),
            reuse,
            relinked,
            touched: None,
            marks: false,
            stashed: false,
            phase: Phase::Setup(Setup::Reach),
            refines,
            colony: None,
            reach_checked: false,
            dropped: 0,
            abandoned: 0,
            cheapest: None,
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

    /// True once the colony has stopped (iteration limit, early stop, an unreachable goal, or
    /// [`Run::finish`]): the polish or the end is next.
    pub fn is_done(&self) -> bool {
        matches!(self.phase, Phase::Polish(_) | Phase::Ended(_))
    }

    /// The name of the piece the next [`Run::poll`] does, for logs: `"reach"`, `"prune"`,
    /// `"route"`, `"walk"` (the ants), `"wolves"` (the wolves rule's paths), `"place"` (the new
    /// best's path), `"update"`, `"lay"` (the path laid out), `"refine"`, `"smooth"` (the DP), `"tail"` (the
    /// smoothing's trace and taut pull, the corridor), `"end"`.
    pub fn piece(&self) -> &'static str {
        match &self.phase {
            Phase::Setup(Setup::Reach) => "reach",
            Phase::Setup(Setup::Prune(_)) => "prune",
            Phase::Setup(Setup::Route(_)) => "route",
            Phase::Colony(w) => w.piece(),
            Phase::Polish(Polish::Start) => "lay",
            Phase::Polish(Polish::Refine(_)) => "refine",
            Phase::Polish(Polish::Smooth(_)) => "smooth",
            Phase::Polish(Polish::Tail(_)) => "tail",
            Phase::Ended(_) => "end",
        }
    }

    /// Do one bounded piece of the run's work and say what it was: [`Poll::Working`] with the
    /// piece's stage while work is left, [`Poll::Done`] (without doing anything) once nothing
    /// is. The pieces, in order: each piece of the setup (the flood fill, the pruning, the coarse
    /// route), each iteration of the colony, each piece of the polish (laying the path out, the
    /// local search a budget of expanded cells at a time, the smoothing a stretch of cells at a
    /// time, the corridor search). Drive it with
    /// `while let Poll::Working(_) = run.poll() { /* yield, check for a cancel */ }`, then call
    /// [`Run::finish`]; see the module docs.
    pub fn poll(&mut self) -> Poll {
        self.poll_observed(&mut |_| {})
    }

    /// [`Run::poll`], calling `on_tour` for every ant of a colony piece that arrived (see
    /// [`Run::step_observed`]).
    fn poll_observed(&mut self, on_tour: &mut dyn FnMut(&[Dir])) -> Poll {
        // The phase is taken out for the piece, which sets the next one.
        match core::mem::replace(&mut self.phase, Phase::Ended(End::NoArrival)) {
            Phase::Setup(s) => {
                self.setup_piece(s);
                Poll::Working(Stage::Setup)
            }
            Phase::Colony(w) => {
                self.colony_piece(w, on_tour);
                Poll::Working(Stage::Colony)
            }
            Phase::Polish(p) => {
                self.polish_piece(p);
                Poll::Working(Stage::Polish)
            }
            Phase::Ended(end) => {
                self.phase = Phase::Ended(end);
                Poll::Done
            }
        }
    }

    /// The colony an iteration at a time, for tests and callers that observe iterations (a
    /// driver polls, [`Run::poll`]): polls until the next iteration has been recorded (the setup
    /// first, if any is left), never into the polish. Returns `true` while the colony goes on.
    pub fn step(&mut self) -> bool {
        self.step_observed(|_| {})
    }

    /// [`Run::step`], calling `on_tour` with the path of every ant that arrived, in ant order,
    /// as directions from the start: exactly the path the ant deposits on (after tightening).
    /// With these, the iteration's pheromone update (eq. 11-13) can be recomputed by hand; the
    /// tests do.
    pub fn step_observed(&mut self, mut on_tour: impl FnMut(&[Dir])) -> bool {
        let iteration = self.iteration;
        while matches!(self.phase, Phase::Setup(_) | Phase::Colony(_))
            && self.iteration == iteration
        {
            self.poll_observed(&mut on_tour);
        }
        matches!(self.phase, Phase::Colony(_))
    }

    /// The phase after the colony stopped: the polish of the best path, or the end when no ant
    /// arrived or the goal was proved unreachable.
    fn after_colony(&self, no_path: bool) -> Phase {
        match (no_path, self.best) {
            (true, _) => Phase::Ended(End::NoPath),
            (false, None) => Phase::Ended(End::NoArrival),
            (false, Some(_)) => Phase::Polish(Polish::Start),
        }
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
    /// smoothed for OHACA, polling whatever is left ([`Run::poll`]). Fails with
    /// [`Error::NoAntArrived`] if no ant has reached the goal (only possible with
    /// [`crate::DeadEnd::Die`], or before the first iteration), with [`Error::PathTooLong`] instead
    /// if ants were dropped for paths longer than the workspace keeps, and with [`Error::NoPath`]
    /// if an unreachable goal ended the run.
    pub fn finish(mut self) -> Result<Plan<'a>, Error> {
        // Stopped early (before the colony ended by itself): the iteration under way is ended
        // first (its best path may be half placed), then the polish of the best so far.
        while let Phase::Colony(w) = &self.phase {
            if !w.started() {
                break;
            }
            self.poll();
        }
        if let Phase::Setup(_) | Phase::Colony(_) = self.phase {
            self.phase = self.after_colony(false);
        }
        while let Poll::Working(_) = self.poll() {}
        match self.phase {
            Phase::Ended(End::NoPath) => return Err(Error::NoPath),
            Phase::Ended(End::NoArrival) => return Err(self.no_arrival()),
            _ => {}
        }
        let Run {
            start,
            params,
            ws,
            best,
            best_iteration,
            iteration,
            moves,
            pruned,
            short,
            warm,
            phase,
            colony,
            ..
        } = self;
        let best = best.ok_or(Error::NoAntArrived)?;
        let Phase::Ended(End::Path { waypoints: k }) = phase else {
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
            shortfalls: short,
            origin: if warm { Origin::Warm } else { Origin::Cold },
            curve,
            params,
        })
    }
}
