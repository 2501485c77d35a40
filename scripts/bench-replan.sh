#!/usr/bin/env bash
# Warm against cold replanning on the firmware under `qemu-system-arm -icount shift=0`: the seven
# scenarios of BENCHMARKS.md ("Replanning") -- complex-26, Boston_0_256 and the lab ROS map, each
# with a wall appearing across the path and with a door opening, and Paris_1_256 with a street
# closed (`scenarios/city-wall.json`: 15 cells across the path) -- driven by `ohaca replan
# --compare` over the emulated UART for seeds 1..=N. Prints a Markdown table: the replan's
# instructions (ticks x 1000), iterations and raw length over the exact optimum, warm and cold.
#
#   scripts/bench-replan.sh [--no-build] [--seeds 3] [--host]
#
# --host runs the host core instead of QEMU (ant moves instead of instructions; no QEMU needed).
set -euo pipefail
cd "$(dirname "$0")/.."
build=1 seeds=3 host=0
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0; shift ;;
    --seeds) seeds="$2"; shift 2 ;;
    --host) host=1; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
if [ "$build" = 1 ]; then
  cargo build --release -q
  cargo build --profile host -q -p ohaca-host --target host-tuple
fi
ohaca="target/$(rustc -vV | sed -n 's/^host: //p')/host/ohaca"
device=()
if [ "$host" = 0 ]; then
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
  scripts/qemu-serve.sh --no-build --icount --port "$port" >/dev/null 2>&1 &
  qemu=$!
  trap 'kill $qemu 2>/dev/null; wait $qemu 2>/dev/null || true' EXIT
  sleep 1
  device=(--tcp "127.0.0.1:$port" --timeout 600)
fi
c26=(--map maps/complex-26.map --start 0,0 --goal 25,25)
boston=(--map maps/large/Boston_0_256.map --start 184,0 --goal 8,254)
# Paris: the longest scenario of its .scen file (optimum 435.96).
paris=(--map maps/large/Paris_1_256.map --start 156,255 --goal 18,15)
lab=(--map host/assets/ros/lab.yaml --start-m -1.2,-0.8 --goal-m 7.25,3.7 --inflate 0.2)
out=$(mktemp)
run() { # name, events, map args...
  local name="$1" events="$2"; shift 2
  for seed in $(seq 1 "$seeds"); do
    printf '%s\t' "$name" >>"$out"
    "$ohaca" replan "${device[@]}" "$@" --events "$events" --compare --json --seed "$seed" >>"$out"
  done
}
run "complex-26, wall" scenarios/wall.json "${c26[@]}"
run "complex-26, door opens" scenarios/complex-26-gap.json "${c26[@]}"
run "Boston_0_256, wall" scenarios/wall.json "${boston[@]}"
run "Boston_0_256, door opens" scenarios/boston-256-gap.json "${boston[@]}"
run "Boston_0_256, far box set, then cleared" scenarios/far-box.json "${boston[@]}"
run "Paris_1_256, city wall" scenarios/city-wall.json "${paris[@]}"
run "lab.yaml 5 cm, wall" scenarios/wall.json "${lab[@]}"
run "lab.yaml 5 cm, door opens" scenarios/lab-gap.json "${lab[@]}"
python3 - "$out" "$host" <<'PY'
import json, sys, statistics as st
rows = {}
for line in open(sys.argv[1]):
    name, js = line.split("\t", 1)
    plans = json.loads(js)
    for k in sorted({p["plan"] for p in plans if p["plan"] > 0}):
        rep = {p["mode"]: p for p in plans if p["plan"] == k}
        label = name if k == 1 and not any(p["plan"] > 1 for p in plans) else f"{name}, replan {k}"
        rows.setdefault(label, []).append(rep)
host = sys.argv[2] == "1"
unit = "ant moves" if host else "instructions"
cost = (lambda p: p["moves"]) if host else (lambda p: p["ticks"] * 1000)
fmt = (lambda v: f"{v / 1e3:.1f} k") if host else (lambda v: f"{v / 1e6:.2f} M")
print(f"| scenario | cold: {unit} | iterations | raw/opt | warm: {unit} | answer | iterations | raw/opt | warm/cold |")
print("| --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: |")
ratios = []
for name, reps in rows.items():
    c = [r["cold"] for r in reps]; w = [r["warm"] for r in reps]
    cc = st.mean(cost(p) for p in c); wc = st.mean(cost(p) for p in w)
    q = lambda ps: st.mean(p["raw_length"] / p["optimum"] for p in ps)
    it = lambda ps: st.mean(p["iterations"] for p in ps)
    kinds = sorted({p.get("origin", "warm") for p in w})
    ratios.append(wc / cc if cc else 0.0)
    print(f"| {name} | {fmt(cc)} | {it(c):.1f} | {q(c):.4f} | {fmt(wc)} | {' / '.join(kinds)} | {it(w):.1f} | {q(w):.4f} | **{100 * wc / cc:.{1 if wc < 0.1 * cc else 0}f} %** |")
print(f"\nMean warm/cold: {100 * st.mean(ratios):.0f} % over {len(ratios)} replans, {len(next(iter(rows.values())))} seeds each.")
PY
