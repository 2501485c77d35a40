#!/usr/bin/env bash
# Warm against cold replanning on the firmware under `qemu-system-arm -icount shift=0`: the seven
# scenarios of BENCHMARKS.md ("Replanning") -- complex-26, Boston_0_256 and the lab ROS map, each
# with a wall appearing across the path and with a door opening, and Paris_1_256 with a street
# closed (`scenarios/city-wall.json`: 15 cells across the path) -- and issue 36's two walls
# (`scenarios/two-walls.json`: 11 cells across the path 8 cells ahead of the robot, then 5 cells 4
# ahead) on Boston_0_256, NewYork_0_512 and Nav2's depot at 5 cm with 0.2 m inflation
# (`maps/depot-r20.map`), driven by `ohaca replan --compare` over the emulated UART for seeds
# 1..=N. Prints a Markdown table: the replan's instructions (ticks x 1000), iterations and raw
# length over the exact optimum, warm and cold; with defmt-print installed also each plan's split
# (the firmware's log: `Run::new` / the iterations / `finish`, mean; "reused" and "repaired"
# answers have none).
#
#   scripts/bench-replan.sh [--no-build] [--seeds 3] [--host | --board f411] [--only NAME]...
#
# --host runs the host core instead of QEMU (ant moves instead of instructions; no QEMU needed);
# --board B runs it as board B's firmware plans (`ohaca replan --board`: its buffers and layout).
# --only NAME runs only the scenarios whose name contains NAME (repeatable; e.g. `--only "two
# walls"`).
set -euo pipefail
cd "$(dirname "$0")/.."
build=1 seeds=3 host=0 board="" only=()
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0; shift ;;
    --seeds) seeds="$2"; shift 2 ;;
    --host) host=1; shift ;;
    --board) host=1; board="$2"; shift 2 ;;
    --only) only+=("$2"); shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
if [ "$build" = 1 ]; then
  cargo build --release -q
  cargo build --profile host -q -p ohaca-host --target host-tuple
fi
ohaca="target/$(rustc -vV | sed -n 's/^host: //p')/host/ohaca"
device=()
defmt=$(mktemp)
log=$(mktemp)
if [ "$host" = 0 ]; then
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
  # The firmware's defmt log (raw frames) into $defmt, decoded once QEMU has stopped.
  scripts/qemu-serve.sh --no-build --icount --port "$port" --defmt "$defmt" >/dev/null 2>&1 &
  qemu=$!
  trap 'kill $qemu 2>/dev/null; wait $qemu 2>/dev/null || true' EXIT
  sleep 1
  device=(--tcp "127.0.0.1:$port" --timeout 600)
elif [ -n "$board" ]; then
  device=(--board "$board")
fi
c26=(--map maps/complex-26.map --start 0,0 --goal 25,25)
boston=(--map maps/large/Boston_0_256.map --start 184,0 --goal 8,254)
# Paris: the longest scenario of its .scen file (optimum 435.96).
paris=(--map maps/large/Paris_1_256.map --start 156,255 --goal 18,15)
lab=(--map host/assets/ros/lab.yaml --start-m -1.2,-0.8 --goal-m 7.25,3.7 --inflate 0.2)
# NewYork: the longest scenario of its .scen file (optimum 714.54), as in scripts/bench_sizes.py.
newyork=(--map maps/large/NewYork_0_512.map --start 509,443 --goal 0,9)
# Nav2's depot at 5 cm, 0.2 m inflation (the same grid as `--map host/assets/ros/depot.yaml
# --inflate 0.2`, maps/README.md): its top-left to bottom-right pair (optimum 693.64).
depot=(--map maps/depot-r20.map --start 14,10 --goal 590,294)
out=$(mktemp)
want() { # name: is it one of --only's?
  [ "${#only[@]}" = 0 ] && return 0
  local o
  for o in "${only[@]}"; do
    case "$1" in *"$o"*) return 0 ;; esac
  done
  return 1
}
run() { # name, events, map args...
  local name="$1" events="$2"; shift 2
  want "$name" || return 0
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
run "Boston_0_256, two walls" scenarios/two-walls.json "${boston[@]}"
run "NewYork_0_512, two walls" scenarios/two-walls.json "${newyork[@]}"
run "depot-r20 (5 cm, 0.2 m inflation), two walls" scenarios/two-walls.json "${depot[@]}"
if [ "$host" = 0 ]; then
  kill "$qemu" 2>/dev/null; wait "$qemu" 2>/dev/null || true
  if command -v defmt-print >/dev/null; then
    defmt-print -e target/thumbv7em-none-eabihf/release/ohaca --log-format '{s}' <"$defmt" >"$log" || true
  fi
fi
python3 - "$out" "$host" "$log" <<'PY'
import json, re, sys, statistics as st
# The firmware's line for each plan, in order: its ticks and, for a run, its split.
pat = re.compile(r"plan \d+: (?:reused|repaired|\d+ iterations), length \S+, \d+ waypoints, (\d+) ticks"
                 r"(?: \(new (\d+), steps (\d+), finish (\d+)\))?")
logged = [tuple(int(g) if g else None for g in m.groups()) for m in pat.finditer(open(sys.argv[3]).read())]
every = [p for line in open(sys.argv[1]) for p in json.loads(line.split("\t", 1)[1])]
split = bool(every) and len(logged) == len(every) and all(
    p["ticks"] == l[0] for p, l in zip(every, logged))
splits = iter([l[1:] if l[1] is not None else None for l in logged])
rows = {}
for line in open(sys.argv[1]):
    name, js = line.split("\t", 1)
    plans = json.loads(js)
    if split:  # the same plans in the same order: attach the split read above
        for p in plans:
            p["split"] = next(splits)
    for k in sorted({p["plan"] for p in plans if p["plan"] > 0}):
        rep = {p["mode"]: p for p in plans if p["plan"] == k}
        label = name if k == 1 and not any(p["plan"] > 1 for p in plans) else f"{name}, replan {k}"
        rows.setdefault(label, []).append(rep)
host = sys.argv[2] == "1"
unit = "ant moves" if host else "instructions"
cost = (lambda p: p["moves"]) if host else (lambda p: p["ticks"] * 1000)
fmt = (lambda v: f"{v / 1e3:.1f} k") if host else (lambda v: f"{v / 1e6:.2f} M")
def parts(ps):
    """Mean `Run::new` / iterations / `finish` of the plans that ran (M instructions); reused
    and repaired answers run no colony (the firmware logs them as reused, without a split)."""
    ran = [p["split"] for p in ps if p.get("split")]
    if not ran:
        return "no run" if ps else ""
    s = " / ".join(f"{st.mean(x[i] for x in ran) / 1e3:.2f}" for i in range(3))
    return s + " M" + (f" ({len(ran)} of {len(ps)})" if len(ran) < len(ps) else "")
extra = " cold: setup / iterations / finish | warm: setup / iterations / finish |" if split else ""
print(f"| scenario | cold: {unit} | iterations | raw/opt | warm: {unit} | answer | iterations | raw/opt | warm/cold |{extra}")
print("| --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: |" + (" ---: | ---: |" if split else ""))
ratios = []
for name, reps in rows.items():
    c = [r["cold"] for r in reps]; w = [r["warm"] for r in reps]
    cc = st.mean(cost(p) for p in c); wc = st.mean(cost(p) for p in w)
    q = lambda ps: st.mean(p["raw_length"] / p["optimum"] for p in ps)
    it = lambda ps: st.mean(p["iterations"] for p in ps)
    kinds = sorted({p.get("origin", "warm") for p in w})
    ratios.append(wc / cc if cc else 0.0)
    print(f"| {name} | {fmt(cc)} | {it(c):.1f} | {q(c):.4f} | {fmt(wc)} | {' / '.join(kinds)} | {it(w):.1f} | {q(w):.4f} | **{100 * wc / cc:.{1 if wc < 0.1 * cc else 0}f} %** |"
          + (f" {parts(c)} | {parts(w)} |" if split else ""))
print(f"\nMean warm/cold: {100 * st.mean(ratios):.0f} % over {len(ratios)} replans, {len(next(iter(rows.values())))} seeds each.")
PY
