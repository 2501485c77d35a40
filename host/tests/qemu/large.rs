//! Building-scale maps on the STM32F411-capacity firmware (the default QEMU build, whose
//! capacity is the chip's: issue 19): maps of up to 262,144 cells of any shape go up over QEMU's
//! UART and are planned at full resolution in the firmware's 103,424-byte arena
//! (`ohaca::planner::arena`), bit for bit as the host core plans them in an arena of the same
//! length, cold and warm.
//!
//! Each test boots its own QEMU; without `qemu-system-arm` the tests fail unless
//! `OHACA_SKIP_QEMU=1`. Upload and plan times are printed (`-- --nocapture`), not asserted.

use crate::depot;
use crate::qemu;

use std::time::Instant;

use ohaca::protocol::{ErrorCode, ErrorReply};
use ohaca::{Params, Point};
use ohaca_host::link::{LinkError, PlanJob};
use ohaca_host::replan::{DevicePlanner, HostPlanner, Planned, Planner};
use ohaca_host::Map;
use qemu::{assert_core_path, core_plan, have_qemu, longest_scenario, maps, Qemu};

/// The F411's capacity (`ohaca::board::F411`).
const CELLS: u32 = ohaca::board::F411.cells as u32;
const STEPS: u32 = ohaca::board::F411.max_steps as u32;

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

/// `maze512-1-0` (512 x 512, corridors one cell wide): the scenario from (40, 125) to
/// (502, 437), whose optimum is 4,000 steps, plans on the STM32F411 build (4,095-step paths in
/// the compact layout; protocol 10's firmware kept 1,876 at 512 x 512 and answered
/// `PathTooLong`), at that optimum and bit for bit as the host core plans it.
#[test]
fn a_4000_step_maze_path_plans_at_512x512_bit_identical_to_the_host() {
    need_qemu!();
    let map = Map::load(maps().join("large/maze512-1-0.map")).expect("maze512-1-0");
    assert_eq!(map.cells(), CELLS as usize);
    let (start, goal) = (Point::new(40, 125), Point::new(502, 437));
    let host = core_plan(&map, start, goal, &Params::default()).expect("host plan");
    assert_eq!(host.raw_cells, 4001, "the scenario's optimum: 4,000 steps");
    plans_as_the_host("maze512-1-0", &map, start, goal, &[1]);
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
    let untimed = |p: Planned| Planned {
        ticks: None,
        fallback: None,
        ..p
    };
    let mut both = |f: &mut dyn FnMut(&mut dyn Planner) -> Planned| {
        let h = untimed(f(&mut host));
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

/// `ohaca` (the binary under test) with `args`: its stdout and stderr.
fn ohaca_cli(args: &[String]) -> (String, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_ohaca"))
        .args(args)
        .output()
        .expect("run the ohaca binary");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    assert!(
        o.status.success(),
        "ohaca {args:?}: {}\n{}",
        o.status,
        text(&o.stderr)
    );
    (text(&o.stdout), text(&o.stderr))
}

/// The keys of a plan report that the device's plan and the host's must share, float bits
/// included (`elapsed_us`, `ticks` and `device` are not the plan's).
fn plan_keys(json: &str) -> Vec<(String, String)> {
    let v: serde_json::Value = serde_json::from_str(json.trim()).expect("one JSON report");
    [
        "found",
        "raw",
        "waypoints",
        "raw_length",
        "length",
        "turns",
        "iterations",
        "best_iteration",
        "moves",
    ]
    .iter()
    .map(|k| (k.to_string(), v[*k].to_string()))
    .collect()
}

/// Issue 29: on maps of more than 68,256 cells the STM32F411 (and this QEMU build) plans in the
/// compact layout, which `ohaca plan` reproduces only with `--board f411`. Nav2's depot
/// (604 x 307) and NewYork_0_512 (512 x 512) through the CLI: `ohaca send` to the QEMU firmware
/// (whose stderr notes the layout) against `ohaca plan --board f411`, one seed each.
#[test]
fn send_to_the_f411_build_is_plan_board_f411_on_the_depot_and_new_york() {
    need_qemu!();
    let (ny_start, ny_goal) = longest_scenario("large/NewYork_0_512.map.scen");
    let pt = |p: Point| format!("{},{}", p.x, p.y);
    let cases = [
        ("depot.map", "9,4".to_string(), "596,300".to_string()),
        ("large/NewYork_0_512.map", pt(ny_start), pt(ny_goal)),
    ];
    let q = Qemu::tcp();
    for (file, start, goal) in cases {
        let path = maps().join(file);
        let map = Map::load(&path).expect("map");
        assert!(
            ohaca_host::board::differs_from_host(&ohaca::board::F411, map.cells()).is_some(),
            "{file}: the F411 plans it in its compact layout"
        );
        let common: Vec<String> = [
            "--map",
            &path.display().to_string(),
            "--start",
            &start,
            "--goal",
            &goal,
            "--seed",
            "1",
            "--json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let t0 = Instant::now();
        let mut send = vec!["send".to_string(), "--tcp".into(), q.addr().into()];
        send.extend(["--timeout".to_string(), "600".into()]);
        send.extend(common.iter().cloned());
        let (dev, note) = ohaca_cli(&send);
        println!("{file}: ohaca send {:.1} s", t0.elapsed().as_secs_f64());
        assert!(
            note.contains("compact layout") && note.contains("--board f411"),
            "{file}: send's note: {note}"
        );
        let mut plan = vec!["plan".to_string(), "--board".into(), "f411".into()];
        plan.extend(common.iter().cloned());
        let (host, _) = ohaca_cli(&plan);
        assert_eq!(
            plan_keys(&dev),
            plan_keys(&host),
            "{file}: send vs plan --board f411"
        );
        // The host's default layout plans another path here (why `--board` exists).
        let mut default = vec!["plan".to_string()];
        default.extend(common.iter().cloned());
        let (own, _) = ohaca_cli(&default);
        assert_ne!(
            plan_keys(&own),
            plan_keys(&host),
            "{file}: the host's default layout"
        );
    }
}
