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
//!    every weight the ants can need is one of 15 numbers (30 with the step length), computed
//!    once per plan ([`Heuristic`]) and looked up through a compile-time class table: no `powf`
//!    or `expf` in the inner loop, and bit-identical on every platform. The last form of the paper's
//!    eq. (10), `xi d(P,G) n_PG / d_ij`, is a vector and is not used.
//!
//! Plain ACA uses `eta_ij = 1 / d_ij` alone (eq. 5): 1 for a straight step, `1/sqrt 2` for a
//! diagonal one. That is the paper's "blind search".

use crate::geometry::SQRT_2;
use crate::grid::{Dir, Point, DX, DY};

/// Octile decomposition of the obstacle-free distance from `p` to `g`: `(straight, diagonal)`
/// step counts, so the distance is `straight + sqrt(2) * diagonal`.
#[inline]
pub fn octile_steps(p: Point, g: Point) -> (i32, i32) {
    let dx = i32::from(p.x.abs_diff(g.x));
    let dy = i32::from(p.y.abs_diff(g.y));
    let (hi, lo) = if dx >= dy { (dx, dy) } else { (dy, dx) };
    (hi.wrapping_sub(lo), lo) // hi >= lo
}

/// Octile distance from `p` to `g`.
#[inline]
pub fn octile(p: Point, g: Point) -> f32 {
    let (s, k) = octile_steps(p, g);
    s as f32 + k as f32 * SQRT_2
}

/// Number of cell classes: see [`Heuristic::key`].
const KEYS: usize = 3 * 3 * 7;

/// Size of the weight table: 15 octile changes x straight/diagonal, then zeros (the last entry
/// stands for classes that cannot occur). A power of two so lookups need no bounds check.
const WEIGHTS: usize = 32;

/// For every cell class and direction, which of the [`WEIGHTS`] applies. Computed at compile time.
///
/// The change of octile distance over move `d` depends on the cell's offset `(dx, dy)` from the
/// goal only through `sign(dx)`, `sign(dy)` and `|dx| - |dy|` clamped to `-3..=3` (one move
/// changes `|dx| - |dy|` by at most 2, so beyond 3 its sign cannot flip): 63 classes. Every class
/// occurs for some offset in `-5..=5`.
// Evaluated at compile time: an index out of range would fail the build, never panic at run time.
#[allow(clippy::indexing_slicing)]
static CLASS: [[u8; 8]; KEYS] = {
    let mut t = [[(WEIGHTS - 1) as u8; 8]; KEYS];
    let mut dy = -5i32;
    while dy <= 5 {
        let mut dx = -5i32;
        while dx <= 5 {
            let key = key_of(dx, dy);
            let (s0, k0) = octile_offset(dx, dy);
            let mut d = 0usize;
            while d < 8 {
                let (s1, k1) = octile_offset(dx + DX[d], dy + DY[d]);
                // ds in -2..=2, dk in -1..=1 (see the module docs), diagonal moves after straight.
                t[key][d] = (((s1 - s0 + 2) * 3 + (k1 - k0 + 1)) as usize + 15 * (d % 2)) as u8;
                d += 1;
            }
            dx += 1;
        }
        dy += 1;
    }
    t
};

/// Class of a goal offset (see [`CLASS`]). Offsets are differences of `u16` coordinates, so
/// nothing here can overflow: the `wrapping_` operations never wrap.
const fn key_of(dx: i32, dy: i32) -> usize {
    let sx = dx.signum().wrapping_add(1);
    let sy = dy.signum().wrapping_add(1);
    let diff = dx.abs().wrapping_sub(dy.abs());
    let diff = if diff < -3 {
        -3
    } else if diff > 3 {
        3
    } else {
        diff
    };
    // 0..63: sx, sy in 0..=2, diff in -3..=3.
    sx.wrapping_mul(3)
        .wrapping_add(sy)
        .wrapping_mul(7)
        .wrapping_add(diff)
        .wrapping_add(3) as usize
}

/// The precomputed `eta^beta` of one plan: 30 numbers (a 128-byte table), indexed through the
/// compile-time class table, so an ant computes its cell's class once per step and then reads
/// two bytes-and-a-float per candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct Heuristic {
    goal: Point,
    /// By octile change `(ds + 2) * 3 + (dk + 1)`, straight moves then diagonal moves, then 0;
    /// normalised so the largest entry is 1.
    weights: [f32; WEIGHTS],
}

/// The 8 candidate weights of one cell (see [`Heuristic::row`]).
#[derive(Clone, Copy, Debug)]
pub struct Row<'h> {
    class: &'static [u8; 8],
    weights: &'h [f32; WEIGHTS],
}

impl Row<'_> {
    /// `eta^beta` of the move in direction `d` (taken modulo 8).
    #[inline]
    pub fn get(&self, d: usize) -> f32 {
        // `& 7` and `& 31` keep both indices in range, so the compiler drops the bounds checks.
        let c = self.class.get(d & 7).copied().unwrap_or(0);
        self.weights
            .get(usize::from(c) & (WEIGHTS - 1))
            .copied()
            .unwrap_or(0.0)
    }
}

impl Heuristic {
    /// The weights for goal `goal`. With `attract = false` (plain ACA) only the step distance
    /// counts; otherwise the goal attraction `a^(xi * change of octile distance)` multiplies it.
    /// Everything is raised to `beta`. Inputs are assumed validated (`0 < a <= 1`, finite
    /// `xi >= 0`, `0 <= beta <= 16`).
    pub fn new(goal: Point, attract: bool, a: f32, xi: f32, beta: f32) -> Self {
        let diag_step = libm::powf(SQRT_2, -beta);
        let mut weights = [0.0f32; WEIGHTS];
        for (i, w) in weights.iter_mut().enumerate().take(30) {
            let change = ((i % 15) / 3) as f32 - 2.0 + ((i % 3) as f32 - 1.0) * SQRT_2;
            let att = if attract {
                libm::powf(a, xi * beta * change)
            } else {
                1.0
            };
            *w = att * if i >= 15 { diag_step } else { 1.0 };
        }
        // Normalise so weights never overflow when multiplied by pheromone; an infinite entry
        // (absurd parameters) becomes 1, the rest shrink accordingly (possibly to 0).
        let max = weights
            .iter()
            .filter(|w| w.is_finite())
            .fold(0.0f32, |m, &w| m.max(w));
        if max > 0.0 {
            for w in weights.iter_mut() {
                *w = if w.is_finite() { *w / max } else { 1.0 };
            }
        }
        Heuristic { goal, weights }
    }

    /// The goal this table attracts to.
    pub fn goal(&self) -> Point {
        self.goal
    }

    /// The class of cell `p` (its offset class relative to the goal).
    #[inline]
    pub fn key(&self, p: Point) -> usize {
        // Differences of u16 values: no i32 overflow.
        key_of(
            i32::from(p.x).wrapping_sub(i32::from(self.goal.x)),
            i32::from(p.y).wrapping_sub(i32::from(self.goal.y)),
        )
    }

    /// `eta^beta` of the 8 moves from cell `p`.
    #[inline]
    pub fn row(&self, p: Point) -> Row<'_> {
        const NONE: [u8; 8] = [(WEIGHTS - 1) as u8; 8];
        Row {
            class: CLASS.get(self.key(p)).unwrap_or(&NONE),
            weights: &self.weights,
        }
    }

    /// `eta^beta` of the 8 moves from cell `p` when the potential field pulls towards `target`
    /// instead of the goal (a sub-goal of [`crate::route`] on large maps).
    #[inline]
    pub fn row_toward(&self, p: Point, target: Point) -> Row<'_> {
        const NONE: [u8; 8] = [(WEIGHTS - 1) as u8; 8];
        // Differences of u16 values: no i32 overflow.
        let key = key_of(
            i32::from(p.x).wrapping_sub(i32::from(target.x)),
            i32::from(p.y).wrapping_sub(i32::from(target.y)),
        );
        Row {
            class: CLASS.get(key).unwrap_or(&NONE),
            weights: &self.weights,
        }
    }

    /// `eta^beta` for moving in direction `d` from `p`.
    #[inline]
    pub fn weight(&self, p: Point, d: Dir) -> f32 {
        self.row(p).get(usize::from(d & 7))
    }
}

/// Octile decomposition of an offset: `(straight, diagonal)` steps.
const fn octile_offset(dx: i32, dy: i32) -> (i32, i32) {
    // Offsets are small (compile time) or differences of u16 values: no wrap.
    let (ax, ay) = (dx.abs(), dy.abs());
    if ax >= ay {
        (ax.wrapping_sub(ay), ay)
    } else {
        (ay.wrapping_sub(ax), ax)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weight computed from scratch, as the module docs define it (before normalisation).
    fn direct(p: Point, g: Point, d: Dir, a: f32, xi: f32, beta: f32) -> f32 {
        let (ex, ey) = (DX[d as usize], DY[d as usize]);
        let q = (i32::from(p.x) + ex, i32::from(p.y) + ey);
        let d0 = octile(p, g);
        let dq = octile_offset(q.0 - i32::from(g.x), q.1 - i32::from(g.y));
        let d1 = dq.0 as f32 + dq.1 as f32 * SQRT_2;
        let step = if d % 2 == 1 { SQRT_2 } else { 1.0 };
        libm::powf(a, xi * beta * (d1 - d0)) * libm::powf(1.0 / step, beta)
    }

    #[test]
    fn octile_matches_definition() {
        assert_eq!(octile_steps(Point::new(0, 0), Point::new(5, 2)), (3, 2));
        assert!((octile(Point::new(0, 0), Point::new(3, 3)) - 3.0 * SQRT_2).abs() < 1e-6);
    }

    #[test]
    fn table_matches_direct_computation_everywhere() {
        let g = Point::new(20, 20);
        let h = Heuristic::new(g, true, 0.3, 1.0, 2.0);
        // Normalisation constant: ratio of any entry to its direct value.
        let scale =
            h.weight(Point::new(25, 21), 4) / direct(Point::new(25, 21), g, 4, 0.3, 1.0, 2.0);
        for y in 1..40u16 {
            for x in 1..40u16 {
                let p = Point::new(x, y);
                for d in 0..8u8 {
                    let want = direct(p, g, d, 0.3, 1.0, 2.0) * scale;
                    let got = h.weight(p, d);
                    assert!(
                        (got / want - 1.0).abs() < 1e-4,
                        "{p:?} d{d}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn attraction_prefers_moves_towards_the_goal() {
        let g = Point::new(10, 0);
        let h = Heuristic::new(g, true, 0.05, 1.0, 2.0);
        let at = Point::new(5, 0);
        let east = h.weight(at, 0);
        let west = h.weight(at, 4);
        let south = h.weight(at, 2);
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
        let p = Point::new(5, 5);
        assert_eq!(h.weight(p, 0), 1.0);
        assert_eq!(h.weight(p, 4), 1.0);
        assert!((h.weight(p, 1) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn extreme_parameters_stay_finite() {
        let h = Heuristic::new(Point::new(3, 3), true, 1e-30, 1e6, 16.0);
        for w in h.weights.iter() {
            assert!(w.is_finite() && *w >= 0.0 && *w <= 1.0);
        }
    }
}
