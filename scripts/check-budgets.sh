#!/usr/bin/env bash
# Memory budgets of the release firmware for the real board (STM32F411CE: 128 KiB RAM, 512 KiB
# flash; issue 10: RAM <= 112 KiB, flash <= 256 KiB, maps of up to 65,536 cells (any shape) held at one bit a cell and planned at full resolution):
#
#   flash      = .vector_table + .text + .rodata + .data (its load image)    <= FLASH_BUDGET (262144)
#   static RAM = .data + .bss + .uninit
#   RAM        = static RAM + measured stack peak + STACK_MARGIN             <= RAM_BUDGET (114688)
#
# Builds the STM32F411 release firmware, prints `llvm-size -A` and the 20 largest symbols, measures
# the stack high-water mark, and exits 1 if a budget is exceeded (2 if something could not be
# measured). The stack peak cannot be measured on the STM32 without hardware, so it is measured on
# the QEMU build of the same firmware (same core, tasks and protocol code; only the board layer
# differs) under qemu-system-arm: scripts/ohaca_client.py runs `selftest` (every request and
# error path) and then `stack` (the deepest requests: 26x26 and 32x32 maps, a 770-cell path, every
# algorithm and smoothing, full runs without early stop), and the firmware reports its peak in
# Stats.stack_peak. STACK_MARGIN (512 bytes) covers what only the STM32 build runs: embassy-stm32's
# init and its USART / timer interrupt handlers instead of QEMU's UART / SysTick ones.
#
#   scripts/check-budgets.sh            (CI: non-interactive, about a minute)
#   FLASH_BUDGET=... RAM_BUDGET=... STACK_MARGIN=... scripts/check-budgets.sh
set -euo pipefail
cd "$(dirname "$0")/.."

FLASH_BUDGET=${FLASH_BUDGET:-262144}
RAM_BUDGET=${RAM_BUDGET:-114688}
STACK_MARGIN=${STACK_MARGIN:-512}
stm32_dir=target/stm32f411
stm32_elf=$stm32_dir/thumbv7em-none-eabihf/release/ohaca
qemu_elf=target/thumbv7em-none-eabihf/release/ohaca

# ---- tools ---------------------------------------------------------------------------------------
llvm_tool() {
  local t
  t=$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/"$1" 2>/dev/null | head -1 || true)
  if [ -z "$t" ] && rustup component add llvm-tools >/dev/null 2>&1; then
    t=$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/"$1" 2>/dev/null | head -1 || true)
  fi
  echo "$t"
}
llvm_size=$(llvm_tool llvm-size)
if command -v nm >/dev/null 2>&1 && nm --version 2>/dev/null | grep -q "GNU nm"; then
  nm_cmd=(nm)
else
  nm_cmd=("$(llvm_tool llvm-nm)")
fi

# Section sizes as "name size" lines (decimal), from llvm-size -A or, without it, readelf.
sections() {
  if [ -n "$llvm_size" ]; then
    "$llvm_size" -A -d "$1" | awk 'NF == 3 && $1 ~ /^\./ {print $1, $2}'
  else
    readelf -SW "$1" | sed -n 's/^ *\[ *[0-9]*\] //p' | awk '$1 ~ /^\./ {print $1, $5}' |
      while read -r name size; do echo "$name $((16#$size))"; done
  fi
}
section() { sections "$1" | awk -v s="$2" '$1 == s {n += $2} END {print n + 0}'; }

# ---- build ---------------------------------------------------------------------------------------
echo "== building the STM32F411 release firmware"
cargo build --release -q --no-default-features --features board-stm32f411 --target-dir "$stm32_dir"
echo "== building the QEMU release firmware (for the stack measurement)"
cargo build --release -q

# ---- where the bytes go --------------------------------------------------------------------------
echo
echo "== $stm32_elf: sections"
if [ -n "$llvm_size" ]; then
  "$llvm_size" -A -d "$stm32_elf"
else
  echo "(llvm-size not found: rustup component add llvm-tools; readelf instead)"
  sections "$stm32_elf"
fi
echo "== 20 largest symbols (size in bytes; t/T code, r/R read-only data, d/D data, b/B RAM)"
"${nm_cmd[@]}" --size-sort -S -C "$stm32_elf" | tail -20 | tac |
  while read -r _addr size kind name; do printf '%8d  %s %s\n' "$((16#$size))" "$kind" "$name"; done

flash=0
for s in .vector_table .text .rodata .data; do flash=$((flash + $(section "$stm32_elf" "$s"))); done
static_ram=0
for s in .data .bss .uninit; do static_ram=$((static_ram + $(section "$stm32_elf" "$s"))); done

# ---- stack peak, measured on the QEMU build ------------------------------------------------------
echo
echo "== measuring the stack peak on the QEMU build (the STM32 one needs hardware)"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log=$(mktemp)
scripts/qemu-serve.sh --no-build --icount --port "$port" --defmt /dev/null 2>"$log" &
qemu=$!
trap 'kill "$qemu" 2>/dev/null || true; wait "$qemu" 2>/dev/null || true; rm -f "$log"' EXIT
stack_peak=""
if timeout 300 python3 scripts/ohaca_client.py --port "$port" selftest >/dev/null &&
   out=$(timeout 300 python3 scripts/ohaca_client.py --port "$port" stack); then
  echo "$out" | sed 's/^/  /'
  stack_peak=$(echo "$out" | awk '/^stack_peak / {print $2}')
fi
kill "$qemu" 2>/dev/null || true
wait "$qemu" 2>/dev/null || true
if [ -z "$stack_peak" ]; then
  echo "could not measure the stack peak; QEMU said:" >&2
  cat "$log" >&2
  exit 2
fi
qemu_static=0
for s in .data .bss .uninit; do qemu_static=$((qemu_static + $(section "$qemu_elf" "$s"))); done

# ---- verdict -------------------------------------------------------------------------------------
ram=$((static_ram + stack_peak + STACK_MARGIN))
status=0
verdict() { if [ "$1" -le "$2" ]; then echo ok; else echo "OVER BUDGET"; status=1; fi; }
flash_ok=$(verdict "$flash" "$FLASH_BUDGET")
ram_ok=$(verdict "$ram" "$RAM_BUDGET")
[ "$flash_ok" = ok ] || status=1
[ "$ram_ok" = ok ] || status=1
echo
echo "== budgets: STM32F411 release firmware, maps of up to 65,536 cells (any shape) planned at full resolution, 50 ants"
printf '| %-58s | %8s | %8s | %-11s |\n' "item" "bytes" "budget" "verdict"
printf '| %-58s | %8s | %8s | %-11s |\n' "---" "---" "---" "---"
printf '| %-58s | %8d | %8d | %-11s |\n' "flash (.vector_table + .text + .rodata + .data)" "$flash" "$FLASH_BUDGET" "$flash_ok"
printf '| %-58s | %8d | %8s | %-11s |\n' "static RAM (.data + .bss + .uninit)" "$static_ram" "" ""
printf '| %-58s | %8d | %8s | %-11s |\n' "stack peak, measured on the QEMU build (Stats.stack_peak)" "$stack_peak" "" ""
printf '| %-58s | %8d | %8s | %-11s |\n' "margin for STM32-only init and interrupt handlers" "$STACK_MARGIN" "" ""
printf '| %-58s | %8d | %8d | %-11s |\n' "RAM (static + stack peak + margin)" "$ram" "$RAM_BUDGET" "$ram_ok"
echo
echo "The stack peak is the QEMU build's (static RAM $qemu_static bytes there), added to the STM32"
echo "build's static RAM: the STM32 stack cannot be measured without the board."
if [ "$status" != 0 ]; then
  echo "FAILED: a memory budget is exceeded" >&2
fi
exit "$status"
