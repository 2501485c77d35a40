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
# The regions beside the DTCM (static RAM above): NOLOAD sections of stm32h743-memory.x, each
# against its region's size (the linker refuses an overflow too); exit 1 if one is over.
status=0
while read -r name size; do
  size=$((16#$size))
  case "$name" in
    .axisram) region="AXI SRAM"; limit=524288 ;;
    .sram123) region="SRAM1-3"; limit=294912 ;;
    .sram4) region="SRAM4"; limit=65536 ;;
    *) region="ITCM"; limit=65536 ;;
  esac
  verdict=ok
  if [ "$size" -gt "$limit" ]; then verdict="OVER BUDGET"; status=1; fi
  printf '  %-14s %8d  (%s, %d: %s)\n' "$name" "$size" "$region" "$limit" "$verdict"
done < <(readelf -SW "$elf" | sed -n 's/^ *\[ *[0-9]*\] //p' | awk '$1 ~ /^\.(axisram|sram123|sram4|itcm)$/ {print $1, $5}')
if [ "$(readelf -SW "$elf" | grep -c ' \.itcm ')" != 1 ]; then
  echo "no .itcm section in $elf" >&2
  status=1
fi
exit "$status"
