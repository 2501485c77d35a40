//! The detour's box, sized by what blocks the answer (the module docs of [`super`], step 3).

use crate::geometry::steps_length;
use crate::map::grid::{is_diagonal, neighbour, Dir, Grid, Point};
use crate::polish::refine::{self, Scratch, MAX_SIDE, MIN_SIDE};

use super::{GiveUp, BOX_MARGIN, MARGIN};

/// The box of cells `min..=max` grown by `margin` on every side, clipped to a `w x h` map.
pub(super) fn grown(min: Point, max: Point, margin: u16, w: u16, h: u16) -> (Point, Point) {
    (
        Point::new(min.x.saturating_sub(margin), min.y.saturating_sub(margin)),
        Point::new(
            max.x.saturating_add(margin).min(w.saturating_sub(1)),
            max.y.saturating_add(margin).min(h.saturating_sub(1)),
        ),
    )
}

/// Cells of the box `lo..=hi`, and whether both sides are at most [`MAX_SIDE`].
pub(super) fn box_cells((lo, hi): (Point, Point)) -> (usize, bool) {
    let w = usize::from(hi.x.saturating_sub(lo.x)).saturating_add(1);
    let h = usize::from(hi.y.saturating_sub(lo.y)).saturating_add(1);
    (w.saturating_mul(h), w <= MAX_SIDE && h <= MAX_SIDE)
}

/// True if one of `cells` lies on a side of the box `lo..=hi` that is not the map's edge: the
/// box may have cut a shorter detour off there.
pub(super) fn hugs((lo, hi): (Point, Point), cells: &[Point], w: u16, h: u16) -> bool {
    cells.iter().any(|p| {
        (p.x == lo.x && lo.x > 0)
            || (p.y == lo.y && lo.y > 0)
            || (p.x == hi.x && hi.x.saturating_add(1) < w)
            || (p.y == hi.y && hi.y.saturating_add(1) < h)
    })
}

/// The raw path between two anchors: offsets `a..=b` of the raw path from `start` by `rest`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Stretch {
    pub(super) a: usize,
    pub(super) b: usize,
    /// The bounding box of its cells.
    pub(super) min: Point,
    pub(super) max: Point,
    /// Its end cells (the anchors).
    pub(super) ca: Point,
    pub(super) cb: Point,
    /// Its raw length.
    pub(super) old: f32,
}

impl Stretch {
    pub(super) fn new(start: Point, rest: &[Dir], a: usize, b: usize) -> Stretch {
        let (mut min, mut max) = (Point::new(u16::MAX, u16::MAX), Point::new(0, 0));
        let (mut ca, mut cb) = (start, start);
        let (mut straight, mut diagonal) = (0u32, 0u32);
        let mut p = start;
        for t in 0..=b {
            if t >= a {
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
            if t >= a && t < b {
                if is_diagonal(d) {
                    diagonal = diagonal.wrapping_add(1);
                } else {
                    straight = straight.wrapping_add(1);
                }
            }
            p = neighbour(p, d);
        }
        Stretch {
            a,
            b,
            min,
            max,
            ca,
            cb,
            old: steps_length(straight, diagonal),
        }
    }

    /// The stretch around the blocked raw moves `lo..hi` for a box margin `m`: anchors
    /// [`MARGIN`] raw cells before and after them, or `m` when that is more (so the detour can
    /// leave the path as far ahead as it must go sideways), clamped to the rest.
    pub(super) fn around(start: Point, rest: &[Dir], (lo, hi): (usize, usize), m: u16) -> Stretch {
        let reach = MARGIN.max(usize::from(m));
        let b = hi.saturating_add(reach).min(rest.len());
        Stretch::new(start, rest, lo.saturating_sub(reach), b)
    }
}

/// A detour found by [`sized_detour`]: its cells (`out[..cells]`) and the stretch it replaces.
#[derive(Clone, Copy, Debug)]
pub(super) struct Detour {
    pub(super) cells: usize,
    pub(super) stretch: Stretch,
}

/// The detour around the blocked raw moves `lo..hi` of the raw path from `start` by `rest`, in a
/// box sized by the change (see the module docs): the anchors' stretch's bounding box grown by a
/// margin of [`BOX_MARGIN`] cells, doubled (the anchors moving out with it) while the detour found
/// hugs the box's inner sides or none was found, as far as `scratch` holds; the last and largest
/// box takes the widest margin that still fits. Writes the detour's cells to `out`.
pub(super) fn sized_detour(
    grid: &Grid<'_>,
    start: Point,
    rest: &[Dir],
    blocked: (usize, usize),
    scratch: &mut Scratch<'_>,
    out: &mut [Point],
) -> Result<Detour, GiveUp> {
    let room = scratch.cells();
    if room < MIN_SIDE.saturating_mul(MIN_SIDE) {
        return Err(GiveUp::NoScratch);
    }
    let (w, h) = (grid.width(), grid.height());
    let bx = |s: &Stretch, m: u16| grown(s.min, s.max, m, w, h);
    let fits = |s: &Stretch, m: u16| {
        let (cells, sides) = box_cells(bx(s, m));
        sides && cells <= room
    };
    let mut m = BOX_MARGIN;
    let mut s = Stretch::around(start, rest, blocked, m);
    if !fits(&s, m) {
        let (needs, _) = box_cells(bx(&s, m));
        return Err(GiveUp::TooLong {
            needs: u32::try_from(needs).unwrap_or(u32::MAX),
            room: u32::try_from(room).unwrap_or(u32::MAX),
        });
    }
    let mut found = None;
    loop {
        let b = bx(&s, m);
        match refine::detour(grid, s.ca, s.cb, b, scratch, out) {
            Some(cells) => {
                found = Some(Detour { cells, stretch: s });
                if !hugs(b, out.get(..cells).unwrap_or_default(), w, h) {
                    break;
                }
            }
            // Keep the one found (`out` is left as it was).
            None if found.is_some() => break,
            None => {}
        }
        // The next margin: doubled, else the widest that fits; done when none grows the box.
        let mut next = m.saturating_mul(2);
        let mut t = Stretch::around(start, rest, blocked, next);
        while next > m && !fits(&t, next) {
            next = m.saturating_add(next.wrapping_sub(m) / 2);
            t = Stretch::around(start, rest, blocked, next);
        }
        if next <= m || (bx(&t, next) == b && (t.a, t.b) == (s.a, s.b)) {
            break;
        }
        (m, s) = (next, t);
    }
    found.ok_or(GiveUp::NoDetour)
}
