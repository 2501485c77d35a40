//! docs/PROTOCOL.md's worked exchange: its bytes are what this code encodes, its plan is what the
//! planner returns, and `print_protocol_doc_example` (ignored) regenerates it.

use super::*;

// ---- docs/PROTOCOL.md: the worked exchange -------------------------------------------------

const EXAMPLE_WAYPOINTS: [Point; 4] = [
    Point::new(0, 0),
    Point::new(1, 0),
    Point::new(3, 1),
    Point::new(3, 2),
];
const EXAMPLE_DIRECTIONS: [u8; 4] = [0, 0, 1, 2];
/// Ticks (µs of virtual time) the QEMU firmware reported for the example plan.
const EXAMPLE_TICKS: u64 = 83;

fn example_path() -> PathReply<'static> {
    PathReply {
        raw_length: 4.414_213_7,
        length: 4.236_068,
        turns: 2,
        iterations: 2,
        best_iteration: 0,
        moves: 96,
        ticks: EXAMPLE_TICKS,
        raw_cells: 5,
        origin: crate::planner::Origin::Cold,
        waypoints: Waypoints::Points(&EXAMPLE_WAYPOINTS),
        directions: &EXAMPLE_DIRECTIONS,
    }
}

/// The reused answer to the example's `PlanWarm` from (2, 0), a cell of the example path, after
/// its `Plan` (no map change since): the rest of that path ([`crate::planner::reuse`]).
const REUSED_WAYPOINTS: [Point; 3] = [Point::new(2, 0), Point::new(3, 1), Point::new(3, 2)];
const REUSED_DIRECTIONS: [u8; 2] = [1, 2];
/// Ticks the QEMU firmware reported for the reused answer.
const REUSED_TICKS: u64 = 2;

fn example_reused() -> PathReply<'static> {
    PathReply {
        raw_length: 2.414_213_7,
        length: 2.414_213_7,
        turns: 1,
        iterations: 0,
        best_iteration: 0,
        moves: 0,
        ticks: REUSED_TICKS,
        raw_cells: 3,
        origin: crate::planner::Origin::Reused,
        waypoints: Waypoints::Points(&REUSED_WAYPOINTS),
        directions: &REUSED_DIRECTIONS,
    }
}

/// What the QEMU firmware answered to `Stats` after the example's first three requests.
fn example_stats() -> StatsReply {
    StatsReply {
        uptime: 55_848,
        boots: 1,
        frames_ok: 4,
        frames_bad: 0,
        rx_overruns: 0,
        rx_bytes: 45,
        tx_frames: 3,
        plans: 1,
        plan_errors: 0,
        cancelled: 0,
        busy: 0,
        last_plan_ticks: EXAMPLE_TICKS,
        map_width: 4,
        map_height: 3,
        queued: 0,
        planning: false,
        stack_peak: 3176,
        replies_dropped: 0,
        parted: 0,
    }
}

/// The exchange of the document: Hello, SetMap (the 4x3 map of the crate docs), Plan, Stats, and
/// a `PlanWarm` from a cell of the planned path, answered with the rest of it.
fn example() -> Vec<(u32, Request<'static>, Reply<'static>)> {
    vec![
        (1, Request::Hello, Reply::Hello(hello())),
        (
            2,
            Request::SetMap {
                width: 4,
                height: 3,
                offset: 0,
                total_len: 2,
                chunk: &MAP,
            },
            Reply::Ack,
        ),
        (
            3,
            Request::Plan {
                start: Point::new(0, 0),
                goal: Point::new(3, 2),
                seed: None,
            },
            Reply::Path(example_path()),
        ),
        (4, Request::Stats, Reply::Stats(example_stats())),
        (
            5,
            Request::PlanWarm {
                start: Point::new(2, 0),
                goal: Point::new(3, 2),
                seed: None,
            },
            Reply::Path(example_reused()),
        ),
    ]
}

#[test]
fn protocol_doc_example_is_exact() {
    let doc = include_str!("../../../docs/PROTOCOL.md");
    let (mut req_wire, mut rep_wire, mut req_pay, mut rep_pay) = (vec![], vec![], vec![], vec![]);
    for (id, req, rep) in example() {
        let f = enc_req(id, &req);
        req_pay.extend(payload_of(&f));
        req_wire.extend(f);
        let f = enc_rep(id, &rep);
        rep_pay.extend(payload_of(&f));
        rep_wire.extend(f);
    }
    let hint = "docs/PROTOCOL.md drifted: regenerate the example with \
        `cargo test -p ohaca --lib --target host-tuple print_protocol_doc_example -- --ignored --nocapture`";
    assert_eq!(doc_bytes(doc, "=> "), req_pay, "{hint}");
    assert_eq!(doc_bytes(doc, "<= "), rep_pay, "{hint}");
    assert_eq!(doc_bytes(doc, ">> "), req_wire, "{hint}");
    assert_eq!(doc_bytes(doc, "<< "), rep_wire, "{hint}");
    // And the wire bytes decode to the example's messages.
    let mut reader = ReplyReader::new();
    let mut n = 0;
    for b in rep_wire {
        if let Feed::Frame(f) = reader.push(b) {
            let (id, r) = decode_reply(f).unwrap();
            assert_eq!((id, r), (example()[n].0, example()[n].2));
            n += 1;
        }
    }
    assert_eq!(n, example().len());
}

#[test]
fn protocol_doc_example_is_what_the_planner_returns() {
    use crate::map::grid::Grid;
    use crate::planner::{reuse, Memory, Run, Storage};
    let g = Grid::new(4, 3, &MAP).unwrap();
    // The device's links (4,096), so the local search runs as on the device.
    let mut s: Box<Storage<1, 16, 4096, 16>> = Box::default();
    let mut memory = Memory::new();
    let defaults = hello().defaults;
    let (start, goal) = (Point::new(0, 0), Point::new(3, 2));
    let mut run = Run::cold(&g, start, goal, &defaults, s.workspace(), &mut memory).unwrap();
    while let crate::planner::Poll::Working(_) = run.poll() {}
    run.keep(&mut memory);
    let p = run.finish().unwrap();
    let want = example_path();
    assert_eq!(p.waypoints(), EXAMPLE_WAYPOINTS);
    assert_eq!(p.directions(), EXAMPLE_DIRECTIONS);
    assert_eq!(
        (p.raw_length, p.length, p.turns, p.iterations),
        (want.raw_length, want.length, want.turns, want.iterations)
    );
    assert_eq!(
        (p.best_iteration, p.moves, p.raw_len() as u32),
        (want.best_iteration, want.moves, want.raw_cells)
    );
    // The PlanWarm: the rest of that path.
    let mut ws = s.workspace();
    let r = reuse(&g, Point::new(2, 0), goal, &defaults, &mut ws, &mut memory).unwrap();
    let want = example_reused();
    assert_eq!(r.origin, want.origin);
    assert_eq!(r.waypoints(), REUSED_WAYPOINTS);
    assert_eq!(r.directions(), REUSED_DIRECTIONS);
    assert_eq!(
        (r.raw_length, r.length, r.turns, r.iterations, r.moves),
        (
            want.raw_length,
            want.length,
            want.turns,
            want.iterations,
            want.moves
        )
    );
    assert_eq!(r.raw_len() as u32, want.raw_cells);
}

fn ser<T: Serialize + ?Sized>(v: &T) -> Vec<u8> {
    let mut buf = vec![0u8; 8192];
    let n = postcard::to_slice(v, &mut buf).unwrap().len();
    buf.truncate(n);
    buf
}

fn params_fields(p: &Params) -> Vec<(String, Vec<u8>)> {
    vec![
        (
            format!("  algorithm = {}", p.algorithm.name()),
            vec![p.algorithm as u8],
        ),
        (format!("  ants = {}", p.ants), ser(&p.ants)),
        (
            format!("  iterations = {}", p.iterations),
            ser(&p.iterations),
        ),
        (format!("  alpha = {} (f32 LE)", p.alpha), ser(&p.alpha)),
        (format!("  beta = {}", p.beta), ser(&p.beta)),
        (format!("  rho = {}", p.rho), ser(&p.rho)),
        (format!("  q = {}", p.q), ser(&p.q)),
        (format!("  a = {}", p.a), ser(&p.a)),
        (format!("  xi = {}", p.xi), ser(&p.xi)),
        (format!("  tau0 = {}", p.tau0), ser(&p.tau0)),
        (format!("  tau_min = {}", p.tau_min), ser(&p.tau_min)),
        (format!("  tau_max = {}", p.tau_max), ser(&p.tau_max)),
        (format!("  patience = {}", p.patience), ser(&p.patience)),
        (
            format!("  warm_patience = {}", p.warm_patience),
            ser(&p.warm_patience),
        ),
        (
            format!("  refine_patience = {}", p.refine_patience),
            ser(&p.refine_patience),
        ),
        (format!("  seed = {}", p.seed), ser(&p.seed)),
        (
            format!("  dead_end = {:?}", p.dead_end),
            vec![p.dead_end as u8],
        ),
        (
            format!("  smoothing = {:?}", p.smoothing),
            vec![p.smoothing as u8],
        ),
        (format!("  tighten = {}", p.tighten), ser(&p.tighten)),
        (format!("  prune = {}", p.prune), ser(&p.prune)),
        (format!("  refine = {}", p.refine), ser(&p.refine)),
    ]
}

fn request_fields(id: u32, r: &Request<'_>) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(format!("id = {id}"), ser(&id))];
    match *r {
        Request::Hello => v.push(("Request::Hello (variant 0)".into(), vec![0])),
        Request::SetMap {
            width,
            height,
            offset,
            total_len,
            chunk,
        } => {
            v.push(("Request::SetMap (variant 1)".into(), vec![1]));
            v.push((format!("  width = {width}"), ser(&width)));
            v.push((format!("  height = {height}"), ser(&height)));
            v.push((format!("  offset = {offset}"), ser(&offset)));
            v.push((format!("  total_len = {total_len}"), ser(&total_len)));
            v.push((
                format!(
                    "  chunk: length {}, bits LSB first (0x20: cell 5 = (1,1) blocked)",
                    chunk.len()
                ),
                ser(chunk),
            ));
        }
        Request::Plan { start, goal, seed } | Request::PlanWarm { start, goal, seed } => {
            let (name, variant) = match r {
                Request::PlanWarm { .. } => ("PlanWarm", 9),
                _ => ("Plan", 3),
            };
            v.push((
                format!("Request::{name} (variant {variant})"),
                vec![variant],
            ));
            v.push((
                format!("  start = ({}, {})", start.x, start.y),
                ser(&(start.x, start.y)),
            ));
            v.push((
                format!("  goal = ({}, {})", goal.x, goal.y),
                ser(&(goal.x, goal.y)),
            ));
            v.push((format!("  seed = {seed:?}"), ser(&seed)));
        }
        Request::Stats => v.push(("Request::Stats (variant 5)".into(), vec![5])),
        _ => panic!("not used by the example"),
    }
    v
}

fn reply_fields(id: u32, r: &Reply<'_>) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(format!("id = {id}"), ser(&id))];
    match r {
        Reply::Hello(h) => {
            v.push(("Reply::Hello (variant 0)".into(), vec![0]));
            v.push((
                format!("  protocol_version = {}", h.protocol_version),
                ser(&h.protocol_version),
            ));
            v.push((
                format!("  firmware_version = {:?}", h.firmware_version),
                ser(h.firmware_version),
            ));
            v.push((format!("  board = {:?}", h.board), ser(h.board)));
            let c = h.capacity;
            v.push((format!("  capacity.cells = {}", c.cells), ser(&c.cells)));
            v.push((
                format!("  capacity.max_side = {}", c.max_side),
                ser(&c.max_side),
            ));
            v.push((
                format!("  capacity.max_steps = {}", c.max_steps),
                ser(&c.max_steps),
            ));
            v.push((
                format!("  capacity.max_chunk = {}", c.max_chunk),
                ser(&c.max_chunk),
            ));
            v.push((
                format!("  capacity.max_request = {}", c.max_request),
                ser(&c.max_request),
            ));
            v.push((
                format!("  capacity.plan_queue = {}", c.plan_queue),
                ser(&c.plan_queue),
            ));
            v.push((
                format!("  capacity.tick_hz = {}", c.tick_hz),
                ser(&c.tick_hz),
            ));
            v.push((format!("  capacity.window = {}", c.window), ser(&c.window)));
            v.push((
                format!("  capacity.window_bytes = {}", c.window_bytes),
                ser(&c.window_bytes),
            ));
            for (name, b) in params_fields(&h.defaults) {
                v.push((name.replacen("  ", "  defaults.", 1), b));
            }
        }
        Reply::Ack => v.push(("Reply::Ack (variant 1)".into(), vec![1])),
        Reply::Path(p) => {
            v.push(("Reply::Path (variant 2)".into(), vec![2]));
            v.push((
                format!("  raw_length = {} (f32 LE)", p.raw_length),
                ser(&p.raw_length),
            ));
            v.push((format!("  length = {}", p.length), ser(&p.length)));
            v.push((format!("  turns = {}", p.turns), ser(&p.turns)));
            v.push((
                format!("  iterations = {}", p.iterations),
                ser(&p.iterations),
            ));
            v.push((
                format!("  best_iteration = {}", p.best_iteration),
                ser(&p.best_iteration),
            ));
            v.push((format!("  moves = {}", p.moves), ser(&p.moves)));
            v.push((format!("  ticks = {}", p.ticks), ser(&p.ticks)));
            v.push((format!("  raw_cells = {}", p.raw_cells), ser(&p.raw_cells)));
            v.push((format!("  origin = {}", p.origin), ser(&p.origin)));
            let pts: Vec<String> = p
                .waypoints
                .iter()
                .map(|q| format!("({},{})", q.x, q.y))
                .collect();
            v.push((
                format!(
                    "  waypoints: {} bytes = {}",
                    p.waypoints.len() * 4,
                    pts.join(" ")
                ),
                ser(&p.waypoints),
            ));
            v.push((
                format!("  directions: {:?} ({})", p.directions, {
                    const NAMES: [&str; 8] = ["E", "SE", "S", "SW", "W", "NW", "N", "NE"];
                    let names: Vec<&str> = p
                        .directions
                        .iter()
                        .map(|&d| NAMES[usize::from(d & 7)])
                        .collect();
                    names.join(" ")
                }),
                ser(p.directions),
            ));
        }
        Reply::Stats(s) => {
            v.push(("Reply::Stats (variant 4)".into(), vec![4]));
            let fields: [(&str, Vec<u8>, String); 19] = [
                ("uptime", ser(&s.uptime), s.uptime.to_string()),
                ("boots", ser(&s.boots), s.boots.to_string()),
                ("frames_ok", ser(&s.frames_ok), s.frames_ok.to_string()),
                ("frames_bad", ser(&s.frames_bad), s.frames_bad.to_string()),
                (
                    "rx_overruns",
                    ser(&s.rx_overruns),
                    s.rx_overruns.to_string(),
                ),
                ("rx_bytes", ser(&s.rx_bytes), s.rx_bytes.to_string()),
                ("tx_frames", ser(&s.tx_frames), s.tx_frames.to_string()),
                ("plans", ser(&s.plans), s.plans.to_string()),
                (
                    "plan_errors",
                    ser(&s.plan_errors),
                    s.plan_errors.to_string(),
                ),
                ("cancelled", ser(&s.cancelled), s.cancelled.to_string()),
                ("busy", ser(&s.busy), s.busy.to_string()),
                (
                    "last_plan_ticks",
                    ser(&s.last_plan_ticks),
                    s.last_plan_ticks.to_string(),
                ),
                ("map_width", ser(&s.map_width), s.map_width.to_string()),
                ("map_height", ser(&s.map_height), s.map_height.to_string()),
                ("queued", ser(&s.queued), s.queued.to_string()),
                ("planning", ser(&s.planning), s.planning.to_string()),
                ("stack_peak", ser(&s.stack_peak), s.stack_peak.to_string()),
                (
                    "replies_dropped",
                    ser(&s.replies_dropped),
                    s.replies_dropped.to_string(),
                ),
                ("parted", ser(&s.parted), s.parted.to_string()),
            ];
            for (name, b, val) in fields {
                v.push((format!("  {name} = {val}"), b));
            }
        }
        _ => panic!("not used by the example"),
    }
    v
}

fn print_frame(marker: &str, wire_marker: &str, fields: Vec<(String, Vec<u8>)>, frame: &[u8]) {
    let payload = payload_of(frame);
    let mut all = vec![];
    for (name, b) in &fields {
        all.extend(b);
        // Long fields wrap at 16 bytes a line.
        let mut chunks: Vec<&[u8]> = b.chunks(16).collect();
        if chunks.is_empty() {
            chunks.push(&[]);
        }
        for (i, c) in chunks.iter().enumerate() {
            let h2 = hex(c);
            if i == 0 {
                println!("{marker}{h2:<48}; {name}");
            } else {
                println!("{marker}{h2}");
            }
        }
    }
    let crc = &payload[all.len()..];
    assert_eq!(&payload[..all.len()], &all[..]);
    println!(
        "{marker}{:<48}; CRC-32 = 0x{:08x}, little endian",
        hex(crc),
        u32::from_le_bytes(crc.try_into().unwrap())
    );
    for c in frame.chunks(16) {
        println!("{wire_marker}{}", hex(c));
    }
}

#[test]
#[ignore = "prints the example block of docs/PROTOCOL.md"]
fn print_protocol_doc_example() {
    for (id, req, rep) in example() {
        println!("\n# request {id}");
        print_frame("=> ", ">> ", request_fields(id, &req), &enc_req(id, &req));
        println!("\n# reply {id}");
        print_frame("<= ", "<< ", reply_fields(id, &rep), &enc_rep(id, &rep));
    }
}

/// The example path's body cut into parts of 16 bytes, as a device would send it if `PART_BYTES`
/// were 16: docs/PROTOCOL.md shows the frames, and that their bytes put together are the body of
/// request 3's `Path` reply.
fn example_parts() -> Vec<Vec<u8>> {
    let body = PathBody::new(&example_path()).unwrap();
    let mut bytes = vec![0u8; body.len()];
    assert_eq!(body.read(0, &mut bytes), body.len());
    bytes
        .chunks(16)
        .enumerate()
        .map(|(k, c)| {
            enc_rep(
                3,
                &Reply::PathPart(PathPart {
                    offset: (k * 16) as u32,
                    total_len: bytes.len() as u32,
                    bytes: c,
                }),
            )
        })
        .collect()
}

#[test]
fn protocol_doc_path_parts_are_exact() {
    let doc = include_str!("../../../docs/PROTOCOL.md");
    for (k, f) in example_parts().iter().enumerate() {
        let line = format!("<~ {}", hex(f));
        assert!(
            doc.contains(&line),
            "docs/PROTOCOL.md lacks part {k} of the parts example: {line}"
        );
    }
    // Put together, they decode as request 3's reply.
    let mut body = Vec::new();
    for f in example_parts() {
        let mut f = f[..f.len() - 1].to_vec();
        let (id, r) = decode_reply(&mut f).unwrap();
        assert_eq!(id, 3);
        let Reply::PathPart(p) = r else { panic!() };
        assert_eq!(p.offset as usize, body.len());
        body.extend_from_slice(p.bytes);
    }
    assert_eq!(decode_path_body(&body), Some(example_path()));
}

#[test]
#[ignore = "prints docs/PROTOCOL.md's parts example"]
fn print_path_parts_example() {
    for f in example_parts() {
        println!("<~ {}", hex(&f));
    }
}
