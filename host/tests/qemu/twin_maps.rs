//! End-to-end tests of the STM32H743's QEMU capacity twin: the mps2-an386 firmware built with
//! `--features twin-h743` (the H743's capacity, 2,097,152 cells and paths of 16,384 steps, and its
//! RAM regions at their sizes: `src/firmware/board/qemu/twin-h743-memory.x`), so what it plans
//! here fits the chip. Maps of 1024 x 1024 and 2048 x 1024 cells go up over QEMU's UART and are
//! planned at full resolution, bit for bit as the host core plans them with the device's
//! workspace shape (`core_plan_steps` with Hello's `max_steps`), and so are paths of up to the
//! twin's 16,384 steps, whose replies (up to 16.5 KB) fit the protocol's `MAX_REPLY` since
//! version 8.
//!
//! The twin is built once per run into `target/twin-h743` (`OHACA_TWIN_FIRMWARE=path/to/elf`
//! uses another ELF). Without `qemu-system-arm` the tests fail unless `OHACA_SKIP_QEMU=1`.
//! Upload and plan times are printed (`-- --nocapture`), not asserted: the whole file takes
//! about 20 s on a 2-core machine (BENCHMARKS.md, section 5).

use crate::qemu;

use std::time::Instant;

use ohaca::protocol::{ErrorCode, ErrorReply};
use ohaca::{Params, Point};
use ohaca_host::link::{LinkError, PlanJob};
use ohaca_host::Map;
use qemu::{
    assert_core_path, core_plan_steps, have_qemu, longest_scenario, maps, twin_firmware, Qemu,
};

/// The H743's capacity (`ohaca::board::H743`).
const CELLS: u32 = 2_097_152;
const STEPS: u32 = 16_384;

fn error_code<T: std::fmt::Debug>(r: Result<T, LinkError>) -> ErrorReply {
    match r {
        Err(LinkError::Device { error, .. }) => error,
        other => panic!("expected a device error, got {other:?}"),
    }
}

/// A 2048 x 1024 map (exactly the twin's 2,097,152 cells), blocked but for four corridors four
/// cells high, 2,032 cells long, at rows 100, 400, 700 and 1000, joined at alternate ends by
/// shafts four cells wide: one way through, 9,000 steps from the first corridor's left end to
/// the last one's.
fn corridors() -> Map {
    const ROWS: [u16; 4] = [100, 400, 700, 1000];
    Map::from_fn(2048, 1024, |x, y| {
        let along = (8..2040).contains(&x) && ROWS.iter().any(|&r| (r..r + 4).contains(&y));
        let shaft = ROWS.windows(2).enumerate().any(|(i, w)| {
            let x0 = if i % 2 == 0 { 2028 } else { 8 };
            (x0..x0 + 4).contains(&x) && (w[0]..w[1] + 4).contains(&y)
        });
        !(along || shaft)
    })
}

#[test]
fn the_twin_reports_the_h743_capacity_and_refuses_more() {
    need_qemu!();
    let q = Qemu::tcp_with(twin_firmware());
    let mut link = q.link();
    let info = link.hello().expect("hello");
    assert_eq!(info.board, "qemu-mps2-an386-twin-h743");
    assert_eq!(info.capacity.cells, CELLS, "{info:?}");
    assert_eq!(info.capacity.max_steps, STEPS, "{info:?}");
    // One row more than 2048 x 1024: refused by cells, and nothing is left.
    let e = error_code(link.set_map(&Map::from_fn(2048, 1025, |_, _| false)));
    assert_eq!(
        e,
        ErrorReply::with(ErrorCode::MapTooLarge, 2048 * 1025, CELLS)
    );
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (0, 0), "{st:?}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// Sydney_0_1024 (1024 x 1024 cells, a city of the Moving AI benchmarks): its longest scenario,
/// with two seeds, bit for bit as the host core plans it with the device's capacity.
#[test]
fn a_1024x1024_city_plans_bit_identical_to_the_host() {
    need_qemu!();
    let q = Qemu::tcp_with(twin_firmware());
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let steps = info.capacity.max_steps as usize;
    let defaults = Params::default();
    assert_eq!(
        info.defaults, defaults,
        "firmware and test built from other sources?"
    );
    let map = Map::load(maps().join("large/Sydney_0_1024.map")).expect("Sydney_0_1024");
    assert_eq!((map.width, map.height), (1024, 1024));
    let t0 = Instant::now();
    link.set_map(&map).expect("upload");
    println!(
        "Sydney_0_1024: upload {:.1} s over QEMU's UART",
        t0.elapsed().as_secs_f64()
    );
    let (start, goal) = longest_scenario("large/Sydney_0_1024.map.scen");
    let jobs: Vec<PlanJob> = [1, 2]
        .map(|seed| PlanJob {
            start,
            goal,
            seed: Some(seed),
        })
        .to_vec();
    let t0 = Instant::now();
    let outcomes = link.plan_many(&jobs).expect("plans");
    println!(
        "Sydney_0_1024 {start:?} -> {goal:?}: 2 plans in {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    for (job, o) in jobs.iter().zip(&outcomes) {
        let seed = job.seed.unwrap_or(0);
        let params = Params { seed, ..defaults };
        let host = core_plan_steps(&map, start, goal, &params, steps).expect("host plan");
        let dev = o.result.as_ref().expect("device path");
        assert_core_path(&format!("Sydney_0_1024 seed {seed}"), &host, dev);
        println!(
            "  seed {seed}: {} cells, length {}, {} iterations, {} ticks",
            dev.raw_cells, dev.length, dev.iterations, dev.ticks
        );
    }
    let st = link.stats().expect("stats");
    println!("stack peak {} bytes", st.stack_peak);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// `maze-128-128-2`'s longest scenario (a maze of 2-wide corridors; the optimum has 1,379 steps,
/// which the STM32F411 build's 2,047 also hold: `qemu/e2e.rs`'s
/// `the_longest_maze_128_128_2_scenario_plans_on_the_device`): the twin plans it, bit for bit as
/// the host core with the twin's capacity, and its raw path is the optimum.
#[test]
fn the_longest_maze_128_128_2_scenario_plans_on_the_twin() {
    need_qemu!();
    let q = Qemu::tcp_with(twin_firmware());
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let steps = info.capacity.max_steps as usize;
    let map = Map::load(maps().join("large/maze-128-128-2.map")).expect("maze-128-128-2");
    link.set_map(&map).expect("upload");
    let (start, goal) = longest_scenario("large/maze-128-128-2-random-1.scen");
    let params = Params {
        seed: 1,
        ..Params::default()
    };
    let dev = link.plan(start, goal, Some(1)).expect("device path");
    let host = core_plan_steps(&map, start, goal, &params, steps).expect("host plan");
    assert_core_path("maze-128-128-2", &host, &dev);
    assert!(dev.raw_cells > 1024, "{} cells", dev.raw_cells);
    assert!(
        (f64::from(dev.raw_length) - 1458.11).abs() < 0.01,
        "raw {}",
        dev.raw_length
    );
    println!(
        "maze-128-128-2 {start:?} -> {goal:?}: {} cells, raw {}, {} iterations, {} ticks",
        dev.raw_cells, dev.raw_length, dev.iterations, dev.ticks
    );
}

/// A 2048 x 1024 map, all the cells the twin holds: a path of 4,632 steps (over twice what the
/// STM32F411 keeps) is the host core's, bit for bit; so is a path of about 9,000 steps (beyond
/// protocol 7's 8,191, the twin's limit before version 8); a path of 6,658 steps, whose
/// reply (6.8 KB) was over protocol 6's largest frame (`MAX_REPLY`, 5,248 bytes, then `Error
/// Internal`), is sent and is the host core's.
#[test]
fn a_2048x1024_map_and_paths_of_thousands_of_steps() {
    need_qemu!();
    let q = Qemu::tcp_with(twin_firmware());
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let steps = info.capacity.max_steps as usize;
    let map = corridors();
    assert_eq!(map.cells(), CELLS as usize);
    let t0 = Instant::now();
    link.set_map(&map).expect("upload");
    println!(
        "2048x1024: upload {:.1} s over QEMU's UART",
        t0.elapsed().as_secs_f64()
    );
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (2048, 1024), "{st:?}");

    let defaults = Params::default();
    let start = Point::new(9, 101);
    // Along two corridors and down two shafts: 4,632 steps.
    let goal = Point::new(9, 702);
    let t0 = Instant::now();
    let dev = link.plan(start, goal, None).expect("device plan");
    println!(
        "2048x1024 {start:?} -> {goal:?}: {} cells in {:.1} s",
        dev.raw_cells,
        t0.elapsed().as_secs_f64()
    );
    let host = core_plan_steps(&map, start, goal, &defaults, steps).expect("host plan");
    assert_core_path("2048x1024, 4,632 steps", &host, &dev);
    assert!(dev.raw_cells > 4096, "{}", dev.raw_cells);

    // Beyond protocol 7's 8,191 steps (the twin's limit then), within its 16,384: few ants,
    // few iterations, so it is quick.
    let few = Params {
        ants: 4,
        iterations: 2,
        ..defaults
    };
    link.set_params(&few).expect("set params");
    let far = Point::new(9, 1001);
    let t0 = Instant::now();
    let dev = link.plan(start, far, None).expect("device plan");
    println!(
        "2048x1024 {start:?} -> {far:?}: {} cells in {:.1} s",
        dev.raw_cells,
        t0.elapsed().as_secs_f64()
    );
    let host = core_plan_steps(&map, start, far, &few, steps).expect("host plan");
    assert_core_path("2048x1024, 9,000 steps", &host, &dev);
    assert!(dev.raw_cells > 8192, "{}", dev.raw_cells);

    // About 6,700 steps: over protocol 6's largest reply, within version 7's.
    link.set_params(&defaults).expect("set params");
    let right = Point::new(2039, 702);
    let t0 = Instant::now();
    let dev = link.plan(start, right, None).expect("device plan");
    println!(
        "2048x1024 {start:?} -> {right:?}: {} cells in {:.1} s",
        dev.raw_cells,
        t0.elapsed().as_secs_f64()
    );
    let host = core_plan_steps(&map, start, right, &defaults, steps).expect("host plan");
    assert_core_path("2048x1024, 6,700 steps", &host, &dev);
    assert!(dev.raw_cells > 5300, "{}", dev.raw_cells);
    // The device goes on: the short plan again.
    let again = link.plan(start, goal, None).expect("device plan");
    assert_eq!(again.raw_cells, host_cells(&map, start, goal, steps));
    let st = link.stats().expect("stats");
    println!("stack peak {} bytes", st.stack_peak);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// Sixteen corridors one cell wide, 1,024 cells long, at rows 1, 3, ..., 31 of a 1026 x 1024
/// map (blocked elsewhere), joined at alternate ends by one cell: a single way from `(1, 1)`
/// through all of them, 16,398 steps to the far end of the last one. So the optimal path is the
/// only one, and a goal on it sets the path's length to the step.
fn serpentine() -> Map {
    Map::from_fn(1026, 1024, |x, y| {
        let corridor = y % 2 == 1 && y <= 31 && (1..=1024).contains(&x);
        // The joint below corridor `y - 1`: at the right end after corridors 1, 5, ..., 29, at
        // the left end after 3, 7, ..., 27.
        let joint = y % 2 == 0 && (2..=30).contains(&y) && x == if y % 4 == 2 { 1024 } else { 1 };
        !(corridor || joint)
    })
}

/// The longest path the twin plans, 16,384 steps (`max_steps`), through the sixteen 1-wide
/// corridors of [`serpentine`]: planned, sent in one `Path` reply (16.5 KB, over protocol 7's
/// 8,191 steps) and bit for bit the host core's; one step more is `PathTooLong`. The
/// corridors leave an ant no choice (the tabu list forbids going back), so a default plan is
/// cheap for its length: about `ants x iterations x steps` moves and nothing to search.
#[test]
fn a_path_of_16384_steps_comes_back_in_one_reply() {
    need_qemu!();
    let q = Qemu::tcp_with(twin_firmware());
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let steps = info.capacity.max_steps as usize;
    assert_eq!(steps, STEPS as usize);
    let map = serpentine();
    let t0 = Instant::now();
    link.set_map(&map).expect("upload");
    println!(
        "serpentine 1026x1024: upload {:.1} s over QEMU's UART",
        t0.elapsed().as_secs_f64()
    );
    let defaults = Params::default();
    let start = Point::new(1, 1);
    // The far end of the last corridor (row 31, entered at the right, going left), `(1, 31)`,
    // is 16,398 steps away: 14 short of it.
    let goal = Point::new(15, 31);
    let t0 = Instant::now();
    let dev = link.plan(start, goal, None).expect("device plan");
    println!(
        "serpentine {start:?} -> {goal:?}: {} cells, {} waypoints, {} iterations in {:.1} s",
        dev.raw_cells,
        dev.waypoints.len(),
        dev.iterations,
        t0.elapsed().as_secs_f64()
    );
    let host = core_plan_steps(&map, start, goal, &defaults, steps).expect("host plan");
    assert_core_path("serpentine, 16,384 steps", &host, &dev);
    assert_eq!(dev.directions.len(), steps);
    assert_eq!(dev.raw_cells as usize, steps + 1);

    // One step more: no ant keeps it.
    let few = Params {
        ants: 4,
        iterations: 2,
        ..defaults
    };
    link.set_params(&few).expect("set params");
    let beyond = Point::new(14, 31);
    let e = error_code(link.plan(start, beyond, None));
    assert_eq!(e.code, ErrorCode::PathTooLong, "{e}");
    assert_eq!(
        core_plan_steps(&map, start, beyond, &few, steps).err(),
        Some(e)
    );
    let st = link.stats().expect("stats");
    println!("stack peak {} bytes", st.stack_peak);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

fn host_cells(map: &Map, start: Point, goal: Point, steps: usize) -> u32 {
    core_plan_steps(map, start, goal, &Params::default(), steps)
        .expect("host plan")
        .raw_cells
}
