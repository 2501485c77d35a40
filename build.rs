//! Picks the firmware's memory layout: the QEMU board's `memory.x` goes on the linker's search
//! path for `board-qemu` builds of the firmware; the STM32F411 build uses the one embassy-stm32
//! generates (feature `memory-x`). Nothing happens for host builds.
use std::{env, fs, path::PathBuf};

fn main() {
    const QEMU_MEMORY: &str = "src/firmware/board/qemu/memory.x";
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={QEMU_MEMORY}");
    let bare_metal = env::var("CARGO_CFG_TARGET_OS").is_ok_and(|os| os == "none");
    if bare_metal && env::var_os("CARGO_FEATURE_BOARD_QEMU").is_some() {
        let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        fs::copy(QEMU_MEMORY, out.join("memory.x")).expect("copy memory.x");
        println!("cargo:rustc-link-search={}", out.display());
    }
}
