//! Tests of the link against a fake device in memory, and the upload sizes of real maps.

#[cfg(test)]
mod fake_device {
    use crate::link::*;
    use ohaca::protocol::{decode_request, encode_reply, RequestReader};

    /// The fake device's script: the replies to one request.
    type Answer = dyn FnMut(u32, Request<'_>) -> Vec<(u32, Response)>;

    /// A fake device: answers requests written to it from a scripted function.
    struct Fake {
        input: RequestReader,
        out: VecDeque<u8>,
        answer: Box<Answer>,
        timeouts: u32,
    }

    fn encode(id: u32, r: &Response) -> Vec<u8> {
        let mut buf = vec![0u8; MAX_REPLY_WIRE];
        let (pts, hello);
        let reply = match r {
            Response::Hello(h) => {
                hello = h.clone();
                Reply::Hello(HelloReply {
                    protocol_version: hello.protocol_version,
                    firmware_version: &hello.firmware_version,
                    board: &hello.board,
                    capacity: hello.capacity,
                    defaults: hello.defaults,
                })
            }
            Response::Ack => Reply::Ack,
            Response::Path(p) => {
                pts = p.clone();
                Reply::Path(pts.reply())
            }
            Response::Error(e) => Reply::Error(*e),
            Response::Stats(s) => Reply::Stats(*s),
            Response::Part(p) => Reply::PathPart(ohaca::protocol::PathPart {
                offset: p.offset,
                total_len: p.total_len,
                bytes: &p.bytes,
            }),
        };
        let n = encode_reply(id, &reply, &mut buf).unwrap();
        buf.truncate(n);
        buf
    }

    impl Read for Fake {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.out.is_empty() {
                self.timeouts += 1;
                return Err(io::Error::new(io::ErrorKind::TimedOut, "nothing"));
            }
            let n = buf.len().min(self.out.len()).min(7);
            for (slot, b) in buf.iter_mut().zip(self.out.drain(..n)) {
                *slot = b;
            }
            Ok(n)
        }
    }

    impl Write for Fake {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            for &b in buf {
                if let Some(Ok(f)) = self.input.push(b).into_frame(MAX_REQUEST_WIRE) {
                    let (id, req) = decode_request(f).unwrap();
                    for (rid, r) in (self.answer)(id, req) {
                        self.out.extend(encode(rid, &r));
                    }
                }
            }
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Transport for Fake {
        fn set_io_timeout(&mut self, _: Duration) -> io::Result<()> {
            Ok(())
        }
    }

    fn fake(answer: impl FnMut(u32, Request<'_>) -> Vec<(u32, Response)> + 'static) -> Link<Fake> {
        Link::new(
            Fake {
                input: RequestReader::new(),
                out: VecDeque::new(),
                answer: Box::new(answer),
                timeouts: 0,
            },
            Duration::from_millis(50),
        )
        .unwrap()
    }

    fn info(queue: u8) -> DeviceInfo {
        DeviceInfo {
            protocol_version: VERSION,
            firmware_version: "0.1.0".into(),
            board: "fake".into(),
            capacity: Capacity {
                cells: 1024,
                max_side: 1024,
                max_steps: 1023,
                max_chunk: 100,
                max_request: 256,
                plan_queue: queue,
                tick_hz: 1_000_000,
                window: 8,
                window_bytes: 1024,
            },
            defaults: Params::default(),
        }
    }

    fn path(seed: u64) -> DevicePath {
        DevicePath {
            raw_length: 1.0,
            length: 1.0,
            turns: 0,
            iterations: 1,
            best_iteration: 0,
            moves: seed,
            ticks: 5,
            raw_cells: 2,
            origin: ohaca::planner::Origin::Cold,
            waypoints: vec![Point::new(0, 0), Point::new(1, 0)],
            directions: vec![0],
        }
    }

    /// `p`'s body in parts of `size` bytes, as a device sends a long path.
    fn parts(p: &DevicePath, size: usize) -> Vec<Response> {
        let body = ohaca::protocol::PathBody::new(&p.reply()).unwrap();
        let mut bytes = vec![0u8; body.len()];
        assert_eq!(body.read(0, &mut bytes), body.len());
        bytes
            .chunks(size)
            .enumerate()
            .map(|(k, c)| {
                Response::Part(OwnedPart {
                    offset: (k * size) as u32,
                    total_len: bytes.len() as u32,
                    bytes: c.to_vec(),
                })
            })
            .collect()
    }

    #[test]
    fn the_parts_of_a_long_path_are_one_path_and_other_replies_pass_them() {
        let long = DevicePath {
            waypoints: (0..300).map(|i| Point::new(i, i)).collect(),
            directions: vec![1; 299],
            raw_cells: 300,
            ..path(9)
        };
        let want = long.clone();
        let mut plan_id = 0;
        let mut link = fake(move |id, req| match req {
            Request::Hello => vec![(id, Response::Hello(info(4)))],
            Request::Plan { .. } => {
                plan_id = id;
                vec![]
            }
            // The Stats reply overtakes the path: it comes between its parts.
            Request::Stats => {
                let mut out: Vec<(u32, Response)> = Vec::new();
                let mut p = parts(&long, 192).into_iter().map(|r| (plan_id, r));
                out.extend(p.by_ref().take(2));
                out.push((id, Response::Stats(StatsReply::default())));
                out.extend(p);
                out
            }
            _ => vec![(id, Response::Ack)],
        });
        link.hello().unwrap();
        let plan = link
            .send(&Request::Plan {
                start: Point::new(0, 0),
                goal: Point::new(299, 299),
                seed: None,
            })
            .unwrap();
        assert_eq!(link.unanswered(), 1);
        assert_eq!(link.stats().unwrap(), StatsReply::default());
        assert_eq!(link.wait_for(plan, "Plan").unwrap(), Response::Path(want));
        assert_eq!(link.unanswered(), 0);
        assert_eq!(link.stray_count(), 0);
    }

    #[test]
    fn parts_out_of_order_are_an_error_and_a_cancel_drops_the_parts() {
        let long = DevicePath {
            waypoints: (0..100).map(|i| Point::new(i, 0)).collect(),
            directions: vec![0; 99],
            raw_cells: 100,
            ..path(3)
        };
        let mut a = Assembler::default();
        let p = parts(&long, 100);
        assert!(p.len() >= 3);
        assert_eq!(a.push(5, p[0].clone()), Ok(None));
        assert_eq!(a.pending(), 1);
        // Cancelled after one part: the reply ends the parts.
        let cancelled = Response::Error(ErrorReply::new(ErrorCode::Cancelled));
        assert_eq!(a.push(5, cancelled.clone()), Ok(Some(cancelled)));
        assert_eq!(a.pending(), 0);
        // A part that skips one is refused.
        assert_eq!(a.push(6, p[0].clone()), Ok(None));
        assert!(a.push(6, p[2].clone()).is_err());
        // In order, the path.
        let mut got = None;
        for r in p {
            got = a.push(7, r).unwrap();
        }
        assert_eq!(got, Some(Response::Path(long)));
    }

    #[test]
    fn ids_increase_and_strays_are_skipped() {
        let mut link = fake(|id, req| match req {
            // A stray id-0 error and a reply to nobody before the real answer.
            Request::Hello => vec![
                (0, Response::Error(ErrorReply::new(ErrorCode::BadCrc))),
                (77, Response::Ack),
                (id, Response::Hello(info(4))),
            ],
            _ => vec![(id, Response::Ack)],
        });
        assert_eq!(link.next_id(), 1);
        let h = link.hello().unwrap();
        assert_eq!(h.board, "fake");
        assert_eq!(link.next_id(), 2);
        link.cancel().unwrap();
        assert_eq!(link.next_id(), 3);
        assert_eq!(link.stray_count(), 2);
        let s = link.take_strays();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].to_string(), "reply 0: error 16 (bad CRC)");
        assert_eq!(s[1].to_string(), "reply 77: Ack");
    }

    #[test]
    fn timeouts_and_device_errors_are_typed() {
        let mut link = fake(|id, req| match req {
            Request::Stats => vec![],
            _ => vec![(
                id,
                Response::Error(ErrorReply::with(ErrorCode::MapTooLarge, 1600, 1024)),
            )],
        });
        let e = link.stats().unwrap_err();
        assert!(matches!(e, LinkError::Timeout { id: 1, .. }), "{e}");
        assert_eq!(e.to_string(), "no reply to Stats (request 1) within 0.05 s");
        let m = Map::from_fn(40, 40, |_, _| false);
        let e = link.set_map(&m).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::MapTooLarge));
        assert_eq!(
            e.to_string(),
            "device refused SetMapRle: map too large (1600 over the limit 1024) (error code 2)"
        );
    }

    #[test]
    fn version_mismatch_is_refused() {
        let mut link = fake(|id, _| {
            let mut i = info(4);
            i.protocol_version = VERSION + 1;
            vec![(id, Response::Hello(i))]
        });
        assert!(matches!(link.hello(), Err(LinkError::Version { .. })));
    }

    #[test]
    fn maps_go_in_chunks_of_the_device() {
        let chunks = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let seen = chunks.clone();
        let mut link = fake(move |id, req| match req {
            Request::Hello => vec![(id, Response::Hello(info(4)))],
            Request::SetMap {
                offset,
                total_len,
                chunk,
                ..
            } => {
                seen.borrow_mut().push((offset, total_len, chunk.len()));
                vec![(id, Response::Ack)]
            }
            _ => vec![],
        });
        // Without a Hello: MAX_CHUNK. A checkerboard: its run-length code is longer, so raw.
        let m = Map::from_fn(32, 32, |x, y| (x + y) % 2 == 0);
        link.set_map(&m).unwrap();
        assert_eq!(*chunks.borrow(), vec![(0, 128, MAX_CHUNK)]);
        chunks.borrow_mut().clear();
        link.hello().unwrap();
        link.set_map(&m).unwrap();
        assert_eq!(*chunks.borrow(), vec![(0, 128, 100), (100, 128, 28)]);
    }

    /// A fake device that applies uploads and cell updates with the protocol's own state
    /// machine (`ohaca::protocol::Upload`), answering each chunk only when the next request
    /// arrives or the window would stall, so the link's window is exercised.
    #[test]
    fn maps_go_run_length_coded_when_shorter_and_arrive_whole() {
        use ohaca::protocol::{set_cells, set_rect, Encoding, MapChunk, MapLimits, Upload};
        use std::cell::RefCell;
        use std::rc::Rc;
        let limits = MapLimits {
            max_cells: 512 * 512,
            max_side: 512,
        };
        let state = Rc::new(RefCell::new((
            Upload::new(),
            vec![0u8; limits.bytes()],
            None::<(u16, u16)>,
            Vec::<&'static str>::new(),
        )));
        let st = state.clone();
        let mut link = fake(move |id, req| {
            let mut g = st.borrow_mut();
            let (up, buf, size, log) = &mut *g;
            log.push(request_name(&req));
            let chunk = match req {
                Request::SetMap {
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                } => Some((Encoding::Raw, width, height, offset, total_len, chunk)),
                Request::SetMapRle {
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                } => Some((Encoding::Rle, width, height, offset, total_len, chunk)),
                _ => None,
            };
            let r = if let Some((encoding, width, height, offset, total_len, chunk)) = chunk {
                let c = MapChunk {
                    encoding,
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                };
                up.accept(&c, limits).and_then(|start| {
                    if start {
                        *size = None;
                    }
                    up.write(&c, buf).map(|done| {
                        if done.is_some() {
                            *size = done;
                        }
                    })
                })
            } else {
                match (req, *size) {
                    (
                        Request::SetRect {
                            x,
                            y,
                            width,
                            height,
                            blocked,
                        },
                        Some(sz),
                    ) => set_rect(sz, buf, (x, y, width, height), blocked),
                    (Request::SetCells { blocked, cells }, Some(sz)) => {
                        set_cells(sz, buf, &cells, blocked)
                    }
                    _ => Err(ErrorReply::new(ErrorCode::NoMap)),
                }
            };
            vec![(
                id,
                match r {
                    Ok(()) => Response::Ack,
                    Err(e) => Response::Error(e),
                },
            )]
        });
        // A 256x256 map of long runs: run-length coded, far fewer bytes than 8 KiB.
        let m = Map::from_fn(256, 256, |x, y| (x / 16 + y / 32) % 3 == 0 && y % 7 != 0);
        let code = MapCode::of(&m);
        assert!(matches!(code, MapCode::Rle(_)));
        assert!(
            code.bytes().len() < m.bits.len() / 2,
            "{}",
            code.bytes().len()
        );
        link.set_map(&m).unwrap();
        {
            let g = state.borrow();
            assert_eq!(g.2, Some((256, 256)));
            assert!(
                (0..65536).all(|i| (g.1[i / 8] >> (i % 8)) & 1 == (m.bits[i / 8] >> (i % 8)) & 1)
            );
            assert!(g.3.iter().all(|n| *n == "SetMapRle"));
            assert_eq!(g.3.len(), code.bytes().len().div_ceil(MAX_CHUNK));
        }
        // Cell updates change the device's map.
        link.set_rect((1, 1), (3, 2), true).unwrap();
        let many: Vec<Point> = (0..130).map(|i| Point::new(i, 200)).collect();
        link.set_cells(&many, true).unwrap();
        {
            let g = state.borrow();
            let at = |x: usize, y: usize| (g.1[(y * 256 + x) / 8] >> ((y * 256 + x) % 8)) & 1 == 1;
            assert!(at(1, 1) && at(3, 2) && at(129, 200));
            // 130 cells went as 60 + 60 + 10.
            assert_eq!(g.3.iter().filter(|n| **n == "SetCells").count(), 3);
        }
        let e = link.set_rect((250, 0), (10, 1), false).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::OutsideMap));
        // A broken run-length code: the error of its chunk, and no stray afterwards.
        let bad = MapCode::Rle(vec![0xFF; 300]);
        let e = link.upload(16, 16, &bad).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::BadRle), "{e}");
        assert_eq!(state.borrow().2, None);
        assert_eq!(link.stray_count(), 0);
        assert!(link.outstanding.is_empty());
    }

    #[test]
    fn plan_many_pipelines_and_keeps_order() {
        // The fake answers plans only once 3 are waiting (or the last job arrives), newest
        // first, and refuses goal x = 9 at once: the link must keep 3 in flight and still
        // return the outcomes in job order.
        let jobs: Vec<PlanJob> = (0..9)
            .map(|k| PlanJob {
                start: Point::new(0, 0),
                goal: Point::new(if k == 4 { 9 } else { 1 }, 0),
                seed: Some(k),
            })
            .collect();
        let mut link2 = {
            let mut waiting: Vec<(u32, Option<u64>)> = Vec::new();
            fake(move |id, req| match req {
                Request::Hello => vec![(id, Response::Hello(info(3)))],
                Request::Plan { seed, goal, .. } => {
                    if goal.x == 9 {
                        return vec![(
                            id,
                            Response::Error(ErrorReply::new(ErrorCode::GoalBlocked)),
                        )];
                    }
                    waiting.push((id, seed));
                    if waiting.len() < 3 && seed != Some(8) {
                        return vec![];
                    }
                    waiting
                        .drain(..)
                        .rev()
                        .map(|(i, s)| (i, Response::Path(path(s.unwrap_or(0)))))
                        .collect()
                }
                _ => vec![],
            })
        };
        link2.hello().unwrap();
        let out = link2.plan_many(&jobs).unwrap();
        assert_eq!(out.len(), 9);
        for (k, o) in out.iter().enumerate() {
            if k == 4 {
                assert_eq!(o.result.as_ref().unwrap_err().code, ErrorCode::GoalBlocked);
            } else {
                assert_eq!(o.result.as_ref().unwrap().moves, k as u64, "{k}");
            }
        }
        let ids: Vec<u32> = out.iter().map(|o| o.id).collect();
        let mut sorted = ids.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 9, "distinct ids {ids:?}");
        assert_eq!(link2.stray_count(), 0);
    }

    #[test]
    fn busy_plans_are_sent_again() {
        let mut refused = 0;
        let mut link = fake(move |id, req| match req {
            Request::Hello => vec![(id, Response::Hello(info(2)))],
            Request::Plan { seed, .. } => {
                if seed == Some(1) && refused < 2 {
                    refused += 1;
                    return vec![(id, Response::Error(ErrorReply::with(ErrorCode::Busy, 2, 2)))];
                }
                vec![(id, Response::Path(path(seed.unwrap_or(0))))]
            }
            _ => vec![],
        });
        link.hello().unwrap();
        let jobs: Vec<PlanJob> = (0..3)
            .map(|k| PlanJob {
                start: Point::new(0, 0),
                goal: Point::new(1, 0),
                seed: Some(k),
            })
            .collect();
        let out = link.plan_many(&jobs).unwrap();
        let moves: Vec<u64> = out
            .iter()
            .map(|o| o.result.as_ref().unwrap().moves)
            .collect();
        assert_eq!(moves, vec![0, 1, 2]);
    }

    #[test]
    fn raw_paths_follow_the_directions() {
        let p = raw_path(Point::new(1, 1), &[0, 1, 2, 3, 4, 5, 6, 7]).unwrap();
        let xy: Vec<(u16, u16)> = p.iter().map(|p| (p.x, p.y)).collect();
        assert_eq!(
            xy,
            vec![
                (1, 1),
                (2, 1),
                (3, 2),
                (3, 3),
                (2, 4),
                (1, 4),
                (0, 3),
                (0, 2),
                (1, 1)
            ]
        );
        assert!(raw_path(Point::new(0, 0), &[8]).is_err());
        assert!(raw_path(Point::new(0, 0), &[4]).is_err());
    }
}

/// Upload sizes of real maps, raw against run-length coded, in bytes on the wire (frames
/// included) and seconds at 115200 baud: `cargo test --profile host -p ohaca-host --target
/// host-tuple --lib upload_sizes -- --ignored --nocapture` (needs `../shared/maps/large`).
#[cfg(test)]
mod upload_sizes {
    use crate::link::*;
    use std::path::Path;

    /// Bytes on the wire of `code`'s upload: every frame, delimiters included, ids from 2.
    fn wire_bytes(w: u16, h: u16, code: &MapCode) -> (usize, usize) {
        let b = code.bytes();
        let mut total = 0;
        let mut frames = 0;
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        for (k, c) in b.chunks(MAX_CHUNK).enumerate() {
            let req = code.request(w, h, k * MAX_CHUNK, c);
            total += encode_request(2 + k as u32, &req, &mut buf).unwrap();
            frames += 1;
        }
        (total, frames)
    }

    #[test]
    #[ignore = "prints upload sizes of the shared large maps and lab.yaml"]
    fn print_upload_sizes() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut maps: Vec<(String, Map)> = vec![];
        let lab = root.join("host/assets/ros/lab.yaml");
        let (m, _) = crate::map::prepare(&lab, Default::default(), Some(0.2), None).unwrap();
        maps.push(("lab.yaml (5 cm, inflated 0.2 m)".into(), m));
        let large = root.join("../shared/maps/large");
        let mut names: Vec<_> = std::fs::read_dir(&large)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
            .unwrap_or_default();
        names.retain(|p| p.extension().is_some_and(|e| e == "map"));
        names.sort();
        for p in names {
            if let Ok(m) = Map::load(&p) {
                if m.width <= 512 && m.height <= 512 {
                    maps.push((p.file_name().unwrap().to_string_lossy().into(), m));
                }
            }
        }
        println!("| map | cells | packed | run-length code | on the wire (RLE) | frames | at 115200 baud | raw upload at 115200 |");
        println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
        for (name, m) in maps {
            let cells = u32::from(m.width) * u32::from(m.height);
            let rle: Vec<u8> = RleEncoder::new(&m.bits, cells).collect();
            let (wr, fr) = wire_bytes(m.width, m.height, &MapCode::Rle(rle.clone()));
            let (ww, _) = wire_bytes(m.width, m.height, &MapCode::Raw(m.bits.clone()));
            println!(
                "| {name} | {}x{} | {} | {} ({:.1} %) | {wr} | {fr} | {:.2} s | {:.2} s |",
                m.width,
                m.height,
                m.bits.len(),
                rle.len(),
                100.0 * rle.len() as f64 / m.bits.len() as f64,
                wr as f64 / 11520.0,
                ww as f64 / 11520.0
            );
        }
    }
}
