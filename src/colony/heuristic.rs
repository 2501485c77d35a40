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
//!    or `expf` in the inner loop, and bit-identical on every platform. The table is scaled by a
//!    weight some move can have (`USED`: 9 of the 30), not by the 15 changes' extremes, which
//!    no single move reaches, so large `beta` does not push the moves away from the goal to 0.
//!    The last form of the paper's
//!    eq. (10), `xi d(P,G) n_PG / d_ij`, is a vector and is not used.
//!
//! Plain ACA uses `eta_ij = 1 / d_ij` alone (eq. 5): 1 for a straight step, `1/sqrt 2` for a
//! diagonal one. That is the paper's "blind search".

use crate::geometry::SQRT_2;
use crate::map::grid::{Dir, Point, DX, DY};

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
static CLASS: [[u8; 8]; KEYS] = CLASS_TABLE;

/// [`CLASS`] as a constant, so [`USED`] can be computed from it at compile time.
#[allow(clippy::indexing_slicing)]
const CLASS_TABLE: [[u8; 8]; KEYS] = {
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

/// Which of the [`WEIGHTS`] some move of some cell class uses. The others stand for octile
/// changes that no single move can make (e.g. `-2 - sqrt 2`: one move changes the octile distance
/// by at most `sqrt 2`), so they must not set the scale of the table. Computed at compile time.
// Evaluated at compile time: an index out of range would fail the build, never panic at run time.
#[allow(clippy::indexing_slicing)]
static USED: [bool; WEIGHTS] = {
    let mut u = [false; WEIGHTS];
    let mut k = 0usize;
    while k < KEYS {
        let mut d = 0usize;
        while d < 8 {
            let i = CLASS_TABLE[k][d] as usize;
            // The last entry is the zero of impossible classes, never a real move's weight.
            if i < WEIGHTS - 1 {
                u[i] = true;
            }
            d += 1;
        }
        k += 1;
    }
    u
};

/// Natural log of `sqrt 2`.
const LN_SQRT_2: f32 = 0.5 * core::f32::consts::LN_2;

/// How far below the largest weight the smallest may lie (natural log): `e^-80` is about
/// `1.8e-35`, above `f32::MIN_POSITIVE` (`1.2e-38`) with room for a pheromone factor of 0.01.
const LOG_SPAN: f32 = 80.0;

/// [`key_of`] of the offset `p - g`. On x86-64 from the coordinates themselves: each sign from
/// two comparisons, each magnitude an absolute difference (fewer instructions a step there than
/// the signed offset's `signum` and `abs`; on the M4 it is the other way round, so the device
/// keeps [`key_of`]). The same class for every pair either way, pinned by a test.
#[inline]
fn key_between(p: Point, g: Point) -> usize {
    if cfg!(target_arch = "arm") {
        // Differences of u16 values: no i32 overflow.
        return key_of(
            i32::from(p.x).wrapping_sub(i32::from(g.x)),
            i32::from(p.y).wrapping_sub(i32::from(g.y)),
        );
    }
    // 0, 1, 2 for p left of, level with, right of g: `signum(p.x - g.x) + 1`.
    // At most 2 each; the difference of two u16 values fits an i32: nothing wraps.
    let sx = usize::from(p.x > g.x).wrapping_add(usize::from(p.x >= g.x));
    let sy = usize::from(p.y > g.y).wrapping_add(usize::from(p.y >= g.y));
    let diff = i32::from(p.x.abs_diff(g.x)).wrapping_sub(i32::from(p.y.abs_diff(g.y)));
    // In 0..=6: the difference clamped to -3..=3, plus 3 (`max`/`min`, not `clamp`, which
    // keeps a panic path).
    #[allow(clippy::manual_clamp)]
    let d = diff.max(-3).min(3).wrapping_add(3) as usize;
    // Below 63: sx, sy <= 2, d <= 6.
    sx.wrapping_mul(21)
        .wrapping_add(sy.wrapping_mul(7))
        .wrapping_add(d)
}

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
    /// scaled so the largest entry a move can use is 1, unless that would push the smallest
    /// below `e^-LOG_SPAN` (see [`Heuristic::new`]). Entries no move uses are 0.
    weights: [f32; WEIGHTS],
}

/// The goal attraction of the potential field (paper eqs. 6-10): a move is weighted by
/// `a^(xi * change of octile distance)`. Absent for plain ACA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attraction {
    /// Attraction base `a`, in `(0, 1]` (paper: 0.05); smaller pulls harder.
    pub a: f32,
    /// Potential-field gain `xi`, finite and `>= 0` (paper: 1).
    pub xi: f32,
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
    /// The weights for goal `goal`. Without an [`Attraction`] (plain ACA) only the step distance
    /// counts; with one, `a^(xi * change of octile distance)` multiplies it. Everything is raised
    /// to `beta`. Inputs are assumed validated (`0 < a <= 1`, finite `xi >= 0`,
    /// `0 <= beta <= 16`).
    pub fn new(goal: Point, attraction: Option<Attraction>, beta: f32) -> Self {
        // Every weight as a natural log: beta * (xi * change * ln a - ln step). Computed in logs
        // so no intermediate over- or underflows before the table is scaled.
        let (ln_a, xi) = match attraction {
            Some(Attraction { a, xi }) => (libm::logf(a), xi),
            None => (0.0, 0.0),
        };
        let mut logs = [0.0f32; WEIGHTS];
        for (i, l) in logs.iter_mut().enumerate().take(30) {
            let change = ((i % 15) / 3) as f32 - 2.0 + ((i % 3) as f32 - 1.0) * SQRT_2;
            let ln_step = if i >= 15 { LN_SQRT_2 } else { 0.0 };
            // `beta == 0` means "no heuristic", whatever the product inside would be.
            // Capped so that differences of logs stay finite (absurd parameters only).
            *l = if beta == 0.0 {
                0.0
            } else {
                let l = beta * (xi * (change * ln_a) - ln_step);
                // Comparisons, not `f32::clamp` (which keeps a panic path in the firmware).
                #[allow(clippy::manual_clamp)]
                let capped = if l > 1e30 {
                    1e30
                } else if l < -1e30 {
                    -1e30
                } else {
                    l
                };
                capped
            };
        }
        // Scale by a weight some move can have (see [`USED`]): the largest one becomes 1, so a
        // weight times pheromone cannot overflow; unless the weights spread over more than
        // `LOG_SPAN`, then the smallest becomes `e^-LOG_SPAN`, so every move that exists keeps a
        // weight > 0 (the largest then exceed 1, and are capped at `f32::MAX`).
        let used = || {
            logs.iter()
                .zip(USED.iter())
                .filter(|(_, u)| **u)
                .map(|(l, _)| *l)
        };
        let hi = used().fold(f32::NEG_INFINITY, f32::max);
        let lo = used().fold(f32::INFINITY, f32::min);
        let offset = if hi - lo > LOG_SPAN {
            lo + LOG_SPAN
        } else {
            hi
        };
        let mut weights = [0.0f32; WEIGHTS];
        for ((w, l), u) in weights.iter_mut().zip(logs.iter()).zip(USED.iter()) {
            if *u {
                let v = libm::expf(*l - offset);
                *w = if v.is_finite() { v } else { f32::MAX };
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
        key_between(p, self.goal)
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
    /// instead of the goal (a sub-goal of [`crate::colony::route`] on large maps).
    #[inline]
    pub fn row_toward(&self, p: Point, target: Point) -> Row<'_> {
        const NONE: [u8; 8] = [(WEIGHTS - 1) as u8; 8];
        let key = key_between(p, target);
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

    fn attract(a: f32, xi: f32) -> Option<Attraction> {
        Some(Attraction { a, xi })
    }

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
        let h = Heuristic::new(g, attract(0.3, 1.0), 2.0);
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
        let h = Heuristic::new(g, attract(0.05, 1.0), 2.0);
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
        let h = Heuristic::new(g, None, 2.0);
        let p = Point::new(5, 5);
        assert_eq!(h.weight(p, 0), 1.0);
        assert_eq!(h.weight(p, 4), 1.0);
        assert!((h.weight(p, 1) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn extreme_parameters_stay_finite() {
        let h = Heuristic::new(Point::new(3, 3), attract(1e-30, 1e6), 16.0);
        for w in h.weights.iter() {
            assert!(w.is_finite() && *w >= 0.0, "{w}");
        }
    }

    /// Every weight a move from some cell can use, over offsets that cover every class.
    fn move_weights(h: &Heuristic) -> Vec<(Point, u8, f32)> {
        let g = h.goal();
        let mut out = Vec::new();
        for y in g.y - 6..=g.y + 6 {
            for x in g.x - 6..=g.x + 6 {
                for d in 0..8u8 {
                    let p = Point::new(x, y);
                    out.push((p, d, h.weight(p, d)));
                }
            }
        }
        out
    }

    #[test]
    fn the_class_from_coordinates_is_the_class_of_the_offset() {
        // Every offset within 9 cells and far ones, from goals at the map's corners, edges and
        // middle (coordinates up to u16::MAX: the offsets' whole range).
        let goals = [
            (0u16, 0u16),
            (5, 7),
            (9, 0),
            (u16::MAX, u16::MAX),
            (40_000, 3),
        ];
        let far = [0i32, 1, 2, 3, 4, 5, 9, 100, 30_000, 65_535];
        for (gx, gy) in goals {
            let g = Point::new(gx, gy);
            let mut offsets: Vec<i32> = (-9..=9).collect();
            offsets.extend(far.iter().flat_map(|&f| [f, -f]));
            for &dx in &offsets {
                for &dy in &offsets {
                    let (x, y) = (i32::from(gx) + dx, i32::from(gy) + dy);
                    if !(0..=65_535).contains(&x) || !(0..=65_535).contains(&y) {
                        continue;
                    }
                    let p = Point::new(x as u16, y as u16);
                    assert_eq!(key_between(p, g), key_of(dx, dy), "{p:?} from {g:?}");
                }
            }
        }
    }

    #[test]
    fn the_scale_is_a_move_that_exists() {
        // The paper's a, xi, beta: the best move any cell can make weighs exactly 1.
        let h = Heuristic::new(Point::new(20, 20), attract(0.05, 1.0), 2.0);
        let max = move_weights(&h).iter().map(|w| w.2).fold(0.0f32, f32::max);
        assert_eq!(max, 1.0);
        // Entries no move uses are 0 (they are never read).
        for (i, w) in h.weights.iter().enumerate() {
            assert_eq!(USED[i], *w > 0.0, "entry {i}: {w}");
        }
        // Of the 15 octile changes x 2 step kinds, a straight step changes the distance by +-1
        // or +-(sqrt 2 - 1), a diagonal one by 0, +-sqrt 2 or +-(2 - sqrt 2): 9 in all.
        assert_eq!(USED.iter().filter(|u| **u).count(), 9);
    }

    #[test]
    fn large_beta_keeps_every_move_that_exists() {
        // beta = 16 with the paper's a: a diagonal step towards the goal and one away from it
        // differ by 0.05^(-16 * 2 sqrt 2), about 1e59, more than f32 can hold between 1 and 0.
        let goal = Point::new(20, 20);
        for (a, xi) in [(0.05, 1.0), (0.3, 1.0), (0.05, 0.5)] {
            let h = Heuristic::new(goal, attract(a, xi), 16.0);
            let ws = move_weights(&h);
            for &(p, d, w) in &ws {
                assert!(w > 0.0 && w.is_finite(), "a {a}: {p:?} d{d}: {w}");
            }
            // The ratios are still the definition's (in logs: direct() would underflow).
            let ln = |p: Point, d: u8| {
                let (ex, ey) = (DX[d as usize], DY[d as usize]);
                let q = (i32::from(p.x) + ex, i32::from(p.y) + ey);
                let d0 = f64::from(octile(p, goal));
                let dq = octile_offset(q.0 - i32::from(goal.x), q.1 - i32::from(goal.y));
                let d1 = f64::from(dq.0) + f64::from(dq.1) * std::f64::consts::SQRT_2;
                let step = if d % 2 == 1 { 0.5f64.ln() / 2.0 } else { 0.0 };
                16.0 * (f64::from(xi) * (d1 - d0) * f64::from(a).ln() + step)
            };
            let (p0, d0, w0) = ws[0];
            for &(p, d, w) in &ws {
                let want = ln(p, d) - ln(p0, d0);
                let got = f64::from(w).ln() - f64::from(w0).ln();
                assert!(
                    (got - want).abs() < 1e-3 * want.abs().max(1.0),
                    "{p:?} d{d}"
                );
            }
        }
    }
}
