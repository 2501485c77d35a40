#!/usr/bin/env bash
# The main job, end to end: build the firmware and the host tool, boot the firmware in QEMU
# (mps2-an386, Cortex-M4) with its UART on a local TCP port, send it the complex-26 map and the
# request (0,0) -> (25,25) with `ohaca send`, and show the path it planned. Then check that the
# device's path is bit-identical to the host's (`ohaca plan --board f411`: the default QEMU
# firmware is the STM32F411's, arena and layout included, so any map it takes), draw it into demo-path.png (if `ohaca render`
# exists), and print the firmware's boot log (if defmt-print is installed). QEMU is stopped on
# exit, whatever happens. Needs no input.
#
#   scripts/demo.sh [--map FILE --start X,Y --goal X,Y] [planner flags, e.g. --seed 5]
#   scripts/demo.sh --map host/assets/ros/lab.yaml --start-m -1.2,-0.8 --goal-m 7.25,3.7 --inflate 0.2
set -euo pipefail
cd "$(dirname "$0")/.."

map=maps/complex-26.map
sflag=--start
gflag=--goal
start=0,0
goal=25,25
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --map) map="$2"; shift 2 ;;
    --start) start="$2"; shift 2 ;;
    --goal) goal="$2"; shift 2 ;;
    --start-m) start="$2"; sflag=--start-m; shift 2 ;;
    --goal-m) goal="$2"; gflag=--goal-m; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) extra+=("$1"); shift ;;
  esac
done

step() { printf '\n== %s\n' "$*" >&2; }

step "setup: Rust target thumbv7em-none-eabihf, qemu-system-arm"
source scripts/setup.sh

# Not quiet: on a fresh clone these two builds take minutes (cargo prints each crate it compiles).
step "build: firmware (release profile, QEMU board)"
cargo build --release
step "build: the host tool (host profile)"
cargo build --profile host -p ohaca-host --target host-tuple
target_dir=${CARGO_TARGET_DIR:-target}
host=$(rustc -vV | sed -n 's/^host: //p')
ohaca="$target_dir/$host/host/ohaca"
elf="$target_dir/thumbv7em-none-eabihf/release/ohaca"
[ -x "$ohaca" ] || { echo "error: host tool not found at $ohaca" >&2; exit 1; }
[ -f "$elf" ] || { echo "error: firmware not found at $elf" >&2; exit 1; }

tmp=$(mktemp -d)
qemu_pid=""
cleanup() {
  if [ -n "$qemu_pid" ]; then
    kill "$qemu_pid" 2>/dev/null || true
    wait "$qemu_pid" 2>/dev/null || true
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# A port is taken if something accepts on it.
port_open() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

step "boot: qemu-system-arm -M mps2-an386, UART0 on a local TCP port"
port=""
for _ in 1 2 3 4 5 6 7 8 9 10; do
  p=$((20000 + RANDOM % 40000))
  port_open "$p" && continue
  # stdout carries the firmware's defmt log (semihosting); keep it for the end.
  qemu-system-arm -M mps2-an386 -display none -monitor none \
    -semihosting-config enable=on,target=native \
    -serial "tcp:127.0.0.1:$p,server=on,wait=off,nodelay=on" \
    -kernel "$elf" </dev/null >"$tmp/defmt.bin" 2>"$tmp/qemu.err" &
  qemu_pid=$!
  for _ in $(seq 1 200); do
    if ! kill -0 "$qemu_pid" 2>/dev/null; then break; fi
    if port_open "$p"; then port=$p; break; fi
    sleep 0.05
  done
  [ -n "$port" ] && break
  wait "$qemu_pid" 2>/dev/null || true
  qemu_pid=""
done
if [ -z "$port" ]; then
  echo "error: QEMU did not start:" >&2
  cat "$tmp/qemu.err" >&2
  exit 1
fi
echo "firmware running, UART0 on 127.0.0.1:$port (qemu pid $qemu_pid)" >&2

step "plan on the device: ohaca send --tcp 127.0.0.1:$port --map $map $sflag $start $gflag $goal ${extra[*]:-}"
status=0
"$ohaca" send --tcp "127.0.0.1:$port" --map "$map" "$sflag" "$start" "$gflag" "$goal" \
  "${extra[@]}" </dev/null || status=$?
if [ "$status" -gt 1 ]; then
  echo "error: ohaca send failed (exit $status)" >&2
  exit "$status"
fi

step "check: the device's path against the host's (ohaca plan --board f411: same planner, layout and seed)"
"$ohaca" send --tcp "127.0.0.1:$port" --map "$map" "$sflag" "$start" "$gflag" "$goal" \
  "${extra[@]}" --json </dev/null >"$tmp/device.json" || true
"$ohaca" plan --board f411 --map "$map" "$sflag" "$start" "$gflag" "$goal" "${extra[@]}" --json \
  </dev/null >"$tmp/host.json" || true
# Everything but the timings and the device's extra keys must be equal, f32 digits included.
strip() { sed -E 's/"elapsed_us":[0-9]+,//; s/,"ticks":[0-9]+//; s/,"device":"[^"]*"//' "$1"; }
if [ -s "$tmp/device.json" ] && [ "$(strip "$tmp/device.json")" = "$(strip "$tmp/host.json")" ]; then
  echo "device and host paths are identical (raw path, waypoints, lengths, iterations, moves)"
else
  echo "warning: the device's result differs from the host's:" >&2
  echo "  device: $(cat "$tmp/device.json")" >&2
  echo "  host:   $(cat "$tmp/host.json")" >&2
fi

if "$ohaca" render --help >"$tmp/render.help" 2>/dev/null; then
  if grep -q -- '--report' "$tmp/render.help"; then
    step "draw: demo-path.png (the device's path)"
    "$ohaca" render --map "$map" "$sflag" "$start" "$gflag" "$goal" "${extra[@]}" \
      --report "$tmp/device.json" --out demo-path.png </dev/null
  else
    step "draw: demo-path.png (the host's plan, identical to the device's)"
    "$ohaca" render --board f411 --map "$map" "$sflag" "$start" "$gflag" "$goal" "${extra[@]}" \
      --out demo-path.png </dev/null
  fi
  echo "wrote demo-path.png"
fi

# Stop QEMU so its log is complete, then decode it.
kill "$qemu_pid" 2>/dev/null || true
wait "$qemu_pid" 2>/dev/null || true
qemu_pid=""
if command -v defmt-print >/dev/null 2>&1; then
  step "firmware log (defmt, decoded by defmt-print)"
  defmt-print -e "$elf" <"$tmp/defmt.bin" 2>&1 || true
else
  echo "(install defmt-print to see the firmware's log: cargo install defmt-print)" >&2
fi
exit "$status"
