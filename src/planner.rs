//! The planner: parameters, caller-provided storage, the iteration loop, early stopping and the
//! result.
//!
//! ```text
//! validate parameters, map size, start and goal
//! flood fill: goal unreachable -> Err(NoPath) at once
//! tau = tau0 everywhere
//! repeat `iterations` times (or until the best has not improved for `patience` iterations):
//!     each of `ants` ants walks start -> goal            (colony)
//!     each ant that arrived deposits Q / L on its path    (update)
//!     HACA/OHACA: reward the iteration's best, punish its worst (update, wolves rule)
//!     tau = clamp((1 - rho) tau + deposits, tau_min, tau_max)
//! the best path found -> raw path; OHACA smooths it (smoothing)
//! ```
//!
//! [`Run`] is the loop as a state machine: [`Run::step`] does one iteration, so the firmware can
//! yield to its executor between iterations and cancel a plan by dropping (or finishing) the run.
//! [`plan`] runs it to the end.
//!
//! Storage: nothing is allocated. A [`Workspace`] borrows every buffer the run needs, each at
//! least `cells` long (see [`Workspace::BYTES_PER_CELL`]); [`Storage`] owns such buffers with a
//! compile-time capacity, for a `static` on the device; the host builds a `Workspace` over `Vec`s
//! with [`Workspace::from_slices`].

use crate::colony::{tighten, Colony, DeadEnd, Walk};
use crate::error::{Endpoint, Error, Param};
use crate::geometry::{polyline_length, steps_length, turns};
use crate::grid::{Dir, Grid, Point, DX, DY};
use crate::heuristic::Heuristic;
use crate::pheromone::Table;
use crate::rng::Xoshiro128pp;
use crate::smoothing::{smooth, SmoothingKind};
use crate::update::{deposit, wolves};

/// The four variants the paper compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum Algorithm {
    /// Plain ant colony: `eta = 1 / d_ij`, classic ant-system update.
    Aca,
    /// ACA plus the potential field's goal attraction in `eta`.
    Paca,
    /// PACA plus the wolves-distribution pheromone update.
    Haca,
    /// HACA plus line-of-sight smoothing of the result.
    #[default]
    Ohaca,
}

impl core::fmt::Display for Algorithm {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

impl Algorithm {
    /// All four, in the paper's order.
    pub const ALL: [Algorithm; 4] = [
        Algorithm::Aca,
        Algorithm::Paca,
        Algorithm::Haca,
        Algorithm::Ohaca,
    ];

    /// Lower-case name (`"aca"`, ...).
    pub const fn name(self) -> &'static str {
        match self {
            Algorithm::Aca => "aca",
            Algorithm::Paca => "paca",
            Algorithm::Haca => "haca",
            Algorithm::Ohaca => "ohaca",
        }
    }

    /// Parse a lower-case name.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(s))
    }

    /// Uses the goal attraction in the heuristic.
    pub const fn attracts(self) -> bool {
        !matches!(self, Algorithm::Aca)
    }

    /// Uses the wolves-distribution update.
    pub const fn wolves(self) -> bool {
        matches!(self, Algorithm::Haca | Algorithm::Ohaca)
    }
}

/// Every tunable of the planner.
///
/// Two presets: [`Params::default`] is this project's setting (the paper's `alpha`, `beta`, `rho`,
/// `Q`, `a`, `xi`, `M` and `N`, plus backtracking ants, path tightening, early stopping after 10
/// stale iterations and shortest smoothing); [`Params::paper`] is the paper's algorithm as
/// written (ants die at dead ends, no tightening, always all `N` iterations, greedy smoothing).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Params {
    /// Which variant to run.
    pub algorithm: Algorithm,
    /// Ants per iteration (paper: M = 50).
    pub ants: u16,
    /// Maximum iterations (paper: N = 100).
    pub iterations: u16,
    /// Pheromone exponent (paper: 1).
    pub alpha: f32,
    /// Heuristic exponent (paper: 2).
    pub beta: f32,
    /// Evaporation rate, in `(0, 1]` (paper: 0.1).
    pub rho: f32,
    /// Pheromone deposit constant (paper: 1).
    pub q: f32,
    /// Goal-attraction base `a`, in `(0, 1]` (paper: 0.05).
    pub a: f32,
    /// Potential-field gain `xi` (paper: 1).
    pub xi: f32,
    /// Initial pheromone on every edge.
    pub tau0: f32,
    /// Lower pheromone bound (the paper's `delta = 0.01`).
    pub tau_min: f32,
    /// Upper pheromone bound.
    pub tau_max: f32,
    /// Stop when the best path has not improved for this many iterations; 0 = never stop early.
    pub patience: u16,
    /// Seed of the random generator.
    pub seed: u64,
    /// What an ant does at a dead end.
    pub dead_end: DeadEnd,
    /// How OHACA smooths the result (the other variants never smooth).
    pub smoothing: SmoothingKind,
    /// Straighten each ant's path before the pheromone update ([`crate::colony::tighten`]); not in
    /// the paper, off for faithful comparisons.
    pub tighten: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            algorithm: Algorithm::Ohaca,
            ants: 50,
            iterations: 100,
            alpha: 1.0,
            beta: 2.0,
            rho: 0.1,
            q: 1.0,
            a: 0.05,
            xi: 1.0,
            tau0: 1.0,
            tau_min: 0.01,
            tau_max: 100.0,
            patience: 10,
            seed: 1,
            dead_end: DeadEnd::Backtrack,
            smoothing: SmoothingKind::Shortest,
            tighten: true,
        }
    }
}

impl Params {
    /// The paper's setting as written: `alpha = 1`, `beta = 2`, `rho = 0.1`, `Q = 1`, `a = 0.05`,
    /// `xi = 1`, `M = 50` ants, always the full `N = 100` iterations (`patience = 0`), ants that
    /// die at dead ends, no path tightening and the paper's greedy smoothing (section 4.3). The
    /// pheromone bounds and the seed are [`Params::default`]'s (the paper gives `delta = 0.01`
    /// and no initial value). Use it for faithful comparisons; `docs/ALGORITHM.md` lists where
    /// the default differs and why.
    pub const fn paper() -> Self {
        Params {
            algorithm: Algorithm::Ohaca,
            ants: 50,
            iterations: 100,
            alpha: 1.0,
            beta: 2.0,
            rho: 0.1,
            q: 1.0,
            a: 0.05,
            xi: 1.0,
            tau0: 1.0,
            tau_min: 0.01,
            tau_max: 100.0,
            patience: 0,
            seed: 1,
            dead_end: DeadEnd::Die,
            smoothing: SmoothingKind::Greedy,
            tighten: false,
        }
    }

    /// Check every field's range.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |p| Err(Error::BadParam(p));
        let in_range = |v: f32, lo: f32, hi: f32| v.is_finite() && v >= lo && v <= hi;
        if self.ants == 0 {
            return bad(Param::Ants);
        }
        if self.iterations == 0 {
            return bad(Param::Iterations);
        }
        if !in_range(self.alpha, 0.0, 16.0) {
            return bad(Param::Alpha);
        }
        if !in_range(self.beta, 0.0, 16.0) {
            return bad(Param::Beta);
        }
        if !(self.rho > 0.0 && self.rho <= 1.0) {
            return bad(Param::Rho);
        }
        if !(self.q.is_finite() && self.q > 0.0) {
            return bad(Param::Q);
        }
        if !(self.a > 0.0 && self.a <= 1.0) {
            return bad(Param::A);
        }
        if !(self.xi.is_finite() && self.xi >= 0.0) {
            return bad(Param::Xi);
        }
        let t_ok = self.tau_min.is_finite()
            && self.tau_max.is_finite()
            && self.tau0.is_finite()
            && self.tau_min > 0.0
            && self.tau_min <= self.tau0
            && self.tau0 <= self.tau_max;
        if !t_ok {
            return bad(Param::Tau);
        }
        Ok(())
    }
}

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
}

/// Every buffer a run needs, borrowed from the caller. Each per-cell buffer must hold at least as
/// many entries as the map has cells; the curve records as many iterations as it has entries.
#[derive(Debug)]
pub struct Workspace<'a> {
    tau: &'a mut [[f32; 4]],
    delta: &'a mut [[f32; 4]],
    visited: &'a mut [u8],
    moves: &'a mut [u8],
    tour: &'a mut [Dir],
    iter_best: &'a mut [Dir],
    iter_worst: &'a mut [Dir],
    best: &'a mut [Dir],
    points: &'a mut [Point],
    prev: &'a mut [u32],
    curve: &'a mut [CurvePoint],
}

impl<'a> Workspace<'a> {
    /// Bytes of storage a run needs per map cell: pheromone and its increment (2 x 16), tabu
    /// stamps (1), allowed-move masks (1), four tours (4), raw path points (4), and links (4: the
    /// flood-fill queue, the tightening positions and the smoothing links). Smoothing keeps its
    /// distances in the increment table, which is free once the iterations are over.
    pub const BYTES_PER_CELL: usize = 2 * 16 + 1 + 1 + 4 + 4 + 4;

    /// A workspace over caller buffers (see the type docs for the sizes).
    #[allow(clippy::too_many_arguments)]
    pub fn from_slices(
        tau: &'a mut [[f32; 4]],
        delta: &'a mut [[f32; 4]],
        visited: &'a mut [u8],
        moves: &'a mut [u8],
        tours: [&'a mut [Dir]; 4],
        points: &'a mut [Point],
        prev: &'a mut [u32],
        curve: &'a mut [CurvePoint],
    ) -> Self {
        let [tour, iter_best, iter_worst, best] = tours;
        Workspace {
            tau,
            delta,
            visited,
            moves,
            tour,
            iter_best,
            iter_worst,
            best,
            points,
            prev,
            curve,
        }
    }

    /// The largest map (in cells) this workspace can plan on.
    pub fn capacity(&self) -> usize {
        [
            self.tau.len(),
            self.delta.len(),
            self.visited.len(),
            self.moves.len(),
            self.tour.len(),
            self.iter_best.len(),
            self.iter_worst.len(),
            self.best.len(),
            self.points.len(),
            self.prev.len(),
        ]
        .into_iter()
        .min()
        .unwrap_or(0)
    }

    /// The pheromone table of the last run (`[E, SE, S, SW]` per cell, row-major).
    pub fn pheromone(&self) -> &[[f32; 4]] {
        self.tau
    }
}

/// Fixed-capacity storage for maps of up to `CELLS` cells and convergence curves of `CURVE`
/// iterations. Put it in a `static` on the device; its size is
/// `CELLS * Workspace::BYTES_PER_CELL + CURVE * 16` bytes.
#[derive(Debug)]
pub struct Storage<const CELLS: usize, const CURVE: usize = 128> {
    tau: [[f32; 4]; CELLS],
    delta: [[f32; 4]; CELLS],
    visited: [u8; CELLS],
    moves: [u8; CELLS],
    tours: [[Dir; CELLS]; 4],
    points: [Point; CELLS],
    prev: [u32; CELLS],
    curve: [CurvePoint; CURVE],
}

impl<const CELLS: usize, const CURVE: usize> Storage<CELLS, CURVE> {
    /// Zeroed storage (a `const fn`, so it can initialise a `static`).
    pub const fn new() -> Self {
        Storage {
            tau: [[0.0; 4]; CELLS],
            delta: [[0.0; 4]; CELLS],
            visited: [0; CELLS],
            moves: [0; CELLS],
            tours: [[0; CELLS]; 4],
            points: [Point::new(0, 0); CELLS],
            prev: [0; CELLS],
            curve: [CurvePoint {
                best: 0.0,
                mean: 0.0,
                best_so_far: 0.0,
                arrived: 0,
            }; CURVE],
        }
    }

    /// Borrow the storage as a [`Workspace`].
    pub fn workspace(&mut self) -> Workspace<'_> {
        let [t0, t1, t2, t3] = &mut self.tours;
        Workspace::from_slices(
            &mut self.tau,
            &mut self.delta,
            &mut self.visited,
            &mut self.moves,
            [t0, t1, t2, t3],
            &mut self.points,
            &mut self.prev,
            &mut self.curve,
        )
    }
}

impl<const CELLS: usize, const CURVE: usize> Default for Storage<CELLS, CURVE> {
    fn default() -> Self {
        Self::new()
    }
}

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

/// A planning run in progress. See the module docs.
pub struct Run<'g, 'a> {
    grid: &'g Grid<'g>,
    start: Point,
    goal: Point,
    params: Params,
    heuristic: Heuristic,
    rng: Xoshiro128pp,
    ws: Workspace<'a>,
    cells: usize,
    stamp: u8,
    iteration: u16,
    best: Option<Best>,
    best_iteration: u16,
    stale: u16,
    moves: u64,
    done: bool,
}

impl<'g, 'a> Run<'g, 'a> {
    /// Validate everything and prepare a run. Fails at once with [`Error::NoPath`] when a flood
    /// fill finds the goal unreachable.
    pub fn new(
        grid: &'g Grid<'g>,
        start: Point,
        goal: Point,
        params: &Params,
        ws: Workspace<'a>,
    ) -> Result<Self, Error> {
        params.validate()?;
        let cells = grid.cells();
        let capacity = ws.capacity();
        if cells > capacity {
            return Err(Error::MapTooLarge {
                cells: u32::try_from(cells).unwrap_or(u32::MAX),
                capacity: u32::try_from(capacity).unwrap_or(u32::MAX),
            });
        }
        for (p, e) in [(start, Endpoint::Start), (goal, Endpoint::Goal)] {
            if !grid.contains(p) {
                return Err(Error::OutOfBounds(e));
            }
            if !grid.is_free(p) {
                return Err(Error::Blocked(e));
            }
        }
        if !grid.reachable(start, goal, ws.visited, ws.prev) {
            return Err(Error::NoPath);
        }
        if let Some(v) = ws.visited.get_mut(..cells) {
            v.fill(0);
        }
        if let Some(t) = ws.tau.get_mut(..cells) {
            t.fill([params.tau0; 4]);
        }
        if let Some(d) = ws.delta.get_mut(..cells) {
            d.fill([0.0; 4]);
        }
        for (i, m) in ws.moves.iter_mut().take(cells).enumerate() {
            *m = grid.move_mask(grid.point(i));
        }
        let heuristic = Heuristic::new(
            goal,
            params.algorithm.attracts(),
            params.a,
            params.xi,
            params.beta,
        );
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
            rng: Xoshiro128pp::from_u64(params.seed),
            ws,
            cells,
            stamp: 0,
            iteration: 0,
            best: None,
            best_iteration: 0,
            stale: 0,
            moves: 0,
            done: false,
        })
    }

    /// Ant moves made so far.
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Iteration (0-based) in which the best path so far was found, if any ant has arrived.
    pub fn best_iteration(&self) -> Option<u16> {
        self.best.map(|_| self.best_iteration)
    }

    /// Length of the best raw path found so far.
    pub fn best_length(&self) -> Option<f32> {
        self.best.map(|b| b.length())
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
    pub fn step_observed(&mut self, mut on_tour: impl FnMut(&[Dir])) -> bool {
        if self.done {
            return false;
        }
        let cells = self.cells;
        let p = self.params;
        let w = self.grid.width();
        // Split the workspace into what the ants read and what the update writes.
        let Workspace {
            tau,
            delta,
            visited,
            tour,
            iter_best,
            iter_worst,
            best: best_tour,
            moves,
            points,
            prev,
            curve,
            ..
        } = &mut self.ws;
        let (Some(tau), Some(delta), Some(visited)) = (
            tau.get_mut(..cells),
            delta.get_mut(..cells),
            visited.get_mut(..cells),
        ) else {
            self.done = true;
            return false;
        };
        let mut tau = Table::new(w, tau);
        let mut delta = Table::new(w, delta);
        let mut it_best: Option<(Best, u32)> = None;
        let mut it_worst: Option<(Best, u32)> = None;
        let mut sum = 0.0f32;
        let mut arrived = 0u32;
        {
            let colony = Colony {
                grid: self.grid,
                start: self.start,
                goal: self.goal,
                tau: &tau,
                heuristic: &self.heuristic,
                alpha: p.alpha,
                dead_end: p.dead_end,
                moves,
            };
            for _ in 0..p.ants {
                self.stamp = self.stamp.wrapping_add(1);
                if self.stamp == 0 {
                    visited.fill(0);
                    self.stamp = 1;
                }
                let Some(walk) = colony.walk(&mut self.rng, visited, self.stamp, tour) else {
                    continue;
                };
                self.moves = self.moves.saturating_add(u64::from(walk.moves));
                let walk = if p.tighten && walk.may_tighten {
                    tighten(self.grid, self.start, walk, tour, moves, points, prev)
                } else {
                    walk
                };
                let Some(path) = tour.get(..walk.steps) else {
                    continue;
                };
                on_tour(path);
                let b = Best::of(&walk);
                let len = b.length();
                sum += len;
                arrived = arrived.saturating_add(1);
                deposit(&mut delta, self.grid, self.start, path, p.q / len);
                match &mut it_best {
                    Some((cur, n)) if cur.same_length(&b) => *n = n.saturating_add(1),
                    Some((cur, _)) if len >= cur.length() => {}
                    _ => {
                        copy_tour(iter_best, path);
                        it_best = Some((b, 1));
                    }
                }
                match &mut it_worst {
                    Some((cur, n)) if cur.same_length(&b) => *n = n.saturating_add(1),
                    Some((cur, _)) if len <= cur.length() => {}
                    _ => {
                        copy_tour(iter_worst, path);
                        it_worst = Some((b, 1));
                    }
                }
            }
        }
        if let (true, Some((b, nb)), Some((wst, nw))) = (p.algorithm.wolves(), it_best, it_worst) {
            if let (Some(bt), Some(wt)) = (iter_best.get(..b.steps), iter_worst.get(..wst.steps)) {
                wolves(
                    &mut delta,
                    self.grid,
                    self.start,
                    p.q,
                    (bt, b.length(), nb),
                    (wt, wst.length(), nw),
                );
            }
        }
        tau.evaporate_and_merge(&mut delta, p.rho, p.tau_min, p.tau_max);

        // Track the run's best.
        let improved = match (it_best, self.best) {
            (Some((b, _)), None) => Some(b),
            (Some((b, _)), Some(g)) if b.length() < g.length() => Some(b),
            _ => None,
        };
        if let Some(b) = improved {
            if let Some(src) = iter_best.get(..b.steps) {
                copy_tour(best_tour, src);
            }
            self.best = Some(b);
            self.best_iteration = self.iteration;
            self.stale = 0;
        } else {
            self.stale = self.stale.saturating_add(1);
        }
        let inf = f32::INFINITY;
        let point = CurvePoint {
            best: it_best.map_or(inf, |(b, _)| b.length()),
            mean: if arrived > 0 {
                sum / arrived as f32
            } else {
                inf
            },
            best_so_far: self.best.map_or(inf, |b| b.length()),
            arrived: u16::try_from(arrived).unwrap_or(u16::MAX),
        };
        if let Some(slot) = curve.get_mut(usize::from(self.iteration)) {
            *slot = point;
        }
        self.iteration = self.iteration.saturating_add(1);
        let early = p.patience > 0 && self.best.is_some() && self.stale >= p.patience;
        self.done = self.iteration >= p.iterations || early;
        !self.done
    }

    /// Stop now and turn the best path found so far into the result (smoothed for OHACA).
    /// Fails with [`Error::NoAntArrived`] if no ant has reached the goal (only possible with
    /// [`DeadEnd::Die`], or before the first iteration).
    pub fn finish(self) -> Result<Plan<'a>, Error> {
        let Run {
            grid,
            start,
            goal,
            params,
            ws,
            best,
            best_iteration,
            iteration,
            moves,
            ..
        } = self;
        let best = best.ok_or(Error::NoAntArrived)?;
        let Workspace {
            best: best_tour,
            points,
            delta,
            prev,
            curve,
            ..
        } = ws;
        // The increment table is all zeros between iterations and unused from here on: lend it
        // to the smoothing as its distance scratch (4 floats per cell, at least n).
        let dist = delta.as_flattened_mut();
        let tour: &'a [Dir] = best_tour.get(..best.steps).ok_or(Error::NoPath)?;
        // Expand the tour into cells.
        let n = best.steps.checked_add(1).ok_or(Error::NoPath)?;
        let pts = points.get_mut(..n).ok_or(Error::NoPath)?;
        for (slot, p) in pts.iter_mut().zip(RawPath::new(start, tour)) {
            *slot = p;
        }
        let kind = if params.algorithm == Algorithm::Ohaca {
            params.smoothing
        } else {
            SmoothingKind::None
        };
        let k = smooth(grid, kind, pts, n, dist, prev);
        let pts: &'a [Point] = points;
        let waypoints = pts.get(..k).ok_or(Error::NoPath)?;
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
        let _ = goal;
        Ok(Plan {
            start,
            tour,
            waypoints,
            raw_length: best.length(),
            length,
            turns: turns(waypoints),
            iterations: iteration,
            best_iteration,
            moves,
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

/// Plan a path: [`Run::new`], [`Run::step`] until done, [`Run::finish`].
pub fn plan<'a>(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: Workspace<'a>,
) -> Result<Plan<'a>, Error> {
    // The run borrows the grid only while it runs; the plan keeps the workspace's buffers.
    let grid = *grid;
    let mut run = Run::new(&grid, start, goal, params, ws)?;
    while run.step() {}
    run.finish()
}

/// The result of a run. Borrows the workspace it was computed in.
#[derive(Clone, Copy, Debug)]
pub struct Plan<'a> {
    start: Point,
    tour: &'a [Dir],
    waypoints: &'a [Point],
    /// Length of the raw 8-connected path, in cell units.
    pub raw_length: f32,
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
    curve: &'a [CurvePoint],
    /// Parameters used.
    pub params: Params,
}

impl<'a> Plan<'a> {
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
    fn new(start: Point, dirs: &'a [Dir]) -> Self {
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
        self.next = self.dirs.next().map(|&d| {
            let di = usize::from(d & 7);
            // A u16 plus -1..=1: no i32 overflow.
            let x = i32::from(cur.x).wrapping_add(DX.get(di).copied().unwrap_or(0));
            let y = i32::from(cur.y).wrapping_add(DY.get(di).copied().unwrap_or(0));
            Point::new(
                x.clamp(0, i32::from(u16::MAX)) as u16,
                y.clamp(0, i32::from(u16::MAX)) as u16,
            )
        });
        Some(cur)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        let w = rows[0].len();
        let mut b = vec![0u8; (w * rows.len()).div_ceil(8)];
        for (y, r) in rows.iter().enumerate() {
            for (x, c) in r.chars().enumerate() {
                if c == '#' {
                    let i = y * w + x;
                    b[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (b, w as u16, rows.len() as u16)
    }

    const ROWS: [&str; 6] = [
        "........", //
        ".####...", //
        "....#.#.", //
        ".##.#.#.", //
        "......#.", //
        "........", //
    ];

    #[test]
    fn finds_a_path_on_a_small_map() {
        let (b, w, h) = grid(&ROWS);
        let g = Grid::new(w, h, &b).unwrap();
        let mut s: Storage<64> = Storage::new();
        let plan = plan(
            &g,
            Point::new(0, 0),
            Point::new(7, 5),
            &Params::default(),
            s.workspace(),
        )
        .unwrap();
        let raw: Vec<_> = plan.raw().collect();
        assert_eq!(raw[0], Point::new(0, 0));
        assert_eq!(*raw.last().unwrap(), Point::new(7, 5));
        assert!(plan.length <= plan.raw_length + 1e-4);
        assert_eq!(plan.waypoints()[0], Point::new(0, 0));
        assert_eq!(*plan.waypoints().last().unwrap(), Point::new(7, 5));
    }

    #[test]
    fn errors() {
        let (b, w, h) = grid(&ROWS);
        let g = Grid::new(w, h, &b).unwrap();
        let mut s: Storage<64> = Storage::new();
        let p = Params::default();
        let e = |st: Point, go: Point, p: &Params, s: &mut Storage<64>| {
            plan(&g, st, go, p, s.workspace()).map(|_| ()).unwrap_err()
        };
        assert_eq!(
            e(Point::new(8, 0), Point::new(0, 0), &p, &mut s),
            Error::OutOfBounds(Endpoint::Start)
        );
        assert_eq!(
            e(Point::new(0, 0), Point::new(1, 1), &p, &mut s),
            Error::Blocked(Endpoint::Goal)
        );
        assert_eq!(
            e(
                Point::new(0, 0),
                Point::new(0, 0),
                &Params { ants: 0, ..p },
                &mut s
            ),
            Error::BadParam(Param::Ants)
        );
        assert_eq!(
            e(
                Point::new(0, 0),
                Point::new(0, 0),
                &Params { rho: 0.0, ..p },
                &mut s
            ),
            Error::BadParam(Param::Rho)
        );
        assert_eq!(
            e(
                Point::new(0, 0),
                Point::new(0, 0),
                &Params { rho: f32::NAN, ..p },
                &mut s
            ),
            Error::BadParam(Param::Rho)
        );
        let mut small: Storage<16> = Storage::new();
        assert_eq!(
            plan(
                &g,
                Point::new(0, 0),
                Point::new(1, 0),
                &p,
                small.workspace()
            )
            .map(|_| ())
            .unwrap_err(),
            Error::MapTooLarge {
                cells: 48,
                capacity: 16
            }
        );
        // Walled-in goal.
        let (b, w, h) = grid(&["..#.", ".###", "...."]);
        let g2 = Grid::new(w, h, &b).unwrap();
        assert_eq!(
            plan(&g2, Point::new(0, 0), Point::new(3, 0), &p, s.workspace())
                .map(|_| ())
                .unwrap_err(),
            Error::NoPath
        );
    }

    #[test]
    fn start_equals_goal() {
        let (b, w, h) = grid(&ROWS);
        let g = Grid::new(w, h, &b).unwrap();
        let mut s: Storage<64> = Storage::new();
        let plan = plan(
            &g,
            Point::new(3, 2),
            Point::new(3, 2),
            &Params::default(),
            s.workspace(),
        )
        .unwrap();
        assert_eq!(plan.waypoints(), &[Point::new(3, 2)]);
        assert_eq!(plan.raw_length, 0.0);
    }

    #[test]
    fn storage_size_is_bytes_per_cell_times_cells() {
        let curve = core::mem::size_of::<CurvePoint>();
        assert_eq!(curve, 16);
        assert_eq!(
            core::mem::size_of::<Storage<1024>>(),
            1024 * Workspace::BYTES_PER_CELL + 128 * curve
        );
        assert_eq!(
            core::mem::size_of::<Storage<676>>(),
            676 * Workspace::BYTES_PER_CELL + 128 * curve
        );
    }

    #[test]
    fn paper_preset_differs_from_default_only_where_documented() {
        let d = Params::default();
        assert_eq!(
            Params::paper(),
            Params {
                patience: 0,
                dead_end: DeadEnd::Die,
                smoothing: SmoothingKind::Greedy,
                tighten: false,
                ..d
            }
        );
        assert_eq!(Params::paper().validate(), Ok(()));
    }

    #[test]
    fn deterministic_per_seed() {
        let (b, w, h) = grid(&ROWS);
        let g = Grid::new(w, h, &b).unwrap();
        let run = |seed, alg| {
            let mut s: Storage<64> = Storage::new();
            let p = Params {
                seed,
                algorithm: alg,
                ..Params::default()
            };
            let pl = plan(&g, Point::new(0, 5), Point::new(7, 0), &p, s.workspace()).unwrap();
            (
                pl.raw().collect::<Vec<_>>(),
                pl.waypoints().to_vec(),
                pl.length.to_bits(),
                pl.iterations,
                pl.moves,
            )
        };
        for alg in Algorithm::ALL {
            assert_eq!(run(7, alg), run(7, alg));
        }
    }
}
