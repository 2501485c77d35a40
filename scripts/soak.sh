#!/usr/bin/env bash
# Long soak of the firmware's link under QEMU, in two phases:
#  1. the QEMU firmware (F411 capacity): build it, then run host/tests/qemu_soak.rs with FRAMES
#     frames (default 100000; the test's own default is 10000) and print its summary (frames
#     sent per kind, replies, errors, the device's counters, wall time). About 2 ms a frame on a
#     2-core machine (QEMU feeds its UART 10 to 16 KB/s): 100000 frames take 3 to 4 minutes.
#  2. faults at scale, on the STM32H743's capacity twin (`--features twin-h743`) and on the F411
#     build (which holds these maps in its arena): host/tests/qemu_soak_twin.rs with ROUNDS rounds (default 10; the
#     test's own default is 1), each uploading a 512 x 512 and a 604 x 307 map raw and run-length
#     coded with injected byte drops and corruption, broken uploads redone, plans checked against
#     the host core. About 25 s a round on each firmware, the two in parallel. ROUNDS = 0 skips it.
# Both are seeded: set OHACA_SOAK_SEED to try another stream.
#   scripts/soak.sh [FRAMES [ROUNDS]]
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${1:-100000}"
rounds="${2:-10}"
case "$frames$rounds" in
  '' | *[!0-9]*) echo "usage: scripts/soak.sh [FRAMES [ROUNDS]]" >&2; exit 2 ;;
esac
target="$(realpath -m "${CARGO_TARGET_DIR:-target}")"  # absolute: the tests run in host/
cargo build --release
OHACA_FIRMWARE="$target/thumbv7em-none-eabihf/release/ohaca" OHACA_SOAK_FRAMES="$frames" \
  cargo test --release -p ohaca-host --target x86_64-unknown-linux-gnu --test qemu_soak -- --nocapture
if [ "$rounds" -gt 0 ]; then
  cargo build --release --features twin-h743 --target-dir "$target/twin-h743"
  OHACA_TWIN_FIRMWARE="$target/twin-h743/thumbv7em-none-eabihf/release/ohaca" \
    OHACA_SOAK_SCALE_ROUNDS="$rounds" \
    cargo test --release -p ohaca-host --target x86_64-unknown-linux-gnu --test qemu_soak_twin -- --nocapture
fi
