#!/usr/bin/env bash
# Long soak of the firmware's link under QEMU, in two phases:
#  1. the QEMU firmware (F411 capacity): build it, then run host/tests/qemu/soak.rs's
#     soak_thousands_of_valid_and_broken_frames with FRAMES frames (default 100000; the test's own
#     default is 10000) and print its summary (frames sent per kind, replies, errors, the device's
#     counters, wall time, then the burst beyond the window). The soak keeps within the device's
#     window (8 requests, 1 KiB outstanding), so nothing may be lost. Without --baud the UART is
#     QEMU's instant TCP socket: about 2 ms a frame on a 2-core machine (QEMU feeds its UART 10 to
#     16 KB/s), 100000 frames in 3 to 4 minutes. With --baud BAUD (e.g. 115200) it goes through
#     the pacing relay (ohaca_host::link::relay: a real 8N1 line at BAUD) and also prints the
#     relay's counters; see BENCHMARKS.md section 8 for wall times.
#  2. faults at scale, on the STM32H743's capacity twin (`--features twin-h743`) and on the F411
#     build (which holds these maps in its arena): host/tests/qemu/soak_twin.rs with ROUNDS rounds (default 10; the
#     test's own default is 1), each uploading a 512 x 512 and a 604 x 307 map raw and run-length
#     coded with injected byte drops and corruption, broken uploads redone, plans checked against
#     the host core. About 25 s a round on each firmware, the two in parallel. ROUNDS = 0 skips it.
# Both are seeded: set OHACA_SOAK_SEED to try another stream.
#   scripts/soak.sh [--baud BAUD] [FRAMES [ROUNDS]]
#   e.g. scripts/soak.sh --baud 115200 10000 0
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { echo "usage: scripts/soak.sh [--baud BAUD] [FRAMES [ROUNDS]]" >&2; exit 2; }
baud=""
if [ "${1:-}" = "--baud" ]; then
  baud="${2:-}"
  shift 2 || usage
  case "$baud" in '' | *[!0-9]*) usage ;; esac
fi
frames="${1:-100000}"
rounds="${2:-10}"
case "$frames$rounds" in
  '' | *[!0-9]*) usage ;;
esac
target="$(realpath -m "${CARGO_TARGET_DIR:-target}")"  # absolute: the tests run in host/
cargo build --release
if [ -n "$baud" ]; then export OHACA_SOAK_BAUD="$baud"; else unset OHACA_SOAK_BAUD; fi
OHACA_FIRMWARE="$target/thumbv7em-none-eabihf/release/ohaca" OHACA_SOAK_FRAMES="$frames" \
  cargo test --profile host -p ohaca-host --target x86_64-unknown-linux-gnu --test qemu \
  -- --nocapture --exact soak::soak_thousands_of_valid_and_broken_frames
if [ "$rounds" -gt 0 ]; then
  cargo build --release --features twin-h743 --target-dir "$target/twin-h743"
  OHACA_TWIN_FIRMWARE="$target/twin-h743/thumbv7em-none-eabihf/release/ohaca" \
    OHACA_SOAK_SCALE_ROUNDS="$rounds" \
    cargo test --profile host -p ohaca-host --target x86_64-unknown-linux-gnu --test qemu -- soak_twin:: --nocapture
fi
