//! The byte-exact examples of docs/PROTOCOL.md, "Big maps and cell updates": their bytes, what
//! they do to the map, and `print_protocol_doc_map_examples` (ignored) to regenerate them.

use super::map::{chunk, rle, LIMITS};
use super::*;

// ---- docs/PROTOCOL.md, "Big maps and cell updates": byte-exact examples ------------------------

/// The examples of the section, in order: each request with its reply.
fn doc_examples() -> Vec<(u32, Request<'static>, Reply<'static>)> {
    const CODE: [u8; 3] = [5, 1, 6];
    const CELLS: [Point; 2] = [Point::new(2, 0), Point::new(2, 1)];
    const WALL: [Point; 1] = [Point::new(3, 1)];
    vec![
        (
            5,
            Request::SetMapRle {
                width: 4,
                height: 3,
                offset: 0,
                total_len: 3,
                chunk: &CODE,
            },
            Reply::Ack,
        ),
        (
            6,
            Request::SetRect {
                x: 1,
                y: 1,
                width: 3,
                height: 1,
                blocked: true,
            },
            Reply::Ack,
        ),
        (
            7,
            Request::SetCells {
                blocked: false,
                cells: Waypoints::Points(&CELLS),
            },
            Reply::Ack,
        ),
        (
            8,
            Request::SetRect {
                x: 2,
                y: 2,
                width: 3,
                height: 1,
                blocked: true,
            },
            Reply::Error(ErrorReply::with(ErrorCode::OutsideMap, 4, 2)),
        ),
        (
            9,
            Request::PlanWarm {
                start: Point::new(0, 2),
                goal: Point::new(3, 2),
                seed: None,
            },
            Reply::Error(ErrorReply::with(ErrorCode::Cancelled, 0, 0)),
        ),
        (
            10,
            Request::SetCells {
                blocked: true,
                cells: Waypoints::Points(&WALL),
            },
            Reply::Ack,
        ),
    ]
}

#[test]
fn protocol_doc_map_examples_are_exact() {
    let doc = include_str!("../../../docs/PROTOCOL.md");
    let (mut rq, mut rqw, mut rp, mut rpw) = (vec![], vec![], vec![], vec![]);
    for (id, req, rep) in doc_examples() {
        let f = enc_req(id, &req);
        rq.extend(payload_of(&f));
        rqw.extend(f);
        let f = enc_rep(id, &rep);
        rp.extend(payload_of(&f));
        rpw.extend(f);
    }
    let hint = "docs/PROTOCOL.md (Big maps and cell updates) drifted: regenerate with \
        `cargo test -p ohaca --lib --target host-tuple print_protocol_doc_map_examples -- \
        --ignored --nocapture`";
    assert_eq!(doc_bytes(doc, "-> "), rq, "{hint}");
    assert_eq!(doc_bytes(doc, "}> "), rqw, "{hint}");
    assert_eq!(doc_bytes(doc, "<- "), rp, "{hint}");
    assert_eq!(doc_bytes(doc, "<{ "), rpw, "{hint}");
    // The RLE code in the text is the map's.
    assert_eq!(rle(&[0x20, 0x00], 12), [5, 1, 6]);
}

/// What the examples do to the 4x3 map, applied here: the map after each, and that the
/// replies are what the device's rules give.
#[test]
fn protocol_doc_map_examples_are_what_the_rules_give() {
    let mut map = [0u8; 2];
    let mut up = Upload::new();
    let ex = doc_examples();
    let Request::SetMapRle {
        width,
        height,
        offset,
        total_len,
        chunk: c,
    } = ex[0].1
    else {
        panic!()
    };
    let m = chunk(Encoding::Rle, width, height, offset, total_len, c);
    assert_eq!(up.accept(&m, LIMITS), Ok(true));
    assert_eq!(up.write(&m, &mut map), Ok(Some((4, 3))));
    assert_eq!(map[0], 0x20);
    for (_, req, rep) in ex[1..4].iter().chain(&ex[5..]) {
        let got = match *req {
            Request::SetRect {
                x,
                y,
                width,
                height,
                blocked,
            } => set_rect((4, 3), &mut map, (x, y, width, height), blocked),
            Request::SetCells { blocked, cells } => set_cells((4, 3), &mut map, &cells, blocked),
            _ => panic!(),
        };
        let got = match got {
            Ok(()) => Reply::Ack,
            Err(e) => Reply::Error(e),
        };
        assert_eq!(&got, rep);
    }
    // Row 1 blocked from x 1 to 3, then (2, 1) cleared: cells 5 and 7 blocked ((3, 1) again).
    assert_eq!(map[0], 0xA0);
    assert_eq!(map[1] & 0x0F, 0);
}

#[test]
#[ignore = "prints the examples of docs/PROTOCOL.md, Big maps and cell updates"]
fn print_protocol_doc_map_examples() {
    for (id, req, rep) in doc_examples() {
        println!("\n# {req:?}");
        let f = enc_req(id, &req);
        println!("-> {:<48}; payload", hex(&payload_of(&f)));
        println!("}}> {}", hex(&f));
        println!("# {rep:?}");
        let f = enc_rep(id, &rep);
        println!("<- {:<48}; payload", hex(&payload_of(&f)));
        println!("<{{ {}", hex(&f));
    }
}
