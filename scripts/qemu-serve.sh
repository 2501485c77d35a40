#!/usr/bin/env bash
# Boot the ohaca firmware (QEMU board) in qemu-system-arm with its UART on a TCP port, for the
# host tool or scripts/ohaca_client.py to talk to. Runs in the foreground until killed.
#
#   scripts/qemu-serve.sh [--port 4444] [--baud B] [--icount] [--no-build] [--elf PATH] [--defmt FILE]
#
#   --baud B     put a real B-baud 8N1 serial line between the port and QEMU's UART (`ohaca relay`:
#                QEMU's UART otherwise moves bytes instantly and buffers megabytes); the relay
#                prints the bytes that crossed the line each way when a client leaves
#   --icount     run with `-icount shift=0`: virtual time advances 1 ns per instruction, so the
#                firmware's ticks (µs) x 1000 = instructions executed (docs/FIRMWARE.md)
#   --no-build   do not run `cargo build --release` first
#   --defmt FILE write the raw defmt log frames to FILE instead of decoding them; by default they
#                are decoded with defmt-print (if installed) to stderr, else written to
#                target/qemu-defmt.bin
set -euo pipefail
cd "$(dirname "$0")/.."

port=4444
icount=()
build=1
elf=target/thumbv7em-none-eabihf/release/ohaca
defmt_out=""
baud=""
while [ $# -gt 0 ]; do
  case "$1" in
    --port) port="$2"; shift 2 ;;
    --baud) baud="$2"; shift 2 ;;
    --icount) icount=(-icount shift=0); shift ;;
    --no-build) build=0; shift ;;
    --elf) elf="$2"; build=0; shift 2 ;;
    --defmt) defmt_out="$2"; shift 2 ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done

if [ "$build" = 1 ]; then
  cargo build --release -q
fi
command -v qemu-system-arm >/dev/null || { echo "qemu-system-arm not found (apt-get install qemu-system-arm)" >&2; exit 1; }

if [ -n "$baud" ]; then
  # The relay boots QEMU itself (UART0 on a socket pair) and serves the port; QEMU's stdout (the
  # defmt frames) is the relay's stdout. OHACA_BIN=path/to/ohaca uses a built tool instead.
  ohaca="${OHACA_BIN:-}"
  if [ -z "$ohaca" ]; then
    cargo build --profile host -q -p ohaca-host --target host-tuple
    ohaca="target/$(rustc -vV | sed -n 's/^host: //p')/host/ohaca"
  fi
  qemu=("$ohaca" relay --baud "$baud" --listen "127.0.0.1:${port}" --elf "$elf" ${icount:+--icount})
else
qemu=(qemu-system-arm -M mps2-an386 -display none -monitor none
  -semihosting-config enable=on,target=native
  -serial "tcp:127.0.0.1:${port},server=on,wait=off,nodelay=on"
  "${icount[@]}" -kernel "$elf")
fi

echo "ohaca firmware: UART on 127.0.0.1:${port}${icount:+ (icount shift=0)}${baud:+ at $baud baud through ohaca relay}" >&2
if [ -z "$defmt_out" ] && command -v defmt-print >/dev/null; then
  # exec keeps this script's pid for QEMU, so killing it stops QEMU; defmt-print then sees EOF.
  exec "${qemu[@]}" > >(defmt-print -e "$elf" >&2)
fi
exec "${qemu[@]}" > "${defmt_out:-target/qemu-defmt.bin}"
