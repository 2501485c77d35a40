#!/usr/bin/env bash
# Golden test of the firmware's boot log: boot the QEMU firmware with no serial input
# (`-serial null`), collect its defmt log from semihosting stdout for a moment, stop QEMU, decode
# the log with defmt-print without timestamps or locations (`{L} {s}`: level and message), and
# compare it with tests/golden/boot.txt. Exits 1 on a difference (and shows it).
#
#   scripts/golden-boot.sh [--no-build] [--bless] [--elf PATH]
#
#   --bless     write the current output to tests/golden/boot.txt instead of comparing
#
# The firmware never exits by itself (it serves its UART), so QEMU is stopped once the log has as
# many lines as the golden file and nothing more has arrived for a second (at most 15 s).
# Installs defmt-print if it is missing (scripts/install-defmt-print.sh: unoptimised, a minute).
set -euo pipefail
cd "$(dirname "$0")/.."

golden=tests/golden/boot.txt
elf=target/thumbv7em-none-eabihf/release/ohaca
build=1
bless=0
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0; shift ;;
    --bless) bless=1; shift ;;
    --elf) elf="$2"; build=0; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done

scripts/install-defmt-print.sh
command -v qemu-system-arm >/dev/null || { echo "qemu-system-arm not found (scripts/setup.sh)" >&2; exit 2; }
if [ "$build" = 1 ]; then
  cargo build --release -q
fi

raw=$(mktemp)
got=$(mktemp)
err=$(mktemp)
qemu-system-arm -M mps2-an386 -display none -monitor none \
  -semihosting-config enable=on,target=native -serial null -kernel "$elf" >"$raw" 2>"$err" &
qemu=$!
trap 'kill "$qemu" 2>/dev/null || true; wait "$qemu" 2>/dev/null || true; rm -f "$raw" "$got" "$err"' EXIT

decode() { defmt-print -e "$elf" --log-format '{L} {s}' <"$raw" 2>/dev/null || true; }
want=$([ -f "$golden" ] && [ "$bless" = 0 ] && wc -l <"$golden" || echo 1)
last_size=-1
quiet=0
for _ in $(seq 1 150); do
  sleep 0.1
  size=$(wc -c <"$raw")
  if [ "$size" = "$last_size" ]; then quiet=$((quiet + 1)); else quiet=0; fi
  last_size=$size
  lines=$(decode | wc -l)
  if [ "$lines" -ge "$want" ] && [ "$quiet" -ge 10 ]; then
    break
  fi
done
kill "$qemu" 2>/dev/null || true
wait "$qemu" 2>/dev/null || true
decode >"$got"

if [ "$bless" = 1 ]; then
  mkdir -p "$(dirname "$golden")"
  cp "$got" "$golden"
  echo "wrote $golden:"
  cat "$golden"
  exit 0
fi
if diff -u "$golden" "$got"; then
  echo "boot log matches $golden"
else
  echo "boot log differs from $golden (scripts/golden-boot.sh --bless accepts the new one)" >&2
  grep -v "terminating on signal" "$err" >&2 || true
  exit 1
fi
