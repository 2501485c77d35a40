//! The references themselves: they reproduce the optima stated in `maps/README.md` and in the
//! `.scen` files, and the independent segment test agrees with the core's `segment_clear`.

use ohaca::geometry::segment_clear as core_clear;
use ohaca::Point;
use ohaca_host_tests::gen;
use ohaca_host_tests::maps::{scenarios, Map};
use ohaca_host_tests::reference::{self, any_angle, dijkstra8, opt8, segment_clear, Segments};
use proptest::prelude::*;

#[test]
fn fixed_maps_match_the_readme() {
    for set in scenarios().iter().take(3) {
        let c = &set.cases[0];
        let o8 = opt8(&set.map, c.start, c.goal).expect("reachable");
        let (aa, path) = any_angle(&set.map, c.start, c.goal).expect("reachable");
        println!(
            "{}: opt8 {o8:.4} (README {:.4}), any-angle {aa:.4} (README {:.4}), {} vertices",
            set.name,
            c.stated_opt8,
            c.stated_any_angle.unwrap(),
            path.len()
        );
        // The README rounds to 4 decimals.
        assert!((o8 - c.stated_opt8).abs() < 5e-5, "{}: {o8}", set.name);
        assert!(
            (aa - c.stated_any_angle.unwrap()).abs() < 5e-5,
            "{}: {aa}",
            set.name
        );
        // The any-angle path is valid by both segment tests.
        for w in path.windows(2) {
            assert!(segment_clear(&set.map, w[0], w[1]));
            assert!(core_clear(&set.map.grid(), w[0], w[1]));
        }
        assert!(aa <= o8 + 1e-12);
    }
}

#[test]
fn scen_optimal_column_matches_for_every_line() {
    // Every line of both `.scen` files, not only the 20 the quality runs use.
    for (name, scen) in ohaca_host_tests::maps::MOVINGAI {
        let dir = ohaca_host_tests::maps::maps_dir();
        let map = Map::load(dir.join(format!("movingai/{name}.map"))).unwrap();
        let entries = ohaca_host_tests::maps::load_scen(dir.join(scen)).unwrap();
        assert!(entries.len() > 100);
        // One Dijkstra per distinct start.
        let mut by_start = std::collections::HashMap::new();
        for e in &entries {
            let d = by_start
                .entry(e.start)
                .or_insert_with(|| dijkstra8(&map, e.start));
            let got = d[map.index(e.goal)];
            // The file prints 8 decimals.
            assert!(
                (got - e.optimal).abs() < 1e-6,
                "{name} {:?}->{:?}: {got} vs {}",
                e.start,
                e.goal,
                e.optimal
            );
            // A* agrees with Dijkstra.
            let a = opt8(&map, e.start, e.goal).unwrap();
            assert!((a - got).abs() < 1e-9);
        }
    }
}

#[test]
fn any_angle_is_between_euclid_and_opt8_on_scenarios() {
    for set in scenarios().iter().skip(3) {
        for c in &set.cases {
            let o8 = opt8(&set.map, c.start, c.goal).unwrap();
            assert!((o8 - c.stated_opt8).abs() < 1e-6);
            let (aa, path) = any_angle(&set.map, c.start, c.goal).unwrap();
            assert!(aa <= o8 + 1e-9, "{}: {aa} > {o8}", set.name);
            assert!(aa >= reference::euclid(c.start, c.goal) - 1e-9);
            for w in path.windows(2) {
                assert!(segment_clear(&set.map, w[0], w[1]));
            }
        }
    }
}

#[test]
fn segment_tests_agree_on_every_pair_of_the_fixed_maps() {
    for set in scenarios().iter().take(3) {
        let m = &set.map;
        let g = m.grid();
        let seg = Segments::new(m);
        let mut clear = 0u64;
        for i in 0..m.cells() {
            for j in i..m.cells() {
                let (a, b) = (m.point(i), m.point(j));
                let r = seg.clear(a, b);
                assert_eq!(r, core_clear(&g, a, b), "{}: {a:?} -> {b:?}", set.name);
                assert_eq!(r, core_clear(&g, b, a), "{}: {b:?} -> {a:?}", set.name);
                clear += u64::from(r);
            }
        }
        assert!(clear > 0);
    }
}

#[test]
fn segment_corner_cases_agree() {
    // Hand-picked touching cases: exact corner contacts, grazing edges, both orders.
    type Case = (&'static [&'static str], (u16, u16), (u16, u16), bool);
    let cases: &[Case] = &[
        (&["...", ".#.", "..."], (0, 0), (2, 2), false),
        (&[".#.", "...", "..."], (0, 0), (2, 2), false),
        (&["...", "...", "#.."], (0, 0), (2, 2), true),
        (&["...", ".#.", "..."], (0, 0), (2, 1), false),
        // (0.5,0.5)->(3.5,1.5) passes (2, 1), the top-left corner of cell (2,1).
        (&["....", "..#.", "...."], (0, 0), (3, 1), false),
        (&["....", "...#", "...."], (0, 0), (3, 1), false),
        (&["...#", "....", "...."], (0, 0), (3, 1), true),
        // ... and touches cells (1,1) and (2,0) at that corner point only.
        (&["....", ".#..", "...."], (0, 0), (3, 1), false),
        (&["..#.", "....", "...."], (0, 0), (3, 1), false),
        (&["....", "....", ".#.."], (0, 0), (3, 1), true),
        // (0.5,0.5)->(4.5,2.5) passes (3, 1.75): a near miss of cell (2,2).
        (&[".....", ".....", "..#.."], (0, 0), (4, 2), true),
        (&[".....", ".....", ".#..."], (0, 0), (4, 2), true),
        (&["....#", ".....", "....."], (0, 0), (4, 2), true),
        (&["#..", "...", "..#"], (2, 0), (0, 2), true),
        (&["....", "....", ".#..", "...."], (0, 0), (2, 3), false),
        (&[".....", ".....", ".....", "...#."], (0, 0), (4, 2), true),
        (&["....#", ".....", ".....", "....."], (0, 3), (4, 1), true),
        (&["...#.", ".....", ".....", "....."], (0, 3), (4, 1), true),
    ];
    for &(rows, a, b, want) in cases {
        let m = Map::from_rows(rows);
        let (a, b) = (Point::new(a.0, a.1), Point::new(b.0, b.1));
        assert_eq!(segment_clear(&m, a, b), want, "{rows:?} {a:?} {b:?}");
        assert_eq!(
            core_clear(&m.grid(), a, b),
            want,
            "core: {rows:?} {a:?} {b:?}"
        );
        assert_eq!(
            core_clear(&m.grid(), b, a),
            want,
            "core: {rows:?} {b:?} {a:?}"
        );
    }
}

proptest! {
    #![proptest_config(gen::config(400))]

    /// Random maps, random segments: the brute-force SAT test, the summed-area version and the
    /// core's column walk all agree.
    #[test]
    fn segment_tests_agree_on_random_segments(
        (m, pairs) in gen::any_map(20).prop_flat_map(|m| {
            let n = m.cells();
            (Just(m), proptest::collection::vec((0..n, 0..n), 1..40))
        })
    ) {
        let g = m.grid();
        let seg = Segments::new(&m);
        for (i, j) in pairs {
            let (a, b) = (m.point(i), m.point(j));
            let r = segment_clear(&m, a, b);
            prop_assert_eq!(r, seg.clear(a, b));
            prop_assert_eq!(r, core_clear(&g, a, b), "{:?} -> {:?} on\n{}", a, b, m.to_ascii());
        }
    }

    /// Long, shallow segments on sparse wide maps (where rounding would show first).
    #[test]
    fn segment_tests_agree_on_long_segments(
        m in gen::noise_map(64, 64, 0.08),
        pairs in proptest::collection::vec((0u16..64, 0u16..64, 0u16..64, 0u16..64), 1..30)
    ) {
        let g = m.grid();
        for (ax, ay, bx, by) in pairs {
            let a = Point::new(ax % m.width(), ay % m.height());
            let b = Point::new(bx % m.width(), by % m.height());
            prop_assert_eq!(segment_clear(&m, a, b), core_clear(&g, a, b), "{:?} -> {:?}", a, b);
        }
    }

    /// The any-angle optimum never exceeds the 8-connected one, never beats the straight line,
    /// and both exist exactly when the goal is reachable.
    #[test]
    fn optima_are_consistent((m, s, g) in gen::case(12)) {
        let o8 = opt8(&m, s, g);
        let aa = any_angle(&m, s, g);
        prop_assert_eq!(o8.is_some(), aa.is_some());
        if let (Some(o8), Some((aa, _))) = (o8, aa) {
            prop_assert!(aa <= o8 + 1e-9);
            prop_assert!(aa >= reference::euclid(s, g) - 1e-9);
        }
    }
}

/// Segments far from the origin on a huge map, where the core's exact arithmetic no longer fits
/// 32 bits (it switches to 64-bit division): still the same answers as the reference.
#[test]
fn segment_tests_agree_beyond_32_bit_products() {
    let (w, h) = (20_000u16, 32_767u16);
    let cells = usize::from(w) * usize::from(h);
    let mut bits = vec![0u8; cells.div_ceil(8)];
    // Sparse obstacles in the band the segments cross (xorshift, fixed seed).
    let mut x = 0x2545_f491_u32;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    let band = 32_747u16..32_767;
    // Every third row stays free, so horizontal segments there are clear.
    for y in band.clone().filter(|y| (y - band.start) % 3 != 0) {
        for cx in 0..w {
            if next() % 97 == 0 {
                let i = usize::from(y) * usize::from(w) + usize::from(cx);
                bits[i / 8] |= 1 << (i % 8);
            }
        }
    }
    let grid = ohaca::Grid::new(w, h, &bits).unwrap();
    let blocked = |cx: i64, cy: i64| {
        let i = cy as usize * usize::from(w) + cx as usize;
        bits[i / 8] >> (i % 8) & 1 == 1
    };
    let mut clear = 0;
    for k in 0..200u32 {
        let (ax, bx) = ((next() % 1000) as u16, w - 1 - (next() % 1000) as u16);
        let ay = band.start + (next() % 20) as u16;
        // Mostly shallow segments (often clear), some steeper ones.
        let by = if k % 4 == 0 {
            band.start + (next() % 20) as u16
        } else {
            ay
        };
        let (a, b) = (Point::new(ax, ay), Point::new(bx, by));
        // The products the core forms exceed i32 here.
        assert!(
            (2 * i64::from(ay) + 1) * 2 * (i64::from(bx) - i64::from(ax)) > i64::from(i32::MAX)
        );
        let (y0, y1) = (i64::from(ay.min(by)), i64::from(ay.max(by)));
        let want = (y0..=y1).all(|cy| {
            (i64::from(ax)..=i64::from(bx))
                .all(|cx| !blocked(cx, cy) || !reference::touches(a, b, (cx, cy)))
        });
        clear += u32::from(want);
        assert_eq!(core_clear(&grid, a, b), want, "{a:?} -> {b:?}");
        assert_eq!(core_clear(&grid, b, a), want, "{b:?} -> {a:?}");
    }
    // Both answers occur.
    assert!(clear > 0 && clear < 200, "{clear} of 200 clear");
}
