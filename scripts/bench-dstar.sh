#!/usr/bin/env bash
# D* Lite (`ohaca replan --dstar`, issue 28) on the seven replanning scenarios of
# scripts/bench-replan.sh, host core, warm drives, seeds 1..=3 (the seed moves the robot: its
# cells are the colony's path). Prints a Markdown table: D* Lite's expansions for the initial
# plan and for each replan (one search kept across the drive), the exact A*'s from scratch on the
# same problems, and the memory each keeps.
#
#   scripts/bench-dstar.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" != --no-build ]; then
  cargo build --profile host -q -p ohaca-host --target host-tuple
fi
ohaca="target/$(rustc -vV | sed -n 's/^host: //p')/host/ohaca"
c26=(--map maps/complex-26.map --start 0,0 --goal 25,25)
boston=(--map maps/large/Boston_0_256.map --start 184,0 --goal 8,254)
paris=(--map maps/large/Paris_1_256.map --start 156,255 --goal 18,15)
lab=(--map host/assets/ros/lab.yaml --start-m -1.2,-0.8 --goal-m 7.25,3.7 --inflate 0.2)
out=$(mktemp)
trap 'rm -f "$out"' EXIT
run() { # name, events, map args...
  local name="$1" events="$2"; shift 2
  for seed in 1 2 3; do
    printf '%s\t' "$name" >>"$out"
    "$ohaca" replan "$@" --events "$events" --dstar --json --seed "$seed" >>"$out"
  done
}
run "complex-26, wall" scenarios/wall.json "${c26[@]}"
run "complex-26, door opens" scenarios/complex-26-gap.json "${c26[@]}"
run "Boston_0_256, wall" scenarios/wall.json "${boston[@]}"
run "Boston_0_256, door opens" scenarios/boston-256-gap.json "${boston[@]}"
run "Paris_1_256, city wall" scenarios/city-wall.json "${paris[@]}"
run "lab.yaml 5 cm, wall" scenarios/wall.json "${lab[@]}"
run "lab.yaml 5 cm, door opens" scenarios/lab-gap.json "${lab[@]}"
python3 - "$out" <<'PY'
import json, sys, statistics as st
rows = {}
for line in open(sys.argv[1]):
    name, js = line.split("\t", 1)
    rows.setdefault(name, []).append(json.loads(js))
k = lambda b: f"{b / 1024:.1f} KiB"
print("| scenario | replans | D* Lite initial: expanded | A* initial: expanded | D* Lite replan: expanded | A* replan from scratch: expanded | D* replan / A* replan | D* replan / D* initial | D* Lite updated (replan) | D* Lite memory | A* memory (peak) |")
print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
for name, drives in rows.items():
    init_d = st.mean(d[0]["dstar"]["expanded"] for d in drives)
    init_a = st.mean(d[0]["dstar"]["astar"]["expanded"] for d in drives)
    rep = [p for d in drives for p in d[1:]]
    rd = st.mean(p["dstar"]["expanded"] for p in rep)
    ra = st.mean(p["dstar"]["astar"]["expanded"] for p in rep)
    ru = st.mean(p["dstar"]["updated"] for p in rep)
    mem = max(p["dstar"]["memory_bytes"] for d in drives for p in d)
    amem = max(p["dstar"]["astar"]["memory_bytes"] for d in drives for p in d)
    n = len(drives[0]) - 1
    print(f"| {name} | {n} | {init_d:,.0f} | {init_a:,.0f} | {rd:,.0f} | {ra:,.0f} | {100*rd/ra:.0f} % | {100*rd/init_d:.1f} % | {ru:,.0f} | {k(mem)} | {k(amem)} |")
print()
print("Per replan, every seed (D* Lite expanded / A* expanded, cells that flipped):")
print()
for name, drives in rows.items():
    per = "; ".join(", ".join(f'{p["dstar"]["expanded"]}/{p["dstar"]["astar"]["expanded"]} ({p["dstar"]["cells_changed"]})' for p in d[1:]) for d in drives)
    print(f"- {name}: {per}")
PY
