#!/usr/bin/env bash
# Long soak of the QEMU firmware's link: build the firmware, then run host/tests/qemu_soak.rs
# with FRAMES frames (default 100000; the test's own default is 10000) and print its summary
# (frames sent per kind, replies, errors, the device's counters, wall time). The frame stream
# is seeded: set OHACA_SOAK_SEED to try another one. About 2 ms a frame on a 2-core machine
# (QEMU feeds its UART 10 to 16 KB/s): 100000 frames take 3 to 4 minutes.
#   scripts/soak.sh [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${1:-100000}"
case "$frames" in
  '' | *[!0-9]*) echo "usage: scripts/soak.sh [FRAMES]" >&2; exit 2 ;;
esac
cargo build --release
target="$(realpath -m "${CARGO_TARGET_DIR:-target}")"  # absolute: the test runs in host/
OHACA_FIRMWARE="$target/thumbv7em-none-eabihf/release/ohaca" OHACA_SOAK_FRAMES="$frames" \
  cargo test --release -p ohaca-host --target x86_64-unknown-linux-gnu --test qemu_soak -- --nocapture
