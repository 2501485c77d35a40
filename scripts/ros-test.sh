#!/usr/bin/env bash
# `ohaca ros` against Eclipse Cyclone DDS (scripts/ros_interop.py), on loopback only: once with
# the firmware in QEMU (its UART on a free local TCP port), once on the host core. Fails if
# either fails (or if cyclonedds or QEMU is missing; OHACA_SKIP_QEMU=1 skips the QEMU half with
# a SKIPPED line).
#
#   scripts/ros-test.sh [--no-build] [--gif FILE]   # --gif: the QEMU run's drive as a GIF
set -euo pipefail
cd "$(dirname "$0")/.."

build=1
gif=()
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0; shift ;;
    --gif) gif=(--gif "$2"); shift 2 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done

host_target=$(rustc -vV | sed -n 's/^host: //p')
if [ "$build" = 1 ]; then
  cargo build --release -q
  cargo build --profile host -q -p ohaca-host --target "$host_target"
fi
ohaca="target/$host_target/host/ohaca"
[ -x "$ohaca" ] || { echo "FAIL: no $ohaca (build it, or drop --no-build)" >&2; exit 1; }

if ! command -v qemu-system-arm >/dev/null; then
  if [ "${OHACA_SKIP_QEMU:-}" != 1 ]; then
    echo "FAIL: qemu-system-arm is missing (source scripts/setup.sh), or set OHACA_SKIP_QEMU=1" >&2
    exit 1
  fi
  echo "SKIPPED: ohaca ros on the QEMU firmware (qemu-system-arm missing, OHACA_SKIP_QEMU=1)"
else
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  scripts/qemu-serve.sh --no-build --port "$port" --defmt /dev/null 2>/dev/null &
  qemu=$!
  trap 'kill $qemu 2>/dev/null || true; wait $qemu 2>/dev/null || true' EXIT
  up=0
  for _ in $(seq 100); do
    if python3 -c "import socket; socket.create_connection(('127.0.0.1', $port), 0.2).close()" \
      2>/dev/null; then up=1; break; fi
    kill -0 $qemu 2>/dev/null || break
    sleep 0.1
  done
  [ "$up" = 1 ] || { echo "FAIL: QEMU did not open its UART on 127.0.0.1:$port" >&2; exit 1; }
  python3 scripts/ros_interop.py --ohaca "$ohaca" --tcp "127.0.0.1:$port" "${gif[@]}"
  kill $qemu 2>/dev/null || true
  wait $qemu 2>/dev/null || true
  trap - EXIT
fi
python3 scripts/ros_interop.py --ohaca "$ohaca" --host
