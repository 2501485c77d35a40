#!/usr/bin/env bash
# Instruction counts of the firmware's plans under `qemu-system-arm -icount shift=0` and the Hello
# round trip over the emulated UART; prints Markdown tables for BENCHMARKS.md.
#
#   scripts/bench-device.sh [--no-build] [--map maps/complex-26.map] [--seeds 10] [--hellos 100]
#
# Builds the QEMU firmware (release), boots it with -icount, uploads the map, plans seeds 1..=N
# from (0,0) to the far corner with the default parameters and again with patience 0 (the full
# 50 x 100 run), then boots it without -icount for the Hello latency. Needs qemu-system-arm and
# python3; defmt-print (optional) adds the split Run::new / iterations / finish.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--no-build" ]; then
  shift
else
  cargo build --release -q
fi
exec python3 scripts/bench_device.py "$@"
