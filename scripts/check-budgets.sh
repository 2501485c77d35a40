#!/usr/bin/env bash
# Memory budgets of the release firmware for the real board (STM32F411CE: 128 KiB RAM, 512 KiB
# flash; issue 10: RAM <= 112 KiB, flash <= 256 KiB, maps of up to 262,144 cells (any shape) held at one bit a cell and planned at full resolution; issue 19):
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
# Then the same for the STM32H743 (Nucleo-H743ZI2: 2 MiB flash; RAM in four regions, DTCM
# 128 KiB, AXI SRAM 512 KiB, SRAM1-3 288 KiB, SRAM4 64 KiB, ITCM 64 KiB; maps of up to 2,097,152
# cells, paths of up to 16,384 steps), per region:
#
#   flash      = .vector_table + .text + .rodata + .data                    <= H7_FLASH_BUDGET (1 MiB)
#   DTCM       = .data + .bss + .uninit + measured stack peak + STACK_MARGIN <= H7_DTCM_BUDGET (120 KiB)
#   AXI SRAM   = .axisram                                                    <= 512 KiB
#   SRAM1-3    = .sram123                                                    <= 288 KiB
#   SRAM4      = .sram4                                                      <= 64 KiB
#   ITCM       = .itcm                                                       <= 64 KiB
#
# Its stack peak is measured on its QEMU capacity twin (`--features twin-h743`: the H743's
# capacity, RAM regions and buffer placement on the mps2-an386), with `selftest`, `stack` and a
# plan on the 1024 x 1024 Sydney_0_1024 map (its longest scenario).
#
#   scripts/check-budgets.sh            (CI: non-interactive, about two minutes)
#   FLASH_BUDGET=... RAM_BUDGET=... STACK_MARGIN=... H7_FLASH_BUDGET=... H7_DTCM_BUDGET=... scripts/check-budgets.sh
set -euo pipefail
cd "$(dirname "$0")/.."

FLASH_BUDGET=${FLASH_BUDGET:-262144}
RAM_BUDGET=${RAM_BUDGET:-114688}
STACK_MARGIN=${STACK_MARGIN:-512}
H7_FLASH_BUDGET=${H7_FLASH_BUDGET:-1048576}
H7_DTCM_BUDGET=${H7_DTCM_BUDGET:-122880}
stm32_dir=target/stm32f411
stm32_elf=$stm32_dir/thumbv7em-none-eabihf/release/ohaca
qemu_elf=target/thumbv7em-none-eabihf/release/ohaca
h7_dir=target/stm32h743
h7_elf=$h7_dir/thumbv7em-none-eabihf/release/ohaca
twin_dir=target/twin-h743
twin_elf=$twin_dir/thumbv7em-none-eabihf/release/ohaca

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
echo "== building the STM32H743 release firmware and its QEMU twin (for its stack measurement)"
cargo build --release -q --no-default-features --features board-stm32h743 --target-dir "$h7_dir"
cargo build --release -q --features twin-h743 --target-dir "$twin_dir"

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

# ---- stack peak, measured on a QEMU build ---------------------------------------------------------
# measure_stack ELF [extra ohaca_client.py command...]: selftest, stack, then the extra command;
# prints the Stats.stack_peak after all of them (exit 2 if it could not be measured).
log=$(mktemp)
trap 'rm -f "$log"' EXIT
measure_stack() {
  local elf=$1 port out peak=""
  shift
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  scripts/qemu-serve.sh --elf "$elf" --icount --port "$port" --defmt /dev/null 2>"$log" &
  qemu=$!
  # (this runs in a command substitution's subshell: its own trap stops QEMU)
  trap 'kill "${qemu:-}" 2>/dev/null || true; wait "${qemu:-}" 2>/dev/null || true' EXIT
  if timeout 300 python3 scripts/ohaca_client.py --port "$port" selftest >/dev/null &&
     { [ $# -eq 0 ] || timeout 600 python3 scripts/ohaca_client.py --port "$port" "$@" >/dev/null; } &&
     out=$(timeout 300 python3 scripts/ohaca_client.py --port "$port" stack); then
    echo "$out" | sed 's/^/  /' >&2
    peak=$(echo "$out" | awk '/^stack_peak / {print $2}')
  fi
  kill "$qemu" 2>/dev/null || true
  wait "$qemu" 2>/dev/null || true
  if [ -z "$peak" ]; then
    echo "could not measure the stack peak of $elf; QEMU said:" >&2
    cat "$log" >&2
    exit 2
  fi
  echo "$peak"
}

echo
echo "== measuring the stack peak on the QEMU build (the STM32 one needs hardware)"
stack_peak=$(measure_stack "$qemu_elf")
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
echo "== budgets: STM32F411 release firmware, maps of up to 262,144 cells (any shape) planned at full resolution in one arena, any number of ants (none is stored)"
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

# ---- the STM32H743: flash, and RAM per region ----------------------------------------------------
echo
echo "== $h7_elf: sections"
if [ -n "$llvm_size" ]; then
  "$llvm_size" -A -d "$h7_elf"
else
  sections "$h7_elf"
fi
echo "== measuring the stack peak on the H743's QEMU twin (selftest, stack, Sydney_0_1024's longest scenario)"
h7_stack=$(measure_stack "$twin_elf" plan --map maps/large/Sydney_0_1024.map --start 1,40 --goal 986,983)
h7_flash=0
for s in .vector_table .text .rodata .data; do h7_flash=$((h7_flash + $(section "$h7_elf" "$s"))); done
h7_static=0
for s in .data .bss .uninit; do h7_static=$((h7_static + $(section "$h7_elf" "$s"))); done
twin_static=0
for s in .data .bss .uninit; do twin_static=$((twin_static + $(section "$twin_elf" "$s"))); done
h7_dtcm=$((h7_static + h7_stack + STACK_MARGIN))
h7_axi=$(section "$h7_elf" .axisram)
h7_sram123=$(section "$h7_elf" .sram123)
h7_sram4=$(section "$h7_elf" .sram4)
h7_itcm=$(section "$h7_elf" .itcm)
# Every region section must be there (`section` prints 0 for a missing one, which would pass the
# budgets below), and the twin must place the same buffers in regions of the same sizes.
for elf in "$h7_elf" "$twin_elf"; do
  for s in .axisram .sram123 .sram4 .itcm; do
    if [ "$(readelf -SW "$elf" | grep -c " \\$s ")" != 1 ]; then
      echo "no $s section in $elf" >&2
      status=1
    fi
  done
done
for s in .axisram .sram123 .sram4 .itcm; do
  if [ "$(section "$twin_elf" "$s")" != "$(section "$h7_elf" "$s")" ]; then
    echo "the twin's $s ($(section "$twin_elf" "$s") bytes) is not the H743's ($(section "$h7_elf" "$s"))" >&2
    status=1
  fi
done
h7_flash_ok=$(verdict "$h7_flash" "$H7_FLASH_BUDGET")
h7_dtcm_ok=$(verdict "$h7_dtcm" "$H7_DTCM_BUDGET")
h7_axi_ok=$(verdict "$h7_axi" 524288)
h7_sram123_ok=$(verdict "$h7_sram123" 294912)
h7_sram4_ok=$(verdict "$h7_sram4" 65536)
h7_itcm_ok=$(verdict "$h7_itcm" 65536)
for v in "$h7_flash_ok" "$h7_dtcm_ok" "$h7_axi_ok" "$h7_sram123_ok" "$h7_sram4_ok" "$h7_itcm_ok"; do
  [ "$v" = ok ] || status=1
done
echo
echo "== budgets: STM32H743 release firmware, maps of up to 2,097,152 cells (any shape) planned at full resolution, paths of up to 16,384 steps, any number of ants (none is stored)"
printf '| %-58s | %8s | %8s | %-11s |\n' "item" "bytes" "budget" "verdict"
printf '| %-58s | %8s | %8s | %-11s |\n' "---" "---" "---" "---"
printf '| %-58s | %8d | %8d | %-11s |\n' "flash (.vector_table + .text + .rodata + .data)" "$h7_flash" "$H7_FLASH_BUDGET" "$h7_flash_ok"
printf '| %-58s | %8d | %8s | %-11s |\n' "DTCM static (.data + .bss + .uninit)" "$h7_static" "" ""
printf '| %-58s | %8d | %8s | %-11s |\n' "stack peak, measured on the QEMU twin (Stats.stack_peak)" "$h7_stack" "" ""
printf '| %-58s | %8d | %8s | %-11s |\n' "margin for STM32-only init and interrupt handlers" "$STACK_MARGIN" "" ""
printf '| %-58s | %8d | %8d | %-11s |\n' "DTCM (static + stack peak + margin; region 131072)" "$h7_dtcm" "$H7_DTCM_BUDGET" "$h7_dtcm_ok"
printf '| %-58s | %8d | %8d | %-11s |\n' "AXI SRAM (.axisram: map, tabu bits)" "$h7_axi" 524288 "$h7_axi_ok"
printf '| %-58s | %8d | %8d | %-11s |\n' "SRAM1-3 (.sram123: pruned-cell bits, pheromone)" "$h7_sram123" 294912 "$h7_sram123_ok"
printf '| %-58s | %8d | %8d | %-11s |\n' "SRAM4 (.sram4: links)" "$h7_sram4" 65536 "$h7_sram4_ok"
printf '| %-58s | %8d | %8d | %-11s |\n' "ITCM (.itcm: 8 bytes off address 0, the coarse route)" "$h7_itcm" 65536 "$h7_itcm_ok"
echo
echo "The stack peak is the twin's (DTCM static $twin_static bytes there; its other regions are the"
echo "H743's, byte for byte), added to the H743 build's DTCM statics."
if [ "$status" != 0 ]; then
  echo "FAILED: a memory budget is exceeded" >&2
fi
exit "$status"
