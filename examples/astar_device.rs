//! The exact A* baseline (`ohaca::astar`) in both its variants, 4 bits a cell plus a heap
//! (`astar::search`) and a `u32` cost a cell plus a heap (`astar::search_costs`), as a bare-metal
//! bench for QEMU's mps2-an386 (Cortex-M4F), counted the way the firmware's plans are (issue 27
//! item 1).
//!
//! ```sh
//! cargo build --release --example astar_device
//! qemu-system-arm -M mps2-an386 -display none -monitor none -serial null \
//!     -semihosting-config enable=on,target=native -icount shift=0 \
//!     -kernel target/thumbv7em-none-eabihf/release/examples/astar_device \
//!     -append "$PWD/maps/complex-26.map 0 0 25 25"
//! ```
//!
//! The command line (semihosting `SYS_GET_CMDLINE`, QEMU's `-append`) names a Moving AI `.map`
//! file on the host and the start and goal cells. The file is read over semihosting and parsed
//! into the map's bits (one bit a cell, `ohaca::grid`) before anything is counted. Counted, for
//! each variant in turn: from that map in RAM to the path's cells written, i.e. the per-cell
//! storage cleared, the search and the path written out. Two lines of `key=value` results go to
//! the host's stdout (the 4-bit variant's keys bare, the cost variant's prefixed `c_`); the exit
//! status is 0 if both found a path, 1 otherwise.
//!
//! **Counting.** QEMU's `-icount shift=0` advances virtual time 1 ns per instruction. SysTick runs
//! from the 25 MHz core clock (`src/firmware/board/qemu/systick.rs`), so one SysTick cycle is
//! 40 instructions; the bench measures it at every start (a loop of `subs`/`bne`, 2 instructions
//! an iteration, run for 1 M and 2 M iterations: `instr_per_cycle`) and reports
//! `instructions = cycles x 40`, with the empty measurement's cost taken off (`overhead_cycles`).
//! The SysTick interrupt counts the 2^24-cycle wraps (about 671 M instructions each).
//!
//! **Memory.** The QEMU board's `memory.x` keeps to the F411's 128 KiB of RAM; the buffers here
//! (the file text, the bits, the nibbles, the costs, the path and the open list) live in the
//! board's 16 MiB of PSRAM at 0x2100_0000, which no linker script uses: one audited `unsafe`
//! below.
//!
//! On the host this example is an empty `main` (the workspace's `--all-targets` runs build it).
#![cfg_attr(all(target_arch = "arm", target_os = "none"), no_std, no_main)]

#[cfg(not(all(target_arch = "arm", target_os = "none")))]
fn main() {}

#[cfg(all(target_arch = "arm", target_os = "none"))]
mod device {
    use core::fmt::Write;
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m::peripheral::{SCB, SYST};
    use cortex_m_rt::{entry, exception};
    use cortex_m_semihosting::{debug, hio, syscall, syscall1};
    use ohaca::astar::{self, Entry};
    use ohaca::{Grid, Point};

    /// The mps2-an386's PSRAM: 16 MiB at 0x2100_0000 (QEMU `mps2.c`, "mps.ram").
    const PSRAM: usize = 0x2100_0000;
    const PSRAM_BYTES: usize = 16 << 20;
    /// SysTick's reload: the full 24 bits.
    const RELOAD: u32 = 0x00FF_FFFF;
    /// Instructions per SysTick cycle under `-icount shift=0`: 1 ns each, 25 MHz core clock.
    const INSTR_PER_CYCLE: u64 = 1_000_000_000 / 25_000_000;

    static WRAPS: AtomicU32 = AtomicU32::new(0);

    #[exception]
    fn SysTick() {
        WRAPS.fetch_add(1, Ordering::Relaxed);
    }

    /// SysTick cycles since it was started.
    #[inline(always)]
    fn now() -> u64 {
        loop {
            let w = WRAPS.load(Ordering::Relaxed);
            let cvr = SYST::get_current();
            let pending = SCB::is_pendst_pending();
            if WRAPS.load(Ordering::Relaxed) == w && !pending {
                return u64::from(w) * (u64::from(RELOAD) + 1) + u64::from(RELOAD - cvr);
            }
        }
    }

    /// `n` iterations of a 2-instruction loop.
    #[inline(never)]
    fn spin(n: u32) {
        // SAFETY: a register-only countdown loop: no memory, no stack.
        unsafe {
            core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) n => _,
                             options(nomem, nostack));
        }
    }

    fn out() -> Option<hio::HostStream> {
        hio::hstdout().ok()
    }

    fn fail(msg: &str) -> ! {
        if let Some(mut o) = out() {
            let _ = writeln!(o, "error={msg}");
        }
        debug::exit(debug::EXIT_FAILURE);
        loop {
            cortex_m::asm::bkpt();
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        fail("panic")
    }

    /// The semihosting command line into `buf`; its length.
    fn cmdline(buf: &mut [u8]) -> Option<usize> {
        let mut block = [buf.as_mut_ptr() as usize, buf.len()];
        // SAFETY: SYS_GET_CMDLINE writes at most `block[1]` bytes to `block[0]` (our buffer) and
        // the length into `block[1]`.
        let r = unsafe { syscall1!(GET_CMDLINE, block.as_mut_ptr()) };
        (r == 0).then_some(block[1].min(buf.len()))
    }

    /// Read the host file `path` into `buf`; its length.
    fn read_file(path: &[u8], buf: &mut [u8]) -> Option<usize> {
        let mut name = [0u8; 512];
        name.get_mut(..path.len())?.copy_from_slice(path);
        // SAFETY: OPEN reads `path.len()` bytes of the NUL-terminated name; READ writes at most
        // the given length into `buf`; FLEN and CLOSE take the handle only.
        unsafe {
            let fd = syscall!(OPEN, name.as_ptr(), 1 /* "rb" */, path.len()) as isize;
            if fd < 0 {
                return None;
            }
            let len = syscall!(FLEN, fd) as isize;
            let len = usize::try_from(len).ok().filter(|&l| l <= buf.len())?;
            let left = syscall!(READ, fd, buf.as_mut_ptr(), len);
            syscall!(CLOSE, fd);
            Some(len - left)
        }
    }

    fn num(t: Option<&[u8]>) -> Option<u16> {
        core::str::from_utf8(t?).ok()?.parse().ok()
    }

    /// Parse a Moving AI `.map` text into `bits` (1 = blocked); `(width, height)`.
    fn parse_map(text: &[u8], bits: &mut [u8]) -> Option<(u16, u16)> {
        let mut lines = text
            .split(|&c| c == b'\n')
            .map(|l| l.strip_suffix(b"\r").unwrap_or(l));
        let (mut w, mut h) = (None, None);
        for l in lines.by_ref() {
            let mut f = l.split(|&c| c == b' ').filter(|t| !t.is_empty());
            match f.next() {
                Some(b"height") => h = num(f.next()),
                Some(b"width") => w = num(f.next()),
                Some(b"map") => break,
                _ => {}
            }
        }
        let (w, h) = (w?, h?);
        let need = ohaca::grid::bytes_for(usize::from(w) * usize::from(h));
        bits.get_mut(..need)?.fill(0);
        for y in 0..usize::from(h) {
            let row = lines.next()?;
            for x in 0..usize::from(w) {
                if !matches!(row.get(x)?, b'.' | b'G' | b'S') {
                    let i = y * usize::from(w) + x;
                    *bits.get_mut(i / 8)? |= 1 << (i % 8);
                }
            }
        }
        Some((w, h))
    }

    /// Split `mem` at `n` bytes rounded up to 4 (every part stays word-aligned).
    fn take(mem: &'static mut [u8], n: usize) -> Option<(&'static mut [u8], &'static mut [u8])> {
        let n = n.checked_add(3)? & !3;
        (n <= mem.len()).then(|| mem.split_at_mut(n))
    }

    #[entry]
    fn main() -> ! {
        let mut cp = cortex_m::Peripherals::take().unwrap_or_else(|| fail("peripherals"));
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(RELOAD);
        cp.SYST.clear_current();
        cp.SYST.enable_interrupt();
        cp.SYST.enable_counter();
        // A counter cleared to 0 reloads on its first clock without an interrupt: start counting
        // once it has.
        while SYST::get_current() == 0 {}

        // Calibration: instructions per SysTick cycle, and the cost of an empty measurement.
        let t0 = now();
        let t1 = now();
        let overhead = t1 - t0;
        let a = now();
        spin(1_000_000);
        let b = now();
        spin(2_000_000);
        let c = now();
        let (c1, c2) = (b - a, c - b);
        // 2 M more instructions in the second loop than the first (2 per iteration).
        let per_cycle_milli = 2_000_000_000u64
            .checked_div(c2.saturating_sub(c1))
            .unwrap_or(0);

        // SAFETY: 0x2100_0000..+16 MiB is RAM on the mps2-an386 (PSRAM) and outside every region
        // of the linker script (flash at 0x0, RAM at 0x2000_0000..+128 KiB), so nothing else
        // refers to it; this is the only reference made to it, taken once, here.
        let mem: &'static mut [u8] =
            unsafe { core::slice::from_raw_parts_mut(PSRAM as *mut u8, PSRAM_BYTES) };

        let mut line = [0u8; 1024];
        let n = cmdline(&mut line).unwrap_or_else(|| fail("no command line"));
        // The last five words: the map file and four coordinates (QEMU puts the kernel's name
        // first when it passes `-append`, and nothing else).
        let mut toks: [&[u8]; 5] = [&[]; 5];
        let mut words = 0usize;
        for t in line[..n]
            .split(|&c| c == b' ' || c == 0)
            .filter(|t| !t.is_empty())
        {
            toks.rotate_left(1);
            toks[4] = t;
            words += 1;
        }
        if words < 5 {
            if let Some(mut o) = out() {
                let _ = writeln!(o, "cmdline={:?}", core::str::from_utf8(&line[..n]));
            }
            fail("usage: MAP SX SY GX GY")
        }
        let path = toks[0];
        let coords = [toks[1], toks[2], toks[3], toks[4]].map(|t| num(Some(t)));
        let [Some(sx), Some(sy), Some(gx), Some(gy)] = coords else {
            fail("usage: MAP SX SY GX GY")
        };

        let (text, rest) = take(mem, 4 << 20).unwrap_or_else(|| fail("memory"));
        let len = read_file(path, text).unwrap_or_else(|| fail("cannot read the map file"));
        let (bits, rest) = take(rest, 128 << 10).unwrap_or_else(|| fail("memory"));
        let (w, h) = parse_map(&text[..len], bits).unwrap_or_else(|| fail("bad map file"));
        let cells = usize::from(w) * usize::from(h);
        let grid = Grid::new(w, h, bits).unwrap_or_else(|_| fail("bad map"));
        let (nibbles, rest) =
            take(rest, astar::nibble_bytes(cells)).unwrap_or_else(|| fail("memory"));
        let (costs_mem, rest) = take(rest, 4 * cells).unwrap_or_else(|| fail("memory"));
        let costs: &mut [u32] = bytemuck::cast_slice_mut(costs_mem);
        let (path_mem, rest) = take(rest, 4 * 65_536).unwrap_or_else(|| fail("memory"));
        let path_out: &mut [Point] = bytemuck::cast_slice_mut(path_mem);
        let heap_len = rest.len() / astar::ENTRY_BYTES * astar::ENTRY_BYTES;
        let heap: &mut [Entry] = bytemuck::cast_slice_mut(&mut rest[..heap_len]);
        let (start, goal) = (Point::new(sx, sy), Point::new(gx, gy));

        // Counted, each variant: map in RAM -> path cells written.
        let t0 = now();
        let r4 = astar::search(&grid, start, goal, nibbles, heap)
            .and_then(|s| astar::write_path(&grid, nibbles, goal, &s, path_out).map(|n| (s, n)));
        let t1 = now();
        let cycles4 = (t1 - t0).saturating_sub(overhead);
        let t0 = now();
        let rc = astar::search_costs(&grid, start, goal, costs, heap).and_then(|s| {
            astar::write_path_costs(&grid, costs, goal, &s, path_out).map(|n| (s, n))
        });
        let t1 = now();
        let cycles_c = (t1 - t0).saturating_sub(overhead);

        let mut o = out().unwrap_or_else(|| fail("no stdout"));
        let _ = writeln!(
            o,
            "astar w={w} h={h} start={sx},{sy} goal={gx},{gy} instr_per_cycle={}.{:03} \
             calib_cycles={c1},{c2} overhead_cycles={overhead}",
            per_cycle_milli / 1000,
            per_cycle_milli % 1000
        );
        let mut ok = true;
        for (prefix, r, cycles) in [("", r4, cycles4), ("c_", rc, cycles_c)] {
            let _ = write!(
                o,
                "{prefix}cycles={cycles} {prefix}instructions={} ",
                cycles * INSTR_PER_CYCLE
            );
            match r {
                Ok((s, n)) => {
                    let _ = writeln!(
                        o,
                        "{prefix}length={:.6} {prefix}steps={} {prefix}cells_written={n} \
                         {prefix}expansions={} {prefix}pushes={} {prefix}peak_heap={} \
                         {prefix}cell_bytes={} {prefix}heap_bytes={} {prefix}ram_bytes={}",
                        s.length,
                        s.steps(),
                        s.expansions,
                        s.pushes,
                        s.peak_heap,
                        s.cell_bytes,
                        s.peak_heap as usize * astar::ENTRY_BYTES,
                        s.ram_bytes()
                    );
                }
                Err(e) => {
                    ok = false;
                    let _ = writeln!(o, "{prefix}error={e}");
                }
            }
        }
        debug::exit(if ok {
            debug::EXIT_SUCCESS
        } else {
            debug::EXIT_FAILURE
        });
        loop {
            cortex_m::asm::bkpt();
        }
    }
}
