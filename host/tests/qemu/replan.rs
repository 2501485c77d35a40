//! Replanning on the firmware under QEMU: the robot's loop of cell updates and `PlanWarm`
//! (`ohaca_host::replan`) gives the device exactly the host core's plans, warm and cold, and the
//! device keeps its colony only when `docs/PROTOCOL.md` says it does.
//!
//! Like `qemu/e2e.rs`, each test boots its own QEMU; without `qemu-system-arm` the tests fail
//! unless `OHACA_SKIP_QEMU=1`.

use crate::qemu;

use ohaca::{Params, Point};
use ohaca_host::link::Link;
use ohaca_host::replan::{drive, DevicePlanner, Drive, HostPlanner, Planned, Scenario};
use ohaca_host::Map;
use qemu::{have_qemu, maps, root, Qemu};

fn scenario(name: &str) -> Scenario {
    let text = std::fs::read_to_string(root().join("scenarios").join(name)).expect("scenario");
    Scenario::parse(&text).expect("parse")
}

/// The device over its link, told the default parameters (returned too, for the host core).
fn device(q: &Qemu) -> (DevicePlanner<std::net::TcpStream>, Params) {
    let mut dev = DevicePlanner { link: q.link() };
    dev.link.hello().expect("hello");
    let p = Params::default();
    dev.link.set_params(&p).expect("params");
    (dev, p)
}

/// The plan without the device's time.
fn untimed(p: &Planned) -> Planned {
    Planned {
        ticks: None,
        fallback: None,
        ..p.clone()
    }
}

fn assert_same_drive(what: &str, host: &Drive, dev: &Drive) {
    assert_eq!(host.steps.len(), dev.steps.len(), "{what}");
    for (i, (h, d)) in host.steps.iter().zip(&dev.steps).enumerate() {
        assert_eq!(h.robot, d.robot, "{what}: plan {i}: robot");
        assert_eq!(untimed(&h.plan), untimed(&d.plan), "{what}: plan {i}");
        assert_eq!(
            (h.plan.raw_length.to_bits(), h.plan.length.to_bits()),
            (d.plan.raw_length.to_bits(), d.plan.length.to_bits()),
            "{what}: plan {i}: length bits"
        );
    }
    assert_eq!(host.trail, dev.trail, "{what}: trail");
}

/// complex-26 with a wall across the path and with a door that opens, warm and cold: every
/// device plan is the host core's, bit for bit, the replans are warm exactly when asked, and
/// every plan is valid on the map of its time (checked by `drive`).
#[test]
fn warm_and_cold_replans_on_the_device_are_the_host_cores() {
    need_qemu!();
    let q = Qemu::tcp();
    let (mut dev, p) = device(&q);
    let map = Map::load(maps().join("complex-26.map")).expect("map");
    let ends = (Point::new(0, 0), Point::new(25, 25));
    for name in ["wall.json", "complex-26-gap.json"] {
        let sc = scenario(name);
        for warm in [true, false] {
            let what = format!("{name}, warm {warm}");
            let host = drive(&sc, &map, ends, &mut HostPlanner::new(p), warm).expect("host");
            let d = drive(&sc, &map, ends, &mut dev, warm).expect("device");
            assert_same_drive(&what, &host, &d);
            assert!(
                !d.steps[0].plan.origin.is_warm(),
                "{what}: the first plan after an upload is cold"
            );
            assert_eq!(d.steps[1].plan.origin.is_warm(), warm, "{what}");
            assert!(!d.steps[1].changed.is_empty(), "{what}");
        }
    }
}

/// The real ROS map at 5 cm (200 x 150 cells, inflated by 0.2 m) with a wall across the path:
/// the warm replan on the device is the host's.
#[test]
fn a_warm_replan_on_the_lab_map_is_the_host_cores() {
    need_qemu!();
    let q = Qemu::tcp();
    let (mut dev, p) = device(&q);
    let (map, frame) = ohaca_host::map::prepare(
        &root().join("host/assets/ros/lab.yaml"),
        ohaca_host::map::Unknown::Blocked,
        Some(0.2),
        None,
    )
    .expect("lab");
    let frame = frame.expect("metric");
    let ends = (
        frame.cell([-1.2, -0.8]).expect("start"),
        frame.cell([7.25, 3.7]).expect("goal"),
    );
    let sc = scenario("wall.json");
    let host = drive(&sc, &map, ends, &mut HostPlanner::new(p), true).expect("host");
    let d = drive(&sc, &map, ends, &mut dev, true).expect("device");
    assert_same_drive("lab", &host, &d);
    assert!(d.steps[1].plan.origin.is_warm());
}

/// When `PlanWarm` keeps the colony: after a plan to the same goal on this map (cold or warm,
/// also one whose request was refused since); not after a new map, not to another goal.
#[test]
fn plan_warm_keeps_the_colony_only_for_the_same_goal_and_map() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link: Link<_> = q.link();
    link.hello().expect("hello");
    let map = Map::load(maps().join("complex-26.map")).expect("map");
    link.set_map(&map).expect("map");
    let (s, g, other) = (Point::new(0, 0), Point::new(25, 25), Point::new(25, 0));
    let warm = |link: &mut Link<_>, goal: Point| {
        link.plan_warm(s, goal, None)
            .expect("plan")
            .origin
            .is_warm()
    };
    assert!(!warm(&mut link, g), "no colony yet");
    assert!(warm(&mut link, g), "same goal");
    assert!(!warm(&mut link, other), "another goal");
    assert!(
        !warm(&mut link, g),
        "back to the first goal: its colony was replaced"
    );
    // A refused plan (start on an obstacle) leaves the colony alone.
    let blocked = (0..26)
        .flat_map(|y| (0..26).map(move |x| Point::new(x, y)))
        .find(|&p| map.is_blocked(p))
        .expect("an obstacle");
    assert!(link.plan_warm(blocked, g, None).is_err());
    assert!(warm(&mut link, g), "after a refused plan");
    // A cold plan records its colony too.
    assert!(!link.plan(s, g, None).expect("cold").origin.is_warm());
    assert!(warm(&mut link, g), "after a cold plan");
    link.set_cells(&[Point::new(12, 12)], true).expect("update");
    assert!(warm(&mut link, g), "a cell update keeps the colony");
    link.set_map(&map).expect("the same map again");
    assert!(!warm(&mut link, g), "a new upload drops it");
}

/// A robot's costmap stream (`ohaca_host::stream`): 100 small random updates at 5 Hz while the
/// robot drives, one new obstacle in ten on or next to its path, a `PlanWarm` after each, on a
/// 256 x 256 city and on Nav2's depot at 5 cm. Every answer is valid on the map of its time
/// (checked by `stream`) and the host core's bit for bit, reused and repaired ones included; most
/// are reused.
/// (The share of the board's time spent planning is measured under `-icount`: `BENCHMARKS.md`,
/// "Replanning".)
#[test]
fn a_costmap_stream_on_the_device_is_the_host_cores() {
    use ohaca_host::stream::{stream, summary, Stream};
    need_qemu!();
    let q = Qemu::tcp();
    let (mut dev, p) = device(&q);
    let s = Stream::default();
    for (name, file, ends) in [
        (
            "Boston_0_256",
            maps().join("large/Boston_0_256.map"),
            (Point::new(184, 0), Point::new(8, 254)),
        ),
        (
            "depot",
            maps().join("depot.map"),
            (Point::new(9, 4), Point::new(596, 300)),
        ),
    ] {
        let map = Map::load(&file).expect("map");
        let host = stream(&s, &map, ends, &mut HostPlanner::new(p), true).expect("host");
        let d = stream(&s, &map, ends, &mut dev, true).expect("device");
        assert_same_drive(name, &host, &d);
        let sum = summary(&d, s.hz, 100e6);
        assert_eq!(sum.replans, s.updates, "{name}: the robot is still driving");
        assert!(sum.reused * 2 > sum.replans, "{name}: {sum:?}");
        assert!(
            sum.warm + sum.repaired > 0,
            "{name}: obstacles on the path are repaired or make runs: {sum:?}"
        );
        // This QEMU runs without `-icount`, so its ticks are not instructions: the cost figures
        // come from `ohaca replan --stream` on `scripts/qemu-serve.sh --icount` (BENCHMARKS.md).
        eprintln!(
            "{name}: {} replans, {} reused, {} repaired, {} warm",
            sum.replans, sum.reused, sum.repaired, sum.warm
        );
    }
}
