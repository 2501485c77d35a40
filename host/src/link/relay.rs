//! A pacing relay: a real serial line (default 115200 8N1) between a client and QEMU's emulated
//! UART, which otherwise moves bytes instantly and buffers megabytes in its socket.
//!
//! It owns the two directions of the line, one thread each, and their counters ([`Counters`]):
//!
//! * **Pacing.** A byte takes [`BITS_PER_BYTE`]` / baud` seconds on the line. Byte `k` of a busy
//!   stretch is delivered no earlier than `start + (k + 1) * 10 / baud` (the end of its stop bit),
//!   where `start` is when the line last left idle; the schedule restarts when the line goes idle,
//!   and never runs ahead. The threads sleep until each slot (they do not spin: that starved
//!   QEMU on a 2-core machine), so a byte may leave up to [`MAX_CATCH_UP`] after its slot while
//!   the next keeps its own; a byte later than that restarts the schedule from its delivery
//!   instead of bursting to catch up. So `n` bytes of a stretch never leave before
//!   `start + n * 10 / baud`, and the first and last of them are at least
//!   `(n - 1) * 10 / baud - MAX_CATCH_UP` apart.
//! * **The device side** is a Unix socket pair whose QEMU end has the kernel's smallest send and
//!   receive buffers ([`Relay::spawn_qemu`]: `-chardev socket,fd=N`). QEMU's CMSDK UART writes one
//!   byte per write and holds `TXFULL` while the socket is not writable, so with only a few bytes
//!   of room the guest's transmitter waits for the line as on a real UART. The relay reads one
//!   byte from the device only when the line is free for it (it holds at most one byte: the one
//!   being shifted out), and records how many bytes QEMU had written that the line had not yet
//!   delivered ([`Counters::backlog_max`]).
//! * **No flow control toward the device.** A device-bound byte is written, without waiting, at
//!   its slot; if the device side cannot take it then, it is lost and counted
//!   ([`Counters::to_device_dropped`]), as a UART without flow control loses it. "Cannot take"
//!   means [`device_slack`] bytes are already waiting for QEMU's UART (which takes one when the
//!   firmware has read the last): room for QEMU's own scheduling delays on a loaded host; past
//!   it, a receiver that stopped reading (or a firmware still booting) loses bytes.
//! * **Line clocks.** Each direction counts the bytes that have passed on its line (toward the
//!   device: delivered plus lost). Latencies can so be measured in bytes on the line, which do
//!   not depend on the host's speed: [`RelayStream::wait_sent`] gives the clocks of both
//!   directions when the last byte a client wrote reached the device, and every byte a client
//!   reads comes with the clocks at its arrival ([`RelayStream::take_arrivals`]).
//! * **Clients.** An in-process [`RelayStream`] (a [`Transport`] for [`Link`]) from
//!   [`Relay::client`], or a TCP connection served by [`Relay::serve`] (`ohaca relay`). One client
//!   at a time; bytes the device sends while no client is attached are discarded when the next
//!   one attaches.
//!
//! Nothing here panics on what the device or a client sends; a closed device ends both threads
//! and the client then reads end-of-file.

use std::net::TcpStream;
use std::os::fd::AsRawFd;
use std::os::unix::net::UnixStream;
use std::process::{Child, Command};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;

use socket2::SockRef;

use super::*;

/// Bits a byte takes on an 8N1 line: start bit, 8 data bits, stop bit.
pub const BITS_PER_BYTE: u32 = 10;

/// How often the relay's threads look at their stop flag while idle.
const POLL: Duration = Duration::from_millis(20);

/// Device-bound stamps kept for [`Counters::stamp_of`] (the most recent ones).
const STAMPS_KEPT: usize = 8192;

/// Arrivals a [`RelayStream`] keeps for [`RelayStream::take_arrivals`] (the most recent ones).
const ARRIVALS_KEPT: usize = 1 << 20;

/// The line clocks of both directions at one moment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stamp {
    /// Bytes passed on the device-bound line (delivered or lost) so far.
    pub to_device: u64,
    /// Bytes delivered on the host-bound line so far.
    pub to_host: u64,
    /// When.
    pub at: Instant,
}

/// A byte the device sent, as a client received it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arrival {
    /// The byte.
    pub byte: u8,
    /// The clocks when it left the line: `stamp.to_host` counts this byte (the first byte the
    /// device ever sent has `to_host == 1`).
    pub stamp: Stamp,
}

/// The relay's counters, readable while it runs (shared with every client).
#[derive(Debug)]
pub struct Counters {
    baud: u32,
    /// Bytes clients handed to the device-bound line.
    accepted: AtomicU64,
    to_device_line: AtomicU64,
    to_device_dropped: AtomicU64,
    to_host_line: AtomicU64,
    backlog_max: AtomicU64,
    held_max: AtomicU64,
    closed: AtomicBool,
    /// Recent device-bound deliveries, for [`Counters::stamp_of`], and their signal.
    stamps: Mutex<VecDeque<Stamp>>,
    delivered: Condvar,
}

/// A copy of the counters at one moment; subtract two for what happened in between.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Snapshot {
    /// Bytes passed on the device-bound line (delivered or lost).
    pub to_device: u64,
    /// Of those, bytes the device side could not take (lost).
    pub to_device_dropped: u64,
    /// Bytes delivered on the host-bound line.
    pub to_host: u64,
}

impl Snapshot {
    /// Device-bound bytes delivered (passed minus lost).
    pub fn to_device_delivered(&self) -> u64 {
        self.to_device.saturating_sub(self.to_device_dropped)
    }

    /// What happened between `earlier` and `self`.
    pub fn since(&self, earlier: &Snapshot) -> Snapshot {
        Snapshot {
            to_device: self.to_device.saturating_sub(earlier.to_device),
            to_device_dropped: self
                .to_device_dropped
                .saturating_sub(earlier.to_device_dropped),
            to_host: self.to_host.saturating_sub(earlier.to_host),
        }
    }
}

impl std::fmt::Display for Snapshot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "to device {} bytes ({} delivered, {} lost), to host {} bytes",
            self.to_device,
            self.to_device_delivered(),
            self.to_device_dropped,
            self.to_host
        )
    }
}

impl Counters {
    fn new(baud: u32) -> Counters {
        Counters {
            baud,
            accepted: AtomicU64::new(0),
            to_device_line: AtomicU64::new(0),
            to_device_dropped: AtomicU64::new(0),
            to_host_line: AtomicU64::new(0),
            backlog_max: AtomicU64::new(0),
            held_max: AtomicU64::new(0),
            closed: AtomicBool::new(false),
            stamps: Mutex::new(VecDeque::new()),
            delivered: Condvar::new(),
        }
    }

    /// The line speed, in bits per second.
    pub fn baud(&self) -> u32 {
        self.baud
    }

    /// One byte's time on the line (10 bits).
    pub fn byte_time(&self) -> Duration {
        byte_time(self.baud)
    }

    /// The device-bound line clock: bytes passed so far (delivered or lost).
    pub fn to_device_line(&self) -> u64 {
        self.to_device_line.load(Ordering::Acquire)
    }

    /// Device-bound bytes the device side could not take at their slot (lost).
    pub fn to_device_dropped(&self) -> u64 {
        self.to_device_dropped.load(Ordering::Acquire)
    }

    /// Device-bound bytes delivered.
    pub fn to_device_delivered(&self) -> u64 {
        self.to_device_line()
            .saturating_sub(self.to_device_dropped())
    }

    /// The host-bound line clock: bytes delivered so far.
    pub fn to_host_line(&self) -> u64 {
        self.to_host_line.load(Ordering::Acquire)
    }

    /// Bytes clients have handed to the device-bound line so far (passed or still waiting).
    pub fn accepted(&self) -> u64 {
        self.accepted.load(Ordering::Acquire)
    }

    /// The most bytes QEMU had written into the socket that the line had not yet delivered
    /// (those in the socket plus the one on the line), since the start or the last
    /// [`Counters::reset_backlog_max`].
    pub fn backlog_max(&self) -> u64 {
        self.backlog_max.load(Ordering::Acquire)
    }

    /// Start [`Counters::backlog_max`] and [`Counters::held_max`] again from 0.
    pub fn reset_backlog_max(&self) {
        self.backlog_max.store(0, Ordering::Release);
        self.held_max.store(0, Ordering::Release);
    }

    /// The most device-bound bytes delivered to QEMU's end of the socket that QEMU had not yet
    /// taken (its UART takes one when the firmware has read the last): what QEMU held back, since
    /// the start or the last [`Counters::reset_backlog_max`]. Estimated from the socket's send
    /// queue (`SIOCOUTQ`, which counts the kernel's memory per one-byte write: divided by that
    /// cost, measured once on a spare socket pair); 0 where the kernel does not say.
    pub fn held_max(&self) -> u64 {
        self.held_max.load(Ordering::Acquire)
    }

    /// True once the device side has closed (QEMU exited) or failed.
    pub fn device_closed(&self) -> bool {
        self.closed.load(Ordering::Acquire)
    }

    /// Both clocks now.
    pub fn now(&self) -> Stamp {
        Stamp {
            to_device: self.to_device_line(),
            to_host: self.to_host_line(),
            at: Instant::now(),
        }
    }

    /// The counters now.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            to_device: self.to_device_line(),
            to_device_dropped: self.to_device_dropped(),
            to_host: self.to_host_line(),
        }
    }

    /// The clocks when the device-bound line's byte number `n` (counting from 1) left it, if it
    /// has and is still among the recent ones kept.
    pub fn stamp_of(&self, n: u64) -> Option<Stamp> {
        let stamps = self.stamps.lock().ok()?;
        let last = stamps.back()?.to_device;
        let back = usize::try_from(last.checked_sub(n)?).ok()?;
        let i = stamps.len().checked_sub(back + 1)?;
        stamps.get(i).copied()
    }

    /// Wait until the device-bound line has passed `n` bytes, at most `timeout`; the clocks
    /// when byte `n` left it (`None` on a timeout, a closed device, or `n == 0`).
    pub fn wait_to_device(&self, n: u64, timeout: Duration) -> Option<Stamp> {
        let deadline = Instant::now() + timeout;
        let mut stamps = self.stamps.lock().ok()?;
        loop {
            if stamps.back().is_some_and(|s| s.to_device >= n) {
                drop(stamps);
                return self.stamp_of(n);
            }
            let now = Instant::now();
            if now >= deadline || self.device_closed() {
                return None;
            }
            stamps = self
                .delivered
                .wait_timeout(stamps, (deadline - now).min(POLL))
                .ok()?
                .0;
        }
    }

    fn record_to_device(&self, dropped: bool) {
        if dropped {
            self.to_device_dropped.fetch_add(1, Ordering::AcqRel);
        }
        let to_device = self.to_device_line.fetch_add(1, Ordering::AcqRel) + 1;
        let stamp = Stamp {
            to_device,
            to_host: self.to_host_line(),
            at: Instant::now(),
        };
        if let Ok(mut s) = self.stamps.lock() {
            if s.len() >= STAMPS_KEPT {
                s.pop_front();
            }
            s.push_back(stamp);
        }
        self.delivered.notify_all();
    }
}

/// One byte's time at `baud` (10 bits; `baud` 0 is taken as 1).
pub fn byte_time(baud: u32) -> Duration {
    Duration::from_nanos(u64::from(BITS_PER_BYTE) * 1_000_000_000 / u64::from(baud.max(1)))
}

/// How late a byte may leave the line and the schedule still hold: a later one restarts the
/// schedule from its delivery instead of catching up. Sleeps overshoot by tens of microseconds;
/// spinning instead (to be exact to the microsecond) took cores from QEMU on a 2-core machine.
pub const MAX_CATCH_UP: Duration = Duration::from_millis(1);

/// When the line is next free, and the pacing rule.
struct Line {
    byte: Duration,
    /// When the current busy stretch began, and the bytes carried since.
    start: Instant,
    carried: u32,
    free_at: Instant,
}

impl Line {
    fn new(baud: u32) -> Line {
        let now = Instant::now();
        Line {
            byte: byte_time(baud),
            start: now,
            carried: 0,
            free_at: now,
        }
    }

    /// Wait until a byte that became available at `ready` has crossed the line: its slot is
    /// `start + carried * byte` on a busy line; an idle line (or one more than
    /// [`MAX_CATCH_UP`] behind) starts a new stretch.
    fn carry(&mut self, ready: Instant) {
        if ready > self.free_at || self.carried >= 1 << 30 {
            self.start = ready;
            self.carried = 0;
        }
        self.carried += 1;
        let slot = self.start + self.byte * self.carried;
        let now = Instant::now();
        if slot > now {
            std::thread::sleep(slot - now);
        }
        let now = Instant::now();
        if now > slot + MAX_CATCH_UP {
            self.start = now;
            self.carried = 0;
            self.free_at = now;
        } else {
            self.free_at = slot;
        }
    }
}

/// Device-bound bytes the device side may leave untaken before the next one is lost: the
/// relay's end has a send buffer for about this many one-byte writes (Linux charges ~768 bytes
/// of buffer for each, and doubles the size asked for). A UART's receiver takes a byte within
/// one byte time, but QEMU reads its socket from its main loop, which a loaded host schedules
/// milliseconds late now and then: with the kernel's smallest buffer (6 bytes, 0.5 ms at
/// 115200) uploads lost bytes on a loaded 2-core machine, and with 20 ms of line too (QEMU's
/// CPU thread descheduled: its UART then takes nothing). The room is the larger of 64 bytes and
/// [`DEVICE_SLACK_TIME`] of line ([`device_slack`]: 1,152 bytes at 115200, 9,216 at 921600),
/// at most what `net.core.wmem_max` lets a socket have (Linux caps it silently).
pub const DEVICE_SLACK: usize = 64;

/// [`DEVICE_SLACK`], or the bytes of [`DEVICE_SLACK_TIME`] on the line if more.
pub fn device_slack(baud: u32) -> usize {
    let per_s = baud / BITS_PER_BYTE;
    DEVICE_SLACK.max((per_s as usize * DEVICE_SLACK_TIME.as_millis() as usize) / 1000)
}

/// The least time of line the device side's room holds (see [`DEVICE_SLACK`]).
pub const DEVICE_SLACK_TIME: Duration = Duration::from_millis(100);

/// The smallest buffers the kernel allows, both ways (QEMU's end).
fn shrink_buffers(s: &UnixStream) -> io::Result<()> {
    let r = SockRef::from(s);
    r.set_send_buffer_size(1)?;
    r.set_recv_buffer_size(1)
}

/// The relay's end: the smallest receive buffer, room for [`device_slack`] bytes toward the
/// device.
fn relay_buffers(s: &UnixStream, baud: u32) -> io::Result<()> {
    let r = SockRef::from(s);
    r.set_send_buffer_size(device_slack(baud) * 384)?;
    r.set_recv_buffer_size(1)
}

/// A running relay: two threads pacing a device socket. Dropping it stops them.
pub struct Relay {
    counters: Arc<Counters>,
    stop: Arc<AtomicBool>,
    to_device: Sender<Vec<u8>>,
    from_device: Arc<Mutex<Receiver<Arrival>>>,
    threads: Vec<JoinHandle<()>>,
}

impl Relay {
    /// Pace `device` (the relay's end of a socket to the device) at `baud`.
    pub fn new(device: UnixStream, baud: u32) -> io::Result<Relay> {
        relay_buffers(&device, baud)?;
        device.set_read_timeout(Some(POLL))?;
        let counters = Arc::new(Counters::new(baud));
        let stop = Arc::new(AtomicBool::new(false));
        let (to_device, device_rx) = mpsc::channel::<Vec<u8>>();
        let (host_tx, from_device) = mpsc::channel::<Arrival>();
        let writer = device.try_clone()?;
        let (c, s) = (Arc::clone(&counters), Arc::clone(&stop));
        let down = std::thread::Builder::new()
            .name("relay-to-device".into())
            .spawn(move || to_device_loop(&writer, &device_rx, &c, &s))?;
        let (c, s) = (Arc::clone(&counters), Arc::clone(&stop));
        let up = std::thread::Builder::new()
            .name("relay-to-host".into())
            .spawn(move || to_host_loop(&device, &host_tx, &c, &s))?;
        Ok(Relay {
            counters,
            stop,
            to_device,
            from_device: Arc::new(Mutex::new(from_device)),
            threads: vec![down, up],
        })
    }

    /// Start QEMU (`qemu`: the whole command but its serial port) with UART0 on a fresh socket
    /// pair (`-chardev socket,id=uart0,fd=N -serial chardev:uart0`), QEMU's end with the
    /// kernel's smallest buffers, and pace it at `baud`.
    ///
    /// QEMU's end is made inheritable only for the spawn: a child another thread starts in that
    /// moment inherits it too (and then holds the socket open after QEMU exits).
    pub fn spawn_qemu(qemu: &mut Command, baud: u32) -> io::Result<(Child, Relay)> {
        let (mine, theirs) = UnixStream::pair()?;
        shrink_buffers(&theirs)?;
        let fd = theirs.as_raw_fd();
        qemu.arg("-chardev")
            .arg(format!("socket,id=uart0,fd={fd}"))
            .args(["-serial", "chardev:uart0"]);
        SockRef::from(&theirs).set_cloexec(false)?;
        let child = qemu.spawn();
        drop(theirs);
        let child = child?;
        match Relay::new(mine, baud) {
            Ok(relay) => Ok((child, relay)),
            Err(e) => {
                let mut child = child;
                let _ = child.kill();
                let _ = child.wait();
                Err(e)
            }
        }
    }

    /// The counters (shared; readable while the relay runs).
    pub fn counters(&self) -> Arc<Counters> {
        Arc::clone(&self.counters)
    }

    /// An in-process client. Bytes the device sent before are discarded. One client at a time:
    /// a second one shares (and competes for) the same bytes.
    pub fn client(&self) -> RelayStream {
        if let Ok(rx) = self.from_device.lock() {
            while rx.try_recv().is_ok() {}
        }
        RelayStream {
            counters: Arc::clone(&self.counters),
            to_device: self.to_device.clone(),
            from_device: Arc::clone(&self.from_device),
            timeout: None,
            arrivals: VecDeque::new(),
            log: true,
        }
    }

    /// Serve one TCP client until it disconnects (or the device closes); what crossed the line
    /// meanwhile.
    pub fn serve(&self, client: TcpStream) -> io::Result<Snapshot> {
        let before = self.counters.snapshot();
        client.set_nodelay(true)?;
        let mut stream = self.client();
        let mut reader = client.try_clone()?;
        let to_device = self.to_device.clone();
        let counters = Arc::clone(&self.counters);
        let done = Arc::new(AtomicBool::new(false));
        let done2 = Arc::clone(&done);
        // Client -> line: as fast as the client writes (the line paces it).
        let pump = std::thread::Builder::new()
            .name("relay-client-in".into())
            .spawn(move || {
                let mut buf = [0u8; 4096];
                loop {
                    match reader.read(&mut buf) {
                        Ok(0) | Err(_) => break,
                        Ok(n) => {
                            let bytes = buf.get(..n).unwrap_or_default().to_vec();
                            counters.accepted.fetch_add(n as u64, Ordering::AcqRel);
                            if to_device.send(bytes).is_err() {
                                break;
                            }
                        }
                    }
                }
                done2.store(true, Ordering::Release);
            })?;
        // Line -> client, until the client leaves or the device closes.
        let mut out = client.try_clone()?;
        stream.set_io_timeout(POLL)?;
        stream.keep_arrivals(false);
        let mut buf = [0u8; 4096];
        while !done.load(Ordering::Acquire) {
            match stream.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    if out.write_all(buf.get(..n).unwrap_or_default()).is_err() {
                        break;
                    }
                }
                Err(e) if is_timeout(&e) => {}
                Err(_) => break,
            }
        }
        let _ = client.shutdown(std::net::Shutdown::Both);
        let _ = pump.join();
        Ok(self.counters.snapshot().since(&before))
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// The device-bound direction: bytes from clients, each written without waiting at its slot;
/// lost if the device side cannot take it then.
fn to_device_loop(
    device: &UnixStream,
    input: &Receiver<Vec<u8>>,
    counters: &Counters,
    stop: &AtomicBool,
) {
    let sock = SockRef::from(device);
    let flags = libc::MSG_DONTWAIT | libc::MSG_NOSIGNAL;
    let mut line = Line::new(counters.baud);
    let per_byte = send_queue_per_byte();
    let mut queue: VecDeque<u8> = VecDeque::new();
    let mut ready = Instant::now();
    while !stop.load(Ordering::Acquire) {
        if queue.is_empty() {
            match input.recv_timeout(POLL) {
                Ok(bytes) => {
                    ready = Instant::now();
                    queue.extend(bytes);
                }
                Err(RecvTimeoutError::Timeout) => continue,
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        loop {
            match input.try_recv() {
                Ok(bytes) => queue.extend(bytes),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => break,
            }
        }
        let Some(b) = queue.pop_front() else {
            continue;
        };
        line.carry(ready);
        let dropped = match sock.send_with_flags(&[b], flags) {
            Ok(1) => false,
            Ok(_) => true,
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => true,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => true,
            Err(_) => {
                counters.closed.store(true, Ordering::Release);
                counters.delivered.notify_all();
                break;
            }
        };
        counters.record_to_device(dropped);
        if let Some(held) = send_queue(device).checked_div(per_byte) {
            counters.held_max.fetch_max(held, Ordering::AcqRel);
        }
    }
}

/// The kernel's count for `s`'s send queue (`SIOCOUTQ`): for a Unix stream socket, the memory of
/// the writes its peer has not read yet; 0 if it does not say. The host tool's one `unsafe`: no
/// safe wrapper of `SIOCOUTQ` is among its dependencies.
#[allow(unsafe_code)]
fn send_queue(s: &UnixStream) -> u64 {
    let mut n: libc::c_int = 0;
    // SAFETY: SIOCOUTQ writes one c_int through the pointer, which points at `n`.
    let r = unsafe { libc::ioctl(s.as_raw_fd(), libc::TIOCOUTQ, &mut n) };
    if r == 0 {
        u64::try_from(n).unwrap_or(0)
    } else {
        0
    }
}

/// What [`send_queue`] counts for one one-byte write its peer has not read (measured on a spare
/// socket pair); 0 if it cannot be measured.
fn send_queue_per_byte() -> u64 {
    let Ok((a, _b)) = UnixStream::pair() else {
        return 0;
    };
    if (&a).write(&[0]).is_err() {
        return 0;
    }
    send_queue(&a)
}

/// The host-bound direction: one byte at a time from the device, read only when the line is free
/// for it, delivered at its slot.
fn to_host_loop(
    device: &UnixStream,
    output: &Sender<Arrival>,
    counters: &Counters,
    stop: &AtomicBool,
) {
    let sock = SockRef::from(device);
    let mut line = Line::new(counters.baud);
    let mut byte = [0u8; 1];
    let mut peek = vec![std::mem::MaybeUninit::<u8>::uninit(); 1 << 16];
    let mut reader = device;
    while !stop.load(Ordering::Acquire) {
        match reader.read(&mut byte) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) if is_timeout(&e) => continue,
            Err(_) => break,
        }
        let ready = Instant::now();
        // What QEMU has written that the line has not delivered: the socket's bytes plus this one.
        let queued = sock
            .recv_with_flags(&mut peek, libc::MSG_PEEK | libc::MSG_DONTWAIT)
            .unwrap_or(0);
        counters
            .backlog_max
            .fetch_max(queued as u64 + 1, Ordering::AcqRel);
        line.carry(ready);
        let to_host = counters.to_host_line.fetch_add(1, Ordering::AcqRel) + 1;
        let arrival = Arrival {
            byte: byte[0],
            stamp: Stamp {
                to_device: counters.to_device_line(),
                to_host,
                at: Instant::now(),
            },
        };
        // Nobody listening (the relay is being dropped): the byte is lost, as on a real line.
        let _ = output.send(arrival);
    }
    counters.closed.store(true, Ordering::Release);
    counters.delivered.notify_all();
}

/// An in-process client of a [`Relay`]: a [`Transport`] for [`Link`] that also gives the line
/// clocks of what it sends ([`RelayStream::wait_sent`]) and receives
/// ([`RelayStream::take_arrivals`]).
///
/// Writes never block (the bytes queue for the line, as in a host's serial driver); reads wait
/// at most the [`Transport::set_io_timeout`] (forever if never set) and return end-of-file once
/// the device has closed and every byte it sent was read.
pub struct RelayStream {
    counters: Arc<Counters>,
    to_device: Sender<Vec<u8>>,
    from_device: Arc<Mutex<Receiver<Arrival>>>,
    timeout: Option<Duration>,
    arrivals: VecDeque<Arrival>,
    log: bool,
}

impl RelayStream {
    /// The relay's counters.
    pub fn counters(&self) -> &Arc<Counters> {
        &self.counters
    }

    /// Wait (at most `timeout`) until every byte written so far (by any client) has passed the
    /// device-bound line; the clocks when the last one did. `None` on a timeout or a closed
    /// device (or if nothing was ever written).
    pub fn wait_sent(&self, timeout: Duration) -> Option<Stamp> {
        self.counters
            .wait_to_device(self.counters.accepted(), timeout)
    }

    /// The bytes read so far (since the last call), each with the clocks of its arrival, oldest
    /// first (at most the last 2^20 are kept).
    pub fn take_arrivals(&mut self) -> Vec<Arrival> {
        self.arrivals.drain(..).collect()
    }

    fn keep_arrivals(&mut self, keep: bool) {
        self.log = keep;
        if !keep {
            self.arrivals = VecDeque::new();
        }
    }
}

impl Read for RelayStream {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let rx = self
            .from_device
            .lock()
            .map_err(|_| io::Error::other("relay receiver poisoned"))?;
        let first = match self.timeout {
            Some(t) => match rx.recv_timeout(t) {
                Ok(a) => a,
                Err(RecvTimeoutError::Timeout) => {
                    return Err(io::Error::new(
                        io::ErrorKind::TimedOut,
                        "relay read timeout",
                    ))
                }
                Err(RecvTimeoutError::Disconnected) => return Ok(0),
            },
            None => match rx.recv() {
                Ok(a) => a,
                Err(_) => return Ok(0),
            },
        };
        let mut n = 0;
        let mut next = Some(first);
        while let Some(a) = next {
            let Some(slot) = buf.get_mut(n) else {
                break;
            };
            *slot = a.byte;
            n += 1;
            if self.log {
                if self.arrivals.len() >= ARRIVALS_KEPT {
                    self.arrivals.pop_front();
                }
                self.arrivals.push_back(a);
            }
            next = if n < buf.len() {
                rx.try_recv().ok()
            } else {
                None
            };
        }
        Ok(n)
    }
}

impl Write for RelayStream {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.counters.device_closed() {
            return Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                "the device closed",
            ));
        }
        if buf.is_empty() {
            return Ok(0);
        }
        self.counters
            .accepted
            .fetch_add(buf.len() as u64, Ordering::AcqRel);
        self.to_device
            .send(buf.to_vec())
            .map_err(|_| io::Error::new(io::ErrorKind::BrokenPipe, "the relay stopped"))?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Transport for RelayStream {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.timeout = Some(timeout.max(Duration::from_millis(1)));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait(what: &str, mut f: impl FnMut() -> bool) {
        let t0 = Instant::now();
        while !f() {
            assert!(t0.elapsed() < Duration::from_secs(20), "{what}");
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Toward the device: paced, every byte delivered while the device reads, line clocks given.
    #[test]
    fn bytes_reach_the_device_at_the_line_rate() {
        let (mine, mut device) = UnixStream::pair().unwrap();
        let relay = Relay::new(mine, 115_200).unwrap();
        let mut client = relay.client();
        let t0 = Instant::now();
        client.write_all(&[7u8; 200]).unwrap();
        let mut got = vec![0u8; 200];
        device.read_exact(&mut got).unwrap();
        let last = client.wait_sent(Duration::from_secs(10)).unwrap();
        assert_eq!(got, vec![7u8; 200]);
        assert_eq!(last.to_device, 200);
        assert!(last.at - t0 >= byte_time(115_200) * 200);
        let c = relay.counters();
        assert_eq!((c.to_device_delivered(), c.to_device_dropped()), (200, 0));
        assert_eq!(c.stamp_of(200), Some(last));
    }

    /// A device that does not read: past the room the relay leaves it, bytes are lost, counted.
    #[test]
    fn bytes_the_device_does_not_take_are_lost_and_counted() {
        let (mine, _device) = UnixStream::pair().unwrap();
        let baud = 921_600;
        let relay = Relay::new(mine, baud).unwrap();
        let mut client = relay.client();
        let n = device_slack(baud) as u64 + 500;
        client.write_all(&vec![1u8; n as usize]).unwrap();
        client.wait_sent(Duration::from_secs(20)).unwrap();
        let c = relay.counters();
        assert_eq!(c.to_device_line(), n);
        assert!(c.to_device_dropped() >= 400, "{:?}", c.snapshot());
        // What the device side held untaken: every byte delivered (the device never read).
        let held = c.held_max();
        let delivered = c.to_device_delivered();
        assert!(
            held * 10 >= delivered * 9 && held <= delivered,
            "held {held} of {delivered}"
        );
    }

    /// Toward the host: paced, each byte with its clock, read one at a time from the device.
    #[test]
    fn bytes_reach_the_client_at_the_line_rate_with_their_clocks() {
        let (mine, mut device) = UnixStream::pair().unwrap();
        let relay = Relay::new(mine, 115_200).unwrap();
        let mut client = relay.client();
        client.set_io_timeout(Duration::from_secs(5)).unwrap();
        let t0 = Instant::now();
        let data: Vec<u8> = (0..100).collect();
        let writer = std::thread::spawn(move || device.write_all(&data).map(|()| device));
        let mut got = Vec::new();
        let mut buf = [0u8; 64];
        while got.len() < 100 {
            let n = client.read(&mut buf).unwrap();
            assert!(n > 0);
            got.extend_from_slice(&buf[..n]);
        }
        let _device = writer.join().unwrap().unwrap();
        assert_eq!(got, (0..100).collect::<Vec<u8>>());
        let arrivals = client.take_arrivals();
        let clocks: Vec<u64> = arrivals.iter().map(|a| a.stamp.to_host).collect();
        assert_eq!(clocks, (1..=100).collect::<Vec<u64>>());
        assert!(arrivals[99].stamp.at - t0 >= byte_time(115_200) * 100);
        wait("backlog", || relay.counters().backlog_max() > 0);
        assert!(relay.counters().backlog_max() <= 100);
    }
}
