//! Replans that cannot improve: the rest of the previous answer from the robot's cell, without a
//! colony run.
//!
//! A robot replans whenever its costmap changes, and most changes are far from its path. After
//! [`super::Run::keep`] the workspace still holds the last answer (its raw path in the best tour,
//! its waypoints in `points`) and [`Memory`] knows where, and which cells were cleared since it was
//! planned. [`reuse`] answers a replan to the same goal with the rest of that answer when it can
//! prove that no new plan could be shorter:
//!
//! 1. **The robot is on the answer**: its cell is a cell of the raw path (the first occurrence).
//!    The raw answer is the rest of the raw path from there; the waypoints are the robot's cell
//!    followed by the waypoints after the segment nearest to it (a collinear first one dropped).
//! 2. **Nothing blocks it**: every move of the raw rest is allowed on the map as it is now
//!    ([`Grid::step`]: free cells, no corner cut) and every segment of the waypoints is clear
//!    ([`segment_clear`]). So a cell blocked since the answer was planned is off it, or the
//!    answer is not reused: it goes to [`super::repair`] (a local detour) and, if that gives up,
//!    to the colony.
//! 3. **No cleared cell can shorten it**: for every rectangle `R` of cells cleared since the
//!    answer was planned, `d(s, R) + d(R, g)` is at least the answer's length, for the octile
//!    distance against the raw length and the Euclidean distance to `R`'s squares against the
//!    smoothed length (`s` the robot's cell, `g` the goal).
//!
//! **Why that is enough** (the proof, also in `docs/ALGORITHM.md`): take any path `Q` from `s` to
//! `g` on the map as it is now. If `Q` touches no cleared cell, every cell it touches was free
//! when the answer was planned (a cell free now and not cleared since was free then), so `Q` was a
//! candidate then and the change gave nothing new. If `Q` touches a cleared cell `c` in `R`, then
//! `|Q| >= d(s, c) + d(c, g) >= d(s, R) + d(R, g) >=` the answer's length, for 8-connected paths
//! through cell centres with the octile distance and for any-angle paths touching `c`'s closed
//! square with the Euclidean one. So no path the change made possible is shorter than the
//! answer, and the answer is valid on the map as it is now (step 2). Blocked cells alone can
//! only lengthen other paths. The reused answer is as good as the rest of the last one was.
//!
//! **Cost**: one walk over the raw path and one [`segment_clear`] per waypoint: a few hundred
//! instructions a path cell, no colony, no pruning, no route; the colony's memory is untouched,
//! so the next warm run still repairs around every change since the colony last ran.
//!
//! **When it does not**: [`reuse`] returns why ([`Fallback`]: no answer for this goal, the robot
//! off it, a cleared cell that may shorten it, or the repair's [`GiveUp`] reason); the firmware
//! logs it and `ohaca replan` prints it, and the caller runs the warm colony.
//!
//! Host and device call the same function on the same workspace layout, so a reused answer is
//! the same bit for bit on both. Panic-free like the rest of the core: indices are checked.

use core::fmt;

use crate::geometry::{bend, distance, segment_clear, steps_length};
use crate::map::grid::{is_diagonal, neighbour, Dir, Grid, Point};
use crate::polish::smoothing::SmoothingKind;

use super::params::{Algorithm, Params};
use super::plan::Reused;
use super::plan::{Origin, Plan};
use super::repair::GiveUp;
use super::warm::{Answer, Memory};
use super::workspace::Workspace;

/// Why [`reuse`] did not answer a replan without a run (the caller then runs the colony, warm).
/// Small, `Copy`, `Display`; `defmt::Format` with the `defmt` feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fallback {
    /// No answer is kept for this map, goal and parameters (no plan since the map was set, another
    /// goal or other parameters), or the robot is on the goal.
    NoAnswer,
    /// The robot's cell is not a cell of the answer's raw path (rule 1).
    OffAnswer,
    /// A cell cleared since the answer was planned may shorten it (rule 3).
    MayShorten,
    /// Something blocks the answer (rule 2) and its repair gave up (why: [`GiveUp`]).
    Repair(GiveUp),
}

impl fmt::Display for Fallback {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Fallback::NoAnswer => f.write_str("no answer kept for this goal"),
            Fallback::OffAnswer => f.write_str("the robot is off the answer"),
            Fallback::MayShorten => f.write_str("a cleared cell may shorten the answer"),
            Fallback::Repair(g) => write!(f, "the repair gave up: {g}"),
        }
    }
}

/// The rest of the last answer to `goal` from the robot's cell `start`, when `memory` says the
/// workspace holds one planned with `params` (any seed) on a map of this size, and no change
/// since can block or shorten it (see the module docs), or its repair around what blocks it
/// ([`Origin::Repaired`]); otherwise why not ([`Fallback`]), and the caller plans (warm). On
/// success the memory's answer becomes the returned one (the next replan starts from it), and
/// the plan's [`Plan::origin`] is [`Origin::Reused`] (or `Repaired`): no iterations, no moves.
///
/// `ws` must be the workspace the last run planned in, laid out the same way (the firmware's
/// storage, the host's arena or heap storage for the same map), unchanged since but for the map.
pub fn reuse<'a>(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: &'a mut Workspace<'_>,
    memory: &mut Memory,
) -> Result<Plan<'a>, Fallback> {
    let reused = answer(grid, start, goal, params, ws, memory)?;
    let Workspace { best, points, .. } = ws;
    Ok(reused.plan(best, points, memory, params))
}

/// [`reuse`]'s answer without its plan: the memory's answer is the new one on success.
pub(super) fn answer(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: &mut Workspace<'_>,
    memory: &mut Memory,
) -> Result<Reused, Fallback> {
    use Fallback::{NoAnswer, OffAnswer};
    if !memory.is_warm_for(grid.width(), grid.height(), goal) || start == goal {
        return Err(NoAnswer);
    }
    let answer = memory.answer.ok_or(NoAnswer)?;
    if answer.params != (Params { seed: 0, ..*params }) {
        return Err(NoAnswer);
    }
    let (raw, waypoints) = answer.ranges();
    let (from, steps, first, end) = (raw.start, raw.end, waypoints.start, waypoints.end);
    // 1. The robot's cell on the raw path.
    let tour: &[Dir] = ws.best.get(from..steps).ok_or(NoAnswer)?;
    let mut p = answer.start;
    let mut at = None;
    for (i, &d) in tour.iter().enumerate() {
        if p == start {
            at = Some(i);
            break;
        }
        p = neighbour(p, d);
    }
    let at = at.ok_or(OffAnswer)?;
    // The waypoints after the segment nearest the robot.
    let wps: &[Point] = ws.points.get(first..end).ok_or(NoAnswer)?;
    let mut entry = nearest_segment(wps, start).ok_or(NoAnswer)?;
    // Dropped when the robot's cell, it and the next are collinear (straight on).
    if let (Some(&a), Some(&b)) = (wps.get(entry), wps.get(entry.wrapping_add(1))) {
        let (cross, dot) = bend(start, a, b);
        if cross == 0 && dot > 0 {
            entry = entry.wrapping_add(1);
        }
    }
    // 2. The rest of the raw path, move by move on the map as it is now ...
    let rest = tour.get(at..).ok_or(OffAnswer)?;
    let (mut straight, mut diagonal) = (0u32, 0u32);
    let mut p = Some(start);
    for &d in rest {
        p = p.and_then(|p| grid.step(p, d));
        if is_diagonal(d) {
            diagonal = diagonal.wrapping_add(1);
        } else {
            straight = straight.wrapping_add(1);
        }
    }
    // ... every segment clear, the robot's first one included; their length summed as
    // [`crate::geometry::polyline_length`] sums the answer's waypoints (left to right from 0),
    // so it is the length a run would report for them.
    let mut prev = start;
    let mut polyline = 0.0f32;
    let mut clear = p == Some(goal);
    for &w in wps.get(entry..).ok_or(NoAnswer)? {
        if !clear || !segment_clear(grid, prev, w) {
            clear = false;
            break;
        }
        polyline += distance(prev, w);
        prev = w;
    }
    if !clear {
        // Blocked: repaired around what blocks it, else planned.
        return super::repair::repair(grid, start, goal, params, ws, memory, answer, at, entry)
            .map_err(Fallback::Repair);
    }
    // 3. The lengths, against every cleared rectangle's lower bounds.
    let raw_length = steps_length(straight, diagonal);
    // Without smoothing a run reports the raw length (`Run::finish`).
    let smoothed = params.algorithm == Algorithm::Ohaca && params.smoothing != SmoothingKind::None;
    let length = if smoothed { polyline } else { raw_length };
    if !memory.cannot_shorten(start, goal, raw_length, length) {
        return Err(Fallback::MayShorten);
    }
    // The robot's cell goes into the slot before the entry: a waypoint it has passed.
    let k0 = first.wrapping_add(entry).checked_sub(1).ok_or(NoAnswer)?;
    // The new answer's ranges, checked before they are recorded ([`Reused::plan`] reads them).
    let ranges = (from.wrapping_add(at)..steps, k0..end);
    if ws.best.get(ranges.0.clone()).is_none() || ws.points.get(ranges.1.clone()).is_none() {
        return Err(NoAnswer);
    }
    *ws.points.get_mut(k0).ok_or(NoAnswer)? = start;
    memory.answer = Some(Answer {
        start,
        from: u32::try_from(ranges.0.start).map_err(|_| NoAnswer)?,
        steps: answer.steps,
        first: u32::try_from(k0).map_err(|_| NoAnswer)?,
        end: answer.end,
        params: answer.params,
    });
    Ok(Reused {
        raw_length,
        length,
        origin: Origin::Reused,
    })
}

/// The index `e >= 1` of the waypoint that ends the segment `wps[e - 1]..wps[e]` nearest to `p`
/// (the later one on a tie: a robot on a waypoint is past it); `None` for fewer than two.
fn nearest_segment(wps: &[Point], p: Point) -> Option<usize> {
    let mut best: Option<(f32, usize)> = None;
    for (i, pair) in wps.windows(2).enumerate() {
        let (Some(&a), Some(&b)) = (pair.first(), pair.get(1)) else {
            continue;
        };
        let d = segment_distance2(p, a, b);
        if best.is_none_or(|(bd, _)| d <= bd) {
            best = Some((d, i.wrapping_add(1)));
        }
    }
    best.map(|(_, e)| e)
}

/// Squared distance from `p` to the segment `a..b` (cell centres).
fn segment_distance2(p: Point, a: Point, b: Point) -> f32 {
    let f = |v: u16| f32::from(v);
    let (vx, vy) = (f(b.x) - f(a.x), f(b.y) - f(a.y));
    let (wx, wy) = (f(p.x) - f(a.x), f(p.y) - f(a.y));
    let len2 = vx * vx + vy * vy;
    let t = if len2 > 0.0 {
        ((wx * vx + wy * vy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (dx, dy) = (wx - t * vx, wy - t * vy);
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_segment_prefers_the_later_on_a_tie() {
        let wps = [Point::new(0, 0), Point::new(10, 0), Point::new(10, 10)];
        assert_eq!(nearest_segment(&wps, Point::new(3, 1)), Some(1));
        assert_eq!(nearest_segment(&wps, Point::new(10, 0)), Some(2));
        assert_eq!(nearest_segment(&wps, Point::new(9, 7)), Some(2));
        assert_eq!(nearest_segment(&wps[..1], Point::new(9, 7)), None);
    }
}
