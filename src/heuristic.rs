//! Heuristic information `eta`: the step distance of plain ACA and the goal attraction of the
//! artificial potential field (paper eqs. 6-10).
//!
//! The paper builds `eta_ij = a^F_att / d_ij` with `F_att = xi * d(P, G)` and `0 < a < 1`, so a
//! move towards the goal is preferred. The transition rule raises it to `beta`. Three readings we
//! chose, and why (also in `docs/ALGORITHM.md`):
//!
//! 1. **`P` is the candidate cell `j`.** The attraction must differ between the candidates of one
//!    step or it cancels out of the probability (eq. 5 normalises over the candidates).
//! 2. **Only the change of potential matters.** `a^(xi d)` underflows `f32` as soon as
//!    `xi * d * ln(1/a) > 87` (the goal 30 cells away with `a = 0.05`), which would make every
//!    candidate weigh 0. Multiplying all candidates by the same `a^(-xi d(i, G))` leaves the
//!    probabilities unchanged, so we use `a^(xi (d(j, G) - d(i, G)))`, which stays near 1.
//! 3. **`d(P, G)` is the octile distance**, the length of the shortest obstacle-free
//!    8-connected path and so the same metric as the objective (eqs. 1-2). Its change over one
//!    move is `ds + sqrt(2) dk` with small integers `ds` in `-2..=2` and `dk` in `-1..=1`, so
//!    every weight the ants can need is one of 15 numbers, computed once per plan: no `powf` or
//!    `expf` in the inner loop, and bit-identical on every platform. The last form of the paper's
//!    eq. (10), `xi d(P,G) n_PG / d_ij`, is a vector and is not used.
//!
//! Plain ACA uses `eta_ij = 1 / d_ij` alone (eq. 5): 1 for a straight step, `1/sqrt 2` for a
//! diagonal one. That is the paper's "blind search".

use crate::geometry::SQRT_2;
use crate::grid::{is_diagonal, Dir, Point};

/// Octile decomposition of the obstacle-free distance from `p` to `g`: `(straight, diagonal)`
/// step counts, so the distance is `straight + sqrt(2) * diagonal`.
#[inline]
pub fn octile_steps(p: Point, g: Point) -> (i32, i32) {
    let dx = (i32::from(p.x) - i32::from(g.x)).abs();
    let dy = (i32::from(p.y) - i32::from(g.y)).abs();
    let (hi, lo) = if dx >= dy { (dx, dy) } else { (dy, dx) };
    (hi - lo, lo)
}

/// Octile distance from `p` to `g`.
#[inline]
pub fn octile(p: Point, g: Point) -> f32 {
    let (s, k) = octile_steps(p, g);
    s as f32 + k as f32 * SQRT_2
}

/// The precomputed `eta^beta` table of one plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Heuristic {
    goal: Point,
    /// `[straight | diagonal][(ds + 2) * 3 + (dk + 1)]`, normalised so the largest entry is 1.
    table: [[f32; 15]; 2],
}

impl Heuristic {
    /// The table for goal `goal`. With `attract = false` (plain ACA) only the step distance
    /// counts; otherwise the goal attraction `a^(xi * change of octile distance)` multiplies it.
    /// Everything is raised to `beta`. Inputs are assumed validated (`0 < a <= 1`, finite
    /// `xi >= 0`, `0 <= beta <= 16`).
    pub fn new(goal: Point, attract: bool, a: f32, xi: f32, beta: f32) -> Self {
        let mut table = [[0.0f32; 15]; 2];
        let diag_step = libm::powf(SQRT_2, -beta);
        let mut max = 0.0f32;
        for (kind, row) in table.iter_mut().enumerate() {
            let step = if kind == 1 { diag_step } else { 1.0 };
            for (i, w) in row.iter_mut().enumerate() {
                let ds = (i / 3) as f32 - 2.0;
                let dk = (i % 3) as f32 - 1.0;
                let att = if attract {
                    libm::powf(a, xi * beta * (ds + dk * SQRT_2))
                } else {
                    1.0
                };
                *w = step * att;
                if w.is_finite() && *w > max {
                    max = *w;
                }
            }
        }
        // Normalise so weights never overflow when multiplied by pheromone; an infinite entry
        // (absurd parameters) becomes 1, the rest shrink accordingly (possibly to 0).
        if max > 0.0 {
            for w in table.iter_mut().flatten() {
                *w = if w.is_finite() { *w / max } else { 1.0 };
            }
        }
        Heuristic { goal, table }
    }

    /// The goal this table attracts to.
    pub fn goal(&self) -> Point {
        self.goal
    }

    /// `eta^beta` for moving in direction `d` from a cell whose octile steps to the goal are
    /// `from` to the cell `to`.
    #[inline]
    pub fn weight(&self, from: (i32, i32), to: Point, d: Dir) -> f32 {
        let (s, k) = octile_steps(to, self.goal);
        let ds = (s - from.0).clamp(-2, 2);
        let dk = (k - from.1).clamp(-1, 1);
        let idx = ((ds + 2) * 3 + (dk + 1)) as usize;
        let kind = usize::from(is_diagonal(d));
        self.table
            .get(kind)
            .and_then(|r| r.get(idx))
            .copied()
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octile_matches_definition() {
        assert_eq!(octile_steps(Point::new(0, 0), Point::new(5, 2)), (3, 2));
        assert!((octile(Point::new(0, 0), Point::new(3, 3)) - 3.0 * SQRT_2).abs() < 1e-6);
    }

    #[test]
    fn attraction_prefers_moves_towards_the_goal() {
        let g = Point::new(10, 0);
        let h = Heuristic::new(g, true, 0.05, 1.0, 2.0);
        let at = Point::new(5, 0);
        let from = octile_steps(at, g);
        let east = h.weight(from, Point::new(6, 0), 0);
        let west = h.weight(from, Point::new(4, 0), 4);
        let south = h.weight(from, Point::new(5, 1), 2);
        assert!(east > south && south > west, "{east} {south} {west}");
        // Ratio of one step closer vs one step away is a^(-2 xi beta) = 0.05^-4.
        let ratio = east / west;
        assert!(
            (ratio / libm::powf(0.05, -4.0) - 1.0).abs() < 1e-3,
            "{ratio}"
        );
    }

    #[test]
    fn plain_aca_prefers_straight_steps_only() {
        let g = Point::new(10, 10);
        let h = Heuristic::new(g, false, 0.05, 1.0, 2.0);
        let from = octile_steps(Point::new(5, 5), g);
        assert_eq!(h.weight(from, Point::new(6, 5), 0), 1.0);
        assert_eq!(h.weight(from, Point::new(4, 5), 4), 1.0);
        assert!((h.weight(from, Point::new(6, 6), 1) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn extreme_parameters_stay_finite() {
        let h = Heuristic::new(Point::new(3, 3), true, 1e-30, 1e6, 16.0);
        for w in h.table.iter().flatten() {
            assert!(w.is_finite() && *w >= 0.0 && *w <= 1.0);
        }
    }
}
