//! Validators for the core's results, built on [`crate::reference`] (never on the core's own
//! checks):
//!
//! - [`check_raw`]: the raw path starts at the start, ends at the goal, visits free in-map cells
//!   only and moves between 8-neighbours without cutting corners.
//! - [`check_waypoints`]: the output polyline starts and ends right, and every segment obeys the
//!   segment rule.
//! - [`check_plan`]: both, plus every number the [`Plan`] reports (lengths, turns, iteration
//!   counts, the convergence curve) recomputed and compared.

use ohaca::{Algorithm, Plan, Point, SmoothingKind};

use crate::maps::Map;
use crate::reference::{euclid, step_allowed, Segments};

/// Tolerance for comparing an `f32` length the core reports with an `f64` recomputation.
pub fn length_tolerance(len: f64) -> f64 {
    1e-5 * len.max(1.0)
}

/// Validate a raw 8-connected path; returns its length (1 per straight, `sqrt 2` per diagonal
/// step, in `f64`).
pub fn check_raw(map: &Map, start: Point, goal: Point, raw: &[Point]) -> Result<f64, String> {
    let (Some(&first), Some(&last)) = (raw.first(), raw.last()) else {
        return Err("empty raw path".into());
    };
    if first != start {
        return Err(format!("raw path starts at {first:?}, not {start:?}"));
    }
    if last != goal {
        return Err(format!("raw path ends at {last:?}, not {goal:?}"));
    }
    for (i, &p) in raw.iter().enumerate() {
        if !map.is_free(p) {
            return Err(format!("raw cell {i} {p:?} is blocked or off the map"));
        }
    }
    let mut len = 0.0;
    for (i, w) in raw.windows(2).enumerate() {
        let dx = i64::from(w[1].x) - i64::from(w[0].x);
        let dy = i64::from(w[1].y) - i64::from(w[0].y);
        if !step_allowed(map, w[0], dx, dy) {
            return Err(format!(
                "raw step {i} {:?} -> {:?} is not an allowed move (not adjacent, or cuts a corner)",
                w[0], w[1]
            ));
        }
        len += if dx != 0 && dy != 0 {
            std::f64::consts::SQRT_2
        } else {
            1.0
        };
    }
    Ok(len)
}

/// Validate an output polyline by the segment rule; returns its Euclidean length in `f64`.
pub fn check_waypoints(
    map: &Map,
    start: Point,
    goal: Point,
    waypoints: &[Point],
) -> Result<f64, String> {
    check_waypoints_with(&Segments::new(map), map, start, goal, waypoints)
}

fn check_waypoints_with(
    seg: &Segments<'_>,
    map: &Map,
    start: Point,
    goal: Point,
    waypoints: &[Point],
) -> Result<f64, String> {
    let (Some(&first), Some(&last)) = (waypoints.first(), waypoints.last()) else {
        return Err("no waypoints".into());
    };
    if first != start || last != goal {
        return Err(format!(
            "waypoints run {first:?} -> {last:?}, not {start:?} -> {goal:?}"
        ));
    }
    if start != goal && waypoints.len() < 2 {
        return Err("a single waypoint for distinct start and goal".into());
    }
    for &p in waypoints {
        if !map.is_free(p) {
            return Err(format!("waypoint {p:?} is blocked or off the map"));
        }
    }
    let mut len = 0.0;
    for w in waypoints.windows(2) {
        if w[0] == w[1] {
            return Err(format!("repeated waypoint {:?}", w[0]));
        }
        if !seg.clear(w[0], w[1]) {
            return Err(format!(
                "segment {:?} -> {:?} touches an obstacle",
                w[0], w[1]
            ));
        }
        len += euclid(w[0], w[1]);
    }
    Ok(len)
}

/// Interior points of a polyline where the direction changes (including reversals).
pub fn count_turns(points: &[Point]) -> u32 {
    points
        .windows(3)
        .filter(|w| {
            let u = (
                i64::from(w[1].x) - i64::from(w[0].x),
                i64::from(w[1].y) - i64::from(w[0].y),
            );
            let v = (
                i64::from(w[2].x) - i64::from(w[1].x),
                i64::from(w[2].y) - i64::from(w[1].y),
            );
            u.0 * v.1 - u.1 * v.0 != 0 || u.0 * v.0 + u.1 * v.1 <= 0
        })
        .count() as u32
}

/// The corners of a polyline: its ends and every interior point where the direction changes.
pub fn corners(points: &[Point]) -> Vec<Point> {
    let mut out: Vec<Point> = points.iter().take(1).copied().collect();
    for w in points.windows(3) {
        if count_turns(w) == 1 {
            out.push(w[1]);
        }
    }
    if points.len() > 1 {
        out.extend(points.last());
    }
    out
}

/// The first pair `(i, j)` with `j >= i + 2` such that `raw[j]` is one allowed move from `raw[i]`:
/// a detour that [`ohaca::tighten::tighten`] promises to remove. `None` for a tight path.
pub fn shortcut(map: &Map, raw: &[Point]) -> Option<(usize, usize)> {
    (0..raw.len()).find_map(|i| {
        (i + 2..raw.len())
            .find(|&j| {
                let dx = i64::from(raw[j].x) - i64::from(raw[i].x);
                let dy = i64::from(raw[j].y) - i64::from(raw[i].y);
                step_allowed(map, raw[i], dx, dy)
            })
            .map(|j| (i, j))
    })
}

/// True if `sub` is a subsequence of `seq` (same order, not necessarily contiguous).
pub fn is_subsequence(sub: &[Point], seq: &[Point]) -> bool {
    let mut it = seq.iter();
    sub.iter().all(|p| it.any(|q| q == p))
}

/// What [`check_plan`] recomputed.
#[derive(Clone, Debug, PartialEq)]
pub struct Checked {
    /// The raw path's cells.
    pub raw: Vec<Point>,
    /// The output waypoints.
    pub waypoints: Vec<Point>,
    /// Raw length, recomputed in `f64`.
    pub raw_length: f64,
    /// Output length, recomputed in `f64`.
    pub length: f64,
}

/// Validate a whole plan for `start -> goal` on `map`: the raw path, the waypoints, and every
/// reported number. `curve_capacity` is how many curve entries the workspace had.
pub fn check_plan(
    map: &Map,
    start: Point,
    goal: Point,
    plan: &Plan<'_>,
    curve_capacity: usize,
) -> Result<Checked, String> {
    let raw: Vec<Point> = plan.raw().collect();
    let raw_length = check_raw(map, start, goal, &raw)?;
    if plan.raw_len() != raw.len() || plan.directions().len() + 1 != raw.len() {
        return Err(format!(
            "raw_len {} / {} directions for {} cells",
            plan.raw_len(),
            plan.directions().len(),
            raw.len()
        ));
    }
    // The ants' tabu list (and tightening) keep the path loop-free.
    let mut seen = std::collections::HashSet::new();
    if let Some(p) = raw.iter().find(|p| !seen.insert(**p)) {
        return Err(format!("raw path visits {p:?} twice"));
    }
    // A walk takes at most 2 * cells moves (each cell entered once, left backwards once).
    let p = &plan.params;
    let max_moves = u64::from(p.ants) * u64::from(plan.iterations) * 2 * map.cells() as u64;
    if plan.moves > max_moves {
        return Err(format!(
            "{} ant moves, at most {max_moves} possible",
            plan.moves
        ));
    }
    let waypoints = plan.waypoints().to_vec();
    let length = check_waypoints(map, start, goal, &waypoints)?;
    // Waypoints are raw cells, except OHACA's shortest smoothing, which pulls its path taut
    // over the cell centres around the raw path (`ohaca::taut`): then it may not be longer than
    // the raw path (checked with the lengths below).
    let taut = p.algorithm == Algorithm::Ohaca && p.smoothing == ohaca::SmoothingKind::Shortest;
    if !taut && !is_subsequence(&waypoints, &raw) {
        return Err("waypoints are not a subsequence of the raw path".into());
    }
    if taut && f64::from(plan.length) > raw_length + length_tolerance(raw_length) {
        return Err(format!(
            "smoothed length {} longer than the raw path {raw_length}",
            plan.length
        ));
    }
    // Lengths.
    let close =
        |reported: f32, exact: f64| (f64::from(reported) - exact).abs() <= length_tolerance(exact);
    if !close(plan.raw_length, raw_length) {
        return Err(format!(
            "raw_length {} but the raw path is {raw_length}",
            plan.raw_length
        ));
    }
    if !close(plan.length, length) {
        return Err(format!(
            "length {} but the waypoints are {length}",
            plan.length
        ));
    }
    let smoothed =
        plan.params.algorithm == Algorithm::Ohaca && plan.params.smoothing != SmoothingKind::None;
    if !smoothed {
        // Unsmoothed: the waypoints are the raw path's corners and the length is the raw length.
        if plan.length.to_bits() != plan.raw_length.to_bits() {
            return Err(format!(
                "unsmoothed length {} != raw length {}",
                plan.length, plan.raw_length
            ));
        }
        if waypoints != corners(&raw) {
            return Err(format!(
                "unsmoothed waypoints {waypoints:?} are not the raw path's corners {:?}",
                corners(&raw)
            ));
        }
    }
    if f64::from(plan.length) > f64::from(plan.raw_length) + 1e-4 {
        return Err(format!(
            "smoothed length {} exceeds raw length {}",
            plan.length, plan.raw_length
        ));
    }
    if plan.turns != count_turns(&waypoints) {
        return Err(format!(
            "turns {} but the waypoints have {}",
            plan.turns,
            count_turns(&waypoints)
        ));
    }
    // No collinear interior waypoints.
    if waypoints.len() >= 2 && plan.turns as usize != waypoints.len() - 2 {
        return Err(format!(
            "{} waypoints but {} turns: collinear waypoints left in",
            waypoints.len(),
            plan.turns
        ));
    }
    // Iteration bookkeeping.
    let (its, best_it) = (plan.iterations, plan.best_iteration);
    if its == 0 || its > p.iterations || best_it >= its {
        return Err(format!(
            "iterations {its}, best_iteration {best_it}, limit {}",
            p.iterations
        ));
    }
    // The patience that applies: a warm replan's, a refining run's (OHACA with the local search on
    // a map of more than `BLOCKS` cells; every storage of these tests lends its scratch), or the
    // plain one.
    // The local search runs for OHACA on every map (its storage here always lends the scratch).
    let refines = p.refine && p.algorithm == Algorithm::Ohaca;
    let patience = if plan.origin == ohaca::planner::Origin::Warm && p.warm_patience > 0 {
        p.warm_patience
    } else if refines && p.refine_patience > 0 {
        p.refine_patience
    } else {
        p.patience
    };
    // A refining run's stale streak ends only on a gain below `REFINE_GAIN` times the best at the
    // last such gain (`ohaca::planner::REFINE_GAIN`): replayed here from the curve when it holds
    // every iteration; a plan whose curve was cut short is held to the weaker bound.
    let curve = plan.curve();
    let streak_from = if refines && curve.len() == usize::from(its) {
        let mut mark: Option<f32> = None;
        let mut from = 0u16;
        for (i, c) in curve.iter().enumerate() {
            if c.best_so_far.is_finite()
                && mark.is_none_or(|m| c.best_so_far < m * ohaca::planner::REFINE_GAIN)
            {
                mark = Some(c.best_so_far);
                from = i as u16;
            }
        }
        if from > best_it {
            return Err(format!(
                "a significant gain at {from} after the best at {best_it}"
            ));
        }
        from
    } else {
        best_it
    };
    // A refining run also stops after the first iteration whose ants all arrived with a mean
    // length within `REFINE_GAIN` of the iteration's best (`ohaca::planner::settled`), replayed
    // here from the curve when it holds every iteration: such an iteration ends the run, and no
    // earlier one may.
    // Large maps only (the pheromone in blocks; the compact layout's are larger still).
    let windowed = refines && map.cells() > ohaca::pheromone::BLOCKS;
    // An iteration the quorum ended after its first ants (`ohaca::quorum`) settled too: it
    // walked `QUORUM` ants, all arrived, and they agree.
    let agreed = |c: &ohaca::planner::CurvePoint| {
        let all = c.walked == p.ants && c.arrived == p.ants;
        let quorum = c.walked == ohaca::quorum::QUORUM
            && ohaca::quorum::QUORUM < p.ants
            && c.arrived == c.walked;
        (all || quorum) && c.mean * ohaca::planner::REFINE_GAIN <= c.best
    };
    // Every iteration walks every ant, except one the quorum ended (the run's last).
    if let Some(i) = curve.iter().position(|c| c.walked != p.ants) {
        if !(windowed && i + 1 == curve.len() && agreed(&curve[i])) {
            return Err(format!(
                "iteration {i} walked {} of {} ants without a quorum",
                curve[i].walked, p.ants
            ));
        }
    }
    let settled = windowed && curve.len() == usize::from(its) && curve.last().is_some_and(agreed);
    if windowed && curve.len() == usize::from(its) {
        if let Some(i) = curve.iter().take(usize::from(its) - 1).position(agreed) {
            return Err(format!(
                "iteration {i} settled the corridor (mean {} of best {}), but the run went on to {its}",
                curve[i].mean, curve[i].best
            ));
        }
    }
    let early = settled
        || patience > 0
            && (u32::from(its) == u32::from(streak_from) + 1 + u32::from(patience)
                || refines
                    && curve.len() != usize::from(its)
                    && u32::from(its) > u32::from(best_it) + u32::from(patience));
    if its != p.iterations && !early {
        return Err(format!(
            "stopped after {its} of {} iterations (best at {best_it}, patience {patience})",
            p.iterations
        ));
    }
    if early && its > p.iterations {
        return Err("early stop after the limit".into());
    }
    // The curve.
    if curve.len() != usize::from(its).min(curve_capacity) {
        return Err(format!(
            "curve has {} points for {its} iterations",
            curve.len()
        ));
    }
    // The local search never lengthens the colony's path, and runs only where it applies.
    if plan.raw_length > plan.colony_length
        || (!refines && plan.raw_length.to_bits() != plan.colony_length.to_bits())
    {
        return Err(format!(
            "raw_length {} against the colony's {} (local search {refines})",
            plan.raw_length, plan.colony_length
        ));
    }
    let mut best_so_far = f32::INFINITY;
    for (i, c) in curve.iter().enumerate() {
        best_so_far = best_so_far.min(c.best);
        if c.best_so_far.to_bits() != best_so_far.to_bits() {
            return Err(format!(
                "curve[{i}].best_so_far {} != running minimum {best_so_far}",
                c.best_so_far
            ));
        }
        if c.best.is_finite() != c.mean.is_finite()
            || (c.best.is_finite() && c.mean < c.best * (1.0 - 1e-6))
        {
            return Err(format!("curve[{i}]: mean {} below best {}", c.mean, c.best));
        }
        let first_best = i == usize::from(best_it);
        if first_best && c.best_so_far.to_bits() != plan.colony_length.to_bits() {
            return Err(format!(
                "curve[{i}] (best_iteration) has best_so_far {}, plan says {}",
                c.best_so_far, plan.colony_length
            ));
        }
        if i < usize::from(best_it) && c.best_so_far <= plan.colony_length {
            return Err(format!(
                "curve[{i}] already reached {} before best_iteration {best_it}",
                c.best_so_far
            ));
        }
    }
    Ok(Checked {
        raw,
        waypoints,
        raw_length,
        length,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: u16, y: u16) -> Point {
        Point::new(x, y)
    }

    #[test]
    fn raw_checks() {
        let m = Map::from_rows(&["...", ".#.", "..."]);
        let ok = [p(0, 0), p(1, 0), p(2, 0), p(2, 1), p(2, 2)];
        assert_eq!(check_raw(&m, p(0, 0), p(2, 2), &ok), Ok(4.0));
        // Corner cut past the obstacle.
        let cut = [p(0, 0), p(1, 0), p(2, 1), p(2, 2)];
        assert!(check_raw(&m, p(0, 0), p(2, 2), &cut).is_err());
        // Jump.
        let jump = [p(0, 0), p(2, 0), p(2, 2)];
        assert!(check_raw(&m, p(0, 0), p(2, 2), &jump).is_err());
        // Through the obstacle.
        let through = [p(0, 0), p(1, 1), p(2, 2)];
        assert!(check_raw(&m, p(0, 0), p(2, 2), &through).is_err());
        // Wrong end.
        assert!(check_raw(&m, p(0, 0), p(2, 1), &ok).is_err());
        // Staying in place is not a move.
        assert!(check_raw(&m, p(0, 0), p(0, 0), &[p(0, 0), p(0, 0)]).is_err());
        assert_eq!(check_raw(&m, p(0, 0), p(0, 0), &[p(0, 0)]), Ok(0.0));
    }

    #[test]
    fn waypoint_checks() {
        let m = Map::from_rows(&["....", ".#..", "...."]);
        assert!(check_waypoints(&m, p(0, 0), p(3, 2), &[p(0, 0), p(3, 2)]).is_err());
        let l = check_waypoints(&m, p(0, 0), p(3, 2), &[p(0, 0), p(2, 0), p(3, 2)]).unwrap();
        assert!((l - (2.0 + 5f64.sqrt())).abs() < 1e-12);
        assert_eq!(count_turns(&[p(0, 0), p(1, 0), p(2, 0), p(3, 1)]), 1);
        assert_eq!(count_turns(&[p(0, 0), p(2, 0), p(1, 0)]), 1);
        assert!(is_subsequence(
            &[p(0, 0), p(2, 0)],
            &[p(0, 0), p(1, 0), p(2, 0)]
        ));
        assert!(!is_subsequence(
            &[p(2, 0), p(0, 0)],
            &[p(0, 0), p(1, 0), p(2, 0)]
        ));
    }
}
