//! Where a plan lies in its workspace ([`Placed`]), to read it again later from a workspace
//! carved from the same memory the same way.
//!
//! A [`Plan`] borrows its raw path and waypoints from the workspace's best tour and points. The
//! firmware sends a long path a part at a time and gives the map's lock up between the parts
//! (on the small boards the workspace is in the map's arena, behind that lock): it keeps the
//! plan's [`Placed`], and for each part lends itself the workspace again and reads the slices
//! back with [`Workspace::placed`]. Nothing here is unsafe: the places are offsets, computed from
//! addresses and checked against the buffers when read (a workspace carved differently gives
//! `None` or other bytes, never a fault; the firmware carves the same map size each time).

use crate::map::dir::Dir;
use crate::map::grid::Point;

use super::{Plan, Workspace};

/// The addresses of a workspace's best tour and points ([`Workspace::bases`]), taken before a
/// run or a reuse borrows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bases {
    best: usize,
    points: usize,
}

/// A plan's raw path and waypoints as ranges of its workspace's best tour and points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placed {
    tour: (usize, usize),
    waypoints: (usize, usize),
}

/// The index of `part` in the buffer that starts at `base`, if it starts there or after, at a
/// whole element.
fn index_of<T>(base: usize, part: &[T]) -> Option<usize> {
    let bytes = (part.as_ptr() as usize).checked_sub(base)?;
    let size = core::mem::size_of::<T>().max(1);
    (bytes.checked_rem(size)? == 0).then_some(bytes.checked_div(size)?)
}

impl Workspace<'_> {
    /// Where its best tour and points start.
    pub fn bases(&self) -> Bases {
        Bases {
            best: self.best.as_ptr() as usize,
            points: self.points.as_ptr() as usize,
        }
    }

    /// The raw path and waypoints of a plan placed in a workspace carved the same way: `None`
    /// if they are not inside this one's buffers.
    pub fn placed(&self, p: &Placed) -> Option<(&[Dir], &[Point])> {
        let tour = self.best.get(p.tour.0..p.tour.1)?;
        let waypoints = self.points.get(p.waypoints.0..p.waypoints.1)?;
        Some((tour, waypoints))
    }
}

impl Plan<'_> {
    /// Where this plan lies in the workspace whose [`Bases`] these are: `None` if its slices
    /// are not in that workspace's best tour and points (every plan of [`super::Run::finish`],
    /// [`super::reuse`] and its repair is).
    pub fn place(&self, bases: Bases) -> Option<Placed> {
        let t = index_of(bases.best, self.tour)?;
        let w = index_of(bases.points, self.waypoints)?;
        Some(Placed {
            tour: (t, t.checked_add(self.tour.len())?),
            waypoints: (w, w.checked_add(self.waypoints.len())?),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::map::grid::Grid;
    use crate::planner::{plan, Params, Storage};
    use crate::Point;

    #[test]
    fn a_plan_is_read_back_from_a_workspace_lent_again() {
        let (bits, w, h) = crate::testutil::bits(&crate::planner::tests::ROWS);
        let g = Grid::new(w, h, &bits).unwrap();
        let mut s: Storage<2, 64, 128, 64> = Storage::new();
        let (placed, tour, waypoints) = {
            let ws = s.workspace();
            let bases = ws.bases();
            let p = plan(
                &g,
                Point::new(0, 0),
                Point::new(7, 5),
                &Params::default(),
                ws,
            )
            .unwrap();
            let placed = p.place(bases).expect("a run's plan lies in its workspace");
            (placed, p.directions().to_vec(), p.waypoints().to_vec())
        };
        // The storage lent again, as the firmware does for each part of a long path.
        let ws = s.workspace();
        let (t, wp) = ws.placed(&placed).unwrap();
        assert_eq!((t.to_vec(), wp.to_vec()), (tour, waypoints));
        assert!(!t.is_empty());
    }
}
