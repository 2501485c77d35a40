//! One ant's walk from start to goal: the transition rule (paper eq. 5/14), the tabu list, and
//! what happens at a dead end.
//!
//! From cell `i` the ant may move to every neighbour `j` that the grid allows (no corner cutting)
//! and that it has not visited yet (the tabu list). It picks `j` with probability proportional to
//! `tau_ij^alpha * eta_ij^beta` (roulette wheel, one uniform draw). If it has no allowed move:
//!
//! - [`DeadEnd::Backtrack`] (default): it steps back along its own path and tries again from there,
//!   keeping the tabu list, so the dead-end branch is never re-entered. The walk is then a
//!   randomised depth-first search, which reaches the goal whenever it is reachable, and the
//!   recorded path (the search stack) is a simple path without loops.
//! - [`DeadEnd::Die`]: the ant is discarded for this iteration, as in the paper.
//!
//! Bound: every cell is entered at most once and left backwards at most once, so a walk takes at
//! most `2 * cells` steps.
//!
//! The path is recorded as one direction byte per step, so a tour costs one byte per step whatever
//! the map size.

use crate::grid::{is_diagonal, opposite, Dir, Grid, Point};
use crate::heuristic::{octile_steps, Heuristic};
use crate::pheromone::Table;
use crate::rng::Xoshiro128pp;

/// What an ant does when every neighbour is blocked or already visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DeadEnd {
    /// Step back along its path and continue (never loses an ant while the goal is reachable).
    #[default]
    Backtrack,
    /// The paper's behaviour: the ant dies and contributes nothing this iteration.
    Die,
}

/// A finished walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Walk {
    /// Steps on the recorded path (the first `steps` bytes of the tour buffer).
    pub steps: usize,
    /// Straight steps on the path.
    pub straight: u32,
    /// Diagonal steps on the path.
    pub diagonal: u32,
    /// Moves made, counting forward steps and backtracking steps.
    pub moves: u32,
}

/// Everything an ant reads; borrowed for one iteration.
pub struct Colony<'g, 't, 'h> {
    /// The map.
    pub grid: &'g Grid<'g>,
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Pheromone, read only during construction.
    pub tau: &'t Table<'t>,
    /// `eta^beta` table.
    pub heuristic: &'h Heuristic,
    /// Pheromone exponent.
    pub alpha: f32,
    /// Dead-end behaviour.
    pub dead_end: DeadEnd,
}

/// `tau^alpha` with the common exponents done without `powf`.
#[inline]
fn pow_alpha(tau: f32, alpha: f32) -> f32 {
    if alpha == 1.0 {
        tau
    } else if alpha == 0.0 {
        1.0
    } else if alpha == 2.0 {
        tau * tau
    } else {
        libm::powf(tau, alpha)
    }
}

impl Colony<'_, '_, '_> {
    /// Walk one ant. `visited[i] == stamp` marks cell `i` as visited (the caller changes `stamp`
    /// between ants, so the buffer is never cleared); `tour` receives the directions.
    /// Returns `None` if the ant died (or, which cannot happen after the reachability check, the
    /// start ran out of moves).
    pub fn walk(
        &self,
        rng: &mut Xoshiro128pp,
        visited: &mut [u16],
        stamp: u16,
        tour: &mut [Dir],
    ) -> Option<Walk> {
        let grid = self.grid;
        let mut cur = self.start;
        let mut steps = 0usize;
        let mut moves = 0u32;
        *visited.get_mut(grid.index(cur))? = stamp;
        while cur != self.goal {
            let from = octile_steps(cur, self.goal);
            let mut cand_dir = [0u8; 8];
            let mut cand_w = [0.0f32; 8];
            let mut n = 0usize;
            let mut total = 0.0f32;
            for d in 0..8u8 {
                let Some(next) = grid.step(cur, d) else {
                    continue;
                };
                if visited.get(grid.index(next)).is_none_or(|&s| s == stamp) {
                    continue;
                }
                let w = pow_alpha(self.tau.get(cur, d), self.alpha)
                    * self.heuristic.weight(from, next, d);
                if let (Some(cd), Some(cw)) = (cand_dir.get_mut(n), cand_w.get_mut(n)) {
                    *cd = d;
                    *cw = w;
                    total += w;
                    n += 1;
                }
            }
            moves = moves.saturating_add(1);
            if n == 0 {
                match self.dead_end {
                    DeadEnd::Die => return None,
                    DeadEnd::Backtrack => {
                        steps = steps.checked_sub(1)?;
                        let back = opposite(*tour.get(steps)?);
                        cur = grid.step(cur, back)?;
                        continue;
                    }
                }
            }
            let pick = if n == 1 {
                0
            } else if total > 0.0 && total.is_finite() {
                let r = rng.next_unit() * total;
                let mut acc = 0.0f32;
                let mut pick = n - 1;
                for (i, w) in cand_w.iter().take(n).enumerate() {
                    acc += w;
                    if r < acc {
                        pick = i;
                        break;
                    }
                }
                pick
            } else {
                // Every weight underflowed to 0 (or overflowed): choose uniformly.
                ((u64::from(rng.next()) * n as u64) >> 32) as usize
            };
            let d = *cand_dir.get(pick)?;
            cur = grid.step(cur, d)?;
            *visited.get_mut(grid.index(cur))? = stamp;
            *tour.get_mut(steps)? = d;
            steps += 1;
        }
        let path = tour.get(..steps)?;
        let diagonal = path.iter().filter(|&&d| is_diagonal(d)).count() as u32;
        Some(Walk {
            steps,
            straight: steps as u32 - diagonal,
            diagonal,
            moves,
        })
    }
}

/// Straighten a finished walk in place: from each cell of the path, jump to the furthest later
/// path cell that is one allowed move away, dropping the detour in between. Returns the new walk.
///
/// This is not in the paper. A depth-first ant path is loop-free but can still bulge (go around
/// three sides of a square where one step would do). Cutting such bulges before the pheromone
/// update makes every ant deposit on a tighter path, which is what lets the colony settle on
/// near-optimal 8-connected paths within a few iterations (see `docs/ALGORITHM.md`). It costs at
/// most 8 lookups per path cell. `pts` and `pos` are scratch of at least `cells` entries.
pub fn tighten(grid: &Grid<'_>, start: Point, walk: Walk, tour: &mut [Dir], pts: &mut [Point], pos: &mut [u32]) -> Walk {
    let n = walk.steps + 1;
    let (Some(pts), Some(path)) = (pts.get_mut(..n), tour.get(..walk.steps)) else { return walk };
    // Lay the path out as cells and remember each cell's position on it.
    let mut p = start;
    for (i, slot) in pts.iter_mut().enumerate() {
        *slot = p;
        if let Some(q) = pos.get_mut(grid.index(p)) {
            *q = i as u32;
        }
        if let Some(&d) = path.get(i) {
            p = grid.step(p, d).unwrap_or(p);
        }
    }
    let mut i = 0usize;
    let mut out = 0usize;
    let (mut straight, mut diagonal) = (0u32, 0u32);
    while i + 1 < n {
        let Some(&cur) = pts.get(i) else { break };
        // Furthest later path cell one allowed move away (the next cell always qualifies).
        let mut best = (i, 0u8);
        for d in 0..8u8 {
            let Some(nb) = grid.step(cur, d) else { continue };
            let Some(&j) = pos.get(grid.index(nb)) else { continue };
            let j = j as usize;
            // `pos` is stale for cells of earlier walks: trust it only if it points back here.
            if j > best.0 && pts.get(j) == Some(&nb) {
                best = (j, d);
            }
        }
        let (j, d) = best;
        if j == i {
            // Cannot happen for a path made of allowed moves; stop rather than loop.
            break;
        }
        if let Some(slot) = tour.get_mut(out) {
            *slot = d;
        }
        out += 1;
        if is_diagonal(d) {
            diagonal += 1;
        } else {
            straight += 1;
        }
        i = j;
    }
    Walk { steps: out, straight, diagonal, moves: walk.moves }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        let w = rows[0].len();
        let mut b = vec![0u8; (w * rows.len()).div_ceil(8)];
        for (y, r) in rows.iter().enumerate() {
            for (x, c) in r.chars().enumerate() {
                if c == '#' {
                    let i = y * w + x;
                    b[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (b, w as u16, rows.len() as u16)
    }

    fn run(
        rows: &[&str],
        start: Point,
        goal: Point,
        dead_end: DeadEnd,
        seed: u64,
    ) -> Option<(Walk, Vec<u8>)> {
        let (b, w, h) = setup(rows);
        let g = Grid::new(w, h, &b).unwrap();
        let mut tau_buf = vec![[1.0f32; 4]; g.cells()];
        let tau = Table::new(w, &mut tau_buf);
        let heur = Heuristic::new(goal, true, 0.05, 1.0, 2.0);
        let c = Colony {
            grid: &g,
            start,
            goal,
            tau: &tau,
            heuristic: &heur,
            alpha: 1.0,
            dead_end,
        };
        let mut visited = vec![0u16; g.cells()];
        let mut tour = vec![0u8; g.cells()];
        let mut rng = Xoshiro128pp::from_u64(seed);
        c.walk(&mut rng, &mut visited, 1, &mut tour)
            .map(|w| (w, tour[..w.steps].to_vec()))
    }

    #[test]
    fn backtracking_escapes_a_trap() {
        // The greedy direction leads into a pocket; the ant must back out.
        let rows = [
            "......", //
            ".####.", //
            ".#..#.", //
            ".#..#.", //
            ".#....", //
        ];
        for seed in 0..50 {
            let (w, tour) = run(
                &rows,
                Point::new(2, 2),
                Point::new(0, 0),
                DeadEnd::Backtrack,
                seed,
            )
            .unwrap();
            // Replay the tour: it must end at the goal.
            let (b, wd, h) = setup(&rows);
            let g = Grid::new(wd, h, &b).unwrap();
            let mut p = Point::new(2, 2);
            for d in &tour {
                p = g.step(p, *d).unwrap();
            }
            assert_eq!(p, Point::new(0, 0));
            assert_eq!(w.straight + w.diagonal, tour.len() as u32);
        }
    }

    #[test]
    fn dying_ants_die_in_dead_ends() {
        // A corridor with a side pocket the attraction pulls into.
        let rows = [
            "#######", //
            "S.....G", //
            "###.###", //
            "###.###", //
        ];
        let mut died = 0;
        let mut reached = 0;
        for seed in 0..200 {
            match run(
                &rows,
                Point::new(0, 1),
                Point::new(6, 1),
                DeadEnd::Die,
                seed,
            ) {
                Some(_) => reached += 1,
                None => died += 1,
            }
        }
        assert!(reached > 0);
        // Backtracking never loses one.
        for seed in 0..200 {
            assert!(run(
                &rows,
                Point::new(0, 1),
                Point::new(6, 1),
                DeadEnd::Backtrack,
                seed
            )
            .is_some());
        }
        let _ = died;
    }
}
