//! The per-iteration pheromone update (paper eq. 11-13).
//!
//! ```text
//! tau(t+1) = clamp( (1 - rho) tau(t) + sum_k dtau_k + dtau_best - dtau_worst , tau_min, tau_max )
//! dtau_k     = Q / L_k            on every edge of ant k's path            (classic ant system)
//! dtau_best  = b * Q / L_best     on the iteration's best path  (wolves rule: feed the strong wolf)
//! dtau_worst = w * Q / L_worst    on the iteration's worst path (wolves rule: drop the weak wolf)
//! ```
//!
//! Readings we chose (also in `docs/ALGORITHM.md`):
//!
//! - **`b` and `w`** are "the number of the local best path and the worst path": the number of
//!   ants of this iteration whose path has the best (resp. worst) length. So the more ants agree
//!   on the best path, the stronger it is rewarded. Lengths are compared exactly, as counts of
//!   straight and diagonal steps.
//! - **Which path**: the reward goes to the path of the *first* ant (in walking order) with the
//!   best length, the punishment to the first ant's with the worst length. The ants of one
//!   iteration are independent draws from the same `tau`, so the first best ant is a uniformly
//!   random one of the `b`: a best path taken by `b_P` of them gets the whole `b Q / L_best` with
//!   probability `b_P / b`, i.e. `b_P Q / L_best` in expectation, exactly what "reward each best
//!   path in proportion to its ants" would give, without storing every best path (the device
//!   has room for one). Likewise for the worst.
//! - **`w = 1` cancels**: one worst ant deposited `Q / L_worst` and gets `w Q / L_worst` taken
//!   back, so its path keeps only evaporation. That is eq. 11-13 as written; in effect the worst
//!   ants do not reinforce their path and the best ants reinforce theirs twice. We keep it rather
//!   than invent a stronger punishment constant the paper does not give.
//! - **No wolves term when every ant has the same length**: then the best and the worst wolf are
//!   the same and reward and punishment would just cancel (or, for two different paths of equal
//!   length, arbitrarily punish one of them).
//! - **Clamping** to `[tau_min, tau_max]` after the whole update, so the punishment cannot drive
//!   an edge negative (which would make eq. 14's `[...]^alpha` undefined).
//!
//! ACA and PACA use only the first two terms; HACA and OHACA add the wolves terms. Ants that died
//! deposit nothing.

use crate::colony::pheromone::{slot_offsets, Table};
use crate::map::grid::{neighbour, Dir, Grid, Point};

/// Add `amount` to every edge of the path that starts at `start` and follows `tour`.
pub fn deposit(table: &mut Table<'_>, grid: &Grid<'_>, start: Point, tour: &[Dir], amount: f32) {
    let blocks = table.blocks();
    if blocks.shift() != 0 {
        // Blocks: locate each edge's block from the cell.
        let mut p = start;
        for &d in tour {
            table.add_flat(blocks.index(p, d), amount);
            p = neighbour(p, d);
        }
        return;
    }
    let offsets = grid.offsets();
    let slots = slot_offsets(&offsets);
    let mut c = grid.index(start);
    let flat = table.flat_mut();
    // Four steps a round (the same additions in the same order), the rest one at a time: the
    // loop's own count and branch are paid once per four edges.
    let mut quads = tour.chunks_exact(4);
    for q in &mut quads {
        for &d in q {
            c = add_edge(flat, &slots, &offsets, c, d, amount);
        }
    }
    for &d in quads.remainder() {
        c = add_edge(flat, &slots, &offsets, c, d, amount);
    }
}

/// One step of [`deposit`]'s flat walk: add `amount` to the entry of the edge from cell `c` in
/// direction `d`, and return the next cell.
#[inline(always)]
fn add_edge(
    flat: &mut [f32],
    slots: &[isize; 8],
    offsets: &[isize; 8],
    c: usize,
    d: Dir,
    amount: f32,
) -> usize {
    // A tour holds directions 0..=7 only (the walk writes them); `& 7` keeps any byte in range
    // of both 8-entry tables without a branch, which the compiler sees.
    let d = usize::from(d & 7);
    let slot = slots.get(d).copied().unwrap_or(0);
    // `c` is a cell index (< cells, and the table's 16 bytes a cell fit in memory), so `4 * c`
    // does not wrap; a stray index is ignored.
    if let Some(v) = flat.get_mut(c.wrapping_mul(4).wrapping_add_signed(slot)) {
        *v += amount;
    }
    c.wrapping_add_signed(offsets.get(d).copied().unwrap_or(0))
}

/// Where [`wolves`] finds the iteration's best and worst paths, one at a time: the best first
/// (deposited on before the worst is asked for, so a workspace that walks both ants again can
/// use one buffer for both), then the worst. `None`: that path cannot be had, and gets nothing.
pub trait WolfPaths {
    /// The iteration's best path (its first ant's), as directions from the start.
    fn best(&mut self) -> Option<&[Dir]>;
    /// The iteration's worst path (its first ant's), asked for after the best one's deposit.
    fn worst(&mut self) -> Option<&[Dir]>;
}

/// Both paths at hand: `(best, worst)`.
impl WolfPaths for (&[Dir], &[Dir]) {
    fn best(&mut self) -> Option<&[Dir]> {
        Some(self.0)
    }
    fn worst(&mut self) -> Option<&[Dir]> {
        Some(self.1)
    }
}

/// The wolves-distribution terms: reward the iteration's best path (`best`: its length and how
/// many ants took that length) with `b * q / l_best` and punish its worst with
/// `w * q / l_worst`, both added into `delta` (merged into `tau` by
/// [`Table::evaporate_and_merge`], which clamps), the best first; the paths come from `paths`.
/// Does nothing when `l_worst <= l_best` (or `l_best <= 0`), and then says so (`false`). The
/// colony's iteration (`planner::run`) calls it; it is the rule's one copy.
pub fn wolves(
    delta: &mut Table<'_>,
    grid: &Grid<'_>,
    start: Point,
    q: f32,
    (best, worst): ((f32, u32), (f32, u32)),
    paths: &mut impl WolfPaths,
) -> bool {
    let Some((reward, punish)) = wolves_amounts(q, best, worst) else {
        return false;
    };
    if let Some(t) = paths.best() {
        deposit(delta, grid, start, t, reward);
    }
    if let Some(t) = paths.worst() {
        deposit(delta, grid, start, t, punish);
    }
    true
}

/// The amounts [`wolves`] deposits, in its order: `b * q / l_best` on the best path, then
/// `-(w * q / l_worst)` on the worst; `None` when `l_worst <= l_best` (or `l_best <= 0`). The
/// colony's pieces (`planner::run`) deposit them a path at a time.
pub fn wolves_amounts(q: f32, best: (f32, u32), worst: (f32, u32)) -> Option<(f32, f32)> {
    let ((l_best, b), (l_worst, w)) = (best, worst);
    if l_worst <= l_best || l_best <= 0.0 {
        return None;
    }
    Some((b as f32 * q / l_best, -(w as f32 * q / l_worst)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colony::pheromone::Blocks;

    /// The flat deposit takes the tour four steps a round and then the rest: every step of a
    /// tour whose length is not a multiple of four (the rest non-empty) gets the amount, once per
    /// time the tour takes it, as the edge-by-edge `get` of the table sees it.
    #[test]
    fn deposit_every_step_of_quads_and_rest() {
        let bits = [0u8; 4];
        let g = Grid::new(5, 5, &bits).unwrap();
        let mut buf = [[0.0f32; 4]; 25];
        let mut t = Table::new(Blocks::new(5, 5), &mut buf);
        assert_eq!(t.blocks().shift(), 0);
        let start = Point::new(0, 0);
        // E, E, SE, S, W, NW, E, S, SE: 9 steps (two rounds of four and one more).
        let tour = [0u8, 0, 1, 2, 4, 5, 0, 2, 1];
        deposit(&mut t, &g, start, &tour, 0.5);
        let mut want = [[0.0f32; 4]; 25];
        let mut w = Table::new(Blocks::new(5, 5), &mut want);
        let mut p = start;
        for &d in &tour {
            let v = w.get(p, d) + 0.5;
            w.add_flat(w.blocks().index(p, d), 0.5);
            assert_eq!(w.get(p, d), v);
            p = neighbour(p, d);
        }
        assert_eq!(t.entries(), w.entries());
        assert!(t.entries().iter().flatten().filter(|v| **v != 0.0).count() >= 8);
    }

    #[test]
    fn reward_best_punish_worst() {
        let bits = [0u8; 2];
        let g = Grid::new(4, 3, &bits).unwrap();
        let mut buf = [[0.0f32; 4]; 12];
        let mut delta = Table::new(Blocks::new(4, 3), &mut buf);
        let start = Point::new(0, 0);
        let best = [1u8, 0, 0]; // SE, E, E
        let worst = [0u8, 0, 2, 0]; // E, E, S, E
        let done = wolves(
            &mut delta,
            &g,
            start,
            1.0,
            ((2.0, 3), (4.0, 1)),
            &mut (&best[..], &worst[..]),
        );
        assert!(done);
        assert_eq!(delta.get(Point::new(0, 0), 1), 1.5);
        assert_eq!(delta.get(Point::new(0, 0), 0), -0.25);
        // An edge on both paths gets both: (1,1)->E? best walks (1,1)->(2,1)->(3,1); worst walks
        // (2,0)->(2,1)->(3,1): the edge (2,1)-(3,1) is shared.
        assert_eq!(delta.get(Point::new(2, 1), 0), 1.5 - 0.25);
        // Equal lengths: no wolves term.
        let mut buf2 = [[0.0f32; 4]; 12];
        let mut d2 = Table::new(Blocks::new(4, 3), &mut buf2);
        let paths = &mut (&best[..], &worst[..]);
        assert!(!wolves(
            &mut d2,
            &g,
            start,
            1.0,
            ((2.0, 3), (2.0, 1)),
            paths
        ));
        assert!(d2.entries().iter().flatten().all(|v| *v == 0.0));
    }
}
