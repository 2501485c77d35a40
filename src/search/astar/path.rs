//! Reading a found path back from the per-cell state ([`path_back`] from the nibbles,
//! [`path_back_costs`] from the costs: the moves from the goal to the start) and writing its
//! cells out, start first ([`write_path`], [`write_path_costs`]). A state that does not lead to
//! the start is [`AstarError::NoTree`], never a loop or a panic.

use crate::map::dir::{opposite, Dir, DX, DY};
use crate::map::grid::{Grid, Point};
use crate::search::cost;

use super::store::nib;
use super::{AstarError, Search, START};

/// The moves of the path [`search`] found, from the goal back to the start: each item is the
/// direction the path took *into* the current cell (so the cell before it is one step in
/// [`opposite`] of it). Ends at the start; yields `Err(NoTree)` once (and then ends) if the
/// nibbles do not lead there within `cells` steps.
pub fn path_back<'n>(grid: &Grid<'_>, nibbles: &'n [u8], goal: Point) -> PathBack<'n> {
    PathBack {
        nibbles,
        offs: grid.offsets(),
        at: grid.index(goal),
        left: grid.cells(),
        done: !grid.contains(goal),
    }
}

/// The iterator of [`path_back`].
#[derive(Clone, Debug)]
pub struct PathBack<'n> {
    nibbles: &'n [u8],
    offs: [isize; 8],
    at: usize,
    left: usize,
    done: bool,
}

impl Iterator for PathBack<'_> {
    type Item = Result<Dir, AstarError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let v = nib(self.nibbles, self.at);
        if v == START {
            self.done = true;
            return None;
        }
        if !(1..=8).contains(&v) || self.left == 0 {
            self.done = true;
            return Some(Err(AstarError::NoTree));
        }
        self.left = self.left.wrapping_sub(1);
        let d: Dir = v.wrapping_sub(1);
        let o = self
            .offs
            .get(usize::from(opposite(d)))
            .copied()
            .unwrap_or(0);
        self.at = self.at.wrapping_add_signed(o);
        Some(Ok(d))
    }
}

/// The moves of the path [`search_costs`] found, from the goal back to the start, as
/// [`path_back`] gives them: at each cell, the first direction `d` (in `0..8`) whose move into
/// the cell is allowed from a neighbour with exactly the cell's cost less the step's (so a
/// shortest path; among equals, the first direction). Ends at the start (cost 0); yields
/// `Err(NoTree)` once (and then ends) if no such neighbour exists.
pub fn path_back_costs<'g, 'c>(
    grid: &Grid<'g>,
    costs: &'c [u32],
    goal: Point,
) -> PathBackCosts<'g, 'c> {
    PathBackCosts {
        grid: *grid,
        costs,
        at: goal,
        done: !grid.contains(goal),
    }
}

/// The iterator of [`path_back_costs`].
#[derive(Clone, Debug)]
pub struct PathBackCosts<'g, 'c> {
    grid: Grid<'g>,
    costs: &'c [u32],
    at: Point,
    done: bool,
}

impl Iterator for PathBackCosts<'_, '_> {
    type Item = Result<Dir, AstarError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let cost = |p: Point| self.costs.get(self.grid.index(p)).copied();
        let g = match cost(self.at) {
            Some(0) => {
                self.done = true;
                return None;
            }
            Some(g) if g != u32::MAX => g,
            _ => {
                self.done = true;
                return Some(Err(AstarError::NoTree));
            }
        };
        // The costs strictly decrease along the walk, so it ends.
        for d in 0..8u8 {
            if let Some(p) = self.grid.step(self.at, opposite(d)) {
                if cost(p).and_then(|c| c.checked_add(cost::step(d))) == Some(g) {
                    self.at = p;
                    return Some(Ok(d));
                }
            }
        }
        self.done = true;
        Some(Err(AstarError::NoTree))
    }
}

/// Write the cells of the path `back` walks from `goal`, start first and goal last, into `out`;
/// `is_start` checks the cell the walk ends at.
fn write_from(
    mut back: impl Iterator<Item = Result<Dir, AstarError>>,
    is_start: impl Fn(Point) -> bool,
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let n = (s.steps() as usize).saturating_add(1);
    let capacity = out.len();
    let slots = out
        .get_mut(..n)
        .ok_or(AstarError::PathTooLong { cells: n, capacity })?;
    let mut p = goal;
    for slot in slots.iter_mut().rev() {
        *slot = p;
        match back.next() {
            Some(Ok(d)) => {
                let o = usize::from(opposite(d));
                let dx = DX.get(o).copied().unwrap_or(0);
                let dy = DY.get(o).copied().unwrap_or(0);
                // Inside the map by the tree's construction; a bad tree is caught below.
                p = Point::new(
                    p.x.wrapping_add_signed(dx as i16),
                    p.y.wrapping_add_signed(dy as i16),
                );
            }
            Some(Err(e)) => return Err(e),
            None => {}
        }
    }
    // The walk must end exactly at the start after `steps` moves.
    match back.next() {
        None if is_start(p) => Ok(n),
        _ => Err(AstarError::NoTree),
    }
}

/// Write the path [`search`] found, start first and goal last, into `out`; returns how many
/// cells (`steps + 1`, with `s` the [`Search`] the nibbles hold).
pub fn write_path(
    grid: &Grid<'_>,
    nibbles: &[u8],
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let back = path_back(grid, nibbles, goal);
    write_from(back, |p| nib(nibbles, grid.index(p)) == START, goal, s, out)
}

/// Write the path [`search_costs`] found, start first and goal last, into `out`; returns how
/// many cells (`steps + 1`, with `s` the [`Search`] the costs hold).
pub fn write_path_costs(
    grid: &Grid<'_>,
    costs: &[u32],
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let back = path_back_costs(grid, costs, goal);
    write_from(back, |p| costs.get(grid.index(p)) == Some(&0), goal, s, out)
}
