//! The core's heap storage ([`ohaca::heap::HeapStorage`]) as the tests use it: a curve of
//! [`DEFAULT_CURVE`] entries, and an allocation failure is a test failure.

pub use ohaca::heap::HeapStorage;

/// Convergence-curve entries [`storage`] allocates (enough for the default 100 iterations and
/// everything the tests run).
pub const DEFAULT_CURVE: usize = 1024;

/// Storage for maps of up to `cells` cells and a curve of [`DEFAULT_CURVE`] iterations.
pub fn storage(cells: usize) -> HeapStorage {
    with_curve(cells, DEFAULT_CURVE)
}

/// Storage for maps of up to `cells` cells and a curve of `curve` iterations.
pub fn with_curve(cells: usize, curve: usize) -> HeapStorage {
    HeapStorage::new(cells, curve).unwrap_or_else(|e| panic!("{e}"))
}

/// Storage whose buffers hold arbitrary junk derived from `salt` ([`HeapStorage::scramble`]), to
/// check that a plan does not depend on what the workspace held before.
pub fn dirty(cells: usize, salt: u32) -> HeapStorage {
    let mut s = storage(cells);
    s.scramble(salt);
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capacity_is_cells() {
        let mut s = storage(37);
        assert_eq!(s.cells(), 37);
        assert_eq!(s.workspace().capacity(), 37);
        assert_eq!(with_curve(3, 7).curve_len(), 7);
        let mut d = dirty(5, 3);
        assert_eq!(d.workspace().capacity(), 5);
    }
}
