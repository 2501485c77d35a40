#!/usr/bin/env bash
# Build the firmware for the ST Nucleo-H743ZI2 (STM32H743ZI, feature board-stm32h743) and print
# its flash and RAM use, per RAM region. It goes to its own target directory, so the QEMU build in
# target/ stays as it is.
#
#   scripts/build-stm32h743.sh        -> target/stm32h743/thumbv7em-none-eabihf/release/ohaca
#   probe-rs run --chip STM32H743ZITx target/stm32h743/thumbv7em-none-eabihf/release/ohaca
#   cargo flash-stm32h743             (builds, flashes and streams the defmt log: .cargo/config.toml)
set -euo pipefail
cd "$(dirname "$0")/.."
target_dir=target/stm32h743
cargo build --release --no-default-features --features board-stm32h743 --target-dir "$target_dir" "$@"
elf="$target_dir/thumbv7em-none-eabihf/release/ohaca"
scripts/firmware-size.sh "$elf"
# The regions beside the DTCM (static RAM above): NOLOAD sections of stm32h743-memory.x.
readelf -SW "$elf" | sed -n 's/^ *\[ *[0-9]*\] //p' | awk '$1 ~ /^\.(axisram|sram123|sram4)$/ {print $1, $5}' |
  while read -r name size; do
    case "$name" in
      .axisram) region="AXI SRAM, 524288" ;;
      .sram123) region="SRAM1-3, 294912" ;;
      *) region="SRAM4, 65536" ;;
    esac
    printf '  %-14s %8d  (%s)\n' "$name" "$((16#$size))" "$region"
  done
