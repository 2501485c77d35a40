//! One planning run on a loaded [`Map`], timed, turned into a [`PlanReport`].
//!
//! This is the step every path-producing subcommand shares: build the core's grid, lend it
//! [`HeapStorage`] (or a board's buffers, `--board`: [`crate::board`]), run [`ohaca::Run`] to the end, and report. "No path" is a normal outcome (a
//! report with `found: false`); everything else the core rejects — bad parameters, start or goal
//! outside the map or on an obstacle — is a [`PlanError`], i.e. bad input.

use std::time::Instant;

use ohaca::planner::Poll;
use ohaca::{Error, Params, Point, Run};

use crate::board::{BoardError, BoardStorage};
use crate::map::Map;
use crate::output::PlanReport;
use ohaca::board::Board;
use ohaca::heap::{AllocError, HeapStorage};
use ohaca::planner::Workspace;

/// Why a request could not be planned at all (as opposed to "no path").
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    /// The core rejected the request; `Display` is the core's message.
    #[error("{0}")]
    Core(Error),
    /// The planner's buffers could not be allocated.
    #[error(transparent)]
    Storage(#[from] AllocError),
    /// `--board`: the map has more cells than the board takes.
    #[error("the {board} board takes maps of up to {capacity} cells, not {cells}")]
    TooLarge {
        /// The board's name.
        board: &'static str,
        /// The map's cells.
        cells: usize,
        /// The board's most cells.
        capacity: usize,
    },
}

impl From<Error> for PlanError {
    fn from(e: Error) -> Self {
        PlanError::Core(e)
    }
}

impl From<BoardError> for PlanError {
    fn from(e: BoardError) -> Self {
        match e {
            BoardError::TooLarge {
                board,
                cells,
                capacity,
            } => PlanError::TooLarge {
                board,
                cells,
                capacity,
            },
            BoardError::Storage(e) => PlanError::Storage(e),
            BoardError::Core(e) => PlanError::Core(e),
        }
    }
}

/// Something that lends the planner a workspace for a map: the host's [`HeapStorage`] or a
/// board's buffers ([`BoardStorage`]).
pub trait Lend {
    /// A workspace for a map of `cells` cells and runs of up to `iterations` iterations.
    fn lend(&mut self, cells: usize, iterations: usize) -> Result<Workspace<'_>, PlanError>;
}

impl Lend for HeapStorage {
    fn lend(&mut self, cells: usize, iterations: usize) -> Result<Workspace<'_>, PlanError> {
        self.ensure(cells, iterations)?;
        Ok(self.workspace())
    }
}

impl Lend for BoardStorage {
    fn lend(&mut self, cells: usize, iterations: usize) -> Result<Workspace<'_>, PlanError> {
        Ok(BoardStorage::lend(self, cells, iterations)?)
    }
}

/// Plan from `start` to `goal` on `map`, allocating storage for this one run.
pub fn plan_map(
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
) -> Result<PlanReport, PlanError> {
    // Reject bad parameters before allocating for them.
    params.validate()?;
    let mut storage = HeapStorage::for_run(map.cells(), params)?;
    plan_map_in(&mut storage, map, start, goal, params)
}

/// Plan from `start` to `goal` on `map` as `board`'s firmware does (`--board`: its buffers and
/// layout, [`crate::board`]), or without one in the host's own storage ([`plan_map`]).
pub fn plan_map_on(
    board: Option<Board>,
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
) -> Result<PlanReport, PlanError> {
    let Some(board) = board else {
        return plan_map(map, start, goal, params);
    };
    params.validate()?;
    let mut storage = BoardStorage::new(board, map.cells(), usize::from(params.iterations))?;
    plan_map_in(&mut storage, map, start, goal, params)
}

/// Plan in caller-provided storage (a [`HeapStorage`] is grown if it is too small), e.g. one
/// storage for many runs.
///
/// Returns a report with `found: false` when the goal is unreachable (or, with
/// [`ohaca::DeadEnd::Die`], no ant reached it), and [`PlanError`] for bad input. The time covers
/// the core's work only (validation, flood fill, iterations, smoothing), not the allocation.
pub fn plan_map_in<S: Lend + ?Sized>(
    storage: &mut S,
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
) -> Result<PlanReport, PlanError> {
    params.validate()?;
    let ws = storage.lend(map.cells(), usize::from(params.iterations))?;
    let grid = map.grid()?;
    let t0 = Instant::now();
    let mut run = Run::new(&grid, start, goal, params, ws)?;
    while let Poll::Working(_) = run.poll() {}
    let iterations = run.iteration();
    match run.finish() {
        Ok(plan) => Ok(PlanReport::from_plan(&plan, t0.elapsed())),
        // The first step's flood fill found the goal unreachable.
        Err(Error::NoPath) => Ok(PlanReport::not_found(
            params,
            Error::NoPath,
            Some(0),
            t0.elapsed(),
        )),
        // With `DeadEnd::Die`, or ants dropped for paths longer than the workspace keeps: the goal
        // is reachable but no ant got there.
        Err(e @ (Error::NoAntArrived | Error::PathTooLong { .. })) => Ok(PlanReport::not_found(
            params,
            format_args!("{e} in {iterations} iterations"),
            Some(iterations),
            t0.elapsed(),
        )),
        Err(e) => Err(e.into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Format;
    use ohaca::error::{Endpoint, Param};

    fn map() -> Map {
        Map::parse("....\n.##.\n....\n", "t", Format::Text).unwrap()
    }

    #[test]
    fn finds_and_reports() {
        let r = plan_map(
            &map(),
            Point::new(0, 1),
            Point::new(3, 1),
            &Params::default(),
        )
        .unwrap();
        assert!(r.found);
        assert_eq!(r.raw.first(), Some(&[0, 1]));
        assert_eq!(r.raw.last(), Some(&[3, 1]));
        assert_eq!(r.waypoints.last(), Some(&[3, 1]));
        assert!(r.length.unwrap() <= r.raw_length.unwrap() + 1e-4);
        assert!(r.error.is_none());
    }

    #[test]
    fn bad_input_is_an_error() {
        let m = map();
        let p = Params::default();
        let e = |s, g, p: &Params| plan_map(&m, s, g, p).unwrap_err();
        assert_eq!(
            e(Point::new(1, 1), Point::new(0, 0), &p),
            PlanError::Core(Error::Blocked(Endpoint::Start))
        );
        assert_eq!(
            e(Point::new(0, 0), Point::new(4, 0), &p),
            PlanError::Core(Error::OutOfBounds(Endpoint::Goal))
        );
        assert_eq!(
            e(Point::new(0, 0), Point::new(1, 0), &Params { ants: 0, ..p }),
            PlanError::Core(Error::BadParam(Param::Ants))
        );
        assert_eq!(
            e(Point::new(1, 1), Point::new(0, 0), &p).to_string(),
            "start is on an obstacle"
        );
    }

    #[test]
    fn unreachable_is_a_report() {
        let m = Map::parse(".#.\n##.\n...\n", "t", Format::Text).unwrap();
        let r = plan_map(&m, Point::new(0, 0), Point::new(2, 2), &Params::default()).unwrap();
        assert!(!r.found);
        assert_eq!(r.iterations, Some(0));
        assert!(r.error.unwrap().starts_with("no path"));
    }

    #[test]
    fn storage_is_reused() {
        let mut s = HeapStorage::default();
        let m = map();
        let p = Params::default();
        let a = plan_map_in(&mut s, &m, Point::new(0, 0), Point::new(3, 2), &p).unwrap();
        let b = plan_map_in(&mut s, &m, Point::new(0, 0), Point::new(3, 2), &p).unwrap();
        assert_eq!(a.raw, b.raw);
        assert_eq!(a.waypoints, b.waypoints);
        assert!(s.cells() >= m.cells());
    }
}
