//! Repaired replans: the rest of the last answer with a local detour around what blocks it,
//! instead of a colony run.
//!
//! [`super::reuse`] hands a replan here when the robot is on the kept answer (its rule 1) but a
//! cell blocked since sits on the raw rest or on one of its waypoint segments (rule 2 fails). On
//! every map and every layout (the full one and the compact one of [`super::arena`], small maps
//! too) this module owns the answer's repair; when it gives up it says why ([`GiveUp`]), and the
//! caller runs the warm colony:
//!
//! 1. **What blocks it**: the raw offsets of the first and last invalid move of the raw rest, and
//!    the blocked waypoint segments. Each waypoint is placed on a raw cell, in order: the nearest
//!    of the raw path's first visit to within [`PLACE_RADIUS`] cells of it (the taut pull moves
//!    waypoints off the raw cells by up to a cell a pass); the first one after the robot that the
//!    raw path ahead never comes near is one the robot has passed (placed on its cell and smoothed
//!    again); any other that is not gives up ([`GiveUp::Unplaced`]).
//! 2. **The anchors**: [`MARGIN`] raw cells before the first blocked move and after the last,
//!    clamped to the robot's cell and the goal. A blocked segment whose raw cells are all free
//!    needs no anchors: the raw path stays, and only its waypoints are smoothed again.
//! 3. **The detour**: exact A* between the anchors ([`crate::polish::refine::detour`]) in a box sized by
//!    the change, not fixed: the bounding box of the raw cells between the anchors (so the
//!    blocked stretch's extent and the anchors' margins), grown by [`BOX_MARGIN`] cells on every
//!    side and clipped to the map. When no path lies in the box, or the one found runs along a
//!    side of the box that is not the map's edge (the box may have cut a shorter one off), the
//!    margin doubles (the last try takes the widest margin that fits), as far as the scratch
//!    holds. So the box follows the obstacle in cells: a wall at 5 cm spans four times the cells
//!    it spans at 20 cm, and so does its box, with no resolution in the core. The scratch is the
//!    most the workspace lends between plans (`planner::lend`, the repair's row: two slices from
//!    the links, the route's words and the tabu set; about 2,700 box cells on the STM32F411 in
//!    both layouts). Giving up: a stretch whose smallest box does not fit the scratch
//!    ([`GiveUp::TooLong`], with both sizes), no path in the largest box ([`GiveUp::NoDetour`]),
//!    a detour longer than the stretch by more than [`longest_detour`] ([`GiveUp::Longer`]).
//! 4. **The splice**: the raw path becomes the kept raw up to the first anchor, the detour, the
//!    kept raw after the second ([`Workspace::best`] rewritten from the robot's offset, the tail
//!    shifted); the waypoints around it are smoothed again by the polish's DP ([`Smoother`], same
//!    [`Params::smoothing`]) from the last kept waypoint before the first anchor (and before the
//!    first blocked segment) to the first after the second (and after the last blocked segment),
//!    and spliced between the kept waypoints.
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
//! on the same layout, and the scratch lent depends only on the buffers' lengths, so a repaired
//! answer is the same bit for bit on both. Panic-free: every index is checked.
//!
//! | file | owns |
//! | --- | --- |
//! | `mod.rs` | [`GiveUp`], the bounds, the repair itself (steps 1, 2 and 4) |
//! | `detour.rs` | the box sized by the change and the detour in it (step 3) |
//! | `input.rs` | where each waypoint lies on the raw path, and the smoothing's sparse input |

use core::fmt;

use crate::geometry::{distance, segment_clear, steps_length};
use crate::map::grid::{direction, is_diagonal, neighbour, Dir, Grid, Point};
use crate::polish::refine::Scratch;
#[cfg(doc)]
use crate::polish::refine::{MAX_SIDE, MIN_SIDE};
use crate::polish::smoothing::{Smoother, SmoothingKind};

use super::lend::Polishing;
use super::params::{Algorithm, Params};
use super::plan::Origin;
use super::plan::Reused;
use super::warm::{Answer, Memory};
use super::workspace::Workspace;

mod detour;
mod input;

use detour::sized_detour;
pub use input::STRIDE;
use input::{cell_at, sparse, Offsets};

/// Raw cells kept between the blocked stretch and each anchor of the detour: room for the detour
/// to leave the old path at an angle instead of turning at the obstacle.
pub const MARGIN: usize = 12;

/// Cells of box around the anchors' stretch on every side at the first try; each further try
/// doubles it (see the module docs).
pub const BOX_MARGIN: u16 = 6;

/// How far (Chebyshev, in cells) a waypoint may lie from the raw cell it is placed on: the taut
/// pull ([`crate::polish::taut`]) moves a waypoint off the raw path by at most a cell a pass.
pub const PLACE_RADIUS: u16 = crate::polish::taut::MAX_PASSES as u16;

/// Why a repair gave up (the replan then goes to the colony, [`super::Fallback::Repair`]). Small,
/// `Copy`, `Display`; `defmt::Format` with the `defmt` feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GiveUp {
    /// The kept answer's waypoints do not lie along its raw path (one farther than
    /// [`PLACE_RADIUS`] cells from every raw cell after the previous one's), or its raw path does
    /// not end at the goal: there is nothing to splice a detour into.
    Unplaced,
    /// The workspace lends no scratch for a box of [`MIN_SIDE`] x [`MIN_SIDE`] cells.
    NoScratch,
    /// The blocked stretch is longer than the box can hold: its anchors and the first margin
    /// ([`BOX_MARGIN`]) need a box of `needs` cells (or a side over [`MAX_SIDE`]), the scratch
    /// holds `room`.
    TooLong {
        /// Cells of the smallest box around the stretch.
        needs: u32,
        /// Cells the lent scratch holds.
        room: u32,
    },
    /// No path joins the anchors inside the largest box the scratch holds.
    NoDetour,
    /// The detour is longer than [`longest_detour`] of the stretch it replaces: the obstacle
    /// closes the corridor, and another one may be shorter.
    Longer,
    /// The repaired raw path or its waypoints do not fit the workspace (its step bound).
    NoRoom,
    /// A segment of the repaired answer is blocked (the smoothing kept one it could not check).
    StillBlocked,
    /// A cell cleared since the answer was planned could shorten the repaired answer (rule 3 of
    /// [`super::reuse`] on the new lengths).
    MayShorten,
}

impl fmt::Display for GiveUp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GiveUp::Unplaced => f.write_str("the waypoints do not lie along the raw path"),
            GiveUp::NoScratch => f.write_str("no scratch for a detour box"),
            GiveUp::TooLong { needs, room } => write!(
                f,
                "the blocked stretch needs a box of {needs} cells, the scratch holds {room}"
            ),
            GiveUp::NoDetour => f.write_str("no detour inside the largest box"),
            GiveUp::Longer => f.write_str("the detour is longer than its bound"),
            GiveUp::NoRoom => f.write_str("the repaired path does not fit the workspace"),
            GiveUp::StillBlocked => f.write_str("a segment of the repaired answer is blocked"),
            GiveUp::MayShorten => f.write_str("a cleared cell may shorten the repaired answer"),
        }
    }
}

/// The longest detour accepted for a stretch whose old raw length is `old`: `old` plus a quarter
/// of it or 20 cells, whichever is more. A wall across a corridor costs a few cells around its
/// end; a detour much longer than that means the obstacle closes the corridor and another one may
/// well be shorter, which only the colony (searching the whole map) can tell.
pub fn longest_detour(old: f32) -> f32 {
    old + (old / 4.0).max(20.0)
}

/// Repair the kept answer around what blocks it (see the module docs); `Err` gives the replan to
/// the colony and says why. `answer` is the memory's answer, the robot's cell `start` is raw cell
/// `at` of it, and the waypoints after the robot's are `points[first + entry..end]`
/// ([`super::reuse`]).
#[allow(clippy::too_many_arguments)] // reuse's state, passed on
pub(super) fn repair(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: &mut Workspace<'_>,
    memory: &mut Memory,
    answer: Answer,
    at: usize,
    entry: usize,
) -> Result<Reused, GiveUp> {
    use GiveUp::{NoRoom, StillBlocked, Unplaced};
    let (raw, waypoints) = answer.ranges();
    let (from, steps, first, end) = (raw.start, raw.end, waypoints.start, waypoints.end);
    // The robot's direction in `best`.
    let base = from.checked_add(at).ok_or(Unplaced)?;
    // The answer, the increments and the buffers idle between plans (`lend::Polishing`).
    let Polishing {
        best,
        points,
        delta,
        mut guide,
        mut idle,
    } = ws.polishing();
    let cap = points.len();
    let rest: &[Dir] = best.get(base..steps).ok_or(Unplaced)?;
    let n = rest.len();
    // L: the robot's cell, then the kept waypoints after it (`head`); `k0` is the robot's slot.
    // The detour goes to `tail`, free: the waypoints end at `end`.
    let (head, tail) = points.split_at_mut_checked(end).ok_or(NoRoom)?;
    let k0 = first
        .checked_add(entry)
        .and_then(|k| k.checked_sub(1))
        .ok_or(Unplaced)?;
    let wps: &[Point] = head.get(first.saturating_add(entry)..).ok_or(Unplaced)?;
    let n_l = wps.len().saturating_add(1);
    let last = wps.len();
    let l_at = |m: usize| -> Result<Point, GiveUp> {
        if m == 0 {
            Ok(start)
        } else {
            wps.get(m.wrapping_sub(1)).copied().ok_or(Unplaced)
        }
    };
    // 1. What blocks the answer: the raw moves from `lo` to `hi` ...
    let mut raw: Option<(usize, usize)> = None;
    let mut p = start;
    for (t, &d) in rest.iter().enumerate() {
        if grid.step(p, d).is_none() {
            let lo = raw.map_or(t, |(lo, _)| lo);
            raw = Some((lo, t.wrapping_add(1)));
        }
        p = neighbour(p, d);
    }
    if p != goal || wps.last() != Some(&goal) {
        return Err(Unplaced);
    }
    // ... and the waypoint segments from L[s0] to L[s1] (by their waypoints' indices).
    let mut segs: Option<(usize, usize)> = None;
    let mut offsets = Offsets::new(start, rest);
    let mut prev = (start, 0usize);
    for m in 1..n_l {
        let w = l_at(m)?;
        let (o, _) = offsets.place(m, w)?;
        if !segment_clear(grid, prev.0, w) {
            segs = Some((segs.map_or(m.wrapping_sub(1), |(s0, _)| s0), m));
        }
        prev = (w, o);
    }
    if prev.1 != n {
        return Err(Unplaced);
    }
    // 2-3. The anchors and the detour between them (none when only segments are blocked: the
    // raw path stays and its waypoints are smoothed again).
    let detour = match raw {
        Some(blocked) => {
            let (sa, sb) = idle.detour(&mut guide);
            let mut scratch = Scratch::new(sa, sb);
            let d = sized_detour(grid, start, rest, blocked, &mut scratch, tail)?;
            let (mut st, mut di) = (0u32, 0u32);
            for pair in tail.get(..d.cells).ok_or(NoRoom)?.windows(2) {
                if let (Some(&p), Some(&q)) = (pair.first(), pair.get(1)) {
                    if is_diagonal(direction(p, q).ok_or(Unplaced)?) {
                        di = di.wrapping_add(1);
                    } else {
                        st = st.wrapping_add(1);
                    }
                }
            }
            if steps_length(st, di) > longest_detour(d.stretch.old) {
                return Err(GiveUp::Longer);
            }
            Some(d)
        }
        None => None,
    };
    let anchors = detour.map(|d| (d.stretch.a, d.stretch.b));
    let (s0, s1) = segs.unwrap_or((usize::MAX, 0));
    // The waypoints smoothed again, L[i] to L[j]: L[i] the last at or before the first anchor
    // and no later than the first blocked segment, L[j] the first at or after the second anchor
    // and no earlier than the last blocked segment's end.
    let (mut i, mut oi, mut j, mut oj) = (0usize, 0usize, last, n);
    let mut j_found = false;
    let mut offsets = Offsets::new(start, rest);
    for m in 1..n_l {
        let (o, passed) = offsets.place(m, l_at(m)?)?;
        if m <= s0 && !passed && anchors.is_none_or(|(a, _)| o <= a) {
            (i, oi) = (m, o);
        }
        if !j_found && m >= s1 && anchors.is_none_or(|(_, b)| o >= b) {
            (j, oj, j_found) = (m, o, true);
        }
    }
    let (li, lj) = (l_at(i)?, l_at(j)?);
    if i >= j || oi > oj {
        return Err(Unplaced);
    }
    // Without a detour the stretch is one cell and the raw path stays.
    let (a, b) = anchors.unwrap_or((oi, oi));
    let dn = detour.map_or(1, |d| d.cells);
    let d_steps = dn.checked_sub(1).ok_or(NoRoom)?;
    // Capacity: the new raw path in `best`, the smoothing's input and the spliced waypoints in
    // `points` (the input at the very end, the waypoints before it).
    let room = cap.checked_sub(end).ok_or(NoRoom)?;
    let grow = |x: usize| x.checked_sub(b)?.checked_add(a)?.checked_add(d_steps);
    let new_n = grow(n).ok_or(NoRoom)?;
    let new_steps = base.checked_add(new_n).ok_or(NoRoom)?;
    let oj_new = grow(oj).ok_or(NoRoom)?;
    // The smoothing's input: L[i]; the raw cells after it up to the first anchor, sparse; the
    // detour's cells; the raw cells after it up to L[j]'s, sparse or none; L[j] ([`sparse`]: on
    // open floor the waypoints around a wall can lie hundreds of cells apart, and the DP costs
    // the cells of its input, not the old segments' length). Counted here on the kept raw path,
    // written below on the new one: the same cells, the same choices.
    let b_new = grow(b).ok_or(NoRoom)?;
    let cell_oi = cell_at(start, rest, oi).ok_or(Unplaced)?;
    let cell_b = cell_at(start, rest, b).ok_or(Unplaced)?;
    let ns = {
        let mut count = 2usize; // L[i] and L[j]
        let mut tally = |_: Point| {
            count = count.saturating_add(1);
            Ok(())
        };
        let part = rest.get(oi..a).ok_or(Unplaced)?;
        let last = sparse(grid, li, cell_oi, part, None, &mut tally)?;
        let last = if d_steps > 0 { cell_b } else { last };
        let part = rest.get(b..oj.saturating_sub(1).max(b)).ok_or(Unplaced)?;
        sparse(grid, last, cell_b, part, Some(lj), &mut tally)?;
        count.saturating_add(d_steps)
    };
    let ns_at = cap.checked_sub(ns).ok_or(NoRoom)?;
    if new_steps > best.len() || ns > room || k0.saturating_add(n_l) > ns_at {
        return Err(NoRoom);
    }
    // 4. The splice. From here on the kept answer is rewritten: give up by forgetting it.
    memory.answer = None;
    if detour.is_some() {
        let to = base
            .checked_add(a)
            .and_then(|x| x.checked_add(d_steps))
            .ok_or(NoRoom)?;
        best.copy_within(base.checked_add(b).ok_or(NoRoom)?..steps, to);
        let dirs = best.get_mut(base.saturating_add(a)..).ok_or(NoRoom)?;
        let cells = points.get(end..end.saturating_add(dn)).ok_or(NoRoom)?;
        for (slot, pair) in dirs.iter_mut().zip(cells.windows(2)) {
            if let (Some(&p), Some(&q)) = (pair.first(), pair.get(1)) {
                *slot = direction(p, q).ok_or(Unplaced)?;
            }
        }
    }
    let new_rest: &[Dir] = best.get(base..new_steps).ok_or(NoRoom)?;
    // The smoothing's input (see `ns` above).
    {
        let input = points.get_mut(ns_at..).ok_or(NoRoom)?;
        *input.first_mut().ok_or(NoRoom)? = li;
        let mut k = 1usize;
        let mut put = |p: Point| {
            *input.get_mut(k).ok_or(NoRoom)? = p;
            k = k.wrapping_add(1);
            Ok(())
        };
        let part = new_rest.get(oi..a).ok_or(Unplaced)?;
        let mut last = sparse(grid, li, cell_oi, part, None, &mut put)?;
        // The detour's cells, every one (the DP finds the corners around the obstacle there).
        let mut p = cell_at(start, new_rest, a).ok_or(Unplaced)?;
        for &d in new_rest.get(a..b_new).ok_or(Unplaced)? {
            p = neighbour(p, d);
            put(p)?;
            last = p;
        }
        let part = new_rest
            .get(b_new..oj_new.saturating_sub(1).max(b_new))
            .ok_or(Unplaced)?;
        sparse(grid, last, p, part, Some(lj), &mut put)?;
        if k != ns.wrapping_sub(1) {
            return Err(NoRoom);
        }
        *input.get_mut(k).ok_or(NoRoom)? = lj;
    }
    let kind = if params.algorithm == Algorithm::Ohaca {
        params.smoothing
    } else {
        SmoothingKind::None
    };
    let ks = {
        let dist = delta.as_flattened_mut();
        let input = points.get_mut(ns_at..).ok_or(NoRoom)?;
        let mut links = idle.smoothing(ns);
        Smoother::new(kind, ns, dist, &mut links).finish(grid, input, dist, &mut links)
    };
    if ks < 2
        || points.get(ns_at) != Some(&li)
        || points.get(ns_at.saturating_add(ks.wrapping_sub(1))) != Some(&lj)
    {
        return Err(StillBlocked);
    }
    // Splice: L[..i], the smoothed waypoints (L[i] to L[j]), L[j + 1..].
    let suffix = k0.saturating_add(j).saturating_add(1)..k0.saturating_add(n_l);
    let suffix_len = suffix.len();
    let s_at = k0.saturating_add(i);
    let new_end = s_at.saturating_add(ks).saturating_add(suffix_len);
    if new_end > ns_at {
        return Err(NoRoom);
    }
    points.copy_within(suffix, s_at.saturating_add(ks));
    points.copy_within(ns_at..ns_at.saturating_add(ks), s_at);
    *points.get_mut(k0).ok_or(NoRoom)? = start;
    // The whole answer, checked as `reuse` checks a kept one.
    let (mut straight, mut diagonal) = (0u32, 0u32);
    let mut p = start;
    for &d in new_rest {
        p = grid.step(p, d).ok_or(StillBlocked)?;
        if is_diagonal(d) {
            diagonal = diagonal.wrapping_add(1);
        } else {
            straight = straight.wrapping_add(1);
        }
    }
    let waypoints: &[Point] = points.get(k0..new_end).ok_or(NoRoom)?;
    if p != goal || waypoints.last() != Some(&goal) {
        return Err(Unplaced);
    }
    let mut prev = start;
    let mut polyline = 0.0f32;
    for &w in waypoints.get(1..).unwrap_or_default() {
        if !segment_clear(grid, prev, w) {
            return Err(StillBlocked);
        }
        polyline += distance(prev, w);
        prev = w;
    }
    let raw_length = steps_length(straight, diagonal);
    let smoothed = params.algorithm == Algorithm::Ohaca && params.smoothing != SmoothingKind::None;
    let length = if smoothed { polyline } else { raw_length };
    if !memory.cannot_shorten(start, goal, raw_length, length) {
        return Err(GiveUp::MayShorten);
    }
    let word = |x: usize| u32::try_from(x).map_err(|_| NoRoom);
    // The new answer's ranges, checked before they are recorded ([`Reused::plan`] reads them).
    if best.get(base..new_steps).is_none() || points.get(k0..new_end).is_none() {
        return Err(NoRoom);
    }
    memory.answer = Some(Answer {
        start,
        from: word(base)?,
        steps: word(new_steps)?,
        first: word(k0)?,
        end: word(new_end)?,
        params: answer.params,
    });
    Ok(Reused {
        raw_length,
        length,
        origin: Origin::Repaired,
    })
}

#[cfg(test)]
mod tests {
    use super::detour::{box_cells, grown, hugs, Stretch};
    use super::*;
    use crate::planner::arena::carve;
    use crate::planner::{reuse, Fallback, Run};
    use alloc::vec;
    use alloc::vec::Vec;

    /// The STM32F411's arena, in words.
    const ARENA: usize = match crate::board::F411.layout {
        crate::board::Layout::Arena { words } => words,
        crate::board::Layout::Separate { .. } => 0,
    };

    #[test]
    fn a_waypoint_pulled_off_the_raw_path_is_placed_on_its_nearest_cell() {
        // A raw path 30 cells east along y = 10 from (0, 10).
        let dirs: Vec<Dir> = vec![0; 30];
        let start = Point::new(0, 10);
        let mut o = Offsets::new(start, &dirs);
        // Three cells off (the taut pull's shifts): the raw cell beside it, not the first one
        // within reach (5 cells before it) nor the first of a Chebyshev plateau.
        assert_eq!(o.find(Point::new(8, 13)), Some(8));
        // On the raw path: itself; and the next one may share the current cell.
        assert_eq!(o.find(Point::new(12, 10)), Some(12));
        assert_eq!(o.find(Point::new(12, 11)), Some(12));
        // In order: a waypoint behind the current cell is placed on the first cell within reach.
        assert_eq!(o.find(Point::new(10, 10)), Some(12));
        // Farther than PLACE_RADIUS from every raw cell after the current one: not placed.
        assert_eq!(o.find(Point::new(20, 10 + PLACE_RADIUS + 1)), None);
        let mut o = Offsets::new(start, &dirs);
        assert_eq!(o.find(Point::new(20, 10 + PLACE_RADIUS)), Some(20));
        assert_eq!(o.find(Point::new(30, 10)), Some(30));
        // The raw path from the robot on (here from x = 10) never comes near a waypoint behind
        // it: the first one after the robot is one it has passed (placed on its cell, not kept);
        // a later one gives up. A failed look-up leaves the current cell where it was.
        let robot = Point::new(10, 10);
        let mut o = Offsets::new(robot, &dirs[10..]);
        assert_eq!(o.place(1, Point::new(0, 12)), Ok((0, true)));
        assert_eq!(o.place(2, Point::new(14, 10)), Ok((4, false)));
        assert_eq!(o.place(3, Point::new(0, 12)), Err(GiveUp::Unplaced));
        assert_eq!(o.place(3, Point::new(15, 10)), Ok((5, false)));
    }

    #[test]
    fn a_detour_hugs_only_the_inner_sides_of_its_box() {
        let (w, h) = (40u16, 30u16);
        let bx = (Point::new(0, 5), Point::new(20, 29));
        // The map's edges (x = 0, y = 29) are not inner sides.
        assert!(!hugs(bx, &[Point::new(0, 10), Point::new(5, 29)], w, h));
        assert!(hugs(bx, &[Point::new(3, 5)], w, h));
        assert!(hugs(bx, &[Point::new(20, 7)], w, h));
        assert_eq!(
            grown(Point::new(2, 3), Point::new(30, 25), 6, w, h),
            (Point::new(0, 0), Point::new(36, 29))
        );
        assert_eq!(
            box_cells((Point::new(0, 0), Point::new(255, 0))),
            (256, false)
        );
    }

    #[test]
    fn the_anchors_move_out_with_the_box() {
        let dirs: Vec<Dir> = vec![0; 100];
        let start = Point::new(0, 10);
        let s = Stretch::around(start, &dirs, (40, 42), BOX_MARGIN);
        assert_eq!((s.a, s.b), (40 - MARGIN, 42 + MARGIN));
        assert_eq!((s.ca, s.cb), (Point::new(28, 10), Point::new(54, 10)));
        assert_eq!((s.min, s.max), (s.ca, s.cb));
        assert_eq!(s.old, 26.0);
        let s = Stretch::around(start, &dirs, (40, 42), 30);
        assert_eq!((s.a, s.b), (10, 72));
        // Clamped to the robot's cell and the goal.
        let s = Stretch::around(start, &dirs, (5, 95), 12);
        assert_eq!((s.a, s.b), (0, 100));
    }

    #[test]
    fn the_smoothing_s_input_skips_open_floor_and_keeps_every_step_in_sight() {
        // 40 x 20 cells, a block in the middle; a raw path east along y = 5 to x = 30, then
        // south to y = 15, then west under the block to x = 20.
        let (w, h) = (40u16, 20u16);
        let mut bits = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
        for y in 8..13u16 {
            for x in 10..28u16 {
                let i = usize::from(y) * usize::from(w) + usize::from(x);
                bits[i / 8] |= 1 << (i % 8);
            }
        }
        let grid = Grid::new(w, h, &bits).unwrap();
        let (east, south, west) = (0 as Dir, 2 as Dir, 4 as Dir);
        let dirs: Vec<Dir> = [(east, 28usize), (south, 10), (west, 10)]
            .iter()
            .flat_map(|&(d, k)| core::iter::repeat_n(d, k))
            .collect();
        let at = Point::new(2, 5);
        let inputs = |then: Option<Point>| {
            let mut out = Vec::new();
            let last = sparse(&grid, at, at, &dirs, then, &mut |p| {
                out.push(p);
                Ok(())
            })
            .unwrap();
            (out, last)
        };
        let (cells, last) = inputs(None);
        // Each input cell sees the one before it; the last raw cell ends them.
        let mut prev = at;
        for &c in &cells {
            assert!(segment_clear(&grid, prev, c), "{prev:?} -> {c:?}");
            prev = c;
        }
        assert_eq!(last, Point::new(20, 15));
        assert_eq!(cells.last(), Some(&last));
        // Open floor: a cell in STRIDE at most, far fewer than the 48 raw cells.
        assert!(cells.len() <= 48 / STRIDE + 3, "{cells:?}");
        assert!(cells.len() >= 3, "the block is in the way: {cells:?}");
        // Nothing when the cell after them is in sight; only the last when it is.
        let straight: Vec<Dir> = vec![east; 20];
        let mut n = 0;
        let end = sparse(
            &grid,
            at,
            at,
            &straight,
            Some(Point::new(30, 5)),
            &mut |_| {
                n += 1;
                Ok(())
            },
        )
        .unwrap();
        assert_eq!((n, end), (0, at));
        let end = sparse(&grid, at, at, &straight, None, &mut |_| {
            n += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!((n, end), (1, Point::new(22, 5)));
    }

    #[test]
    fn the_reasons_read_as_sentences() {
        let r = Fallback::Repair(GiveUp::TooLong {
            needs: 9000,
            room: 2730,
        });
        assert_eq!(
            alloc::format!("{r}"),
            "the repair gave up: the blocked stretch needs a box of 9000 cells, \
             the scratch holds 2730"
        );
        assert_eq!(
            alloc::format!("{}", Fallback::OffAnswer),
            "the robot is off the answer"
        );
    }

    #[test]
    fn the_compact_arena_repairs_a_wall_dropped_on_the_path() {
        // A 15 x 15 m floor at 5 cm (300 x 300 cells, more than the 68,256 of the F411's full
        // layout): open, with a few pillars. A wall of 11 cells across the path, dropped ahead
        // of the robot, is repaired, not planned by the colony.
        let (w, h) = (300u16, 300u16);
        let cells = usize::from(w) * usize::from(h);
        let mut bits = vec![0u8; cells.div_ceil(8)];
        let block = |bits: &mut Vec<u8>, x: u16, y: u16| {
            let i = usize::from(y) * usize::from(w) + usize::from(x);
            bits[i / 8] |= 1 << (i % 8);
        };
        for (x0, y0) in [(60u16, 40u16), (150, 200), (220, 90), (100, 250)] {
            for y in y0..y0 + 12 {
                for x in x0..x0 + 12 {
                    block(&mut bits, x, y);
                }
            }
        }
        let (s, g) = (Point::new(10, 20), Point::new(285, 280));
        let p = Params::default();
        let mut arena = vec![0u32; ARENA];
        let mut memory = Memory::new();
        let first: Vec<Point> = {
            let grid = Grid::new(w, h, &bits).unwrap();
            let c = carve(&mut arena, cells, crate::board::F411.max_steps).unwrap();
            assert!(c.compact);
            let mut run = Run::warm(&grid, s, g, &p, c.workspace, &mut memory).unwrap();
            while let crate::planner::Poll::Working(_) = run.poll() {}
            run.keep(&mut memory);
            run.finish().unwrap().raw().collect()
        };
        let here = first[30];
        // Across the path 20 cells ahead of the robot.
        let (c0, c1) = (first[50], first[51]);
        let (dx, dy) = (
            i32::from(c1.x) - i32::from(c0.x),
            i32::from(c1.y) - i32::from(c0.y),
        );
        for k in -5..=5i32 {
            let (x, y) = (i32::from(c0.x) - k * dy, i32::from(c0.y) + k * dx);
            block(&mut bits, x as u16, y as u16);
            memory.cell(Point::new(x as u16, y as u16), false, true);
        }
        let grid = Grid::new(w, h, &bits).unwrap();
        let mut ws = carve(&mut arena, cells, crate::board::F411.max_steps)
            .unwrap()
            .workspace;
        let plan = reuse(&grid, here, g, &p, &mut ws, &mut memory).unwrap();
        assert_eq!(plan.origin, Origin::Repaired);
        let raw: Vec<Point> = plan.raw().collect();
        assert_eq!((raw[0], *raw.last().unwrap()), (here, g));
        for (pair, &d) in raw.windows(2).zip(plan.directions()) {
            assert_eq!(grid.step(pair[0], d), Some(pair[1]));
        }
        for pair in plan.waypoints().windows(2) {
            assert!(segment_clear(&grid, pair[0], pair[1]));
        }
        // Around an 11-cell wall: a few cells longer than the rest it replaces.
        let old = steps_length(
            first[30..]
                .windows(2)
                .filter(|p| p[0].x == p[1].x || p[0].y == p[1].y)
                .count() as u32,
            first[30..]
                .windows(2)
                .filter(|p| p[0].x != p[1].x && p[0].y != p[1].y)
                .count() as u32,
        );
        assert!(
            plan.raw_length > old && plan.raw_length < old + 10.0,
            "{} {old}",
            plan.raw_length
        );
    }
}
