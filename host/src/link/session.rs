//! [`Link`]: a blocking session with the device. Request ids, framing (COBS, CRC) of requests and
//! replies, waiting for a reply by id, strays, map uploads in chunks, plans one at a time or
//! pipelined ([`PlanJob`], [`PlanOutcome`]).

use super::*;

/// One plan of a [`Link::plan_many`] batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlanJob {
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Seed for this plan only (`None`: the parameters' seed).
    pub seed: Option<u64>,
}

/// The answer to one [`PlanJob`].
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOutcome {
    /// Id of the request that was answered.
    pub id: u32,
    /// The path, or the device's error (e.g. `NoPath`, `GoalBlocked`).
    pub result: Result<DevicePath, ErrorReply>,
    /// From sending the request to receiving its reply.
    pub round_trip: Duration,
}

/// A blocking protocol client over a [`Transport`]. See the module docs.
pub struct Link<T: Transport> {
    io: T,
    reader: Box<ReplyReader>,
    rx: Vec<u8>,
    rx_pos: usize,
    rx_len: usize,
    next_id: u32,
    timeout: Duration,
    /// Ids sent and not yet answered.
    pub(super) outstanding: HashSet<u32>,
    /// Replies to outstanding ids that arrived while another was awaited.
    buffered: VecDeque<(u32, Response)>,
    /// Requests sent and not answered yet (their last reply frame not received), with their
    /// bytes on the wire: the device's window ([`Link::send`] keeps within it).
    unanswered: HashMap<u32, usize>,
    /// The parts of long paths received so far.
    parts: Assembler,
    strays: Vec<Stray>,
    stray_count: u64,
    info: Option<DeviceInfo>,
}

impl Link<TcpStream> {
    /// Connect over TCP (`HOST:PORT`, e.g. QEMU's `-serial tcp:...`), with `TCP_NODELAY`.
    /// `timeout` bounds the connection attempt and becomes the link's [`Link::timeout`].
    pub fn tcp(addr: &str, timeout: Duration) -> Result<Self, LinkError> {
        let open_err = |source| LinkError::Open {
            target: addr.to_string(),
            source,
        };
        let addrs: Vec<_> = addr.to_socket_addrs().map_err(open_err)?.collect();
        let mut last = io::Error::new(io::ErrorKind::NotFound, "no address");
        for a in addrs {
            match TcpStream::connect_timeout(&a, timeout.max(Duration::from_millis(1))) {
                Ok(s) => {
                    s.set_nodelay(true).map_err(open_err)?;
                    return Link::new(s, timeout);
                }
                Err(e) => last = e,
            }
        }
        Err(open_err(last))
    }
}

impl Link<Serial> {
    /// Open a serial device (`/dev/ttyUSB0`, `/dev/ttyACM0`, a pty, `COM3`) at `baud`, 8N1, no
    /// flow control; unread input is discarded.
    pub fn serial(path: &str, baud: u32, timeout: Duration) -> Result<Self, LinkError> {
        let open_err = |e: serialport::Error| LinkError::Open {
            target: path.to_string(),
            source: io::Error::from(e),
        };
        let port = serialport::new(path, baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(timeout.max(Duration::from_millis(1)))
            .open()
            .map_err(open_err)?;
        // Ignore a failure: a pty, for one, may not support it, and nothing depends on it.
        let _ = port.clear(serialport::ClearBuffer::Input);
        Link::new(Serial(port), timeout)
    }
}

impl<T: Transport> Link<T> {
    /// A link over an open transport. Sends one `00` byte, so a partial frame left in the
    /// device's reader (from an earlier client) is flushed out instead of swallowing the first
    /// request.
    pub fn new(io: T, timeout: Duration) -> Result<Self, LinkError> {
        let mut link = Link {
            io,
            reader: Box::new(ReplyReader::new()),
            rx: vec![0; 4096],
            rx_pos: 0,
            rx_len: 0,
            next_id: 1,
            timeout,
            outstanding: HashSet::new(),
            buffered: VecDeque::new(),
            unanswered: HashMap::new(),
            parts: Assembler::default(),
            strays: Vec::new(),
            stray_count: 0,
            info: None,
        };
        link.send_raw(&[0])?;
        Ok(link)
    }

    /// How long each call waits for its reply.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// Change [`Link::timeout`].
    pub fn set_timeout(&mut self, timeout: Duration) {
        self.timeout = timeout;
    }

    /// What the device said in the last [`Link::hello`].
    pub fn info(&self) -> Option<&DeviceInfo> {
        self.info.as_ref()
    }

    /// The transport.
    pub fn transport(&mut self) -> &mut T {
        &mut self.io
    }

    /// Stray replies skipped so far (the last [`MAX_STRAYS`]), emptied.
    pub fn take_strays(&mut self) -> Vec<Stray> {
        std::mem::take(&mut self.strays)
    }

    /// How many stray replies were skipped since the link was opened.
    pub fn stray_count(&self) -> u64 {
        self.stray_count
    }

    /// Write bytes as they are (a test may send broken frames). Bounded by [`Link::timeout`].
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.io
            .set_io_timeout(self.timeout)
            .map_err(LinkError::Io)?;
        match self.io.write_all(bytes).and_then(|()| self.io.flush()) {
            Ok(()) => Ok(()),
            Err(e) if is_timeout(&e) => Err(LinkError::Timeout {
                request: "write",
                id: 0,
                timeout: self.timeout,
            }),
            Err(e) if is_disconnect(&e) => Err(LinkError::Disconnected),
            Err(e) => Err(LinkError::Io(e)),
        }
    }

    /// The id the next request will get.
    pub fn next_id(&self) -> u32 {
        self.next_id
    }

    /// Send a request without waiting; returns its id. Its reply is kept until
    /// [`Link::wait_for`] (or [`Link::recv`]) takes it. Keeps within the device's window
    /// (`Capacity::window` requests and `window_bytes` bytes not answered yet, one request
    /// before [`Link::hello`]): it first reads and keeps replies until the request fits.
    pub fn send(&mut self, req: &Request<'_>) -> Result<u32, LinkError> {
        let id = self.next_id;
        self.next_id = self.next_id.checked_add(1).unwrap_or(1);
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        let n = encode_request(id, req, &mut buf).map_err(|error| LinkError::Encode {
            request: request_name(req),
            error,
        })?;
        self.make_room(n, request_name(req))?;
        self.send_raw(buf.get(..n).unwrap_or(&[]))?;
        self.outstanding.insert(id);
        self.unanswered.insert(id, n);
        Ok(id)
    }

    /// The device's window: requests and bytes (one request of any size before Hello).
    fn window(&self) -> (usize, usize) {
        self.info.as_ref().map_or((1, MAX_REQUEST_WIRE), |i| {
            (
                usize::from(i.capacity.window).max(1),
                usize::from(i.capacity.window_bytes).max(MAX_REQUEST_WIRE),
            )
        })
    }

    /// Read replies (kept for their callers) until a request of `bytes` bytes fits the window.
    fn make_room(&mut self, bytes: usize, request: &'static str) -> Result<(), LinkError> {
        let (requests, room) = self.window();
        let deadline = Instant::now() + self.timeout;
        while !self.unanswered.is_empty()
            && (self.unanswered.len() >= requests
                || self.unanswered.values().sum::<usize>() + bytes > room)
        {
            let (got, resp) = self.read_frame(deadline, request, 0)?;
            self.keep(got, resp);
        }
        Ok(())
    }

    /// Keep a reply that is not the one awaited: for its caller if its request is outstanding,
    /// else as a stray.
    fn keep(&mut self, got: u32, resp: Response) {
        if got != UNKNOWN_ID && self.outstanding.contains(&got) {
            self.buffered.push_back((got, resp));
        } else {
            self.stray_count += 1;
            if self.strays.len() >= MAX_STRAYS {
                self.strays.remove(0);
            }
            self.strays.push(Stray::Reply {
                id: got,
                response: resp,
            });
        }
    }

    /// Requests sent and not answered yet.
    pub fn unanswered(&self) -> usize {
        self.unanswered.len()
    }

    /// Wait for the reply to request `id` (named `request` in a timeout message), at most
    /// [`Link::timeout`]. Replies to other requests in flight are kept; strays are skipped.
    pub fn wait_for(&mut self, id: u32, request: &'static str) -> Result<Response, LinkError> {
        let r = self.wait_matching(|i| i == id, request, id);
        if r.is_err() {
            // Given up: a reply that comes later is a stray, and no longer holds the window.
            self.outstanding.remove(&id);
            self.unanswered.remove(&id);
        }
        r.map(|(_, resp)| resp)
    }

    /// The next reply of any id (a kept one first), at most [`Link::timeout`]: for callers that
    /// drive the protocol themselves.
    pub fn recv(&mut self) -> Result<(u32, Response), LinkError> {
        if let Some(r) = self.buffered.pop_front() {
            self.outstanding.remove(&r.0);
            return Ok(r);
        }
        let deadline = Instant::now() + self.timeout;
        let (id, resp) = self.read_frame(deadline, "any request", 0)?;
        self.outstanding.remove(&id);
        Ok((id, resp))
    }

    /// Send `req` and wait for its reply.
    pub fn call(&mut self, req: &Request<'_>) -> Result<Response, LinkError> {
        let id = self.send(req)?;
        self.wait_for(id, request_name(req))
    }

    /// Send `req` and expect `Ack`.
    fn call_ack(&mut self, req: &Request<'_>) -> Result<(), LinkError> {
        let request = request_name(req);
        match self.call(req)? {
            Response::Ack => Ok(()),
            other => Err(unexpected(request, other)),
        }
    }

    /// `Hello`: who the device is and what it can do. Fails with [`LinkError::Version`] if it
    /// speaks another protocol version.
    pub fn hello(&mut self) -> Result<DeviceInfo, LinkError> {
        match self.call(&Request::Hello)? {
            Response::Hello(info) => {
                if info.protocol_version != VERSION {
                    return Err(LinkError::Version {
                        device: info.protocol_version,
                        host: VERSION,
                    });
                }
                self.info = Some(info.clone());
                Ok(info)
            }
            other => Err(unexpected("Hello", other)),
        }
    }

    /// Upload `map`, run-length coded if that is shorter ([`MapCode::of`]), in chunks of at most
    /// [`MAX_CHUNK`] bytes (or the device's `max_chunk`, if smaller), [`UPLOAD_WINDOW`] in
    /// flight. The device has no map from the first chunk on; `map` becomes its map when the
    /// last chunk is acknowledged.
    pub fn set_map(&mut self, map: &Map) -> Result<(), LinkError> {
        self.upload(map.width, map.height, &MapCode::of(map))
    }

    /// [`Link::set_map`], calling `progress(bytes acknowledged, bytes in all)` after every chunk
    /// the device acknowledged (for a progress bar).
    pub fn set_map_with_progress(
        &mut self,
        map: &Map,
        progress: impl FnMut(usize, usize),
    ) -> Result<(), LinkError> {
        self.upload_with(map.width, map.height, &MapCode::of(map), progress)
    }

    /// [`Link::set_map`] from raw parts, always as `SetMap`: `bits` packed as [`ohaca::grid`]
    /// stores them (the device checks their length).
    pub fn set_map_bits(&mut self, width: u16, height: u16, bits: &[u8]) -> Result<(), LinkError> {
        self.upload(width, height, &MapCode::Raw(bits.to_vec()))
    }

    /// Upload a map coded as `code`: its chunks, [`UPLOAD_WINDOW`] in flight. The first device
    /// error ends the upload (the replies of the chunks behind it are awaited and dropped).
    pub fn upload(&mut self, width: u16, height: u16, code: &MapCode) -> Result<(), LinkError> {
        self.upload_with(width, height, code, |_, _| {})
    }

    /// [`Link::upload`] with a progress callback (see [`Link::set_map_with_progress`]).
    pub fn upload_with(
        &mut self,
        width: u16,
        height: u16,
        code: &MapCode,
        mut progress: impl FnMut(usize, usize),
    ) -> Result<(), LinkError> {
        let chunk = self
            .info
            .as_ref()
            .map_or(MAX_CHUNK, |i| usize::from(i.capacity.max_chunk))
            .clamp(1, MAX_CHUNK);
        let bytes = code.bytes();
        let mut in_flight: VecDeque<(u32, &'static str, usize)> = VecDeque::new();
        let mut first_error = None;
        let mut offset = 0usize;
        // An empty map (a zero side) still goes out once, as one zero byte, so the device says
        // what is wrong with it (`BadMap`; an empty chunk would be `TooLarge` 0 before that).
        loop {
            let end = (offset + chunk).min(bytes.len());
            let piece = match bytes.get(offset..end) {
                Some(p) if !p.is_empty() => p,
                _ => &[0u8][..],
            };
            let req = code.request(width, height, offset, piece);
            in_flight.push_back((self.send(&req)?, request_name(&req), end));
            offset = end;
            let last = offset >= bytes.len();
            while in_flight.len() >= UPLOAD_WINDOW
                || ((last || first_error.is_some()) && !in_flight.is_empty())
            {
                let (id, name, acked) = in_flight.pop_front().unwrap_or((0, "SetMap", 0));
                match self.wait_for(id, name)? {
                    Response::Ack => progress(acked, bytes.len()),
                    other => {
                        first_error.get_or_insert(unexpected(name, other));
                    }
                }
            }
            if let Some(e) = first_error {
                return Err(e);
            }
            if last {
                return Ok(());
            }
        }
    }

    /// `SetRect`: block (`blocked`) or clear the cells of a rectangle of the device's map (its
    /// running and queued plans are cancelled).
    pub fn set_rect(
        &mut self,
        (x, y): (u16, u16),
        (width, height): (u16, u16),
        blocked: bool,
    ) -> Result<(), LinkError> {
        self.call_ack(&Request::SetRect {
            x,
            y,
            width,
            height,
            blocked,
        })
    }

    /// `SetCells`: block or clear a list of cells, in requests of at most
    /// [`MAX_UPDATE_CELLS`] (each cancels the device's running and queued plans).
    pub fn set_cells(&mut self, cells: &[Point], blocked: bool) -> Result<(), LinkError> {
        for part in cells.chunks(MAX_UPDATE_CELLS) {
            self.call_ack(&Request::SetCells {
                blocked,
                cells: Waypoints::Points(part),
            })?;
        }
        Ok(())
    }

    /// `PlanWarm`: [`Link::plan`], asking the device to keep the colony of its previous plan to
    /// the same goal (a device may plan cold).
    pub fn plan_warm(
        &mut self,
        start: Point,
        goal: Point,
        seed: Option<u64>,
    ) -> Result<DevicePath, LinkError> {
        match self.call(&Request::PlanWarm { start, goal, seed })? {
            Response::Path(p) => Ok(p),
            other => Err(unexpected("PlanWarm", other)),
        }
    }

    /// `SetParams`: the parameters of every later plan.
    pub fn set_params(&mut self, params: &Params) -> Result<(), LinkError> {
        self.call_ack(&Request::SetParams(*params))
    }

    /// `Plan` on the active map; `seed` overrides the parameters' seed for this plan.
    pub fn plan(
        &mut self,
        start: Point,
        goal: Point,
        seed: Option<u64>,
    ) -> Result<DevicePath, LinkError> {
        match self.call(&Request::Plan { start, goal, seed })? {
            Response::Path(p) => Ok(p),
            other => Err(unexpected("Plan", other)),
        }
    }

    /// `Cancel`: stop the running plan and drop the queued ones (their replies, `Cancelled`,
    /// are kept for their callers, or become strays).
    pub fn cancel(&mut self) -> Result<(), LinkError> {
        self.call_ack(&Request::Cancel)
    }

    /// `Stats`: the device's counters.
    pub fn stats(&mut self) -> Result<StatsReply, LinkError> {
        match self.call(&Request::Stats)? {
            Response::Stats(s) => Ok(s),
            other => Err(unexpected("Stats", other)),
        }
    }

    /// Plan every job, pipelined: up to the device's `plan_queue` (from the last
    /// [`Link::hello`]; 1 without one) requests in flight. `each(index, outcome)` is called in
    /// job order as soon as an outcome and all before it are in. A device error for one job
    /// (`NoPath`, `GoalBlocked`, ...) is that job's outcome; a transport failure (timeout,
    /// disconnect, undecodable frame) ends the batch with an error. A plan refused with `Busy`
    /// (another client filling the queue) is sent again later. The timeout applies to each
    /// reply: the batch fails only if the device stays silent that long.
    pub fn plan_each(
        &mut self,
        jobs: &[PlanJob],
        mut each: impl FnMut(usize, PlanOutcome),
    ) -> Result<(), LinkError> {
        let window = self
            .info
            .as_ref()
            .map_or(1, |i| usize::from(i.capacity.plan_queue))
            .max(1);
        let mut next = 0usize;
        let mut retry: VecDeque<usize> = VecDeque::new();
        let mut inflight: HashMap<u32, (usize, Instant)> = HashMap::new();
        let mut done: BTreeMap<usize, PlanOutcome> = BTreeMap::new();
        let mut emitted = 0usize;
        let mut busy_since: Option<Instant> = None;
        while emitted < jobs.len() {
            while inflight.len() < window {
                let Some(i) = retry
                    .pop_front()
                    .or_else(|| (next < jobs.len()).then_some(next))
                else {
                    break;
                };
                if i == next {
                    next += 1;
                }
                let Some(job) = jobs.get(i) else { break };
                let id = self.send(&Request::Plan {
                    start: job.start,
                    goal: job.goal,
                    seed: job.seed,
                })?;
                inflight.insert(id, (i, Instant::now()));
            }
            if inflight.is_empty() {
                // Everything left was refused as Busy with nothing of ours in flight: the
                // queue is someone else's. Wait a little, give up after the timeout.
                let since = *busy_since.get_or_insert_with(Instant::now);
                if since.elapsed() > self.timeout {
                    return Err(LinkError::Device {
                        request: "Plan",
                        error: ErrorReply::new(ErrorCode::Busy),
                    });
                }
                std::thread::sleep(Duration::from_millis(20));
                continue;
            }
            let first = inflight.keys().min().copied().unwrap_or(0);
            let (id, resp) =
                match self.wait_matching(|id| inflight.contains_key(&id), "Plan", first) {
                    Ok(r) => r,
                    Err(e) => {
                        for id in inflight.keys() {
                            self.outstanding.remove(id);
                            self.unanswered.remove(id);
                        }
                        return Err(e);
                    }
                };
            let Some((i, sent)) = inflight.remove(&id) else {
                continue;
            };
            let result = match resp {
                Response::Path(p) => Ok(p),
                Response::Error(e) if e.code == ErrorCode::Busy => {
                    retry.push_back(i);
                    continue;
                }
                Response::Error(e) => Err(e),
                other => return Err(unexpected("Plan", other)),
            };
            busy_since = None;
            done.insert(
                i,
                PlanOutcome {
                    id,
                    result,
                    round_trip: sent.elapsed(),
                },
            );
            while let Some(o) = done.remove(&emitted) {
                each(emitted, o);
                emitted += 1;
            }
        }
        Ok(())
    }

    /// [`Link::plan_each`], collected: one outcome per job, in job order.
    pub fn plan_many(&mut self, jobs: &[PlanJob]) -> Result<Vec<PlanOutcome>, LinkError> {
        let mut out = Vec::with_capacity(jobs.len());
        self.plan_each(jobs, |_, o| out.push(o))?;
        Ok(out)
    }

    /// Wait for a reply whose id satisfies `want` (kept replies first). `request` and `id`
    /// name what is awaited in a timeout message.
    fn wait_matching(
        &mut self,
        want: impl Fn(u32) -> bool,
        request: &'static str,
        id: u32,
    ) -> Result<(u32, Response), LinkError> {
        if let Some(pos) = self.buffered.iter().position(|(i, _)| want(*i)) {
            if let Some(r) = self.buffered.remove(pos) {
                self.outstanding.remove(&r.0);
                return Ok(r);
            }
        }
        let deadline = Instant::now() + self.timeout;
        loop {
            let (got, resp) = self.read_frame(deadline, request, id)?;
            if want(got) {
                self.outstanding.remove(&got);
                return Ok((got, resp));
            }
            self.keep(got, resp);
        }
    }

    /// The next complete reply from the wire, decoded, before `deadline`: the parts of a long
    /// path are put together into one [`Response::Path`].
    fn read_frame(
        &mut self,
        deadline: Instant,
        request: &'static str,
        id: u32,
    ) -> Result<(u32, Response), LinkError> {
        loop {
            let (got, resp) = self.read_one(deadline, request, id)?;
            if let Some(resp) = self.parts.push(got, resp).map_err(LinkError::Decode)? {
                self.unanswered.remove(&got);
                return Ok((got, resp));
            }
        }
    }

    /// The next complete frame from the wire, decoded, before `deadline`.
    fn read_one(
        &mut self,
        deadline: Instant,
        request: &'static str,
        id: u32,
    ) -> Result<(u32, Response), LinkError> {
        loop {
            while self.rx_pos < self.rx_len {
                let Some(&b) = self.rx.get(self.rx_pos) else {
                    break;
                };
                self.rx_pos += 1;
                if let Some(frame) = self.reader.push(b).into_frame(MAX_REPLY_WIRE) {
                    let (got, reply) = frame.and_then(decode_reply).map_err(LinkError::Decode)?;
                    return Ok((got, Response::from(&reply)));
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout {
                    request,
                    id,
                    timeout: self.timeout,
                });
            }
            self.io
                .set_io_timeout(deadline - now)
                .map_err(LinkError::Io)?;
            match self.io.read(&mut self.rx) {
                Ok(0) => return Err(LinkError::Disconnected),
                Ok(n) => {
                    self.rx_pos = 0;
                    self.rx_len = n;
                }
                Err(e) if is_timeout(&e) => {}
                Err(e) if is_disconnect(&e) => return Err(LinkError::Disconnected),
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
    }
}
