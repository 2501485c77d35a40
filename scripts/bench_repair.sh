#!/usr/bin/env bash
# Issue 36, item 4: a wall dropped on the path, repaired or planned warm, on the device.
#
#   scripts/bench_repair.sh [--elf ELF] [--seeds N] [--out DIR]
#
# Boots the QEMU release firmware (default: target/thumbv7em-none-eabihf/release/ohaca, built by
# `cargo build --release`) with `-icount shift=0` (1 tick = 1000 instructions) and drives
# `scenarios/two-walls.json` (a wall of 11 cells 8 path cells ahead of the robot, then one of 5
# cells 4 ahead) on Boston_0_256, NewYork_0_512 and Nav2's depot at 5 cm with 0.2 m inflation
# (three corner-to-corner pairs), cold then warm (`ohaca replan --compare`), seeds 1..=N. Prints
# one Markdown row per replan: the cold and warm instructions (mean over the seeds), the warm
# answers' origins (seed in brackets; a seed whose walls cut the goal off is left out), warm /
# cold, and raw / optimum of both. The JSON of every drive stays in DIR. Figures:
# docs/bench/repair-issue36.md.
set -euo pipefail
cd "$(dirname "$0")/.."

elf=target/thumbv7em-none-eabihf/release/ohaca
seeds=3
out=target/bench-repair
while [ $# -gt 0 ]; do
  case "$1" in
    --elf) elf="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
ohaca=${OHACA:-target/$(rustc -vV | sed -n 's/^host: //p')/host/ohaca}
if [ ! -x "$ohaca" ]; then
  echo "build the host tool first: cargo build --profile host -p ohaca-host --target host-tuple" >&2
  exit 2
fi
mkdir -p "$out"

port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
scripts/qemu-serve.sh --elf "$elf" --icount --port "$port" --defmt /dev/null 2>"$out/qemu.log" &
qemu=$!
trap 'kill "$qemu" 2>/dev/null || true; wait "$qemu" 2>/dev/null || true' EXIT
sleep 2

depot=(--map host/assets/ros/depot.yaml --inflate 0.2)
scenarios=(
  "boston|--map maps/large/Boston_0_256.map --start 184,0 --goal 8,254"
  "newyork|--map maps/large/NewYork_0_512.map --start 509,443 --goal 0,9"
  "depot-a|${depot[*]} --start 11,9 --goal 592,296"
  "depot-b|${depot[*]} --start 592,6 --goal 12,296"
  "depot-c|${depot[*]} --start 12,296 --goal 592,6"
)
for s in "${scenarios[@]}"; do
  name=${s%%|*}
  args=${s#*|}
  for seed in $(seq 1 "$seeds"); do
    # shellcheck disable=SC2086
    if ! "$ohaca" replan --tcp "127.0.0.1:$port" $args --events scenarios/two-walls.json \
      --compare --json --seed "$seed" >"$out/$name-$seed.json" 2>"$out/$name-$seed.err"; then
      # A seed whose first path puts a wall where it cuts the goal off: no replan to compare.
      echo "$name, seed $seed: $(cat "$out/$name-$seed.err")" >&2
      rm -f "$out/$name-$seed.json"
    fi
  done
done

python3 - "$out" "$seeds" <<'PY'
import json, os, statistics, sys
out, seeds = sys.argv[1], int(sys.argv[2])
names = ["boston", "newyork", "depot-a", "depot-b", "depot-c"]
print("| scenario | replan | cold: instructions | warm: instructions | answers (seeds) | warm/cold | raw/opt cold | raw/opt warm |")
print("| --- | ---: | ---: | ---: | --- | ---: | ---: | ---: |")
for n in names:
    runs = [[dict(r, seed=s) for r in json.load(open(f"{out}/{n}-{s}.json"))] for s in range(1, seeds + 1)
            if os.path.exists(f"{out}/{n}-{s}.json")]
    if not runs:
        print(f"| {n} | - | no seed gives a reachable goal after the walls | | | | | |")
        continue
    for plan in (1, 2):
        cold = [r for run in runs for r in run if r["mode"] == "cold" and r["plan"] == plan]
        warm = [r for run in runs for r in run if r["mode"] == "warm" and r["plan"] == plan]
        ci = statistics.mean(r["ticks"] * 1000 for r in cold)
        wi = statistics.mean(r["ticks"] * 1000 for r in warm)
        ratio = lambda rs: statistics.mean(r["raw_length"] / r["optimum"] for r in rs)
        origins = ", ".join(f'{r["origin"]} ({r["seed"]})' for r in warm)
        print(f"| {n} | {plan} | {ci / 1e6:.2f} M | {wi / 1e6:.2f} M | {origins} | "
              f"**{100 * wi / ci:.1f} %** | {ratio(cold):.4f} | {ratio(warm):.4f} |")
PY
