//! The result of a run: the path ([`Plan`], its cells as a [`RawPath`]) and the convergence curve
//! ([`CurvePoint`]).

use crate::map::grid::{neighbour, Dir, Point};

use super::params::Params;
use super::warm::Memory;

/// One point of the convergence curve.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CurvePoint {
    /// Shortest raw path of this iteration (`f32::INFINITY` if no ant arrived).
    pub best: f32,
    /// Mean raw path length of the ants that arrived (`f32::INFINITY` if none).
    pub mean: f32,
    /// Shortest raw path found so far.
    pub best_so_far: f32,
    /// Ants that reached the goal in this iteration (all of them unless they die at dead ends).
    pub arrived: u16,
    /// Ants that walked in this iteration: all of them, unless the quorum ended it early
    /// ([`crate::planner::quorum`]).
    pub walked: u16,
}

/// Where a [`Plan`] comes from. On the wire it is [`crate::protocol::PathReply::origin`], one
/// byte: the variant's index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Origin {
    /// `0`: a colony run from scratch (`Plan`, or a `PlanWarm` with no colony to keep).
    #[default]
    Cold,
    /// `1`: a colony run that kept the previous run's pheromone ([`super::Run::warm`]).
    Warm,
    /// `2`: no run: the rest of the previous answer from the robot's cell, checked on the map as
    /// it is now, because no change since can shorten it or blocks it ([`super::reuse`]).
    Reused,
    /// `3`: no run: the rest of the previous answer with a local detour around what blocks it
    /// (exact A* in a box, smoothed again), checked whole on the map as it is now and against
    /// every cleared cell ([`super::reuse`], any map; the box sized by what blocks it).
    Repaired,
}

impl Origin {
    /// True unless the path was planned from scratch.
    pub fn is_warm(self) -> bool {
        self != Origin::Cold
    }

    /// The name used in logs and tables: `cold`, `warm`, `reused`, `repaired`.
    pub fn name(self) -> &'static str {
        match self {
            Origin::Cold => "cold",
            Origin::Warm => "warm",
            Origin::Reused => "reused",
            Origin::Repaired => "repaired",
        }
    }
}

impl core::fmt::Display for Origin {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// A replan answered from the last answer (`reuse::answer`, or its repair): its lengths and
/// origin; where it lies
/// in the workspace is the memory's answer now. It borrows nothing, so a caller that owns the
/// workspace can still hand it to a run when there is no such answer
/// ([`super::session::answer`]).
#[derive(Clone, Copy, Debug)]
pub struct Reused {
    pub(super) raw_length: f32,
    pub(super) length: f32,
    pub(super) origin: Origin,
}

impl Reused {
    /// The plan: the memory's answer's raw path in `best` and waypoints in `points` (ranges
    /// the answer checked before it recorded them).
    pub(super) fn plan<'a>(
        self,
        best: &'a [Dir],
        points: &'a [Point],
        memory: &Memory,
        params: &Params,
    ) -> Plan<'a> {
        let (start, tour, waypoints) = match memory.answer {
            Some(a) => {
                let (tour, waypoints) = a.ranges();
                (
                    a.start,
                    best.get(tour).unwrap_or_default(),
                    points.get(waypoints).unwrap_or_default(),
                )
            }
            None => (Point::new(0, 0), &[][..], &[][..]),
        };
        Plan::without_run(
            (start, tour, waypoints),
            (self.raw_length, self.length),
            self.origin,
            *params,
        )
    }
}

/// The result of a run. Borrows the workspace it was computed in.
#[derive(Clone, Copy, Debug)]
pub struct Plan<'a> {
    pub(super) start: Point,
    pub(super) tour: &'a [Dir],
    pub(super) waypoints: &'a [Point],
    /// Length of the raw 8-connected path, in cell units: the colony's best path, shortened by the
    /// local search where it ran ([`Params::refine`]).
    pub raw_length: f32,
    /// Length of the colony's best raw path (the convergence curve's last `best_so_far`): equal to
    /// `raw_length` unless the local search shortened it.
    pub colony_length: f32,
    /// Length of the output path through [`Plan::waypoints`] (smoothed for OHACA).
    pub length: f32,
    /// Turns (inflection points) along the waypoints.
    pub turns: u32,
    /// Iterations run.
    pub iterations: u16,
    /// Iteration (0-based) in which the best path was first found.
    pub best_iteration: u16,
    /// Ant moves made, forward and backtracking, over the whole run.
    pub moves: u64,
    /// Cells pruned before the ants ran ([`crate::map::prune`]).
    pub pruned: u32,
    /// The steps that ran short of scratch (none in a workspace the arena or a board's
    /// `Storage` lays out; [`super::Shortfalls`]).
    pub shortfalls: super::Shortfalls,
    /// Where the path comes from: a cold run, a warm one ([`super::Run::warm`]), or the rest of
    /// the previous answer ([`super::reuse`]).
    pub origin: Origin,
    pub(super) curve: &'a [CurvePoint],
    /// Parameters used.
    pub params: Params,
}

impl<'a> Plan<'a> {
    /// An answer without a run ([`super::reuse`], its repair): no iterations, moves or curve,
    /// the raw length also the colony's.
    pub(super) fn without_run(
        (start, tour, waypoints): (Point, &'a [Dir], &'a [Point]),
        (raw_length, length): (f32, f32),
        origin: Origin,
        params: Params,
    ) -> Self {
        Plan {
            start,
            tour,
            waypoints,
            raw_length,
            colony_length: raw_length,
            length,
            turns: crate::geometry::turns(waypoints),
            iterations: 0,
            best_iteration: 0,
            moves: 0,
            pruned: 0,
            shortfalls: super::Shortfalls::NONE,
            origin,
            curve: &[],
            params,
        }
    }

    /// The raw 8-connected path, start to goal.
    pub fn raw(&self) -> RawPath<'a> {
        RawPath::new(self.start, self.tour)
    }

    /// The raw path as directions (one byte per step).
    pub fn directions(&self) -> &'a [Dir] {
        self.tour
    }

    /// Cells in the raw path (steps + 1).
    pub fn raw_len(&self) -> usize {
        // A slice is at most `isize::MAX` long, so this does not wrap.
        self.tour.len().wrapping_add(1)
    }

    /// The output waypoints: first = start, last = goal, no collinear interior points.
    pub fn waypoints(&self) -> &'a [Point] {
        self.waypoints
    }

    /// Per-iteration best / mean length (as many iterations as the workspace's curve holds).
    pub fn curve(&self) -> &'a [CurvePoint] {
        self.curve
    }
}

/// Iterator over the cells of a raw path.
#[derive(Clone, Debug)]
pub struct RawPath<'a> {
    next: Option<Point>,
    dirs: core::slice::Iter<'a, Dir>,
}

impl<'a> RawPath<'a> {
    /// The cells of the path that starts at `start` and follows `dirs` (directions as in
    /// [`crate::map::grid::DX`]).
    pub fn new(start: Point, dirs: &'a [Dir]) -> Self {
        RawPath {
            next: Some(start),
            dirs: dirs.iter(),
        }
    }
}

impl Iterator for RawPath<'_> {
    type Item = Point;
    fn next(&mut self) -> Option<Point> {
        let cur = self.next?;
        self.next = self.dirs.next().map(|&d| neighbour(cur, d));
        Some(cur)
    }
}
