#!/usr/bin/env bash
# Instructions per frame of the wire's CRC-32 and COBS, hand-written (src/protocol/frame.rs)
# against the `crc` crate, the `cobs` crate and postcard's COBS + CRC flavours
# (host-tests/examples/frame_bench.rs; BENCHMARKS.md, "Dependencies by measurement").
#
#   scripts/frame-bench.sh            (needs valgrind; about a minute)
#
# Counts x86-64 instructions under callgrind (exact, and the same under any load): each variant
# runs once with 1 frame and once with 101, and the difference of the two totals / 100 is printed.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "valgrind is needed" >&2; exit 2; }
cargo build -q --release -p ohaca-host-tests --target x86_64-unknown-linux-gnu --example frame_bench
bin=target/x86_64-unknown-linux-gnu/release/examples/frame_bench
"$bin"
ir() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$@" 2>&1 >/dev/null \
    | sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
variants=$("$bin" | sed 's/.*variants: \[//; s/\]//; s/[",]//g')
printf '%-22s %12s %12s\n' variant "256 B" "2520 B"
for v in $variants; do
  row=()
  for len in 256 2520; do
    a=$(ir "$v" "$len" 1)
    b=$(ir "$v" "$len" 101)
    row+=("$(((b - a) / 100))")
  done
  printf '%-22s %12s %12s\n' "$v" "${row[@]}"
done
