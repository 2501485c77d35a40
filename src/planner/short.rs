//! [`Shortfalls`]: the steps of a run that had less scratch than they ask for, counted in the
//! result rather than passed over in silence.
//!
//! Every buffer a phase borrows is lent by a rule on the buffers' lengths (`planner::lend`),
//! and a layout from [`super::arena::carve`] or a [`super::Storage`] sized by the board holds
//! them all, so a plan on the device has no shortfall. A workspace a caller lays out by hand may
//! be shorter: the plan is then still a valid path, but a step ran in a cheaper form or not at
//! all, and [`super::Plan::shortfalls`] says which. The firmware logs it; the host's `plan`
//! prints it.

use core::fmt;

/// A set of steps that ran short of scratch (empty: none did).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Shortfalls(u8);

impl Shortfalls {
    /// No step ran short.
    pub const NONE: Self = Self(0);
    /// No room for the coarse route: the ants were pulled at the goal alone.
    pub const ROUTE: Self = Self(1);
    /// No room to stash the route's links: the next warm start builds the route again.
    pub const STASH: Self = Self(1 << 1);
    /// No scratch for the local search: the colony's path was not refined.
    pub const REFINE: Self = Self(1 << 2);
    /// Too few links for the shortest-path smoothing: the greedy rule smoothed the path.
    pub const SMOOTHING: Self = Self(1 << 3);
    /// Too little scratch for the small maps' exact corridor search: the smoothed path stands.
    pub const CORRIDOR: Self = Self(1 << 4);
    /// Too few links (and path cells' words) for tightening's index: some ants' walks were not
    /// tightened.
    pub const TIGHTEN: Self = Self(1 << 5);

    const NAMES: [(Self, &'static str); 6] = [
        (Self::ROUTE, "route"),
        (Self::STASH, "stash"),
        (Self::REFINE, "refine"),
        (Self::SMOOTHING, "smoothing"),
        (Self::CORRIDOR, "corridor"),
        (Self::TIGHTEN, "tightening"),
    ];

    /// Whether no step ran short.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every step of `other` is in the set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Add the steps of `other`.
    pub fn insert(&mut self, other: Self) {
        self.0 |= other.0;
    }

    /// The set as a byte (bit 0 the route, 1 the stash, 2 the local search, 3 the smoothing, 4
    /// the corridor search, 5 tightening).
    pub const fn bits(self) -> u8 {
        self.0
    }
}

impl fmt::Display for Shortfalls {
    /// `none`, or the steps' names separated by commas (`route, smoothing`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        let mut first = true;
        for (step, name) in Self::NAMES {
            if self.contains(step) {
                if !first {
                    f.write_str(", ")?;
                }
                f.write_str(name)?;
                first = false;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    #[test]
    fn a_set_names_its_steps() {
        let mut s = Shortfalls::NONE;
        assert_eq!(s.to_string(), "none");
        s.insert(Shortfalls::SMOOTHING);
        s.insert(Shortfalls::ROUTE);
        assert!(s.contains(Shortfalls::ROUTE) && !s.contains(Shortfalls::STASH));
        assert_eq!(
            (s.to_string(), s.bits()),
            ("route, smoothing".to_string(), 0b1001)
        );
    }
}
