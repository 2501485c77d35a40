//! Property tests of the corridor search (`ohaca::corridor`, the last step of OHACA's default
//! smoothing on small maps) against the independent any-angle reference of `ohaca_host_tests`:
//!
//! - on random maps, starting from the colony's smoothed path of the greedy (paper) rule: the
//!   result is valid under the segment rule (the reference's own segment test), starts and ends
//!   where the input did, is never longer than the input and never shorter than the exact
//!   any-angle optimum;
//! - with a radius that covers the whole map it *is* the exact any-angle optimum
//!   (`reference::any_angle`, a different search over all free cells).

use ohaca::corridor::{shortest, RADIUS};
use ohaca::geometry::polyline_length;
use ohaca::{plan, Params, Point, SmoothingKind};
use ohaca_host_tests::gen;
use ohaca_host_tests::maps::Map;
use ohaca_host_tests::reference::{any_angle, Segments};
use proptest::prelude::*;

/// The greedy-smoothed waypoints of a default colony plan, or `None` when there is no path.
fn greedy_waypoints(m: &Map, s: Point, g: Point, seed: u64) -> Option<Vec<Point>> {
    let grid = m.grid();
    let mut st = ohaca_host_tests::heap::storage(m.cells());
    let p = Params {
        seed,
        smoothing: SmoothingKind::Greedy,
        ..Params::default()
    };
    let plan = plan(&grid, s, g, &p, st.workspace()).ok()?;
    Some(plan.waypoints().to_vec())
}

fn corridor(m: &Map, input: &[Point], radius: u16) -> Vec<Point> {
    // Room for a path of more points than the input, as the planner's `points` has.
    let mut pts = input.to_vec();
    pts.resize(m.cells(), Point::new(0, 0));
    let mut cell = vec![[0.0f32; 4]; m.cells()];
    let mut list = vec![0u32; 2 * m.cells()];
    let n = shortest(
        &m.grid(),
        &mut pts,
        input.len(),
        radius,
        &mut cell,
        &mut list,
    );
    pts.truncate(n);
    pts
}

proptest! {
    #![proptest_config(gen::config(96))]

    #[test]
    fn the_corridor_path_is_valid_never_longer_and_exact_with_the_whole_map(
        (m, s, g) in gen::case(24),
        seed in 0u64..1000,
    ) {
        let Some(input) = greedy_waypoints(&m, s, g, seed) else { return Ok(()) };
        let (opt, _) = any_angle(&m, s, g).expect("the colony found a path, so one exists");
        let seg = Segments::new(&m);
        let before = f64::from(polyline_length(&input));
        for radius in [RADIUS, 64] {
            let out = corridor(&m, &input, radius);
            prop_assert_eq!(out.first(), Some(&s));
            prop_assert_eq!(out.last(), Some(&g));
            for w in out.windows(2) {
                prop_assert!(seg.clear(w[0], w[1]), "{:?} -> {:?} not clear", w[0], w[1]);
            }
            let after = f64::from(polyline_length(&out));
            prop_assert!(after <= before + 1e-9, "radius {radius}: {after} > {before}");
            prop_assert!(after >= opt - 1e-3, "radius {radius}: {after} < optimum {opt}");
            if radius == 64 {
                prop_assert!((after - opt).abs() < 1e-3, "whole map: {after} against {opt}");
            }
        }
    }
}
