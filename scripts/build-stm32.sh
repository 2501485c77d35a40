#!/usr/bin/env bash
# Build the firmware for the STM32F411 "Black Pill" (feature board-stm32f411) and print its flash
# and RAM use. It goes to its own target directory, so the QEMU build in target/ stays as it is.
#
#   scripts/build-stm32.sh            -> target/stm32f411/thumbv7em-none-eabihf/release/ohaca
#   probe-rs run --chip STM32F411CEUx target/stm32f411/thumbv7em-none-eabihf/release/ohaca
set -euo pipefail
cd "$(dirname "$0")/.."
target_dir=target/stm32f411
cargo build --release --no-default-features --features board-stm32f411 --target-dir "$target_dir" "$@"
elf="$target_dir/thumbv7em-none-eabihf/release/ohaca"
scripts/firmware-size.sh "$elf"
