//! The step costs of the crate's integer searches, in one place: what a straight and a diagonal
//! step cost, and the octile distance in the same units.
//!
//! **What it owns.** Two scales ([`Scale`]):
//!
//! - [`EXACT`], the cell searches' ([`super::astar`], the refine window's A*, the host's
//!   D* Lite): a straight step costs [`STRAIGHT`] = 33,461 units and a diagonal [`DIAGONAL`] =
//!   47,321. `DIAGONAL / STRAIGHT` is a convergent of `sqrt 2` with `DIAGONAL^2 - 2 STRAIGHT^2 =
//!   -1` (a Pell solution). Every cost compared (`g`, and `f = g + h` with `h` the octile
//!   distance, consistent for these costs) is `A STRAIGHT + B DIAGONAL` for non-negative integers
//!   `A`, `B`; while `A + B <= `[`EXACT_STEPS`], two such integers compare exactly as the real
//!   lengths `A + B sqrt 2` do, equality included. Proof: with `x = dA + dB sqrt 2 != 0` and
//!   `y = dA - dB sqrt 2`, `x y = dA^2 - 2 dB^2` is a non-zero integer, so `|x| >= 1 / |y| >=
//!   1 / (N (1 + sqrt 2))` for `|dA|, |dB| <= N`; the integer difference is `STRAIGHT x + dB
//!   (DIAGONAL - STRAIGHT sqrt 2)` and `|DIAGONAL - STRAIGHT sqrt 2| = 1 / (DIAGONAL + STRAIGHT
//!   sqrt 2)`, so the sign survives while `N^2 < STRAIGHT (DIAGONAL + STRAIGHT sqrt 2) / (1 +
//!   sqrt 2)`, i.e. `N < 36218` (the unit test `exact_costs_order_as_lengths` checks it for every
//!   `dB` exhaustively). A search on this scale is therefore exact in the reals, not only up to a
//!   float's rounding. (The refine window searched on `13860 / 19601` before, exact only while
//!   the diagonal counts differed by less than about 9,800; both scales order every window's
//!   costs the same way, so its paths did not change, bit for bit.)
//! - [`BLOCKS`], the coarse route's (`colony::route`): 10 a straight block step, 14 a diagonal
//!   one. A block is `2^shift` cells a side, so a block route is coarse whatever its costs; the
//!   route keeps its key (`g + h`) in the 19 bits left of each block's word, where the exact
//!   scale would hold 15 block steps; and `14 / 10` orders block routes differently from
//!   `sqrt 2` (a route of 5 diagonals ties 7 straight steps), so moving it to [`EXACT`] would
//!   change the route, hence the paths.
//!
//! Every direction test is [`is_diagonal`]. (The colony's float lengths, `steps_length` and the
//! heuristic's `SQRT_2`, are lengths, not search costs, and stay with the geometry.)
//!
//! **Guarantees.** Constant functions, no panic: the octile distance wraps only beyond what a map
//! of `u16` sides reaches (`65,535 * DIAGONAL < 2^32`).

use crate::map::dir::{is_diagonal, Dir};

/// A pair of step costs and the octile distance they make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scale {
    /// Cost of a straight step.
    pub straight: u32,
    /// Cost of a diagonal step.
    pub diagonal: u32,
}

impl Scale {
    /// The cost of a step in direction `d`.
    #[inline(always)]
    pub const fn step(&self, d: Dir) -> u32 {
        if is_diagonal(d) {
            self.diagonal
        } else {
            self.straight
        }
    }

    /// The octile distance of an offset of `dx` by `dy` steps: `max - min` straight steps and
    /// `min` diagonal ones, worked out as `max * straight + min * (diagonal - straight)` (two
    /// multiplications; wrapping: exact for offsets below 2^16 on [`EXACT`]).
    #[inline(always)]
    pub const fn octile(&self, dx: u32, dy: u32) -> u32 {
        let (hi, lo) = if dx < dy { (dy, dx) } else { (dx, dy) };
        hi.wrapping_mul(self.straight)
            .wrapping_add(lo.wrapping_mul(self.diagonal.wrapping_sub(self.straight)))
    }
}

/// Cost units of a straight step on the exact scale.
pub const STRAIGHT: u32 = 33_461;
/// Cost units of a diagonal step on the exact scale: `DIAGONAL^2 - 2 STRAIGHT^2 = -1`.
pub const DIAGONAL: u32 = 47_321;
/// The exact scale of the cell searches (module docs).
pub const EXACT: Scale = Scale {
    straight: STRAIGHT,
    diagonal: DIAGONAL,
};
/// Step counts up to which [`EXACT`] costs compare exactly as lengths (module docs; the bound
/// is `N < 36218`, kept round).
pub const EXACT_STEPS: u32 = 36_000;

/// The coarse route's block steps (module docs: why not [`EXACT`]).
pub const BLOCKS: Scale = Scale {
    straight: 10,
    diagonal: 14,
};

/// The cost of a step in direction `d` on the exact scale.
#[inline(always)]
pub const fn step(d: Dir) -> u32 {
    EXACT.step(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pair of costs `A STRAIGHT + B DIAGONAL` with `A, B <= EXACT_STEPS` compares as
    /// `A + B sqrt 2` does. The fixed-point difference `dA STRAIGHT + dB DIAGONAL` grows with
    /// `dA`, so for each `dB` it suffices that it is negative at the largest `dA` with
    /// `dA + dB sqrt 2 < 0` and positive at the next (within `|dA| <= EXACT_STEPS`); `sqrt 2` is
    /// irrational, so no real difference is 0 unless both are. (At `dB = STRAIGHT`, beyond the
    /// bound, `dA = -DIAGONAL` would give a false tie.)
    #[test]
    fn exact_costs_order_as_lengths() {
        let (s, d, n) = (
            i64::from(STRAIGHT),
            i64::from(DIAGONAL),
            i64::from(EXACT_STEPS),
        );
        assert_eq!(d * d - 2 * s * s, -1);
        for db in 1..=n {
            // k < db sqrt 2 < k + 1.
            let two = 2 * db * db;
            let mut k = (two as f64).sqrt() as i64;
            while k * k > two {
                k -= 1;
            }
            while (k + 1) * (k + 1) <= two {
                k += 1;
            }
            assert_ne!(k * k, two);
            // dA = -(k + 1): real negative; dA = -k: real positive (and -dB mirrors both). Only
            // |dA| <= N occurs: below -N, the smallest dA that does.
            if k < n {
                assert!(-(k + 1) * s + db * d < 0, "dB {db}");
            }
            assert!(-k.min(n) * s + db * d > 0, "dB {db}");
        }
    }

    #[test]
    fn steps_and_octile() {
        for d in 0..8u8 {
            let want = if d % 2 == 1 { DIAGONAL } else { STRAIGHT };
            assert_eq!(step(d), want);
            assert_eq!(BLOCKS.step(d), if d % 2 == 1 { 14 } else { 10 });
        }
        assert_eq!(EXACT.octile(5, 3), 2 * STRAIGHT + 3 * DIAGONAL);
        assert_eq!(EXACT.octile(3, 5), 2 * STRAIGHT + 3 * DIAGONAL);
        assert_eq!(BLOCKS.octile(7, 2), 5 * 10 + 2 * 14);
        assert_eq!(EXACT.octile(65_535, 65_535), 65_535 * DIAGONAL);
    }
}
