//! Replanning scenarios: a robot follows its path while cells of its map change, and replans
//! from the cell it has reached, warm (keeping the colony, [`ohaca::planner::Run::warm`] /
//! `PlanWarm`) or cold. The same scenario drives the host core or a device over its link, so the
//! two can be compared plan by plan.
//!
//! The robot's start and goal come with the map (`ohaca replan --map ... --start ... --goal ...`);
//! what changes is a JSON file:
//!
//! ```json
//! {
//!   "initial": [ { "rect": [10, 10, 3, 1], "blocked": true } ],
//!   "events": [
//!     { "at": 0.33, "wall_ahead": { "cells": 5, "ahead": 6 } },
//!     { "at": 0.5, "rect": [10, 10, 3, 1], "blocked": false }
//!   ]
//! }
//! ```
//!
//! - `initial`: changes made before the first plan (e.g. a closed door);
//! - each event happens when the robot has travelled the fraction `at` of the path it is
//!   following (its raw 8-connected path); the robot then replans from its cell to the goal;
//! - a change is a rectangle `[x, y, width, height]`, a list of `cells` (`[[x, y], ...]`), or
//!   `wall_ahead`: `cells` cells across the robot's path, centred `ahead` path cells in front of it
//!   (never on the robot's cell or the goal); `blocked` defaults to true.
//!
//! Every plan is checked (every step an allowed move on the map of its time) and measured against
//! the exact shortest 8-connected path on that map ([`shortest`]).

use std::collections::BinaryHeap;

use serde::Deserialize;

use ohaca::board::{Board, F411};
use ohaca::planner::session;
use ohaca::planner::{Fallback, Memory, Origin, Poll};
use ohaca::{Grid, Params, Point};

use crate::board::{BoardError, BoardStorage};
use crate::link::{DevicePath, Link, LinkError, Transport};
use crate::map::Map;

/// What changes in a replanning scenario (see the module docs for the file format).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Changes before the first plan.
    #[serde(default)]
    pub initial: Vec<Change>,
    /// Changes while the robot drives, in order.
    #[serde(default)]
    pub events: Vec<Event>,
}

/// A change at a point of the robot's drive.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Event {
    /// Fraction of its current path the robot has travelled, `0..=1`.
    pub at: f64,
    /// What changes.
    #[serde(flatten)]
    pub change: Change,
}

/// Cells that become blocked (or free).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Change {
    /// `[x, y, width, height]`.
    #[serde(default)]
    pub rect: Option<[u16; 4]>,
    /// Single cells.
    #[serde(default)]
    pub cells: Option<Vec<[u16; 2]>>,
    /// A wall across the robot's path.
    #[serde(default)]
    pub wall_ahead: Option<WallAhead>,
    /// A square of free cells far from the robot's path.
    #[serde(default)]
    pub box_away: Option<BoxAway>,
    /// The cells of the previous change (set to `blocked`: `false` clears a box again).
    #[serde(default)]
    pub undo: bool,
    /// Blocked (default) or cleared.
    #[serde(default = "yes")]
    pub blocked: bool,
}

fn yes() -> bool {
    true
}

/// `cells` cells across the path, centred `ahead` path cells in front of the robot.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallAhead {
    /// Cells in the wall.
    pub cells: u16,
    /// Path cells between the robot and the wall's centre.
    pub ahead: u16,
}

/// A `size x size` square of free cells, every cell at least `distance` cells (Chebyshev) from
/// the robot and every cell of the rest of its path: the first such square in row-major order.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxAway {
    /// Cells a side.
    pub size: u16,
    /// Cells between the box and the path, at least.
    pub distance: u16,
}

/// Why a scenario cannot be read or driven.
#[derive(Debug, thiserror::Error)]
pub enum ReplanError {
    /// The scenario file is not the JSON described above.
    #[error("{0}")]
    Json(#[from] serde_json::Error),
    /// An event's `at` is not a fraction.
    #[error("event {event}: `at` must be in 0..=1, not {at}")]
    At {
        /// The event's index.
        event: usize,
        /// Its `at`.
        at: f64,
    },
    /// A change names none or several of its kinds.
    #[error("each change needs exactly one of rect, cells, wall_ahead, box_away, undo")]
    OneKind,
    /// A cell of a change is outside the map.
    #[error("cell ({x}, {y}) is outside the map")]
    Outside {
        /// Column.
        x: i64,
        /// Row.
        y: i64,
    },
    /// A cell of a `rect` change is outside the map.
    #[error("rect cell ({x}, {y}) is outside the map")]
    RectOutside {
        /// Column.
        x: i64,
        /// Row.
        y: i64,
    },
    /// `wall_ahead` on a path of fewer than 3 cells.
    #[error("wall_ahead: the robot's path is too short")]
    PathTooShort,
    /// `wall_ahead` found no path cell at its centre.
    #[error("wall_ahead: no path cell there")]
    NoPathCell,
    /// `box_away` before the first plan.
    #[error("box_away: no path yet")]
    NoPathYet,
    /// `box_away` found no square far enough from the path.
    #[error("box_away: no free {size} x {size} square {distance} cells from the path")]
    NoBox {
        /// Cells a side.
        size: u16,
        /// Cells from the path.
        distance: u16,
    },
    /// A plan's raw path does not run from the start to the goal.
    #[error("the path does not join start and goal")]
    NotJoined,
    /// A plan's raw path makes a move the map does not allow.
    #[error("step ({}, {}) -> ({}, {}) is not an allowed move", .from.x, .from.y, .to.x, .to.y)]
    BadStep {
        /// The cell it leaves.
        from: Point,
        /// The cell it reaches.
        to: Point,
    },
    /// The host planner was asked to plan before it had a map.
    #[error("no map yet")]
    NoMap,
    /// The board's buffers cannot take the map.
    #[error(transparent)]
    Board(#[from] BoardError),
    /// The core refused the map, the endpoints or the parameters.
    #[error("{0}")]
    Core(ohaca::Error),
    /// The device's link failed or the device refused.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// What went wrong at an event of the scenario.
    #[error("event {event}: {error}")]
    Event {
        /// The event's index.
        event: usize,
        /// What went wrong.
        error: Box<ReplanError>,
    },
    /// A costmap stream's rates are out of range ([`crate::stream::Stream`]).
    #[error("stream: hz and speed must be positive, near in 0..=1")]
    BadStream,
    /// What went wrong at an update of a costmap stream.
    #[error("update {update}: {error}")]
    Update {
        /// The update's index.
        update: usize,
        /// What went wrong.
        error: Box<ReplanError>,
    },
}

impl From<ohaca::Error> for ReplanError {
    fn from(e: ohaca::Error) -> Self {
        ReplanError::Core(e)
    }
}

impl ReplanError {
    /// `self` at event `event` of the scenario.
    fn at_event(self, event: usize) -> Self {
        ReplanError::Event {
            event,
            error: Box::new(self),
        }
    }

    /// `self` at update `update` of a costmap stream.
    pub(crate) fn at_update(self, update: usize) -> Self {
        ReplanError::Update {
            update,
            error: Box::new(self),
        }
    }
}

impl Scenario {
    /// Parse a scenario file's text.
    pub fn parse(text: &str) -> Result<Scenario, ReplanError> {
        let s: Scenario = serde_json::from_str(text)?;
        for (i, e) in s.events.iter().enumerate() {
            if !(0.0..=1.0).contains(&e.at) {
                return Err(ReplanError::At { event: i, at: e.at });
            }
        }
        for c in s.initial.iter().chain(s.events.iter().map(|e| &e.change)) {
            let n = [
                c.rect.is_some(),
                c.cells.is_some(),
                c.wall_ahead.is_some(),
                c.box_away.is_some(),
                c.undo,
            ]
            .iter()
            .filter(|&&b| b)
            .count();
            if n != 1 {
                return Err(ReplanError::OneKind);
            }
        }
        Ok(s)
    }
}

/// A plan as the scenario sees it, from the core or a device.
#[derive(Clone, Debug, PartialEq)]
pub struct Planned {
    /// Every cell of the raw path, start first.
    pub raw: Vec<Point>,
    /// The smoothed waypoints.
    pub waypoints: Vec<Point>,
    /// Raw path length (cells).
    pub raw_length: f32,
    /// Length through the waypoints.
    pub length: f32,
    /// Iterations run.
    pub iterations: u16,
    /// Ant moves over the run.
    pub moves: u64,
    /// Device ticks (`None` on the host).
    pub ticks: Option<u64>,
    /// Cold, warm (the run kept the previous colony), reused (the rest of the previous answer)
    /// or repaired (that with a local detour).
    pub origin: Origin,
    /// Why a warm plan was not answered without a run ([`ohaca::planner::reuse`]'s reason:
    /// the host core's; `None` from a device, which does not send it, and for cold plans).
    pub fallback: Option<Fallback>,
}

impl Planned {
    /// A plan of the host core, with the device's ticks if any.
    pub fn of(plan: &ohaca::Plan<'_>, ticks: Option<u64>) -> Self {
        Planned {
            raw: plan.raw().collect(),
            waypoints: plan.waypoints().to_vec(),
            raw_length: plan.raw_length,
            length: plan.length,
            iterations: plan.iterations,
            moves: plan.moves,
            ticks,
            origin: plan.origin,
            fallback: None,
        }
    }
}

/// Something that plans: the host core or a device.
pub trait Planner {
    /// Make the map the active map.
    fn set_map(&mut self, map: &Map) -> Result<(), ReplanError>;
    /// Block or clear `cells` (every one on the map).
    fn change(&mut self, cells: &[Point], blocked: bool) -> Result<(), ReplanError>;
    /// Plan from `start` to `goal`, warm or cold.
    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, ReplanError>;
}

/// The host core, planning as a board's firmware does ([`crate::board::BoardStorage`]), so its
/// paths are the device's bit for bit. [`HostPlanner::new`] (`ohaca replan` and `ohaca ros
/// --host` without `--board`) plans as the STM32F411 and the default QEMU firmware do (in an
/// arena of its length laid out by `ohaca::planner::arena::carve`, its path bound: 2,047 steps
/// in the full layout, 4,095 in the compact one),
/// and on a map too large for that arena with heap storage and the same path bound;
/// [`HostPlanner::on`] (`--board`) exactly as the board does, refusing maps it does not take.
pub struct HostPlanner {
    map: Map,
    params: Params,
    board: Board,
    /// Refuse maps the board does not take (`--board`), rather than plan them on the heap.
    strict: bool,
    /// The board's buffers for the map (none before the first map).
    storage: Option<BoardStorage>,
    memory: Memory,
}

/// The default QEMU firmware's longest ant path (the STM32F411's, [`ohaca::board::F411`];
/// Hello's `capacity.max_steps`).
pub const DEVICE_STEPS: usize = F411.max_steps;

impl HostPlanner {
    /// A planner with `params` and no map yet, planning as the STM32F411 does (see the type's
    /// docs).
    pub fn new(params: Params) -> Self {
        HostPlanner {
            map: Map::from_fn(0, 0, |_, _| false),
            params,
            board: F411,
            strict: false,
            storage: None,
            memory: Memory::new(),
        }
    }

    /// A planner with `params` planning exactly as `board` does (`--board`).
    pub fn on(params: Params, board: Board) -> Self {
        HostPlanner {
            board,
            strict: true,
            ..HostPlanner::new(params)
        }
    }

    /// The board it plans as.
    pub fn board(&self) -> Board {
        self.board
    }
}

impl Planner for HostPlanner {
    fn set_map(&mut self, map: &Map) -> Result<(), ReplanError> {
        let iterations = usize::from(self.params.iterations);
        let storage = if self.strict {
            BoardStorage::new(self.board, map.cells(), iterations)
        } else {
            BoardStorage::lenient(self.board, map.cells(), iterations)
        };
        self.storage = Some(storage?);
        self.map = map.clone();
        self.memory.forget();
        Ok(())
    }

    fn change(&mut self, cells: &[Point], blocked: bool) -> Result<(), ReplanError> {
        for &p in cells {
            // As the firmware does: a cleared cell counts as freed if it was blocked.
            let was_blocked = self.map.is_blocked(p);
            set_cell(&mut self.map, p, blocked)?;
            self.memory.cell(p, was_blocked, blocked);
        }
        Ok(())
    }

    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, ReplanError> {
        let grid = self.map.grid()?;
        let mut ws = self
            .storage
            .as_mut()
            .ok_or(ReplanError::NoMap)?
            .workspace()?;
        // The firmware's dispatch (`ohaca::planner::session`): a warm replan that no change since
        // can shorten or block is the rest of the last answer (or its local repair); else the
        // reason, kept for the table, and a run.
        let (ends, memory) = ((start, goal), &mut self.memory);
        let fallback = match session::answer(&grid, ends, &self.params, &mut ws, memory, warm) {
            Ok(reused) => {
                let plan = reused.into_plan(ws, memory, &self.params);
                return Ok(Planned::of(&plan, None));
            }
            Err(why) => why,
        };
        let mut run = session::start(&grid, ends, &self.params, ws, memory, warm)?;
        // The one loop (the firmware's, without its yields), then what the run leaves for the
        // next warm start.
        while let Poll::Working(_) = run.poll() {}
        let plan = session::end(run, &mut self.memory)?;
        Ok(Planned {
            fallback,
            ..Planned::of(&plan, None)
        })
    }
}

/// A device over its link (`SetMap`, `SetCells`, `Plan` / `PlanWarm`).
pub struct DevicePlanner<T: Transport> {
    /// The link.
    pub link: Link<T>,
}

impl<T: Transport> Planner for DevicePlanner<T> {
    fn set_map(&mut self, map: &Map) -> Result<(), ReplanError> {
        Ok(self.link.set_map(map)?)
    }

    fn change(&mut self, cells: &[Point], blocked: bool) -> Result<(), ReplanError> {
        Ok(self.link.set_cells(cells, blocked)?)
    }

    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, ReplanError> {
        let r: Result<DevicePath, LinkError> = if warm {
            self.link.plan_warm(start, goal, None)
        } else {
            self.link.plan(start, goal, None)
        };
        let p = r?;
        Ok(Planned {
            raw: p.raw(start)?,
            waypoints: p.waypoints.clone(),
            raw_length: p.raw_length,
            length: p.length,
            iterations: p.iterations,
            moves: p.moves,
            ticks: Some(p.ticks),
            origin: p.origin,
            fallback: None,
        })
    }
}

pub(crate) fn set_cell(map: &mut Map, p: Point, blocked: bool) -> Result<(), ReplanError> {
    map.set(p, blocked).map_err(|_| ReplanError::Outside {
        x: i64::from(p.x),
        y: i64::from(p.y),
    })
}

/// One plan of a scenario run.
#[derive(Clone, Debug)]
pub struct Step {
    /// The robot's cell when it planned.
    pub robot: Point,
    /// Where that cell is on [`Drive::trail`] (the plan is driven from there).
    pub at: usize,
    /// Cells changed just before this plan (empty for the first plan without `initial`).
    pub changed: Vec<Point>,
    /// Blocked (true) or cleared.
    pub blocked: bool,
    /// The map this plan saw.
    pub map: Map,
    /// The plan.
    pub plan: Planned,
    /// Exact shortest 8-connected length from the robot's cell on this map.
    pub optimum: Option<f64>,
}

/// A scenario run: every plan, and the cells the robot drove through.
#[derive(Clone, Debug)]
pub struct Drive {
    /// The plans, first one first.
    pub steps: Vec<Step>,
    /// The robot's cells, start to goal.
    pub trail: Vec<Point>,
}

/// Run `scenario` on `map` from `start` to `goal` with `planner`; replans are warm when `warm`.
/// The map (with the initial changes) is uploaded first.
pub fn drive(
    scenario: &Scenario,
    map: &Map,
    (start, goal): (Point, Point),
    planner: &mut dyn Planner,
    warm: bool,
) -> Result<Drive, ReplanError> {
    let mut map = map.clone();
    let mut changed = Vec::new();
    let mut blocked = true;
    for c in &scenario.initial {
        let cells = resolve(c, &map, &[], 0, goal, &changed)?;
        for &p in &cells {
            set_cell(&mut map, p, c.blocked)?;
        }
        blocked = c.blocked;
        changed.extend(cells);
    }
    planner.set_map(&map)?;
    let mut robot = start;
    let mut trail = vec![start];
    let mut steps: Vec<Step> = Vec::new();
    steps.push(plan_step(
        planner,
        (robot, 0),
        goal,
        &map,
        changed,
        blocked,
        false,
    )?);
    for (i, e) in scenario.events.iter().enumerate() {
        let path = steps.last().map(|s| s.plan.raw.clone()).unwrap_or_default();
        // The robot drives `at` of its path (its last cell is the goal: stop one short).
        let to = ((e.at * (path.len().saturating_sub(1)) as f64).round() as usize)
            .min(path.len().saturating_sub(2));
        trail.extend(path.iter().skip(1).take(to));
        robot = path.get(to).copied().unwrap_or(robot);
        let prev = steps.last().map(|s| s.changed.clone()).unwrap_or_default();
        let cells = resolve(&e.change, &map, &path, to, goal, &prev)?;
        let cells: Vec<Point> = cells.into_iter().filter(|&p| p != robot).collect();
        for &p in &cells {
            set_cell(&mut map, p, e.change.blocked)?;
        }
        planner
            .change(&cells, e.change.blocked)
            .map_err(|e| e.at_event(i))?;
        let at = trail.len() - 1;
        let step = plan_step(
            planner,
            (robot, at),
            goal,
            &map,
            cells,
            e.change.blocked,
            warm,
        )
        .map_err(|e| e.at_event(i))?;
        steps.push(step);
    }
    if let Some(last) = steps.last() {
        trail.extend(last.plan.raw.iter().skip(1));
    }
    Ok(Drive { steps, trail })
}

/// Plan from the robot's cell, check the plan and measure the optimum.
pub(crate) fn plan_step(
    planner: &mut dyn Planner,
    (robot, at): (Point, usize),
    goal: Point,
    map: &Map,
    changed: Vec<Point>,
    blocked: bool,
    warm: bool,
) -> Result<Step, ReplanError> {
    let plan = planner.plan(robot, goal, warm)?;
    check(map, robot, goal, &plan.raw)?;
    Ok(Step {
        robot,
        at,
        changed,
        blocked,
        map: map.clone(),
        optimum: shortest(map, robot, goal),
        plan,
    })
}

/// The cells of a change, given the robot's path and its position on it.
fn resolve(
    c: &Change,
    map: &Map,
    path: &[Point],
    at: usize,
    goal: Point,
    prev: &[Point],
) -> Result<Vec<Point>, ReplanError> {
    if c.undo {
        return Ok(prev.to_vec());
    }
    if let Some(b) = c.box_away {
        return box_away(map, path.get(at..).unwrap_or(path), b);
    }
    let on_map = |x: i64, y: i64| {
        (x >= 0 && y >= 0 && x < i64::from(map.width) && y < i64::from(map.height))
            .then(|| Point::new(x as u16, y as u16))
    };
    if let Some([x, y, w, h]) = c.rect {
        let mut out = Vec::new();
        for yy in u32::from(y)..u32::from(y) + u32::from(h) {
            for xx in u32::from(x)..u32::from(x) + u32::from(w) {
                out.push(
                    on_map(i64::from(xx), i64::from(yy)).ok_or(ReplanError::RectOutside {
                        x: i64::from(xx),
                        y: i64::from(yy),
                    })?,
                );
            }
        }
        return Ok(out);
    }
    if let Some(cells) = &c.cells {
        return cells
            .iter()
            .map(|&[x, y]| {
                on_map(i64::from(x), i64::from(y)).ok_or(ReplanError::Outside {
                    x: i64::from(x),
                    y: i64::from(y),
                })
            })
            .collect();
    }
    let Some(w) = c.wall_ahead else {
        return Ok(Vec::new());
    };
    if path.len() < 3 {
        return Err(ReplanError::PathTooShort);
    }
    // The wall's centre stays off the goal (the path's last cell) and has a next cell.
    let centre = (at + usize::from(w.ahead)).min(path.len() - 2).max(at + 1);
    let (Some(&c0), Some(&c1)) = (path.get(centre), path.get(centre + 1)) else {
        return Err(ReplanError::NoPathCell);
    };
    let (dx, dy) = (
        i64::from(c1.x) - i64::from(c0.x),
        i64::from(c1.y) - i64::from(c0.y),
    );
    // Across the path: the direction turned by 90 degrees.
    let (px, py) = (-dy, dx);
    let n = i64::from(w.cells);
    let mut out = Vec::new();
    for k in -(n / 2)..(n - n / 2) {
        if let Some(p) = on_map(i64::from(c0.x) + k * px, i64::from(c0.y) + k * py) {
            if p != goal && p != path.get(at).copied().unwrap_or(goal) {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// The first `size x size` square of free cells at least `distance` cells from every cell of
/// `path` (row-major order of its top-left corner).
fn box_away(map: &Map, path: &[Point], b: BoxAway) -> Result<Vec<Point>, ReplanError> {
    let (size, d) = (b.size.max(1), b.distance);
    if path.is_empty() {
        return Err(ReplanError::NoPathYet);
    }
    let far = |x: u16, y: u16| {
        path.iter().all(|p| {
            let dx = if p.x < x {
                x - p.x
            } else {
                p.x.saturating_sub(x + size - 1)
            };
            let dy = if p.y < y {
                y - p.y
            } else {
                p.y.saturating_sub(y + size - 1)
            };
            dx.max(dy) >= d
        })
    };
    for y in 0..map.height.saturating_sub(size - 1) {
        for x in 0..map.width.saturating_sub(size - 1) {
            let cells: Vec<Point> = (y..y + size)
                .flat_map(|yy| (x..x + size).map(move |xx| Point::new(xx, yy)))
                .collect();
            if cells.iter().all(|&p| !map.is_blocked(p)) && far(x, y) {
                return Ok(cells);
            }
        }
    }
    Err(ReplanError::NoBox { size, distance: d })
}

/// Check that `raw` goes from `start` to `goal` by allowed moves on `map`.
pub fn check(map: &Map, start: Point, goal: Point, raw: &[Point]) -> Result<(), ReplanError> {
    let grid = map.grid()?;
    if raw.first() != Some(&start) || raw.last() != Some(&goal) {
        return Err(ReplanError::NotJoined);
    }
    for (&a, &b) in raw.iter().zip(raw.iter().skip(1)) {
        let ok = (0..8u8).any(|d| grid.step(a, d) == Some(b));
        if !ok {
            return Err(ReplanError::BadStep { from: a, to: b });
        }
    }
    Ok(())
}

/// Exact shortest 8-connected path length (no corner cutting) from `start` to `goal`, by
/// Dijkstra; `None` if unreachable.
pub fn shortest(map: &Map, start: Point, goal: Point) -> Option<f64> {
    let grid: Grid<'_> = map.grid().ok()?;
    let mut dist = vec![f64::INFINITY; grid.cells()];
    #[derive(PartialEq)]
    struct Item(f64, usize);
    impl Eq for Item {}
    impl PartialOrd for Item {
        fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Item {
        fn cmp(&self, o: &Self) -> std::cmp::Ordering {
            o.0.total_cmp(&self.0)
        }
    }
    let mut heap = BinaryHeap::new();
    *dist.get_mut(grid.index(start))? = 0.0;
    heap.push(Item(0.0, grid.index(start)));
    let goal_i = grid.index(goal);
    while let Some(Item(d, i)) = heap.pop() {
        if i == goal_i {
            return Some(d);
        }
        if d > dist.get(i).copied().unwrap_or(0.0) {
            continue;
        }
        let p = grid.point(i);
        for dir in 0..8u8 {
            if let Some(q) = grid.step(p, dir) {
                let nd = d + if dir & 1 == 1 {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                };
                let qi = grid.index(q);
                if let Some(slot) = dist.get_mut(qi) {
                    if nd < *slot {
                        *slot = nd;
                        heap.push(Item(nd, qi));
                    }
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn open(w: u16, h: u16) -> Map {
        Map::from_fn(w, h, |_, _| false)
    }

    #[test]
    fn a_wall_ahead_makes_the_robot_replan_around_it() {
        let map = open(24, 24);
        let sc = Scenario::parse(r#"{"events":[{"at":0.3,"wall_ahead":{"cells":7,"ahead":4}}]}"#)
            .unwrap();
        for warm in [false, true] {
            let mut p = HostPlanner::new(Params::default());
            let ends = (Point::new(1, 12), Point::new(22, 12));
            let d = drive(&sc, &map, ends, &mut p, warm).unwrap();
            assert_eq!(d.steps.len(), 2);
            let s = &d.steps[1];
            assert_eq!(s.changed.len(), 7);
            assert!(s.changed.iter().all(|&c| s.map.is_blocked(c)));
            // The replan saw the wall: it is valid on the changed map and no ant crossed it.
            check(&s.map, s.robot, Point::new(22, 12), &s.plan.raw).unwrap();
            assert_eq!(s.plan.origin.is_warm(), warm);
            assert!(s.optimum.unwrap() > f64::from(22 - s.robot.x));
            assert!(d.steps.iter().all(|s| d.trail[s.at] == s.robot));
            assert_eq!(d.trail.first(), Some(&Point::new(1, 12)));
            assert_eq!(d.trail.last(), Some(&Point::new(22, 12)));
        }
    }

    #[test]
    fn warm_and_cold_replans_differ_only_after_the_change() {
        let map = open(20, 20);
        let sc = Scenario::parse(
            r#"{"initial":[{"rect":[5,5,6,6]}],
                "events":[{"at":0.4,"rect":[5,5,6,6],"blocked":false}]}"#,
        )
        .unwrap();
        let ends = (Point::new(0, 0), Point::new(19, 19));
        let host = || HostPlanner::new(Params::default());
        let cold = drive(&sc, &map, ends, &mut host(), false).unwrap();
        let warm = drive(&sc, &map, ends, &mut host(), true).unwrap();
        assert_eq!(cold.steps[0].plan, warm.steps[0].plan);
        assert!(!cold.steps[1].plan.origin.is_warm() && warm.steps[1].plan.origin.is_warm());
        assert_eq!(cold.steps[1].changed.len(), 36);
        assert!(!cold.steps[1].blocked);
    }

    #[test]
    fn bad_scenarios_are_refused() {
        assert!(matches!(
            Scenario::parse(r#"{"events":[{"at":2,"rect":[0,0,1,1]}]}"#),
            Err(ReplanError::At { event: 0, .. })
        ));
        assert!(matches!(
            Scenario::parse(r#"{"events":[{"at":0.5}]}"#),
            Err(ReplanError::OneKind)
        ));
        assert!(matches!(
            Scenario::parse(r#"{"oops":1}"#),
            Err(ReplanError::Json(_))
        ));
        let sc = Scenario::parse(r#"{"initial":[{"rect":[2,0,9,1]}]}"#).unwrap();
        let ends = (Point::new(0, 0), Point::new(3, 0));
        let mut host = HostPlanner::new(Params::default());
        let e = drive(&sc, &open(4, 1), ends, &mut host, true).unwrap_err();
        assert!(matches!(e, ReplanError::RectOutside { x: 4, y: 0 }), "{e}");
        assert_eq!(e.to_string(), "rect cell (4, 0) is outside the map");
    }

    #[test]
    fn shortest_is_octile_on_an_open_map() {
        let d = shortest(&open(10, 10), Point::new(0, 0), Point::new(9, 4)).unwrap();
        assert!((d - (5.0 + 4.0 * std::f64::consts::SQRT_2)).abs() < 1e-9);
        let wall = Map::from_fn(5, 5, |x, _| x == 2);
        assert_eq!(shortest(&wall, Point::new(0, 0), Point::new(4, 4)), None);
    }
}
