#!/usr/bin/env bash
# End-to-end check of the QEMU firmware: build it, boot it under `-icount shift=0` with its UART
# on a free local port, run scripts/ohaca_client.py selftest against it (every request, the
# error paths, Busy, Cancel, a map switch during a plan, corrupted frames), stop QEMU.
#   scripts/qemu-selftest.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/.."
[ "${1:-}" = "--no-build" ] || cargo build --release -q
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log=$(mktemp)
scripts/qemu-serve.sh --no-build --icount --port "$port" --defmt "$log.defmt" 2>"$log" &
qemu=$!
trap 'kill "$qemu" 2>/dev/null || true; wait "$qemu" 2>/dev/null || true; rm -f "$log" "$log.defmt"' EXIT
status=0
timeout 300 python3 scripts/ohaca_client.py --port "$port" selftest || status=$?
if [ "$status" != 0 ]; then
  echo "selftest failed ($status); QEMU said:" >&2
  cat "$log" >&2
  if command -v defmt-print >/dev/null; then
    defmt-print -e target/thumbv7em-none-eabihf/release/ohaca < "$log.defmt" >&2 || true
  fi
fi
exit "$status"
