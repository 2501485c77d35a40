//! Figures in the documents that a test can produce, checked here so they cannot go stale
//! (the byte-exact example of `docs/PROTOCOL.md`, and that its plan is the core's, are checked by
//! `src/protocol/tests/document.rs`):
//!
//! - the request size limits of `docs/PROTOCOL.md`: the reader's 259 COBS bytes (delimiter not
//!   counted), `TooLarge` reporting the frame's whole length, and the largest request's size;
//! - its reply limits: `MAX_STEPS`, `MAX_WAYPOINTS`, `MAX_DIRECTIONS`, `MAX_REPLY` and
//!   `MAX_REPLY_WIRE`, and that the widest path reply is exactly `MAX_REPLY` bytes;
//! - the widest path reply in parts (its body, its parts, the largest part and all of them on the
//!   wire) and the STM32F411's path steps per layout, in `docs/PROTOCOL.md` and
//!   `docs/FIRMWARE.md`;
//! - the parameter table of `docs/ALGORITHM.md` against `Params::default()` and `Params::paper()`.

use ohaca::protocol::{
    encode_reply, encode_request, Feed, PathBody, PathPart, PathReply, Reply, Request,
    RequestReader, Waypoints, MAX_CHUNK, MAX_DIRECTIONS, MAX_REPLY, MAX_REPLY_WIRE, MAX_REQUEST,
    MAX_REQUEST_WIRE, MAX_STEPS, MAX_UPDATE_CELLS, MAX_WAYPOINTS, PART_BYTES, VERSION,
};
use ohaca::{DeadEnd, Params, Point, SmoothingKind};

fn doc(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The number after `label` in `text` (digits, possibly with a thousands separator).
fn number_after(text: &str, label: &str) -> u64 {
    let at = text
        .find(label)
        .unwrap_or_else(|| panic!("{label:?} not in the document"));
    text[at + label.len()..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == ',')
        .filter(|c| c.is_ascii_digit())
        .collect::<String>()
        .parse()
        .unwrap_or_else(|_| panic!("no number after {label:?}"))
}

#[test]
fn the_request_size_limits_are_the_documents() {
    let text = doc("PROTOCOL.md");
    assert_eq!(number_after(&text, "| `MAX_REQUEST` |"), MAX_REQUEST as u64);
    assert_eq!(
        number_after(&text, "its reader holds `MAX_REQUEST_WIRE` ="),
        MAX_REQUEST_WIRE as u64
    );
    // The reader holds MAX_REQUEST_WIRE bytes before the delimiter, not counting it.
    let feed = |n: usize| {
        let mut r = RequestReader::new();
        for _ in 0..n {
            assert!(matches!(r.push(0x01), Feed::Pending));
        }
        match r.push(0) {
            Feed::Frame(f) => Ok(f.len()),
            Feed::TooLarge { len } => Err(len),
            Feed::Pending => panic!("no frame"),
        }
    };
    assert_eq!(feed(MAX_REQUEST_WIRE), Ok(MAX_REQUEST_WIRE));
    // One more: dropped, and TooLarge reports the frame's whole length (without the 00).
    assert_eq!(feed(MAX_REQUEST_WIRE + 1), Err(MAX_REQUEST_WIRE + 1));
    assert_eq!(feed(1000), Err(1000));
    // COBS makes at most 258 bytes of a 256-byte payload (one code byte per 254, plus one).
    let most = number_after(&text, "(at most");
    assert_eq!(most as usize, MAX_REQUEST + MAX_REQUEST.div_ceil(254));
    assert!(most as usize <= MAX_REQUEST_WIRE);
    // The largest request: a SetCells with MAX_UPDATE_CELLS cells (with the longest id); a
    // SetMap with a full chunk and every number at its longest varint comes next.
    let cells = [0xffu8; 4 * MAX_UPDATE_CELLS];
    let set_cells = Request::SetCells {
        blocked: true,
        cells: Waypoints::Packed(&cells),
    };
    let largest = number_after(
        &text,
        "the largest request, a `SetCells` with 60 cells and the largest id, is",
    );
    assert_eq!(
        largest as usize,
        postcard_len(&set_cells),
        "docs/PROTOCOL.md: the largest request's size"
    );
    assert!(largest as usize <= MAX_REQUEST);
    let big = [0xffu8; MAX_CHUNK];
    let req = Request::SetMap {
        width: u16::MAX,
        height: u16::MAX,
        offset: u32::MAX,
        total_len: u32::MAX,
        chunk: &big,
    };
    assert_eq!(
        number_after(&text, "(a `SetMap` with a full chunk:") as usize,
        postcard_len(&req)
    );
    assert!(postcard_len(&req) < largest as usize);
    let params = Request::SetParams(Params {
        seed: u64::MAX,
        ants: u16::MAX,
        iterations: u16::MAX,
        patience: u16::MAX,
        ..Params::default()
    });
    assert!(postcard_len(&params) < largest as usize);
}

#[test]
fn the_reply_size_limits_are_the_documents() {
    let text = doc("PROTOCOL.md");
    assert_eq!(
        number_after(&text, "# ohaca wire protocol, version"),
        u64::from(VERSION)
    );
    assert_eq!(number_after(&text, "| `MAX_STEPS` |"), MAX_STEPS as u64);
    assert_eq!(
        number_after(&text, "| `MAX_WAYPOINTS` |"),
        MAX_WAYPOINTS as u64
    );
    assert_eq!(
        number_after(&text, "| `MAX_DIRECTIONS` |"),
        MAX_DIRECTIONS as u64
    );
    assert_eq!(number_after(&text, "| `MAX_REPLY` |"), MAX_REPLY as u64);
    assert_eq!(
        number_after(&text, "reader needs `MAX_REPLY_WIRE` ="),
        MAX_REPLY_WIRE as u64
    );
    // The widest path reply (every field at its longest varint, every step a waypoint) is
    // exactly MAX_REPLY bytes of payload, and fits MAX_REPLY_WIRE on the wire.
    let points = vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS];
    let dirs = vec![7u8; MAX_DIRECTIONS];
    let widest = Reply::Path(widest_path(&points, &dirs));
    let mut buf = vec![0u8; MAX_REPLY_WIRE];
    let n = encode_reply(u32::MAX, &widest, &mut buf).expect("the widest path fits");
    assert_eq!(decoded_len(&buf[..n - 1]), MAX_REPLY);
}

/// The widest path reply: every field at its longest varint, every step a waypoint.
fn widest_path<'a>(points: &'a [Point], dirs: &'a [u8]) -> PathReply<'a> {
    PathReply {
        raw_length: f32::MAX,
        length: f32::MAX,
        turns: u32::MAX,
        iterations: u16::MAX,
        best_iteration: u16::MAX,
        moves: u64::MAX,
        ticks: u64::MAX,
        raw_cells: u32::MAX,
        origin: ohaca::planner::Origin::Reused,
        waypoints: Waypoints::Points(points),
        directions: dirs,
    }
}

/// `n` with a space between thousands, as the documents write figures ("81 975").
fn spaced(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// The widest path reply in parts, as a device sends it: its body (`MAX_REPLY` less the id, the
/// variant and the CRC), how many parts, the largest part on the wire (offset and `total_len`
/// fit three varint bytes, not the five `PART_BYTES`' bound allows), and every part on the wire.
#[test]
fn the_widest_reply_in_parts_is_the_documents() {
    let points = vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS];
    let dirs = vec![7u8; MAX_DIRECTIONS];
    let path = widest_path(&points, &dirs);
    let body = PathBody::new(&path).expect("the widest body");
    let total = body.len();
    let (mut offset, mut parts, mut largest, mut wire) = (0, 0, 0, 0);
    let mut bytes = [0u8; PART_BYTES];
    let mut frame = vec![0u8; 512];
    while offset < total {
        let k = body.read(offset, &mut bytes);
        let part = PathPart {
            offset: offset as u32,
            total_len: total as u32,
            bytes: &bytes[..k],
        };
        let n = encode_reply(u32::MAX, &Reply::PathPart(part), &mut frame).expect("a part");
        (parts, largest, wire) = (parts + 1, largest.max(n), wire + n);
        offset += k;
    }
    assert_eq!((total, parts, largest, wire), (81_975, 427, 212, 90_428));
    let text = doc("PROTOCOL.md");
    for want in [
        format!("{} bytes of body", spaced(total)),
        format!("{parts} parts, {} bytes on the wire", spaced(wire)),
        format!("a part is at most {largest} bytes on the wire"),
        format!("at most {largest} bytes on the wire: "),
    ] {
        assert!(text.contains(&want), "PROTOCOL.md lacks {want:?}");
    }
}

/// The STM32F411's (and the default QEMU board's) path steps: `Hello`'s `max_steps`, the full
/// layout's steps up to the largest map that has it, and the compact layout's on the largest maps,
/// as docs/PROTOCOL.md's `Capacity` and docs/FIRMWARE.md say.
#[test]
fn the_f411_steps_are_the_documents() {
    use ohaca::board::{Layout, F411};
    use ohaca::planner::arena::steps_for;
    let Layout::Arena { words } = F411.layout else {
        panic!("the F411 has an arena")
    };
    let steps = |cells| steps_for(words, cells, F411.max_steps).expect("it takes the map");
    assert_eq!(F411.max_steps, 4095);
    // The full layout's largest map, and the compact layout's first and largest.
    let full = (1..=F411.cells)
        .rev()
        .find(|&c| !steps(c).1)
        .expect("a map in the full layout");
    assert_eq!((full, steps(full)), (68_256, (2047, false)));
    for cells in [full + 1, 512 * 506, 512 * 512] {
        assert_eq!(steps(cells), (4095, true), "{cells} cells");
    }
    let capacity = format!(
        "{} on the QEMU board and the STM32F411 (ant paths of up to {} steps on maps of up to {} \
         cells, the full layout; {} on every larger map they take, 512 x 512 included)",
        spaced(F411.max_steps),
        spaced(steps(full).0),
        spaced(full),
        spaced(steps(F411.cells).0)
    );
    let protocol = doc("PROTOCOL.md").replace('\n', " ");
    assert!(
        protocol.contains(&capacity),
        "PROTOCOL.md lacks {capacity:?}"
    );
    let firmware = doc("FIRMWARE.md").replace('\n', " ");
    for want in [
        format!("`max_steps` = {}", spaced(F411.max_steps)),
        format!(
            "{} steps on maps of up to {} cells",
            spaced(steps(full).0),
            spaced(full)
        ),
    ] {
        assert!(firmware.contains(&want), "FIRMWARE.md lacks {want:?}");
    }
}

/// Payload bytes (postcard + CRC) of `req` with the longest id.
fn postcard_len(req: &Request<'_>) -> usize {
    let mut buf = [0u8; 2 * MAX_REQUEST_WIRE];
    let n = encode_request(u32::MAX, req, &mut buf).expect("encode");
    decoded_len(&buf[..n - 1])
}

/// Bytes of a COBS frame (without its delimiter) once decoded: what the reader hands the decoder.
fn decoded_len(body: &[u8]) -> usize {
    let mut out = Vec::new();
    let mut i = 0;
    while i < body.len() {
        let code = body[i] as usize;
        out.extend_from_slice(&body[i + 1..i + code]);
        i += code;
        if code != 0xff && i < body.len() {
            out.push(0);
        }
    }
    out.len()
}

#[test]
fn the_parameter_table_is_the_cores() {
    let text = doc("ALGORITHM.md");
    let row = |name: &str| -> Vec<String> {
        // The last such row: the parameter table ends the document (another table may start
        // with a parameter's name, as the warm-start one does).
        let line = text
            .lines()
            .rev()
            .find(|l| l.starts_with(&format!("| `{name}` |")))
            .unwrap_or_else(|| panic!("no row for {name} in ALGORITHM.md's parameter table"));
        line.split('|').map(|c| c.trim().to_string()).collect()
    };
    let (d, p) = (Params::default(), Params::paper());
    let num = |s: &str| s.parse::<f32>().unwrap_or_else(|_| panic!("{s:?}"));
    for (name, dv, pv) in [
        ("alpha", d.alpha, p.alpha),
        ("beta", d.beta, p.beta),
        ("rho", d.rho, p.rho),
        ("q", d.q, p.q),
        ("a", d.a, p.a),
        ("xi", d.xi, p.xi),
        ("ants", f32::from(d.ants), f32::from(p.ants)),
        (
            "iterations",
            f32::from(d.iterations),
            f32::from(p.iterations),
        ),
        ("patience", f32::from(d.patience), f32::from(p.patience)),
        (
            "warm_patience",
            f32::from(d.warm_patience),
            f32::from(p.warm_patience),
        ),
        (
            "refine_patience",
            f32::from(d.refine_patience),
            f32::from(p.refine_patience),
        ),
    ] {
        let r = row(name);
        assert_eq!(
            (num(&r[2]), num(&r[3])),
            (dv, pv),
            "ALGORITHM.md row {name}"
        );
    }
    let words = |name: &str| {
        let r = row(name);
        (r[2].clone(), r[3].clone())
    };
    let dead = |x: DeadEnd| x.name().to_string();
    assert_eq!(words("dead_end"), (dead(d.dead_end), dead(p.dead_end)));
    let smooth = |k: SmoothingKind| {
        match k {
            SmoothingKind::Shortest => "shortest",
            SmoothingKind::Greedy => "greedy",
            SmoothingKind::None => "none",
        }
        .to_string()
    };
    assert_eq!(
        words("smoothing"),
        (smooth(d.smoothing), smooth(p.smoothing))
    );
    let on = |b: bool| if b { "on" } else { "off" }.to_string();
    assert_eq!(words("tighten"), (on(d.tighten), on(p.tighten)));
    assert_eq!(words("prune"), (on(d.prune), on(p.prune)));
    assert_eq!(words("refine"), (on(d.refine), on(p.refine)));
}
