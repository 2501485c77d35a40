//! Picks the firmware's memory layout: the root `memory.x` (which cortex-m-rt's `link.x`
//! includes, and the linker finds first, in the working directory) includes `board-memory.x`;
//! this script copies the selected board's layout into `OUT_DIR` under that name and puts
//! `OUT_DIR` on the linker's search path. Nothing happens for host builds.
use std::{env, fs, path::PathBuf};

/// Each board's feature (as cargo passes it to build scripts) and its layout file.
const BOARDS: [(&str, &str); 3] = [
    (
        "CARGO_FEATURE_BOARD_QEMU",
        "src/firmware/board/qemu/memory.x",
    ),
    (
        "CARGO_FEATURE_BOARD_STM32F411",
        "src/firmware/board/stm32f411-memory.x",
    ),
    (
        "CARGO_FEATURE_BOARD_STM32H743",
        "src/firmware/board/stm32h743-memory.x",
    ),
];

/// The QEMU board built as the STM32H743's capacity twin (`board-qemu` + `twin-h743`): the H743's
/// RAM regions, at their sizes, carved out of the mps2-an386's SSRAM.
const TWIN_H743: (&str, &str) = (
    "CARGO_FEATURE_TWIN_H743",
    "src/firmware/board/qemu/twin-h743-memory.x",
);

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    for (_, file) in BOARDS.iter().chain([&TWIN_H743]) {
        println!("cargo:rerun-if-changed={file}");
    }
    let bare_metal = env::var("CARGO_CFG_TARGET_OS").is_ok_and(|os| os == "none");
    if !bare_metal {
        return;
    }
    let selected: Vec<&str> = BOARDS
        .iter()
        .filter(|(feature, _)| env::var_os(feature).is_some())
        .map(|&(_, file)| file)
        .collect();
    let [mut layout] = selected[..] else {
        // The firmware itself says which board features are allowed; a library build for the
        // target without a board links nothing.
        return;
    };
    if env::var_os(TWIN_H743.0).is_some() && env::var_os(BOARDS[0].0).is_some() {
        layout = TWIN_H743.1;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy(layout, out.join("board-memory.x")).expect("copy the board's memory layout");
    println!("cargo:rustc-link-search={}", out.display());
}
