//! Writes the seed inputs of the `wire_frame` and `map_parsers` targets into `fuzz/seeds/<target>/`
//! (small, committed) from the protocol's own encoders and the repository's maps.
//!
//! ```text
//! cd fuzz && cargo run --example make_seeds --target x86_64-unknown-linux-gnu
//! ```

use std::fs;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::{GrayImage, ImageFormat, Luma, Rgba, RgbaImage};
use ohaca::protocol::{
    encode_reply, encode_request, Capacity, ErrorCode, ErrorReply, HelloReply, PathReply, Reply,
    Request, StatsReply, Waypoints, MAX_CHUNK, MAX_DIRECTIONS, MAX_REPLY_WIRE, MAX_REQUEST,
    MAX_REQUEST_WIRE, MAX_STEPS, MAX_UPDATE_CELLS, MAX_WAYPOINTS, VERSION,
};
use ohaca::{Algorithm, DeadEnd, Params, Point, SmoothingKind};
use ohaca_host::map::Map;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn req(id: u32, r: &Request<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; MAX_REQUEST_WIRE];
    let n = encode_request(id, r, &mut buf).expect("seed request encodes");
    buf.truncate(n);
    buf
}

fn rep(id: u32, r: &Reply<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; MAX_REPLY_WIRE];
    let n = encode_reply(id, r, &mut buf).expect("seed reply encodes");
    buf.truncate(n);
    buf
}

/// Every `SetMap` chunk of `map`, `chunk` bytes each, ids from `id`.
fn set_map(map: &Map, chunk: usize, id: u32) -> Vec<Vec<u8>> {
    let total = map.bits.len() as u32;
    map.bits
        .chunks(chunk)
        .enumerate()
        .map(|(i, c)| {
            req(
                id + i as u32,
                &Request::SetMap {
                    width: map.width,
                    height: map.height,
                    offset: (i * chunk) as u32,
                    total_len: total,
                    chunk: c,
                },
            )
        })
        .collect()
}

fn wire_frame_seeds(root: &Path) -> Result<Vec<(String, Vec<u8>)>> {
    let mut out: Vec<(String, Vec<u8>)> = Vec::new();
    let complex = Map::load(root.join("maps/complex-26.map"))?;
    let random = Map::load(root.join("maps/movingai/random-32-32-20.map"))?;
    let params = Params {
        algorithm: Algorithm::Haca,
        ants: 50,
        iterations: 100,
        seed: 0xDEAD_BEEF,
        dead_end: DeadEnd::Die,
        smoothing: SmoothingKind::Greedy,
        tighten: false,
        ..Params::default()
    };
    let plan = Request::Plan {
        start: Point::new(0, 0),
        goal: Point::new(25, 25),
        seed: Some(42),
    };

    // Single requests, one frame a file.
    out.push(("req-hello".into(), req(1, &Request::Hello)));
    out.push((
        "req-set-params-default".into(),
        req(2, &Request::SetParams(Params::default())),
    ));
    out.push((
        "req-set-params-haca".into(),
        req(3, &Request::SetParams(params)),
    ));
    for (i, f) in set_map(&complex, MAX_CHUNK, 4).into_iter().enumerate() {
        out.push((format!("req-set-map-complex26-{i}"), f));
    }
    out.push(("req-plan-seed".into(), req(5, &plan)));
    out.push((
        "req-plan-noseed".into(),
        req(
            u32::MAX,
            &Request::Plan {
                start: Point::new(65535, 0),
                goal: Point::new(31, 31),
                seed: None,
            },
        ),
    ));
    out.push(("req-cancel".into(), req(6, &Request::Cancel)));
    out.push(("req-stats".into(), req(300, &Request::Stats)));

    // A whole session as the host sends it: 32-byte chunks of complex-26, 128-byte chunks of a
    // 32x32 map.
    let mut session = req(1, &Request::Hello);
    session.extend(req(2, &Request::SetParams(params)));
    for f in set_map(&complex, 32, 3) {
        session.extend(f);
    }
    session.extend(req(10, &plan));
    session.extend(req(11, &Request::Stats));
    session.extend(req(12, &Request::Cancel));
    out.push(("session-complex26".into(), session));
    let mut session = Vec::new();
    for f in set_map(&random, MAX_CHUNK, 100) {
        session.extend(f);
    }
    session.extend(req(
        200,
        &Request::Plan {
            start: Point::new(0, 0),
            goal: Point::new(31, 31),
            seed: None,
        },
    ));
    out.push(("session-random32".into(), session));

    // Protocol 3: a run-length upload of complex-26 in 16-byte chunks, cell updates, warm plan.
    let cells = u32::from(complex.width) * u32::from(complex.height);
    let code: Vec<u8> = ohaca::protocol::RleEncoder::new(&complex.bits, cells).collect();
    let mut session = Vec::new();
    for (k, c) in code.chunks(16).enumerate() {
        session.extend(req(
            20 + k as u32,
            &Request::SetMapRle {
                width: complex.width,
                height: complex.height,
                offset: (k * 16) as u32,
                total_len: code.len() as u32,
                chunk: c,
            },
        ));
    }
    session.extend(req(
        60,
        &Request::SetRect {
            x: 3,
            y: 4,
            width: 5,
            height: 2,
            blocked: true,
        },
    ));
    let pts = [Point::new(1, 1), Point::new(25, 25), Point::new(26, 0)];
    session.extend(req(
        61,
        &Request::SetCells {
            blocked: false,
            cells: Waypoints::Points(&pts),
        },
    ));
    session.extend(req(
        62,
        &Request::PlanWarm {
            start: Point::new(0, 0),
            goal: Point::new(25, 25),
            seed: Some(3),
        },
    ));
    out.push(("session-rle-updates".into(), session));
    // Protocol 6 and 7 singles: the largest request (SetCells with MAX_UPDATE_CELLS cells and the
    // longest id), a rectangle, a warm plan, first chunks of maps sized by cells (604 x 307 fits
    // 512 x 512's cells; 2048 x 1025 is over the twin's 2,097,152; 5000 x 10 over the side).
    let many_cells: Vec<Point> = (0..MAX_UPDATE_CELLS as u16)
        .map(|i| Point::new(u16::MAX - i, i * 7))
        .collect();
    out.push((
        "req-set-cells-max".into(),
        req(
            u32::MAX,
            &Request::SetCells {
                blocked: true,
                cells: Waypoints::Points(&many_cells),
            },
        ),
    ));
    out.push((
        "req-set-rect".into(),
        req(
            80,
            &Request::SetRect {
                x: 600,
                y: 300,
                width: 4,
                height: 7,
                blocked: false,
            },
        ),
    ));
    out.push((
        "req-plan-warm".into(),
        req(
            81,
            &Request::PlanWarm {
                start: Point::new(603, 306),
                goal: Point::new(0, 0),
                seed: None,
            },
        ),
    ));
    for (name, w, h) in [
        ("req-set-map-604x307", 604u16, 307u16),
        ("req-set-map-2048x1025", 2048, 1025),
        ("req-set-map-5000x10", 5000, 10),
    ] {
        let total = (u32::from(w) * u32::from(h)).div_ceil(8);
        out.push((
            name.into(),
            req(
                82,
                &Request::SetMap {
                    width: w,
                    height: h,
                    offset: 0,
                    total_len: total,
                    chunk: &[0x0f; 64],
                },
            ),
        ));
    }
    out.push((
        "req-set-map-rle-bad".into(),
        req(
            70,
            &Request::SetMapRle {
                width: 4,
                height: 3,
                offset: 0,
                total_len: 3,
                chunk: &[5, 1, 7],
            },
        ),
    ));

    // Replies, as the host reads them.
    let hello = HelloReply {
        protocol_version: VERSION,
        firmware_version: "0.1.0",
        board: "qemu-mps2-an386",
        capacity: Capacity {
            cells: 4096,
            max_side: 4096,
            max_steps: 1023,
            max_chunk: MAX_CHUNK as u16,
            max_request: MAX_REQUEST as u16,
            plan_queue: 4,
            tick_hz: 1_000_000,
            // The QEMU board's, from its description.
            window: ohaca::board::F411.window as u8,
            window_bytes: ohaca::board::F411.rx_ring as u16,
        },
        defaults: Params::default(),
    };
    out.push(("rep-hello".into(), rep(1, &Reply::Hello(hello))));
    // The STM32H743 twin's Hello: capacity by cells, the longest paths.
    let twin = HelloReply {
        board: "qemu-mps2-an386-twin-h743",
        capacity: Capacity {
            cells: 2_097_152,
            max_steps: MAX_STEPS as u32,
            ..hello.capacity
        },
        ..hello
    };
    out.push(("rep-hello-twin".into(), rep(1, &Reply::Hello(twin))));
    out.push(("rep-ack".into(), rep(2, &Reply::Ack)));
    let points = [
        Point::new(0, 0),
        Point::new(3, 2),
        Point::new(10, 10),
        Point::new(25, 25),
    ];
    let directions: Vec<u8> = (0..40).map(|i| (i % 3) as u8).collect();
    let path = PathReply {
        raw_length: 41.8,
        length: 39.15,
        turns: 2,
        iterations: 21,
        best_iteration: 7,
        moves: 4200,
        ticks: 1689,
        raw_cells: 41,
        origin: ohaca::planner::Origin::Warm,
        waypoints: Waypoints::Points(&points),
        directions: &directions,
    };
    out.push(("rep-path".into(), rep(10, &Reply::Path(path))));
    // The largest path the protocol allows, and a reply frame one byte over the host's buffer.
    let many: Vec<Point> = (0..MAX_WAYPOINTS as u16)
        .map(|i| Point::new(i, i / 3))
        .collect();
    let steps: Vec<u8> = (0..MAX_DIRECTIONS).map(|i| (i % 8) as u8).collect();
    let max_path = PathReply {
        waypoints: Waypoints::Points(&many),
        directions: &steps,
        ..path
    };
    out.push(("rep-path-max".into(), rep(14, &Reply::Path(max_path))));
    // The twin's longest path as it plans it: MAX_STEPS steps through sixteen corridors, 32
    // waypoints (`host/tests/qemu/twin_maps.rs`, the serpentine), about 16.5 KB.
    let corners: Vec<Point> = (0..32u16)
        .map(|i| Point::new(if (i + 1) % 4 < 2 { 1 } else { 1024 }, 1 + 2 * (i / 2)))
        .collect();
    let long: Vec<u8> = (0..MAX_STEPS).map(|i| [0, 2, 4][i % 3]).collect();
    let long_path = PathReply {
        waypoints: Waypoints::Points(&corners),
        directions: &long,
        raw_cells: MAX_STEPS as u32 + 1,
        ..path
    };
    out.push(("rep-path-long".into(), rep(15, &Reply::Path(long_path))));
    let mut over = vec![0x17u8; MAX_REPLY_WIRE];
    over.push(0);
    out.push(("rep-too-large".into(), over));
    out.push((
        "rep-error-busy".into(),
        rep(11, &Reply::Error(ErrorReply::with(ErrorCode::Busy, 4, 4))),
    ));
    out.push((
        "rep-error-badparam".into(),
        rep(
            12,
            &Reply::Error(ErrorReply::with(ErrorCode::BadParam, 3, 0)),
        ),
    ));
    out.push((
        "rep-error-unknown-id".into(),
        rep(0, &Reply::Error(ErrorReply::new(ErrorCode::BadCrc))),
    ));
    let stats = StatsReply {
        uptime: 123_456_789,
        boots: 1,
        frames_ok: 10,
        frames_bad: 1,
        rx_bytes: 999,
        tx_frames: 11,
        plans: 3,
        map_width: 26,
        map_height: 26,
        queued: 1,
        planning: true,
        stack_peak: 9000,
        ..StatsReply::default()
    };
    out.push(("rep-stats".into(), rep(13, &Reply::Stats(stats))));

    // Damaged frames: a flipped CRC byte, no delimiter, an overlong frame, lone delimiters.
    let mut bad = req(7, &Request::Stats);
    let n = bad.len();
    bad[n - 2] ^= 0x55;
    out.push(("bad-crc".into(), bad));
    let mut cut = req(8, &plan);
    cut.pop();
    out.push(("no-delimiter".into(), cut));
    let mut long = vec![0x42u8; MAX_REQUEST_WIRE + 5];
    long.push(0);
    long.extend(req(9, &Request::Hello));
    out.push(("too-large-then-hello".into(), long));
    out.push(("zeros".into(), vec![0, 0, 0]));
    Ok(out)
}

fn png(img: &RgbaImage) -> Vec<u8> {
    let mut v = Cursor::new(Vec::new());
    img.write_to(&mut v, ImageFormat::Png).expect("png encodes");
    v.into_inner()
}

fn pgm(img: &GrayImage) -> Vec<u8> {
    let mut v = Cursor::new(Vec::new());
    img.write_to(&mut v, ImageFormat::Pnm).expect("pgm encodes");
    v.into_inner()
}

fn with(sel: u8, body: &[u8]) -> Vec<u8> {
    let mut v = vec![sel];
    v.extend_from_slice(body);
    v
}

fn map_seeds(root: &Path) -> Result<Vec<(String, Vec<u8>)>> {
    let mut out = Vec::new();
    for f in [
        "maps/simple-18.map",
        "maps/complex-26.map",
        "maps/classic-20.map",
        "maps/movingai/random-32-32-10.map",
        "maps/movingai/random-32-32-20.map",
    ] {
        let name = Path::new(f)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("map");
        out.push((
            format!("movingai-{name}"),
            with(b'M', &fs::read(root.join(f))?),
        ));
    }
    let simple = Map::load(root.join("maps/simple-18.map"))?;
    out.push((
        "text-simple18".into(),
        with(b'T', simple.to_text().as_bytes()),
    ));
    out.push((
        "text-crlf-digits".into(),
        with(b'T', b"\xef\xbb\xbf0101\r\n1..#\r\n####\r\n\r\n"),
    ));
    out.push((
        "auto-movingai".into(),
        with(b'A', b"type octile\nwidth 4\nheight 2\nmap\nS.@T\nWG..\n"),
    ));
    out.push((
        "auto-named-map".into(),
        with(
            b'a',
            b"\xef\xbb\xbftype octile\r\nheight 2\r\nwidth 3\r\nmap\r\n..@\r\nO.S\r\n",
        ),
    ));

    // ROS: the shipped lab map, and small ones in each mode.
    let mut lab = fs::read(root.join("host/assets/ros/lab.yaml"))?;
    lab.push(0);
    lab.extend(fs::read(root.join("host/assets/ros/lab.pgm"))?);
    out.push(("ros-lab".into(), with(b'R', &lab)));
    let small = GrayImage::from_fn(12, 9, |x, y| {
        Luma([match (x + 2 * y) % 5 {
            0 => 0,
            1 => 205,
            2 => 100,
            _ => 254,
        }])
    });
    let yamls = [
        "image: small.pgm\nresolution: 0.1\norigin: [-1.0, 2.5, 0.3]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        "image: /abs/small.pgm\nresolution: 1\norigin: [0, 0]\nnegate: 1\nmode: scale\n",
        "image: small.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nmode: raw\noccupied_thresh: 0.5\nfree_thresh: 0.5\n",
    ];
    for (i, y) in yamls.iter().enumerate() {
        let mut v = y.as_bytes().to_vec();
        v.push(0);
        v.extend(pgm(&small));
        out.push((
            format!("ros-small-{i}"),
            with(if i == 1 { b'r' } else { b'R' }, &v),
        ));
    }
    let rgba = RgbaImage::from_fn(10, 7, |x, y| {
        Rgba([
            (x * 25) as u8,
            (y * 36) as u8,
            128,
            if x == 3 { 100 } else { 255 },
        ])
    });
    let mut v = yamls[2].as_bytes().to_vec();
    v.push(0);
    v.extend(png(&rgba));
    out.push(("ros-small-png".into(), with(b'R', &v)));

    // Plain images.
    out.push(("image-png".into(), with(b'I', &png(&rgba))));
    out.push(("image-pgm".into(), with(b'I', &pgm(&small))));
    out.push((
        "image-pgm-ascii".into(),
        with(b'I', b"P2\n3 2\n255\n0 255 128\n12 200 255\n"),
    ));
    Ok(out)
}

fn write(dir: &Path, seeds: &[(String, Vec<u8>)]) -> Result<()> {
    fs::create_dir_all(dir)?;
    for (name, bytes) in seeds {
        fs::write(dir.join(name), bytes)?;
    }
    println!("{}: {} seeds", dir.display(), seeds.len());
    Ok(())
}

fn main() -> Result<()> {
    let fuzz = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let root = fuzz.parent().ok_or("no repository root")?.to_path_buf();
    write(&fuzz.join("seeds/wire_frame"), &wire_frame_seeds(&root)?)?;
    write(&fuzz.join("seeds/map_parsers"), &map_seeds(&root)?)?;
    Ok(())
}
