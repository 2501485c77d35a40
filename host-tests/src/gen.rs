//! Random maps and start/goal pairs for proptest.
//!
//! Two map families, so that both scattered obstacles and long walls with dead ends and pockets
//! get exercised:
//!
//! - [`noise_map`]: every cell blocked independently with a random density;
//! - [`walls_map`]: random horizontal and vertical wall segments plus a little noise.
//!
//! [`case`] picks one of them and a start and goal cell, which it clears (so the endpoints are
//! valid; the error paths for bad endpoints are tested separately). Everything shrinks towards
//! small, empty maps.

use ohaca::Point;
use proptest::collection::vec;
use proptest::prelude::*;

use crate::maps::Map;

/// Maps of `1..=max_w` x `1..=max_h` cells, each blocked with a probability drawn from
/// `0..max_density`.
pub fn noise_map(max_w: u16, max_h: u16, max_density: f64) -> impl Strategy<Value = Map> {
    (1..=max_w, 1..=max_h, 0.0..max_density).prop_flat_map(|(w, h, d)| {
        vec(prop::bool::weighted(d), usize::from(w) * usize::from(h))
            .prop_map(move |cells| Map::new(w, h, cells))
    })
}

/// Maps of `2..=max_w` x `2..=max_h` cells with up to 8 straight walls and light noise.
pub fn walls_map(max_w: u16, max_h: u16) -> impl Strategy<Value = Map> {
    (2..=max_w, 2..=max_h).prop_flat_map(|(w, h)| {
        let wall = (0..w, 0..h, 1..=w.max(h), any::<bool>());
        (
            vec(wall, 0..8),
            vec(prop::bool::weighted(0.08), usize::from(w) * usize::from(h)),
        )
            .prop_map(move |(walls, noise)| {
                let mut m = Map::new(w, h, noise);
                for (x, y, len, horizontal) in walls {
                    for k in 0..len {
                        let (cx, cy) = if horizontal { (x + k, y) } else { (x, y + k) };
                        if cx < w && cy < h {
                            m.set(Point::new(cx, cy), true);
                        }
                    }
                }
                m
            })
    })
}

/// Either map family, up to `max_side` x `max_side`.
pub fn any_map(max_side: u16) -> impl Strategy<Value = Map> {
    prop_oneof![
        3 => noise_map(max_side, max_side, 0.5),
        2 => walls_map(max_side, max_side),
    ]
}

/// A map with a start and a goal cell, both made free.
pub fn case(max_side: u16) -> impl Strategy<Value = (Map, Point, Point)> {
    any_map(max_side).prop_flat_map(|m| {
        let n = m.cells();
        (Just(m), 0..n, 0..n).prop_map(|(mut m, s, g)| {
            let (s, g) = (m.point(s), m.point(g));
            m.set(s, false);
            m.set(g, false);
            (m, s, g)
        })
    })
}

/// A map with arbitrary start and goal points, possibly blocked and possibly up to 2 cells
/// beyond the border (for the error paths).
pub fn raw_case(max_side: u16) -> impl Strategy<Value = (Map, Point, Point)> {
    any_map(max_side).prop_flat_map(|m| {
        let (w, h) = (m.width() + 2, m.height() + 2);
        (Just(m), 0..w, 0..h, 0..w, 0..h)
            .prop_map(|(m, sx, sy, gx, gy)| (m, Point::new(sx, sy), Point::new(gx, gy)))
    })
}

/// The proptest configuration the tests use: `cases` cases, and failing inputs saved next to the
/// test file (`tests/NAME.regressions`), since integration tests have no `lib.rs` beside them for
/// proptest's default location.
pub fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("regressions"),
        )),
        ..ProptestConfig::default()
    }
}
