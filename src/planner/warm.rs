//! Warm starts: replanning to the same goal after the map changed, on the colony that the previous
//! plan left in the workspace.
//!
//! A robot replans when a person steps into its path or a door opens. A cold plan forgets what the
//! colony learnt; a warm one keeps its pheromone, which still marks the good corridors towards the
//! goal on most of the map, and repairs it only where the map changed:
//!
//! | colony state | on a warm start |
//! | --- | --- |
//! | pheromone, away from the changes | kept, clamped into the current `[tau_min, tau_max]` |
//! | pheromone within [`REPAIR_RADIUS`] cells of a change | set back to `tau0`, as in a cold start |
//! | pheromone on edges into new obstacles | kept: ants are never offered a blocked move, so it is inert |
//! | pruned cells, the coarse route | repaired around the changes and the two starts when the last run kept them ([`super::Run::keep`]): [`crate::map::prune::repair`], [`crate::colony::route::repair`], bit for bit what a rebuild gives; else rebuilt |
//! | reachability | not checked up front with backtracking ants: the first ant proves a cut-off goal |
//! | the early stop | after [`Params::warm_patience`] stale iterations instead of [`Params::patience`] |
//!
//! The local reset is Guntsch and Middendorf's "tau-strategy" for dynamic ant colony problems
//! ("Pheromone modification strategies for ant algorithms applied to dynamic TSP", 2001): forget
//! near the change, keep far from it. Without it, a colony whose trail leads into a new wall keeps
//! pushing its ants at the wall, and a newly opened gap beside the trail stays at `tau_min` (the
//! colony's memory says "nothing good here") where a cold colony would have tried it. With it, the
//! ants explore around the change as a fresh colony would, and follow the old trail everywhere
//! else.
//!
//! [`Memory`] is the bookkeeping: which map size and goal the workspace's pheromone belongs to and
//! the bounding box of the cells changed since. The caller keeps one beside the storage, reports
//! map changes to it and passes it to [`super::Run::warm`]; a warm start whose memory does not
//! match (another goal, another map, no previous run) is a cold start.
//!
//! The memory also keeps where the last answer lies in the workspace and which cells were cleared
//! since it was planned, for [`super::reuse`]; its rule 3 (no cleared cell can shorten the answer)
//! is [`Memory::cannot_shorten`], beside the rectangles it reads. Host and device use the same
//! code, so a sequence of warm plans gives the same paths on both.

use crate::colony::heuristic::octile;
use crate::colony::pheromone::Table;
use crate::geometry::sqrt;
use crate::map::grid::Point;

/// Pheromone within this many cells (Chebyshev distance) of a changed cell is reset to `tau0` on
/// a warm start. Chosen by measurement (`BENCHMARKS.md`, replanning): a wall across the path needs
/// the ants to leave the old trail a few cells before it, and a gap beside the trail must be
/// reachable from the trail's reset part.
pub const REPAIR_RADIUS: u16 = 6;

/// A rectangle of cells, corners included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Area {
    /// Top-left corner.
    pub min: Point,
    /// Bottom-right corner (`>= min` on both axes).
    pub max: Point,
}

impl Area {
    /// The single cell `p`.
    pub const fn cell(p: Point) -> Self {
        Area { min: p, max: p }
    }

    /// The `width x height` cells from `(x, y)` (clamped at the coordinate range); `None` when a
    /// side is zero.
    pub fn rect(x: u16, y: u16, width: u16, height: u16) -> Option<Self> {
        if width == 0 || height == 0 {
            return None;
        }
        Some(Area {
            min: Point::new(x, y),
            // width >= 1, so `width - 1` does not wrap.
            max: Point::new(
                x.saturating_add(width.wrapping_sub(1)),
                y.saturating_add(height.wrapping_sub(1)),
            ),
        })
    }

    /// The smallest area holding both.
    pub fn union(self, o: Area) -> Area {
        Area {
            min: Point::new(self.min.x.min(o.min.x), self.min.y.min(o.min.y)),
            max: Point::new(self.max.x.max(o.max.x), self.max.y.max(o.max.y)),
        }
    }

    /// Cells inside.
    pub fn cells(&self) -> u64 {
        let side = |a: u16, b: u16| u64::from(b.saturating_sub(a)).saturating_add(1);
        side(self.min.x, self.max.x).saturating_mul(side(self.min.y, self.max.y))
    }

    /// The corners, as `(min, max)`.
    pub fn corners(self) -> (Point, Point) {
        (self.min, self.max)
    }

    /// True if `p` lies inside.
    pub fn contains(&self, p: Point) -> bool {
        (self.min.x..=self.max.x).contains(&p.x) && (self.min.y..=self.max.y).contains(&p.y)
    }

    /// This area grown by `r` cells on every side (clamped at the coordinate range).
    pub fn grown(self, r: u16) -> Area {
        Area {
            min: Point::new(self.min.x.saturating_sub(r), self.min.y.saturating_sub(r)),
            max: Point::new(self.max.x.saturating_add(r), self.max.y.saturating_add(r)),
        }
    }
}

/// What the pheromone in a workspace belongs to, and the map changes since. See the module docs.
///
/// ```
/// use ohaca::grid::Point;
/// use ohaca::planner::{Area, Memory};
/// let mut memory = Memory::new();
/// assert!(!memory.is_warm_for(64, 64, Point::new(60, 60))); // nothing planned yet
/// memory.planned(64, 64, Point::new(60, 60));
/// memory.changed(Area::cell(Point::new(10, 12)), None);
/// assert!(memory.is_warm_for(64, 64, Point::new(60, 60)));
/// assert!(!memory.is_warm_for(64, 64, Point::new(1, 1))); // another goal: cold
/// assert_eq!(memory.changes(), Some(Area::cell(Point::new(10, 12))));
/// memory.forget(); // a new map
/// assert!(!memory.is_warm_for(64, 64, Point::new(60, 60)));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Memory {
    /// Map width, height and goal of the last run that set the pheromone.
    owner: Option<(u16, u16, Point)>,
    /// Bounding box of every cell changed since that run started.
    changes: Option<Area>,
    /// What else that run left in the workspace for a warm start to repair instead of rebuild
    /// ([`super::Run::keep`]).
    kept: Option<Kept>,
    /// The last answer to the owner's goal, kept in the workspace for a replan to reuse
    /// ([`super::reuse`]).
    pub(super) answer: Option<Answer>,
    /// The cells cleared since that answer was planned, as at most [`FREED`] rectangles.
    pub(super) freed: Freed,
    /// Cells that were free when that answer was planned and are blocked since
    /// ([`Memory::cell`]): clearing one of them again restores the map the answer was planned on
    /// there, so it is not a cleared cell.
    blocked: Blocked,
}

/// Cells a [`Memory`] remembers as blocked since its answer was planned (were free then).
pub const BLOCKED: usize = 32;

/// See [`Memory::cell`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Blocked {
    cells: [Option<Point>; BLOCKED],
    /// A cell did not fit: clearing a cell not listed counts as a cleared cell anyway, so the
    /// list is only an optimisation; kept for the record.
    overflowed: bool,
}

impl Blocked {
    const fn new() -> Self {
        Blocked {
            cells: [None; BLOCKED],
            overflowed: false,
        }
    }

    fn push(&mut self, p: Point) {
        match self.cells.iter_mut().find(|c| c.is_none()) {
            Some(slot) => *slot = Some(p),
            None => self.overflowed = true,
        }
    }

    /// Remove `p` if listed; true if it was.
    fn take(&mut self, p: Point) -> bool {
        match self.cells.iter_mut().find(|c| **c == Some(p)) {
            Some(slot) => {
                *slot = None;
                true
            }
            None => false,
        }
    }
}

/// Rectangles of cleared cells a [`Memory`] tells apart; a further one is merged into the one
/// it grows least (a larger rectangle: fewer replans proven unnecessary, never a wrong proof).
pub const FREED: usize = 8;

/// Rectangles of at most this many cells are recorded cell by cell ([`Memory::rect`]).
pub const CELL_BY_CELL: u64 = 64;

/// The cells cleared since an answer was planned ([`Memory::changed`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Freed {
    areas: [Option<Area>; FREED],
}

impl Freed {
    /// Add `area`: into a free slot, else merged into the rectangle it grows least.
    fn add(&mut self, area: Area) {
        let mut grow: Option<(u64, usize)> = None;
        for (i, slot) in self.areas.iter_mut().enumerate() {
            match slot {
                None => {
                    *slot = Some(area);
                    return;
                }
                Some(a) => {
                    let g = a.union(area).cells().saturating_sub(a.cells());
                    if grow.is_none_or(|(best, _)| g < best) {
                        grow = Some((g, i));
                    }
                }
            }
        }
        if let Some(slot) = grow.and_then(|(_, i)| self.areas.get_mut(i)) {
            *slot = slot.map(|a| a.union(area));
        }
    }

    /// The rectangles.
    pub(super) fn areas(&self) -> impl Iterator<Item = Area> + '_ {
        self.areas.iter().flatten().copied()
    }
}

/// The last answer a [`Memory`] keeps: its raw path is `best[from..steps]` of the workspace,
/// starting at `start`, and its waypoints `points[first..end]` ([`super::reuse`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Answer {
    /// The answer's first cell (`points[first]`, and the raw path's).
    pub(super) start: Point,
    /// The raw path's first direction in the best tour.
    pub(super) from: u32,
    /// One past its last.
    pub(super) steps: u32,
    /// The first waypoint in `points`.
    pub(super) first: u32,
    /// One past the last.
    pub(super) end: u32,
    /// The parameters that planned it (seed set to 0: a replan with another seed reuses it).
    pub(super) params: super::Params,
}

impl Answer {
    /// Where it lies: its raw path's directions in the best tour (`from..steps`) and its
    /// waypoints in `points` (`first..end`), as indices (saturating: a range past a buffer reads
    /// as absent).
    pub(super) fn ranges(&self) -> (core::ops::Range<usize>, core::ops::Range<usize>) {
        let at = |v: u32| usize::try_from(v).unwrap_or(usize::MAX);
        (at(self.from)..at(self.steps), at(self.first)..at(self.end))
    }
}

/// What a run left in the workspace besides its pheromone and its answer ([`super::Run::keep`]):
/// its pruning marks, and maybe its coarse route's links.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Kept {
    /// The start the marks were pruned for ([`crate::map::prune::prune`], with the goal of the
    /// memory's owner, on the map as it was before [`Memory::changes`]).
    pub(super) start: Point,
    /// True if the route's links are stashed in the pheromone increments
    /// ([`crate::colony::route::stash`], their last [`crate::colony::route::stash_len`] slots).
    pub(super) route: bool,
}

impl Memory {
    /// No colony yet: the next run is cold.
    pub const fn new() -> Self {
        Memory {
            owner: None,
            changes: None,
            kept: None,
            answer: None,
            freed: Freed {
                areas: [None; FREED],
            },
            blocked: Blocked::new(),
        }
    }

    /// The map was replaced (or the pheromone overwritten some other way): the next run is cold.
    pub fn forget(&mut self) {
        *self = Memory::new();
    }

    /// Cells in `area` changed (blocked or cleared), and those of them that were blocked and are
    /// free now lie in `cleared` (`None`: none). A caller that does not know passes
    /// `Some(area)`: a cleared cell is the one kind of change that can make a kept answer longer
    /// than a new plan ([`super::reuse`]), so a larger `cleared` is always safe.
    pub fn changed(&mut self, area: Area, cleared: Option<Area>) {
        self.changes = Some(match self.changes {
            Some(a) => a.union(area),
            None => area,
        });
        if let Some(c) = cleared {
            self.freed.add(c);
        }
    }

    /// Cell `p` changed from blocked (`was_blocked`) or free to `blocked` or free: the precise
    /// form of [`Memory::changed`] for one cell. A cell blocked and cleared again since the
    /// answer was planned is as it was then, so it does not count as cleared (a costmap's
    /// passing obstacle costs no replan when it leaves); this is remembered for up to
    /// [`BLOCKED`] cells, beyond which such a cell counts as cleared (never a wrong proof).
    pub fn cell(&mut self, p: Point, was_blocked: bool, blocked: bool) {
        let area = Area::cell(p);
        match (was_blocked, blocked) {
            (false, true) => {
                self.changed(area, None);
                self.blocked.push(p);
            }
            (true, false) => {
                let restored = self.blocked.take(p);
                self.changed(area, (!restored).then_some(area));
            }
            // Written as it was: nothing changed.
            _ => {}
        }
    }

    /// The cells of `area` were set to `blocked`, `was_blocked` reading the map before the
    /// write: cell by cell ([`Memory::cell`]) when `area` has at most [`CELL_BY_CELL`] cells, so
    /// a small box set and cleared again is no change to the answer; else one rectangle whose
    /// cleared part is the cells that were blocked ([`Memory::changed`]). What the firmware's
    /// receiver and the host's replanning both call, with the map they are about to write.
    pub fn rect(&mut self, area: Area, blocked: bool, was_blocked: impl Fn(Point) -> bool) {
        let (lo, hi) = area.corners();
        let cells = (lo.y..=hi.y).flat_map(|y| (lo.x..=hi.x).map(move |x| Point::new(x, y)));
        if area.cells() <= CELL_BY_CELL {
            for p in cells {
                self.cell(p, was_blocked(p), blocked);
            }
        } else {
            let cleared = if blocked {
                None
            } else {
                cells
                    .filter(|&p| was_blocked(p))
                    .map(Area::cell)
                    .reduce(Area::union)
            };
            self.changed(area, cleared);
        }
    }

    /// Rule 3 of [`super::reuse`]: no rectangle of cells cleared since the answer was planned
    /// can give a path from `start` to `goal` shorter than `raw_length` (octile distances through
    /// its cells) or `length` (Euclidean distances to its cells' squares).
    pub(super) fn cannot_shorten(
        &self,
        start: Point,
        goal: Point,
        raw_length: f32,
        length: f32,
    ) -> bool {
        self.freed.areas().all(|area| {
            let euclid = box_distance(start, area) + box_distance(goal, area) - SLACK;
            let oct = box_octile(start, area) + box_octile(goal, area) - SLACK;
            oct >= raw_length && euclid >= length
        })
    }

    /// A run on a `width x height` map to `goal` set the pheromone (called by
    /// [`super::Run::warm`]; no changes since).
    pub fn planned(&mut self, width: u16, height: u16, goal: Point) {
        *self = Memory::new();
        self.owner = Some((width, height, goal));
    }

    /// What the last run left besides its pheromone, if it said so ([`super::Run::keep`]).
    pub(super) fn kept(&self) -> Option<Kept> {
        self.kept
    }

    /// The run that last called [`Memory::planned`] left `kept` in the workspace.
    pub(super) fn keep(&mut self, kept: Kept) {
        self.kept = Some(kept);
    }

    /// True if a run on a `width x height` map to `goal` can start warm.
    pub fn is_warm_for(&self, width: u16, height: u16, goal: Point) -> bool {
        self.owner == Some((width, height, goal))
    }

    /// Bounding box of the cells changed since the last run, if any.
    pub fn changes(&self) -> Option<Area> {
        self.changes
    }
}

/// A lower bound is lowered by this much before it is compared with a length, so that the
/// rounding of either (f32, a few ulps) can never turn "a path through the cleared cells could be
/// shorter" into a reuse.
const SLACK: f32 = 1.0 / 64.0;

/// Cells between `p` and the rectangle on one axis (0 inside).
fn gap(v: u16, lo: u16, hi: u16) -> u16 {
    if v < lo {
        lo.wrapping_sub(v)
    } else {
        v.saturating_sub(hi)
    }
}

/// Euclidean distance from the centre of `p` to the union of the closed squares of `area`'s
/// cells (0 inside).
fn box_distance(p: Point, area: Area) -> f32 {
    let d = |g: u16| (f32::from(g) - 0.5).max(0.0);
    let (dx, dy) = (
        d(gap(p.x, area.min.x, area.max.x)),
        d(gap(p.y, area.min.y, area.max.y)),
    );
    sqrt(dx * dx + dy * dy)
}

/// Octile distance from `p` to the nearest cell of `area` (0 inside).
fn box_octile(p: Point, area: Area) -> f32 {
    let q = Point::new(
        // Not `clamp`: it panics on `min > max`, which an `Area` never has.
        p.x.max(area.min.x).min(area.max.x),
        p.y.max(area.min.y).min(area.max.y),
    );
    octile(p, q)
}

/// Prepare a kept pheromone table for a warm start: clamp every entry into `[tau_min, tau_max]`
/// (the bounds may have changed since), then set every entry of an edge with an end within
/// [`REPAIR_RADIUS`] cells of `changes` to `tau0`. Returns the entries reset.
pub(super) fn repair(
    tau: &mut Table<'_>,
    changes: Option<Area>,
    tau0: f32,
    tau_min: f32,
    tau_max: f32,
) -> u32 {
    tau.clamp(tau_min, tau_max);
    let Some(area) = changes else { return 0 };
    // An edge belongs to the entry of its west/north end ([`crate::colony::pheromone`]), so growing the
    // area by one more cell reaches the entries of edges that enter it from the west or north.
    let area = area.grown(REPAIR_RADIUS.saturating_add(1));
    tau.fill_area(area.min, area.max, tau0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colony::pheromone::Blocks;

    #[test]
    fn box_distances_are_lower_bounds() {
        let area = Area::rect(10, 10, 3, 2).unwrap();
        // Inside: 0.
        assert_eq!(box_distance(Point::new(11, 11), area), 0.0);
        assert_eq!(box_octile(Point::new(12, 10), area), 0.0);
        // Beside: to the square's edge (half a cell short of the centre).
        assert_eq!(box_distance(Point::new(5, 10), area), 4.5);
        assert_eq!(box_octile(Point::new(5, 10), area), 5.0);
        // Every cell of the area is at least as far as the bound, from every cell around.
        for y in 0..25u16 {
            for x in 0..25u16 {
                let p = Point::new(x, y);
                for cy in 10..12u16 {
                    for cx in 10..13u16 {
                        let c = Point::new(cx, cy);
                        assert!(octile(p, c) >= box_octile(p, area));
                        assert!(crate::geometry::distance(p, c) + 0.7072 >= box_distance(p, area));
                    }
                }
            }
        }
    }

    #[test]
    fn areas_grow_and_join() {
        let a = Area::rect(2, 3, 4, 1).unwrap();
        assert_eq!(a.max, Point::new(5, 3));
        assert!(a.contains(Point::new(5, 3)) && !a.contains(Point::new(6, 3)));
        assert_eq!(Area::rect(1, 1, 0, 5), None);
        let u = a.union(Area::cell(Point::new(0, 9)));
        assert_eq!((u.min, u.max), (Point::new(0, 3), Point::new(5, 9)));
        let g = Area::cell(Point::new(1, 65534)).grown(3);
        assert_eq!((g.min, g.max), (Point::new(0, 65531), Point::new(4, 65535)));
    }

    #[test]
    fn memory_matches_size_and_goal_only() {
        let mut m = Memory::new();
        let g = Point::new(3, 4);
        assert!(!m.is_warm_for(8, 8, g));
        m.planned(8, 8, g);
        assert!(m.is_warm_for(8, 8, g));
        assert!(!m.is_warm_for(8, 9, g));
        assert!(!m.is_warm_for(8, 8, Point::new(4, 4)));
        m.changed(Area::cell(Point::new(1, 1)), None);
        m.changed(
            Area::cell(Point::new(5, 0)),
            Some(Area::cell(Point::new(5, 0))),
        );
        assert_eq!(m.changes(), Area::rect(1, 0, 5, 2));
        m.planned(8, 8, g);
        assert_eq!(m.changes(), None);
    }

    #[test]
    fn a_cell_blocked_and_cleared_again_is_not_cleared() {
        let mut m = Memory::new();
        m.planned(8, 8, Point::new(7, 7));
        let (p, q) = (Point::new(2, 2), Point::new(3, 3));
        m.cell(p, false, true); // a passing obstacle
        m.cell(p, true, false); // gone again: as when planned
        assert_eq!(m.freed.areas().count(), 0);
        assert_eq!(m.changes(), Some(Area::cell(p)));
        m.cell(q, true, false); // blocked when planned: cleared
        assert_eq!(m.freed.areas().collect::<Vec<_>>(), [Area::cell(q)]);
        m.cell(Point::new(5, 5), false, false); // written as it was: nothing
        assert_eq!(m.changes(), Some(Area::cell(p).union(Area::cell(q))));
        // Beyond BLOCKED listed cells, a cleared one counts as cleared.
        let mut m = Memory::new();
        for i in 0..=BLOCKED as u16 {
            m.cell(Point::new(i, 0), false, true);
        }
        m.cell(Point::new(BLOCKED as u16, 0), true, false);
        assert_eq!(m.freed.areas().count(), 1);
        m.cell(Point::new(0, 0), true, false);
        assert_eq!(m.freed.areas().count(), 1, "listed: restored");
    }

    #[test]
    fn cleared_rectangles_merge_where_they_grow_least() {
        let mut m = Memory::new();
        for i in 0..FREED as u16 {
            m.changed(
                Area::cell(Point::new(10 * i, 0)),
                Some(Area::cell(Point::new(10 * i, 0))),
            );
        }
        m.changed(
            Area::cell(Point::new(31, 1)),
            Some(Area::cell(Point::new(31, 1))),
        );
        let areas: Vec<Area> = m.freed.areas().collect();
        assert_eq!(areas.len(), FREED);
        assert!(
            areas.contains(&Area::rect(30, 0, 2, 2).unwrap()),
            "{areas:?}"
        );
    }

    #[test]
    fn repair_resets_near_the_change_and_clamps_elsewhere() {
        // 64 x 64 cells: one entry a 2 x 2 block (32 x 32 = 1024 entries).
        let blocks = Blocks::new(64, 64);
        assert_eq!(blocks.shift(), 1);
        let mut buf = [[50.0f32; 4]; 1024];
        buf[0] = [500.0, 0.001, 7.0, 7.0];
        let mut tau = Table::new(blocks, &mut buf);
        let change = Area::cell(Point::new(40, 40));
        let reset = repair(&mut tau, Some(change), 1.0, 0.01, 100.0);
        let r = REPAIR_RADIUS + 1;
        // Cells 40-r ..= 40+r on both axes, in 2 x 2 blocks.
        let lo = (40 - r) / 2;
        let hi = (40 + r) / 2;
        let side = u32::from(hi - lo + 1);
        assert_eq!(reset, side * side);
        for by in 0..32u16 {
            for bx in 0..32u16 {
                let e = tau.entries()[usize::from(by) * 32 + usize::from(bx)];
                let near = (lo..=hi).contains(&bx) && (lo..=hi).contains(&by);
                let want = if near {
                    [1.0; 4]
                } else if (bx, by) == (0, 0) {
                    [100.0, 0.01, 7.0, 7.0]
                } else {
                    [50.0; 4]
                };
                assert_eq!(e, want, "block ({bx}, {by})");
            }
        }
        // No changes: only the clamp.
        let mut buf = [[500.0f32; 4]; 16];
        let mut tau = Table::new(Blocks::new(4, 4), &mut buf);
        assert_eq!(repair(&mut tau, None, 1.0, 0.01, 100.0), 0);
        assert!(tau.entries().iter().all(|e| *e == [100.0; 4]));
    }

    #[test]
    fn a_rectangle_is_told_cell_by_cell_when_small() {
        // 4 x 4 cells (at most `BLOCKED` remembered): set and cleared again, cell by cell, so
        // nothing counts as freed.
        let free = |_: Point| false;
        let all_blocked = |_: Point| true;
        let mut m = Memory::new();
        let small = Area::rect(2, 3, 4, 4).unwrap();
        m.rect(small, true, free);
        m.rect(small, false, all_blocked);
        assert_eq!(m.freed.areas().count(), 0);
        assert_eq!(m.changes(), Some(small));
        // 9 x 8 cells: one rectangle; clearing it frees exactly the cells that were blocked.
        let mut m = Memory::new();
        let large = Area::rect(2, 3, 9, 8).unwrap();
        m.rect(large, true, free);
        assert_eq!(m.freed.areas().count(), 0);
        let one = Point::new(5, 6);
        m.rect(large, false, |p| p == one);
        assert_eq!(
            m.freed.areas().collect::<alloc::vec::Vec<_>>(),
            [Area::cell(one)]
        );
        // Set and cleared again as a rectangle: every cell counts as freed (no cell is
        // remembered).
        let mut m = Memory::new();
        m.rect(large, true, free);
        m.rect(large, false, all_blocked);
        assert_eq!(m.freed.areas().collect::<alloc::vec::Vec<_>>(), [large]);
        // Nothing was blocked: nothing is freed.
        let mut m = Memory::new();
        m.rect(large, false, free);
        assert_eq!((m.freed.areas().count(), m.changes()), (0, Some(large)));
    }
}
