#!/usr/bin/env bash
# Flash and RAM use of a firmware ELF (default: the QEMU build), from its section headers.
#   flash = .vector_table + .text + .rodata + .data (its load image)
#   RAM   = .data + .bss + .uninit (static RAM; the stack takes the rest)
# Uses readelf (binutils); `llvm-size -A` prints the same sections.
set -euo pipefail
cd "$(dirname "$0")/.."
elf="${1:-target/thumbv7em-none-eabihf/release/ohaca}"
flash=0
ram=0
while read -r name size; do
  size=$((16#$size))
  case "$name" in
    .vector_table|.text|.rodata) flash=$((flash + size)) ;;
    .data) flash=$((flash + size)); ram=$((ram + size)) ;;
    .bss|.uninit) ram=$((ram + size)) ;;
    *) continue ;;
  esac
  printf '  %-14s %8d\n' "$name" "$size"
done < <(readelf -SW "$elf" | sed -n 's/^ *\[ *[0-9]*\] //p' | awk '{print $1, $5}')
echo "$elf"
echo "  flash $flash bytes ($((flash / 1024)) KiB), static RAM $ram bytes ($((ram / 1024)) KiB)"
