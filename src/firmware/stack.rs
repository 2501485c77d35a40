//! Stack high-water mark.
//!
//! cortex-m-rt (feature `paint-stack`) fills the whole stack region with
//! [`cortex_m_rt::STACK_PAINT_VALUE`] in the reset handler, before `.data` is initialised and
//! `main` runs. The region is `_stack_end` (the end of static RAM: `.data`, `.bss`, `.uninit`)
//! to `_stack_start` (the top of RAM, the initial stack pointer). The stack grows down from the
//! top, and interrupt handlers run on it too, so the lowest word that no longer holds the paint
//! is the deepest the stack has ever reached. The QEMU board has the STM32F411's layout (its
//! `memory.x` copies the 128 KiB of RAM), and its `twin-h743` build the STM32H743's (the stack at
//! the top of the 128 KiB DTCM, the large buffers in the other regions), so the numbers carry
//! over to the chips.

use core::ptr::{addr_of, read_volatile};

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    /// Top of the stack (cortex-m-rt's linker script; the initial stack pointer).
    static _stack_start: u32;
    /// Bottom of the stack region: the end of static RAM.
    static _stack_end: u32;
}

/// The stack region, `(bottom, top)` addresses.
fn region() -> (usize, usize) {
    // Only the symbols' addresses are taken (safe), never their (nonexistent) values.
    (
        addr_of!(_stack_end) as usize,
        addr_of!(_stack_start) as usize,
    )
}

/// Bytes of RAM the stack may use.
pub fn size() -> u32 {
    let (bottom, top) = region();
    top.saturating_sub(bottom) as u32
}

/// Most stack used since boot, in bytes: from the top of RAM down to the lowest word that lost
/// its paint. Reads up to [`size`] / 4 words (about 0.1 ms at 96 MHz); equals [`size`] if the
/// stack reached the end of static RAM (it has then overwritten statics).
pub fn peak() -> u32 {
    let (bottom, top) = region();
    let mut at = bottom;
    while at < top {
        // SAFETY: `at` is a word-aligned address inside RAM, between the end of the statics and
        // the top of the stack: memory no Rust object owns (the unused part of the stack) or a
        // live stack frame, which a volatile read cannot disturb. `_stack_end` is 4-byte aligned
        // (cortex-m-rt asserts it).
        let word = unsafe { read_volatile(at as *const u32) };
        if word != STACK_PAINT_VALUE {
            break;
        }
        at += 4;
    }
    top.saturating_sub(at) as u32
}
