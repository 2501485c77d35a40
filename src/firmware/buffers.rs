//! Where the map buffer and the planner's buffers live in RAM, per board, and the one function
//! that hands them out at boot: [`take`].
//!
//! - **STM32F411 and the default QEMU board** (maps of up to 262,144 cells, paths of up to
//!   4,095 steps, 2,047 in the full layout): one arena of 103,424 bytes, a zeroed static in
//!   `.bss` lent to `state::MAP`'s lock at boot ([`take`]): the map in its first bytes, the planner's buffers after it, laid out per map by
//!   `ohaca::planner::arena::carve` when a plan starts ([`lend`]). A 256 x 256 map leaves the
//!   planner every buffer a fixed 95,232-byte `Storage` would have; a 512 x 512 one takes 32 KiB and
//!   leaves the compact layout (4,095-step paths, `ohaca::planner::arena`'s docs).
//! - **STM32H743 and its QEMU twin** (`twin-h743`; maps of up to 2,097,152 cells, paths of up
//!   to 16,384 steps): the map (256 KiB) and the planner's two per-cell bit sets (256 KiB each)
//!   do not fit one RAM region (the largest, the AXI SRAM, has 512 KiB), so every buffer is a
//!   static of its own, placed with `#[link_section]` into the board's regions
//!   (`board/stm32h743-memory.x`, `board/qemu/twin-h743-memory.x`), and the planner's workspace
//!   is built from them with `Workspace::new(Buffers { .. })`:
//!
//! | region (size) | section | buffers | bytes |
//! | --- | --- | --- | ---: |
//! | AXI SRAM (512 KiB) | `.axisram` (NOLOAD) | map, `tabu` | 262,144 + 262,144 |
//! | SRAM1-3 (288 KiB) | `.sram123` (NOLOAD) | `dead`, `tau`, `delta` | 262,144 + 16,384 + 16,384 |
//! | SRAM4 (64 KiB) | `.sram4` (NOLOAD) | `links` (16,384) | 65,536 |
//! | ITCM (64 KiB) | `.itcm` (NOLOAD) | 8 bytes left out (no static at address 0), `guide` | 8 + 16,384 |
//! | DTCM (128 KiB) | `.bss` | 2 tours (16,385 each), `points` (16,385), `moves` | 32,770 + 65,540 + 1,024 |
//!
//! Every region but the DTCM and the ITCM is then full to the byte; the DTCM keeps about 23 KiB
//! for the rest of the firmware's statics (about 6 KiB) and the stack (about 3.4 KiB measured,
//! BENCHMARKS.md, section 5b), within the budget of 120 KiB. An ant path step costs 6 bytes of
//! DTCM: a byte in each of the two tours (the iteration's best and worst ants are walked again
//! rather than kept, as on the STM32F411) and a 4-byte path cell. The links (tightening's
//! positions, the coarse route's heap, the smoothing's links) are tightening's smallest hash
//! table for the longest path (`ohaca::tighten::hash_words`): 32,768 half-word slots for 16,385
//! cells, a load factor of up to 2/3 (one of 1/2 would need 128 KiB), which tightens exactly as
//! the per-cell index does. The device records no convergence curve (it never reports one), and
//! the coarse route moved from the DTCM to the ITCM (the CPU reads and writes it as data). Only
//! a best path of exactly 16,384 steps (16,385 cells, one more than the links) is smoothed
//! greedily instead of by the shortest-path smoothing; the host plans it alike
//! (`host/tests/qemu/qemu.rs`, `core_plan_steps`).
//!
//! The NOLOAD sections are not touched by the startup code (cortex-m-rt zeroes `.bss` only), so
//! their statics are `Region`s, `MaybeUninit` memory that [`take`] fills with zeros element by
//! element before it lends it out, once. Nothing reads them before.

pub use layout::{lend, take, MapBuf, PlanStorage, BYTES, MAP_INIT};

/// The lock the map buffer lives behind (`state::MAP`), which [`take`] lends the map to on the
/// boards whose map is a static of its own.
pub type MapLock =
    embassy_sync::mutex::Mutex<embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex, MapBuf>;

/// Which layout the board's description asks for (`ohaca::board::Board::layout`), derived once:
/// the cargo feature that picks the `layout` module below must agree with it.
const ARENA: bool = crate::firmware::board::BOARD.is_arena();
const _: () = assert!(ARENA == cfg!(not(any(feature = "twin-h743", feature = "board-stm32h743"))));

/// The map and the planner's buffers in one arena behind the map's lock (STM32F411 and the
/// default QEMU board).
#[cfg(not(feature = "twin-h743"))]
#[cfg(not(feature = "board-stm32h743"))]
mod layout {
    use ohaca::board::Layout;
    use ohaca::grid::Grid;
    use ohaca::planner::arena;
    use ohaca::planner::{Memory, Workspace};
    use static_cell::ConstStaticCell;

    use crate::firmware::board::BOARD;
    use crate::firmware::limits::{MAP_BYTES, PLAN_CELLS, PLAN_STEPS};

    /// The arena's words: the board's (`ohaca::board::F411`'s 25,856).
    const WORDS: usize = match BOARD.layout {
        Layout::Arena { words } => words,
        Layout::Separate { .. } => 0,
    };
    // Every map the device takes fits the arena at full resolution, and its map bytes are the
    // arena's first words (what the receiver writes).
    const _: () = assert!(arena::capacity(WORDS) >= PLAN_CELLS);
    const _: () = assert!(MAP_BYTES <= 4 * WORDS);

    /// The planner's own storage: nothing beyond the arena in the map's lock ([`lend`] carves
    /// the workspace out of it for each plan).
    pub struct PlanStorage;

    /// Bytes of the planner's buffers at the largest map (the arena without the map).
    pub const BYTES: usize = 4 * WORDS - MAP_BYTES;

    /// The arena: the map in its first [`MAP_BYTES`] bytes (what the receiver writes and
    /// `Deref` shows), the planner's buffers after the map of each plan (`lend`), lent to the
    /// lock once at boot by [`take`] (empty before); and what the pheromone in it remembers of
    /// the last plan (`ohaca::planner::Memory`), under the same lock as the map whose changes it
    /// records. The arena is a static of its own, zeroed in `.bss`: inside the lock beside the
    /// memory's initial value it would be 101 KiB of initialised `.data` in flash.
    pub struct MapBuf {
        words: Option<&'static mut [u32; WORDS]>,
        memory: Memory,
    }

    /// Its value at boot: no arena yet, no plan remembered.
    pub const MAP_INIT: MapBuf = MapBuf {
        words: None,
        memory: Memory::new(),
    };

    /// The arena's words, zeroed (`.bss`), lent to `state::MAP` by [`take`].
    static ARENA: ConstStaticCell<[u32; WORDS]> = ConstStaticCell::new([0; WORDS]);

    impl MapBuf {
        /// The map's bytes and the colony memory, both writable at once.
        pub fn split(&mut self) -> (&mut [u8], &mut Memory) {
            let words: &mut [u32] = match &mut self.words {
                Some(w) => &mut w[..],
                None => &mut [],
            };
            let bytes: &mut [u8] = bytemuck::cast_slice_mut(words);
            (
                bytes.get_mut(..MAP_BYTES).unwrap_or(&mut []),
                &mut self.memory,
            )
        }
    }

    impl core::ops::Deref for MapBuf {
        type Target = [u8];
        fn deref(&self) -> &[u8] {
            let words: &[u32] = self.words.as_deref().map_or(&[], |w| &w[..]);
            let bytes: &[u8] = bytemuck::cast_slice(words);
            bytes.get(..MAP_BYTES).unwrap_or(&[])
        }
    }

    impl core::ops::DerefMut for MapBuf {
        fn deref_mut(&mut self) -> &mut [u8] {
            self.split().0
        }
    }

    /// The map of `width x height` cells and a workspace for one plan on it, both from the
    /// arena (`ohaca::planner::arena::carve`: every buffer on maps of up to 68,256 cells, the
    /// compact layout beyond), and the colony memory.
    pub fn lend<'a>(
        map: &'a mut MapBuf,
        _storage: &'a mut PlanStorage,
        width: u16,
        height: u16,
    ) -> Result<(Grid<'a>, Workspace<'a>, &'a mut Memory), ohaca::Error> {
        let cells = usize::from(width) * usize::from(height);
        let words: &'a mut [u32] = match &mut map.words {
            Some(w) => &mut w[..],
            None => &mut [],
        };
        let carved = arena::carve(words, cells, PLAN_STEPS)?;
        let bits: &'a [u8] = carved.map;
        Ok((
            Grid::new(width, height, bits)?,
            carved.workspace,
            &mut map.memory,
        ))
    }

    static STORAGE: ConstStaticCell<PlanStorage> = ConstStaticCell::new(PlanStorage);

    /// Hand out the planner's storage and lend the arena to the map buffer behind `map_lock`
    /// (the lock `state::MAP`): the one place that does. Call once, at boot, before any task
    /// runs; a second call panics.
    pub fn take(map_lock: &super::MapLock) -> &'static mut PlanStorage {
        let storage = STORAGE.take();
        let mut buf = defmt::unwrap!(map_lock.try_lock().ok(), "the map buffer is locked at boot");
        buf.words = Some(ARENA.take());
        storage
    }
}

/// The planner's storage as separate statics over the STM32H743's RAM regions (the H743 and
/// its QEMU twin; the module docs have the table).
#[cfg(any(feature = "twin-h743", feature = "board-stm32h743"))]
mod layout {
    use core::cell::UnsafeCell;
    use core::mem::{size_of, MaybeUninit};
    use core::sync::atomic::{AtomicBool, Ordering};

    use static_cell::ConstStaticCell;

    use ohaca::bitmap::words;
    use ohaca::board::Layout;
    use ohaca::grid::{Dir, Point};
    use ohaca::pheromone::BLOCKS;
    use ohaca::planner::{Buffers, Memory, Workspace};
    use ohaca::route::GUIDE_BLOCKS;

    use crate::firmware::board::BOARD;
    use crate::firmware::limits::{MAP_BYTES, PLAN_CELLS, PLAN_STEPS};

    /// The map buffer behind `state::MAP`'s lock: the [`MAP`] static, lent to it once by
    /// [`take`]; empty before (nothing can read unset memory through it). With it, what the
    /// pheromone in the planner's storage remembers of the last plan (`ohaca::planner::Memory`),
    /// under the same lock as the map whose changes it records.
    pub struct MapBuf {
        bytes: Option<&'static mut [u8]>,
        memory: Memory,
    }

    /// Its value at boot: no buffer yet, no plan remembered.
    pub const MAP_INIT: MapBuf = MapBuf {
        bytes: None,
        memory: Memory::new(),
    };

    impl MapBuf {
        /// The map's bytes and the colony memory, both writable at once.
        pub fn split(&mut self) -> (&mut [u8], &mut Memory) {
            let bytes: &mut [u8] = match &mut self.bytes {
                Some(b) => b,
                None => &mut [],
            };
            (bytes, &mut self.memory)
        }
    }

    impl core::ops::Deref for MapBuf {
        type Target = [u8];
        fn deref(&self) -> &[u8] {
            self.bytes.as_deref().unwrap_or(&[])
        }
    }

    impl core::ops::DerefMut for MapBuf {
        fn deref_mut(&mut self) -> &mut [u8] {
            self.split().0
        }
    }

    /// Words of each per-cell bit set.
    const WORDS: usize = words(PLAN_CELLS);
    /// Entries of each tour and of the path cells: paths of up to [`PLAN_STEPS`] steps.
    const STEPS: usize = PLAN_STEPS + 1;
    /// Links and the move table's cells, from the board's description (`ohaca::board::H743`).
    const SEPARATE: (usize, usize) = match BOARD.layout {
        Layout::Separate { links, moves } => (links, moves),
        Layout::Arena { .. } => (0, 0),
    };
    /// Links: tightening's smallest hash table for the longest path (`ohaca::tighten::hash_words`:
    /// 32,768 half-word slots for 16,385 cells, a load factor of up to 2/3; one of 1/2 would
    /// need 65,536), and at least the coarse route's blocks (its heap): 16,384 words, all of
    /// SRAM4. The host plans in the same (`ohaca plan --board h743`).
    const LINKS: usize = SEPARATE.0;
    const _: () = assert!(LINKS >= GUIDE_BLOCKS && 4 * LINKS <= ohaca::board::H743_SRAM4_BYTES);
    /// The move table for maps of up to this many cells (larger maps compute moves on the fly).
    const MOVES: usize = SEPARATE.1;

    /// Memory the startup code does not initialise (a NOLOAD section): [`Region::fill`] writes
    /// every element before the memory is lent out, once.
    #[repr(transparent)]
    struct Region<T, const N: usize>(UnsafeCell<MaybeUninit<[T; N]>>);

    // SAFETY: the memory is only reached through `fill`, which `take` calls once per region
    // (guarded by `TAKEN`), before any task runs; afterwards the one `&'static mut` it returned
    // is the only way to it.
    unsafe impl<T, const N: usize> Sync for Region<T, N> {}

    impl<T: Copy, const N: usize> Region<T, N> {
        const fn new() -> Self {
            Region(UnsafeCell::new(MaybeUninit::uninit()))
        }

        /// Write `value` into every element and lend the whole array.
        ///
        /// # Safety
        /// At most once per region (the returned reference is exclusive for `'static`).
        #[allow(clippy::mut_from_ref)] // the memory is an UnsafeCell's, lent once (# Safety)
        unsafe fn fill(&'static self, value: T) -> &'static mut [T] {
            let first = self.0.get().cast::<T>();
            for i in 0..N {
                // SAFETY: `i < N`: inside the array; nothing else refers to it (the caller's
                // promise), and writing does not read the uninitialised value.
                unsafe { first.add(i).write(value) };
            }
            // SAFETY: all `N` elements were just initialised; the caller lends them once.
            unsafe { core::slice::from_raw_parts_mut(first, N) }
        }
    }

    /// The map: AXI SRAM.
    #[link_section = ".axisram.map"]
    static MAP: Region<u8, MAP_BYTES> = Region::new();
    /// The tabu bit set: AXI SRAM, beside the map.
    #[link_section = ".axisram.tabu"]
    static TABU: Region<u32, WORDS> = Region::new();
    /// The pruned-cell bit set: SRAM1-3.
    #[link_section = ".sram123.dead"]
    static DEAD: Region<u32, WORDS> = Region::new();
    /// Pheromone and its increments: SRAM1-3, after `dead`.
    #[link_section = ".sram123.tau"]
    static TAU: Region<[f32; 4], BLOCKS> = Region::new();
    #[link_section = ".sram123.delta"]
    static DELTA: Region<[f32; 4], BLOCKS> = Region::new();
    /// Links: SRAM4.
    #[link_section = ".sram4.links"]
    static LINKS_BUF: Region<u32, LINKS> = Region::new();
    /// The coarse route: ITCM (data accesses from the CPU; the section starts 8 bytes in, so no
    /// static is at address 0).
    #[link_section = ".itcm.guide"]
    static GUIDE: Region<u32, GUIDE_BLOCKS> = Region::new();

    /// What stays in the DTCM's `.bss` (zeroed by the startup code): the ant's tour and the
    /// best one (the iteration's best and worst ants are walked again instead of kept), the path
    /// cells and the move table.
    struct Dtcm {
        tours: [[Dir; STEPS]; 2],
        points: [Point; STEPS],
        moves: [u8; MOVES],
    }
    static DTCM: ConstStaticCell<Dtcm> = ConstStaticCell::new(Dtcm {
        tours: [[0; STEPS]; 2],
        points: [Point::new(0, 0); STEPS],
        moves: [0; MOVES],
    });

    static TAKEN: AtomicBool = AtomicBool::new(false);

    /// Bytes of the planner's buffers (without the map).
    pub const BYTES: usize = 2 * size_of::<[u32; WORDS]>()
        + 2 * size_of::<[[f32; 4]; BLOCKS]>()
        + size_of::<[u32; LINKS]>()
        + size_of::<[u32; GUIDE_BLOCKS]>()
        + size_of::<Dtcm>();

    /// The planner's buffers, each a `'static` slice of its own static.
    pub struct PlanStorage {
        tau: &'static mut [[f32; 4]],
        delta: &'static mut [[f32; 4]],
        tabu: &'static mut [u32],
        dead: &'static mut [u32],
        moves: &'static mut [u8],
        tours: [&'static mut [Dir]; 2],
        points: &'static mut [Point],
        links: &'static mut [u32],
        guide: &'static mut [u32],
    }

    impl PlanStorage {
        /// Lend the buffers as a workspace for one run (no convergence curve: the device does
        /// not report one).
        pub fn workspace(&mut self) -> Workspace<'_> {
            let [tour, best] = &mut self.tours;
            Workspace::new(Buffers {
                tau: self.tau,
                delta: self.delta,
                tabu: self.tabu,
                dead: self.dead,
                moves: self.moves,
                tours: [tour, &mut [], &mut [], best],
                points: self.points,
                links: self.links,
                curve: &mut [],
                guide: self.guide,
            })
        }
    }

    /// The map of `width x height` cells and the planner's workspace for one plan on it.
    pub fn lend<'a>(
        map: &'a mut MapBuf,
        storage: &'a mut PlanStorage,
        width: u16,
        height: u16,
    ) -> Result<(ohaca::grid::Grid<'a>, Workspace<'a>, &'a mut Memory), ohaca::Error> {
        let (bits, memory) = map.split();
        let bits: &'a [u8] = bits;
        Ok((
            ohaca::grid::Grid::new(width, height, bits)?,
            storage.workspace(),
            memory,
        ))
    }

    /// Build the planner's storage from the statics and lend the map static to `map` (the map
    /// buffer behind `state::MAP`'s lock): the one place that does. Call once, at boot, after
    /// the board's `init` (on the STM32H743 it enables the SRAM1-3 clocks) and before any task
    /// runs; a second call panics.
    pub fn take(map_lock: &super::MapLock) -> &'static mut PlanStorage {
        static STORAGE: ConstStaticCell<Option<PlanStorage>> = ConstStaticCell::new(None);
        let taken = TAKEN.swap(true, Ordering::AcqRel);
        defmt::assert!(!taken, "the planner's buffers are taken once");
        // SAFETY: once (`TAKEN`), so each region is filled and lent once.
        let (map, tabu, dead, tau, delta, links, guide) = unsafe {
            (
                MAP.fill(0),
                TABU.fill(0),
                DEAD.fill(0),
                TAU.fill([0.0; 4]),
                DELTA.fill([0.0; 4]),
                LINKS_BUF.fill(0),
                GUIDE.fill(0),
            )
        };
        let dtcm = DTCM.take();
        let [t0, t1] = &mut dtcm.tours;
        let storage = STORAGE.take().insert(PlanStorage {
            tau,
            delta,
            tabu,
            dead,
            moves: &mut dtcm.moves,
            tours: [t0, t1],
            points: &mut dtcm.points,
            links,
            guide,
        });
        let mut buf = defmt::unwrap!(map_lock.try_lock().ok(), "the map buffer is locked at boot");
        buf.bytes = Some(map);
        storage
    }
}
