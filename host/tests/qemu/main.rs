//! The firmware under QEMU (`qemu-system-arm -M mps2-an386`), end to end against the host side of
//! the link: one test binary (`cargo test ... --test qemu`), one module per concern, so the
//! dependency graph is linked once rather than once per file. Run one module with a filter, e.g.
//! `--test qemu -- responsive::`.
//!
//! Each test boots its own QEMU and kills it when done. The firmware (and the H743's capacity
//! twin, for `twin_maps` and `soak_twin`) is built once per run (`qemu::firmware`). Without
//! `qemu-system-arm` the tests fail, unless `OHACA_SKIP_QEMU=1`: then each prints a `SKIPPED` line
//! and returns. Nothing asserts on wall time: bounds are counts (bytes, frames, instructions
//! under `-icount`).

// The helpers (and the `need_qemu!` macro) come first, so the test modules see the macro.
#[macro_use]
mod qemu;
mod depot;

// Requests, replies, errors and the `ohaca send` tool over TCP and a pty.
mod e2e;
// Building-scale maps on the STM32F411-capacity firmware, bit for bit the host core's plans.
mod large;
// Behind the pacing relay (a real serial line): byte counts and line clocks.
mod paced;
// No planner piece over 1 M instructions, under `-icount`.
mod pieces;
// The robot's replanning loop: the device's plans are the host core's, warm and cold.
mod replan;
// Answers while a plan runs, and a `Cancel` is final, in device instructions.
mod responsive;
// Thousands of valid and broken frames, every reply checked.
mod soak;
// Faults at scale on the H743's capacity twin.
mod soak_twin;
// The H743's capacity twin on 1024 x 1024 and 2048 x 1024 maps.
mod twin_maps;
