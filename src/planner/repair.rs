//! Repaired replans: the rest of the last answer with a local detour around what blocks it,
//! instead of a colony run.
//!
//! [`super::reuse`] hands a replan here when the robot is on the kept answer (its rule 1) but a
//! cell blocked since sits on the raw rest or on one of its waypoint segments (rule 2 fails). On
//! large maps (more than [`BLOCKS`] cells: a coarse route, so the local search's scratch exists)
//! this module owns the answer's repair:
//!
//! 1. **The stretch**: the raw offsets of the first and last invalid move of the raw rest, and of
//!    every blocked waypoint segment (each waypoint is placed on the raw cell it lies on or beside,
//!    in order; one that is not within a cell of the raw path gives up). Anchors [`MARGIN`] raw
//!    cells before and after it, clamped to the robot's cell and the goal.
//! 2. **The detour**: exact A* between the anchors in a box around the stretch, as large as the
//!    local search's window ([`crate::refine::detour`], the same scratch: links, coarse route
//!    words, tabu bits). No path in the box, or one longer than the stretch by more than
//!    [`longest_detour`], gives up.
//! 3. **The splice**: the raw path becomes the kept raw up to the first anchor, the detour, the
//!    kept raw after the second ([`Workspace::best`] rewritten from the robot's offset, the tail
//!    shifted); the waypoints around it are smoothed again by the polish's DP ([`Smoother`], same
//!    [`Params::smoothing`]) from the last kept waypoint before the first anchor to the first
//!    after the second, and spliced between the kept waypoints.
//!
//! **Guarantees**: the returned answer is checked whole exactly as [`super::reuse`] checks a
//! kept one (every raw move with [`Grid::step`], every waypoint segment with [`segment_clear`],
//! ending at the goal) and against every rectangle of cells cleared since the last colony run
//! (rule 3, on the new lengths: no cleared cell can shorten it). It is not proven shortest: a
//! detour inside a box is the best path that keeps the rest, and the colony may find another
//! corridor; hence the bound on its length. Giving up after the splice started clears
//! [`Memory`]'s answer (the caller then runs the warm colony, which plans afresh). Only buffers
//! that are scratch after a run are written besides the answer's own (`best`, `points`): the
//! links, the coarse route's words, the tabu bits and the front of the pheromone increments (the
//! smoothing's ring); the pheromone, the pruning marks and the stashed route links stay, so the
//! next warm run repairs its colony as after any other replan. Host and device run the same code
//! on the same layout, with the same fixed scratch size ([`REFINE_WORDS`]), so a repaired answer
//! is the same bit for bit on both. Panic-free: every index is checked.

use crate::geometry::{distance, segment_clear, steps_length};
use crate::grid::{direction, is_diagonal, neighbour, Dir, Grid, Point};
use crate::pheromone::BLOCKS;
use crate::refine::{self, Scratch};
use crate::smoothing::{Smoother, SmoothingKind};

use super::lend::Polishing;
use super::params::{Algorithm, Params};
use super::plan::{Origin, Plan};
use super::run::{REFINE_WORDS, SHORT_REFINE_WORDS};
use super::warm::{Answer, Memory};
use super::workspace::Workspace;

/// Raw cells kept between the blocked stretch and each anchor of the detour: room for the detour
/// to leave the old path at an angle instead of turning at the obstacle.
pub const MARGIN: usize = 12;

/// Cells of box around the stretch beyond its bounding box, on every side (then grown into the
/// window's area).
const BOX_MARGIN: usize = 6;

/// The longest detour accepted for a stretch whose old raw length is `old`: `old` plus a quarter
/// of it or 20 cells, whichever is more. A wall across a corridor costs a few cells around its
/// end; a detour much longer than that means the obstacle closes the corridor and another one may
/// well be shorter, which only the colony (searching the whole map) can tell.
pub fn longest_detour(old: f32) -> f32 {
    old + (old / 4.0).max(20.0)
}

/// Cells between two points (Chebyshev).
fn cheb(a: Point, b: Point) -> u16 {
    a.x.abs_diff(b.x).max(a.y.abs_diff(b.y))
}

/// Repair the kept answer around what blocks it (see the module docs); `None` gives the replan
/// to the colony. `answer` is the memory's answer, the robot's cell `start` is raw cell `at` of
/// it, and the waypoints after the robot's are `points[first + entry..end]` ([`super::reuse`]).
#[allow(clippy::too_many_arguments)] // reuse's state, passed on
pub(super) fn repair<'a>(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: &'a mut Workspace<'_>,
    memory: &mut Memory,
    answer: Answer,
    at: usize,
    entry: usize,
) -> Option<Plan<'a>> {
    if grid.cells() <= BLOCKS {
        return None;
    }
    let idx = |v: u32| usize::try_from(v).unwrap_or(usize::MAX);
    let (from, steps) = (idx(answer.from), idx(answer.steps));
    let (first, end) = (idx(answer.first), idx(answer.end));
    let base = from.checked_add(at)?; // the robot's direction in `best`
    let rest: &[Dir] = ws.best.get(base..steps)?;
    let n = rest.len();
    // L: the robot's cell, then the kept waypoints after it; `k0` is the robot's slot.
    let k0 = first.checked_add(entry)?.checked_sub(1)?;
    let wps: &[Point] = ws.points.get(first.checked_add(entry)?..end)?;
    let n_l = wps.len().checked_add(1)?;
    let l_at = |m: usize| -> Option<Point> {
        if m == 0 {
            Some(start)
        } else {
            wps.get(m.wrapping_sub(1)).copied()
        }
    };
    // 1. The stretch: invalid moves, and blocked segments by the raw offsets of their ends.
    let (mut lo, mut hi) = (usize::MAX, 0usize);
    let mut p = start;
    for (t, &d) in rest.iter().enumerate() {
        if grid.step(p, d).is_none() {
            lo = lo.min(t);
            hi = hi.max(t.wrapping_add(1));
        }
        p = neighbour(p, d);
    }
    if p != goal || wps.last() != Some(&goal) {
        return None;
    }
    // Each waypoint's raw offset: the first raw cell at or after the previous one's within a
    // cell of it (the taut pull moves waypoints off the raw cells by a cell).
    let mut offsets = Offsets::new(start, rest);
    let mut prev = (start, 0usize);
    for m in 1..n_l {
        let w = l_at(m)?;
        let o = offsets.find(w)?;
        if !segment_clear(grid, prev.0, w) {
            lo = lo.min(prev.1);
            hi = hi.max(o);
        }
        prev = (w, o);
    }
    if lo > hi || prev.1 != n {
        return None;
    }
    // The anchors and the waypoints around them: L[i] the last at or before `a`, L[j] the first
    // at or after `b`.
    let a = lo.saturating_sub(MARGIN);
    let b = hi.saturating_add(MARGIN).min(n);
    let (mut i, mut oi, mut j, mut oj) = (0usize, 0usize, n_l.checked_sub(1)?, n);
    let mut offsets = Offsets::new(start, rest);
    let (mut min, mut max) = (Point::new(u16::MAX, u16::MAX), Point::new(0, 0));
    let (mut ca, mut cb) = (start, start);
    let (mut straight, mut diagonal) = (0u32, 0u32);
    {
        let mut p = start;
        for t in 0..=n {
            if (a..=b).contains(&t) {
                min = Point::new(min.x.min(p.x), min.y.min(p.y));
                max = Point::new(max.x.max(p.x), max.y.max(p.y));
            }
            if t == a {
                ca = p;
            }
            if t == b {
                cb = p;
            }
            let Some(&d) = rest.get(t) else { break };
            if (a..b).contains(&t) {
                if is_diagonal(d) {
                    diagonal = diagonal.wrapping_add(1);
                } else {
                    straight = straight.wrapping_add(1);
                }
            }
            p = neighbour(p, d);
        }
    }
    let old_stretch = steps_length(straight, diagonal);
    for m in 1..n_l {
        let o = offsets.find(l_at(m)?)?;
        if o <= a {
            (i, oi) = (m, o);
        }
        if o >= b && j == n_l.wrapping_sub(1) && m < j {
            (j, oj) = (m, o);
        }
    }
    let (li, lj) = (l_at(i)?, l_at(j)?);
    // 2. The detour, into the tail of `points` (free: the waypoints end at `end`).
    // The answer, the increments and the buffers idle between plans (`lend::Polishing`).
    let Polishing {
        best,
        points,
        delta,
        mut guide,
        mut idle,
    } = ws.polishing();
    let cap = points.len();
    let (sa, sb) = idle.refine(&mut guide, REFINE_WORDS, SHORT_REFINE_WORDS)?;
    let mut scratch = Scratch::new(sa, sb);
    let room = cap.checked_sub(end)?;
    let tail = points.get_mut(end..)?;
    let dn = refine::detour(grid, ca, cb, (min, max), BOX_MARGIN, &mut scratch, tail)?;
    let d_steps = dn.checked_sub(1)?;
    let (mut st, mut di) = (0u32, 0u32);
    for pair in tail.get(..dn)?.windows(2) {
        if let (Some(&p), Some(&q)) = (pair.first(), pair.get(1)) {
            if is_diagonal(direction(p, q)?) {
                di = di.wrapping_add(1);
            } else {
                st = st.wrapping_add(1);
            }
        }
    }
    if steps_length(st, di) > longest_detour(old_stretch) {
        return None;
    }
    // Capacity: the new raw path in `best`, the smoothing's input and the spliced waypoints in
    // `points` (the input at the very end, the waypoints before it).
    let new_n = n.checked_sub(b)?.checked_add(a)?.checked_add(d_steps)?;
    let new_steps = base.checked_add(new_n)?;
    let oj_new = oj.checked_sub(b)?.checked_add(a)?.checked_add(d_steps)?;
    let ns = oj_new.checked_sub(oi)?.checked_add(1)?;
    let ns_at = cap.checked_sub(ns)?;
    if new_steps > best.len() || ns > room || k0.checked_add(n_l)? > ns_at {
        return None;
    }
    // 3. The splice. From here on the kept answer is rewritten: give up by forgetting it.
    memory.answer = None;
    // The detour's cells to the front of the tail's room (it was written there already).
    best.copy_within(
        base.checked_add(b)?..steps,
        base.checked_add(a)?.checked_add(d_steps)?,
    );
    {
        let dirs = best.get_mut(base.checked_add(a)?..)?;
        let cells = points.get(end..end.checked_add(dn)?)?;
        for (slot, pair) in dirs.iter_mut().zip(cells.windows(2)) {
            if let (Some(&p), Some(&q)) = (pair.first(), pair.get(1)) {
                *slot = direction(p, q)?;
            }
        }
    }
    let new_rest: &[Dir] = best.get(base..new_steps)?;
    // The smoothing's input: L[i], the new raw cells strictly between its offset and L[j]'s, L[j].
    {
        let input = points.get_mut(ns_at..)?;
        let mut p = start;
        let mut k = 0usize;
        for (t, &d) in new_rest.iter().enumerate() {
            if t > oi && t < oj_new {
                *input.get_mut(k)? = p;
                k = k.wrapping_add(1);
            } else if t == oi {
                *input.get_mut(k)? = li;
                k = k.wrapping_add(1);
            }
            p = neighbour(p, d);
        }
        if k != ns.wrapping_sub(1) {
            return None;
        }
        *input.get_mut(ns.checked_sub(1)?)? = lj;
    }
    let kind = if params.algorithm == Algorithm::Ohaca {
        params.smoothing
    } else {
        SmoothingKind::None
    };
    let ks = {
        let dist = delta.as_flattened_mut();
        let input = points.get_mut(ns_at..)?;
        let links = idle.smoothing(ns);
        Smoother::new(kind, ns, dist, links).finish(grid, input, dist, links)
    };
    if ks < 2
        || points.get(ns_at) != Some(&li)
        || points.get(ns_at.checked_add(ks.wrapping_sub(1))?) != Some(&lj)
    {
        return None;
    }
    // Splice: L[..i], the smoothed waypoints (L[i] to L[j]), L[j + 1..].
    let suffix = k0.checked_add(j)?.checked_add(1)?..k0.checked_add(n_l)?;
    let suffix_len = suffix.len();
    let s_at = k0.checked_add(i)?;
    let new_end = s_at.checked_add(ks)?.checked_add(suffix_len)?;
    if new_end > ns_at {
        return None;
    }
    points.copy_within(suffix, s_at.checked_add(ks)?);
    points.copy_within(ns_at..ns_at.checked_add(ks)?, s_at);
    *points.get_mut(k0)? = start;
    // The whole answer, checked as `reuse` checks a kept one.
    let (mut straight, mut diagonal) = (0u32, 0u32);
    let mut p = start;
    for &d in new_rest {
        p = grid.step(p, d)?;
        if is_diagonal(d) {
            diagonal = diagonal.wrapping_add(1);
        } else {
            straight = straight.wrapping_add(1);
        }
    }
    let waypoints: &[Point] = points.get(k0..new_end)?;
    if p != goal || waypoints.last() != Some(&goal) {
        return None;
    }
    let mut prev = start;
    let mut polyline = 0.0f32;
    for &w in waypoints.get(1..)? {
        if !segment_clear(grid, prev, w) {
            return None;
        }
        polyline += distance(prev, w);
        prev = w;
    }
    let raw_length = steps_length(straight, diagonal);
    let smoothed = params.algorithm == Algorithm::Ohaca && params.smoothing != SmoothingKind::None;
    let length = if smoothed { polyline } else { raw_length };
    if !memory.cannot_shorten(start, goal, raw_length, length) {
        return None;
    }
    memory.answer = Some(Answer {
        start,
        from: u32::try_from(base).ok()?,
        steps: u32::try_from(new_steps).ok()?,
        first: u32::try_from(k0).ok()?,
        end: u32::try_from(new_end).ok()?,
        params: answer.params,
    });
    let tour: &'a [Dir] = best.get(base..new_steps)?;
    let waypoints: &'a [Point] = points.get(k0..new_end)?;
    Some(Plan::without_run(
        (start, tour, waypoints),
        (raw_length, length),
        Origin::Repaired,
        *params,
    ))
}

/// Raw offsets of waypoints along a raw path, in order ([`Offsets::find`]).
struct Offsets<'r> {
    dirs: &'r [Dir],
    /// The raw cell at offset `t`.
    p: Point,
    t: usize,
}

impl<'r> Offsets<'r> {
    fn new(start: Point, dirs: &'r [Dir]) -> Self {
        Offsets {
            dirs,
            p: start,
            t: 0,
        }
    }

    /// The offset of the first raw cell from the current one on within a cell of `w` (the
    /// current one stays current: the next waypoint may lie beside the same cell).
    fn find(&mut self, w: Point) -> Option<usize> {
        loop {
            if cheb(self.p, w) <= 1 {
                // Beside it: the waypoint itself when one of the next two cells is.
                let (mut q, mut u) = (self.p, self.t);
                for _ in 0..2 {
                    if q == w {
                        break;
                    }
                    let Some(&d) = self.dirs.get(u) else { break };
                    q = neighbour(q, d);
                    u = u.wrapping_add(1);
                }
                if q == w {
                    (self.p, self.t) = (q, u);
                }
                return Some(self.t);
            }
            let &d = self.dirs.get(self.t)?;
            self.p = neighbour(self.p, d);
            self.t = self.t.wrapping_add(1);
        }
    }
}
