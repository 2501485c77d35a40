//! Picks the firmware's memory layout: the root `memory.x` (which cortex-m-rt's `link.x`
//! includes, and the linker finds first, in the working directory) includes `board-memory.x`;
//! this script copies the selected board's layout into `OUT_DIR` under that name and puts
//! `OUT_DIR` on the linker's search path. Nothing happens for host builds.
use std::{env, fs, path::PathBuf};

/// Each board's feature (as cargo passes it to build scripts) and its layout file.
const BOARDS: [(&str, &str); 2] = [
    (
        "CARGO_FEATURE_BOARD_QEMU",
        "src/firmware/board/qemu/memory.x",
    ),
    (
        "CARGO_FEATURE_BOARD_STM32F411",
        "src/firmware/board/stm32f411-memory.x",
    ),
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    for (_, file) in BOARDS {
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
    let [layout] = selected[..] else {
        // The firmware itself says which board features are allowed; a library build for the
        // target without a board links nothing.
        return;
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy(layout, out.join("board-memory.x")).expect("copy the board's memory layout");
    println!("cargo:rustc-link-search={}", out.display());
}
