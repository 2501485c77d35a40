//! One planning run that keeps more than the report: the convergence curve and, on request, the
//! final pheromone table. `render` and `experiment` use it; [`crate::plan_map::plan_map_in`]
//! stays the lean path for `plan`.
//!
//! The pheromone is read from the storage ([`ohaca::heap::HeapStorage`], or a board's:
//! [`crate::board::BoardStorage`]) after the plan is turned into an owned report:
//! the core leaves the table of the last iteration in the workspace's `tau` buffer (smoothing only
//! uses the increment table), so nothing in the core needs to change to get it.

use std::time::Instant;

use ohaca::planner::Poll;
use ohaca::{Error, Params, Point, Run};

use crate::map::Map;
use crate::output::PlanReport;
use crate::plan_map::{Lend, PlanError};

/// A run's report with its convergence curve and, if asked for, its pheromone.
#[derive(Clone, Debug, PartialEq)]
pub struct Traced {
    /// The same report `ohaca plan --json` prints.
    pub report: PlanReport,
    /// Best-so-far raw length after each iteration run ([`ohaca::CurvePoint::best_so_far`];
    /// `f32::INFINITY` while no ant has arrived). Empty when the goal is unreachable.
    pub best_so_far: Vec<f32>,
    /// The final pheromone, `[E, SE, S, SW]` per cell, row-major (see [`ohaca::pheromone`]).
    pub pheromone: Option<Vec<[f32; 4]>>,
    /// Ants sent out over the run (`ants x iterations`).
    pub ants_sent: u64,
    /// Ants that reached the goal ([`ohaca::CurvePoint::arrived`], summed); smaller than
    /// `ants_sent` only when ants die at dead ends.
    pub ants_arrived: u64,
}

/// Plan like [`crate::plan_map::plan_map_in`], keeping the curve and (with `pheromone`) a copy of
/// the final pheromone table. The time in the report covers the core's work only.
pub fn plan_traced<S: Lend + ?Sized>(
    storage: &mut S,
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
    pheromone: bool,
) -> Result<Traced, PlanError> {
    params.validate()?;
    let iterations_max = usize::from(params.iterations);
    let ws = storage.lend(map.cells(), iterations_max)?;
    let grid = map.grid()?;
    let t0 = Instant::now();
    let mut run = Run::new(&grid, start, goal, params, ws)?;
    while let Poll::Working(_) = run.poll() {}
    let iterations = run.iteration();
    let ants_sent = u64::from(iterations) * u64::from(params.ants);
    let finished = run.finish();
    let no_path = matches!(finished, Err(Error::NoPath));
    let (report, best_so_far, ants_arrived) = match finished {
        Ok(plan) => {
            let report = PlanReport::from_plan(&plan, t0.elapsed());
            let curve = plan.curve().iter().map(|c| c.best_so_far).collect();
            let arrived = plan.curve().iter().map(|c| u64::from(c.arrived)).sum();
            (report, curve, arrived)
        }
        // The first step's flood fill found the goal unreachable.
        Err(Error::NoPath) => (
            PlanReport::not_found(params, Error::NoPath, Some(0), t0.elapsed()),
            Vec::new(),
            0,
        ),
        // With `DeadEnd::Die`, or ants dropped for paths longer than the workspace keeps: no ant
        // ever arrived, so the best so far was never finite.
        Err(e @ (Error::NoAntArrived | Error::PathTooLong { .. })) => (
            PlanReport::not_found(
                params,
                format_args!("{e} in {iterations} iterations"),
                Some(iterations),
                t0.elapsed(),
            ),
            vec![f32::INFINITY; usize::from(iterations)],
            0,
        ),
        Err(e) => return Err(e.into()),
    };
    // The plan is gone; the workspace's pheromone buffer still holds the last iteration's table.
    let pheromone = if pheromone && !no_path {
        let ws = storage.lend(map.cells(), iterations_max)?;
        let tau = ws.pheromone();
        Some(tau.get(..map.cells()).unwrap_or(tau).to_vec())
    } else {
        None
    };
    Ok(Traced {
        report,
        best_so_far,
        pheromone,
        ants_sent,
        ants_arrived,
    })
}

/// A per-cell intensity from the edge pheromone: the largest value on any of the cell's 8 edges
/// (the 4 it owns and the 4 its W, NW, N, NE neighbours own). Row-major, `width * height`.
pub fn cell_pheromone(tau: &[[f32; 4]], width: u16, height: u16) -> Vec<f32> {
    let (w, h) = (i64::from(width), i64::from(height));
    let get = |x: i64, y: i64, k: usize| -> f32 {
        if x < 0 || y < 0 || x >= w || y >= h {
            return 0.0;
        }
        tau.get((y * w + x) as usize)
            .and_then(|e| e.get(k))
            .copied()
            .unwrap_or(0.0)
    };
    let mut out = Vec::with_capacity(usize::from(width) * usize::from(height));
    for y in 0..h {
        for x in 0..w {
            // Own edges: E(0) SE(1) S(2) SW(3); W = E of (x-1, y), NW = SE of (x-1, y-1),
            // N = S of (x, y-1), NE = SW of (x+1, y-1).
            let v = [
                get(x, y, 0),
                get(x, y, 1),
                get(x, y, 2),
                get(x, y, 3),
                get(x - 1, y, 0),
                get(x - 1, y - 1, 1),
                get(x, y - 1, 2),
                get(x + 1, y - 1, 3),
            ]
            .into_iter()
            .fold(0.0f32, f32::max);
            out.push(v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Format;
    use crate::plan_map::plan_map;
    use ohaca::heap::HeapStorage;
    use ohaca::DeadEnd;

    fn map() -> Map {
        Map::parse("......\n.##...\n....#.\n......\n", "t", Format::Text).unwrap()
    }

    #[test]
    fn same_report_as_plan() {
        let m = map();
        let p = Params::default();
        let (s, g) = (Point::new(0, 0), Point::new(5, 3));
        let a = plan_map(&m, s, g, &p).unwrap();
        let mut st = HeapStorage::default();
        let t = plan_traced(&mut st, &m, s, g, &p, true).unwrap();
        let strip = |mut r: PlanReport| {
            r.elapsed_us = 0;
            r
        };
        assert_eq!(strip(t.report.clone()), strip(a));
        assert_eq!(
            t.best_so_far.len(),
            usize::from(t.report.iterations.unwrap())
        );
        assert_eq!(
            t.best_so_far.last().copied(),
            t.report.raw_length,
            "the curve ends at the best raw length"
        );
        assert!(t.best_so_far.windows(2).all(|w| w[1] <= w[0]));
        let tau = t.pheromone.unwrap();
        assert_eq!(tau.len(), m.cells());
        assert!(tau
            .iter()
            .flatten()
            .all(|v| *v >= p.tau_min && *v <= p.tau_max));
        // Something was deposited: the table is not uniform any more.
        assert!(tau.iter().flatten().any(|v| *v != tau[0][0]));
    }

    #[test]
    fn unreachable_and_dead_ants() {
        let m = Map::parse(".#.\n##.\n...\n", "t", Format::Text).unwrap();
        let mut st = HeapStorage::default();
        let t = plan_traced(
            &mut st,
            &m,
            Point::new(0, 0),
            Point::new(2, 2),
            &Params::default(),
            true,
        )
        .unwrap();
        assert!(!t.report.found);
        assert!(t.best_so_far.is_empty());
        assert!(t.pheromone.is_none());
        // A long corridor with side pockets, one ant, one iteration, dying ants: may fail; when
        // it does, the curve is all infinity.
        let m = Map::parse(
            "..........\n.#.#.#.#..\n.#.#.#.#.#\n.#.#.#.#..\n",
            "t",
            Format::Text,
        )
        .unwrap();
        for seed in 1..20 {
            let p = Params {
                dead_end: DeadEnd::Die,
                ants: 1,
                iterations: 2,
                seed,
                ..Params::default()
            };
            let t =
                plan_traced(&mut st, &m, Point::new(0, 3), Point::new(9, 3), &p, false).unwrap();
            if !t.report.found {
                assert_eq!(t.best_so_far, vec![f32::INFINITY; 2]);
            }
        }
    }

    #[test]
    fn cell_intensity_reads_all_eight_edges() {
        // 3x3, one edge set on the centre cell's NW edge (owned by (0,0) as SE).
        let mut tau = vec![[0.0f32; 4]; 9];
        tau[0][1] = 5.0;
        let c = cell_pheromone(&tau, 3, 3);
        assert_eq!(c[0], 5.0);
        assert_eq!(c[4], 5.0, "the centre sees its NW edge");
        assert_eq!(c[1], 0.0);
        // NE edge of (0, 1) is SW of (1, 0).
        let mut tau = vec![[0.0f32; 4]; 9];
        tau[1][3] = 2.0;
        let c = cell_pheromone(&tau, 3, 3);
        assert_eq!((c[1], c[3], c[4]), (2.0, 2.0, 0.0));
    }
}
