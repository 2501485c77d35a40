//! Building-scale maps on the STM32F411-capacity firmware (the default QEMU build, whose
//! capacity is the chip's: issue 19): maps of up to 262,144 cells of any shape go up over QEMU's
//! UART and are planned at full resolution in the firmware's 103,424-byte arena
//! (`ohaca::planner::arena`), bit for bit as the host core plans them in an arena of the same
//! length, cold and warm.
//!
//! Each test boots its own QEMU; without `qemu-system-arm` the tests fail unless
//! `OHACA_SKIP_QEMU=1`. Upload and plan times are printed (`-- --nocapture`), not asserted.

#[macro_use]
#[path = "common/qemu.rs"]
mod qemu;
#[path = "common/depot.rs"]
mod depot;

use std::time::Instant;

use ohaca::protocol::{ErrorCode, ErrorReply};
use ohaca::{Params, Point};
use ohaca_host::link::{LinkError, PlanJob};
use ohaca_host::replan::{DevicePlanner, HostPlanner, Planned, Planner};
use ohaca_host::Map;
use qemu::{assert_core_path, core_plan, have_qemu, longest_scenario, maps, Qemu};

/// The F411's capacity (`src/firmware/board/mod.rs`, `SMALL`).
const CELLS: u32 = 262_144;
const STEPS: u32 = 2047;

#[test]
fn the_f411_build_takes_262144_cells_and_refuses_more() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    assert_eq!(info.capacity.cells, CELLS, "{info:?}");
    assert_eq!(info.capacity.max_steps, STEPS, "{info:?}");
    // One row more than 512 x 512: refused by cells, and nothing is left.
    match link.set_map(&Map::from_fn(512, 513, |_, _| false)) {
        Err(LinkError::Device { error, .. }) => assert_eq!(
            error,
            ErrorReply::with(ErrorCode::MapTooLarge, 512 * 513, CELLS)
        ),
        other => panic!("expected MapTooLarge, got {other:?}"),
    }
    // A long thin map of as many cells is one map, not a refusal.
    link.set_map(&Map::from_fn(4096, 64, |x, y| x % 64 == 63 && y > 0))
        .expect("4096 x 64");
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (4096, 64), "{st:?}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// Upload `map`, plan `start -> goal` with `seeds`, and require the host core's paths.
fn plans_as_the_host(name: &str, map: &Map, start: Point, goal: Point, seeds: &[u64]) {
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let defaults = Params::default();
    assert_eq!(
        info.defaults, defaults,
        "firmware and test built from other sources?"
    );
    let t0 = Instant::now();
    link.set_map(map).expect("upload");
    println!(
        "{name} ({} x {}): upload {:.1} s over QEMU's UART",
        map.width,
        map.height,
        t0.elapsed().as_secs_f64()
    );
    let jobs: Vec<PlanJob> = seeds
        .iter()
        .map(|&seed| PlanJob {
            start,
            goal,
            seed: Some(seed),
        })
        .collect();
    let t0 = Instant::now();
    let outcomes = link.plan_many(&jobs).expect("plans");
    println!(
        "{name} {start:?} -> {goal:?}: {} plans in {:.1} s",
        jobs.len(),
        t0.elapsed().as_secs_f64()
    );
    for (job, o) in jobs.iter().zip(&outcomes) {
        let seed = job.seed.unwrap_or(0);
        let params = Params { seed, ..defaults };
        let host = core_plan(map, start, goal, &params).expect("host plan");
        let dev = o.result.as_ref().expect("device path");
        assert_core_path(&format!("{name} seed {seed}"), &host, dev);
        println!(
            "  seed {seed}: {} cells, raw {}, length {}, {} iterations, {} ticks",
            dev.raw_cells, dev.raw_length, dev.length, dev.iterations, dev.ticks
        );
    }
    let st = link.stats().expect("stats");
    println!("stack peak {} bytes", st.stack_peak);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// NewYork_0_512 (512 x 512 cells, a city of the Moving AI benchmarks): its longest scenario
/// (714.5 cells), bit for bit as the host core plans it.
#[test]
fn a_512x512_city_plans_at_full_resolution_bit_identical_to_the_host() {
    need_qemu!();
    let map = Map::load(maps().join("large/NewYork_0_512.map")).expect("NewYork_0_512");
    assert_eq!(map.cells(), CELLS as usize);
    let (start, goal) = longest_scenario("large/NewYork_0_512.map.scen");
    plans_as_the_host("NewYork_0_512", &map, start, goal, &[1, 2]);
}

/// A 604 x 307 depot (the shape of Nav2's sample depot: racks in rows, pillars, noise), corner
/// to corner, bit for bit as the host core plans it.
#[test]
fn a_604x307_depot_plans_at_full_resolution_bit_identical_to_the_host() {
    need_qemu!();
    let (start, goal) = (Point::new(1, 305), Point::new(602, 1));
    // The first seed whose noise leaves the corners connected.
    let map = (1..)
        .map(depot::depot)
        .find(|m| core_plan(m, start, goal, &Params::default()).is_ok())
        .expect("a connected depot");
    plans_as_the_host("depot", &map, start, goal, &[1]);
}

/// The robot's loop on a 512 x 512 map: a cold plan, cells blocked on its path, a warm replan
/// (the colony kept in the arena between plans), as the host core does it.
#[test]
fn a_warm_replan_on_a_512x512_map_is_the_host_cores() {
    need_qemu!();
    let map = Map::load(maps().join("large/NewYork_0_512.map")).expect("NewYork_0_512");
    let (start, goal) = longest_scenario("large/NewYork_0_512.map.scen");
    let q = Qemu::tcp();
    let mut dev = DevicePlanner { link: q.link() };
    let mut host = HostPlanner::new(Params::default());
    let untimed = |p: Planned| Planned { ticks: None, ..p };
    let mut both = |f: &mut dyn FnMut(&mut dyn Planner) -> Planned| {
        let h = f(&mut host);
        let d = untimed(f(&mut dev));
        assert_eq!(h, d);
        assert_eq!(
            (h.raw_length.to_bits(), h.length.to_bits()),
            (d.raw_length.to_bits(), d.length.to_bits())
        );
        h
    };
    let cold = both(&mut |p| {
        p.set_map(&map).expect("map");
        p.plan(start, goal, false).expect("cold plan")
    });
    // Block three cells a third of the way along the path, clear of the robot.
    let at = cold.raw.len() / 3;
    let wall: Vec<Point> = cold.raw[at..at + 3].to_vec();
    let robot = cold.raw[at / 2];
    let warm = both(&mut |p| {
        p.change(&wall, true).expect("cells");
        p.plan(robot, goal, true).expect("warm plan")
    });
    assert!(warm.origin.is_warm(), "the colony was kept");
    assert!(warm.raw.iter().all(|c| !wall.contains(c)));
    println!(
        "NewYork_0_512: cold {} iterations, {} moves; warm {} iterations, {} moves",
        cold.iterations, cold.moves, warm.iterations, warm.moves
    );
}
