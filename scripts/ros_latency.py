#!/usr/bin/env python3
"""Message-to-path latency of `ohaca ros` (BENCHMARKS.md, "ROS 2"): a Moving AI map published as
a `nav_msgs/OccupancyGrid` from Cyclone DDS (0.05 m cells), after the start and the goal, until
`/plan` arrives: the node converts the map, uploads it to the device, plans and publishes.
Prints one line per run and the node's own figures (`/plan_info`).

    scripts/qemu-serve.sh --icount --port 4444 &
    scripts/ros_latency.py --ohaca target/x86_64-unknown-linux-gnu/release/ohaca \\
        --tcp 127.0.0.1:4444 --map maps/large/Boston_0_256.map --start 184,0 --goal 8,254
"""

import argparse
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ros_interop as ri  # noqa: E402  (sets CYCLONEDDS_URI: loopback only)

RES = 0.05


def load_moving_ai(path):
    lines = open(path).read().splitlines()
    h = int(next(l for l in lines if l.startswith("height")).split()[1])
    w = int(next(l for l in lines if l.startswith("width")).split()[1])
    rows = lines[lines.index("map") + 1:][:h]
    # Moving AI row 0 is the top; ROS row 0 the bottom.
    return w, h, [[ri.FREE if c in ".G" else ri.OCC for c in rows[h - 1 - j]] for j in range(h)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ohaca", required=True)
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--host", action="store_true")
    g.add_argument("--tcp")
    ap.add_argument("--map", required=True, help="a Moving AI .map file")
    ap.add_argument("--start", required=True, help="X,Y cell (Moving AI: row 0 at the top)")
    ap.add_argument("--goal", required=True)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=300.0)
    a = ap.parse_args()
    w, h, grid = load_moving_ai(a.map)

    def metres(s):
        x, y = (int(v) for v in s.split(","))
        return ((x + 0.5) * RES, (h - 1 - y + 0.5) * RES)

    start, goal = metres(a.start), metres(a.goal)
    domain = 201
    cmd = [a.ohaca, "ros", "--domain", str(domain), "--only-network", "127.0.0.1",
           "--timeout", str(a.timeout), "--run-for", str(a.timeout * a.runs + 60)]
    cmd += ["--tcp", a.tcp] if a.tcp else ["--host"]
    node = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        t = ri.Test.__new__(ri.Test)
        t.domain, t.node, t.a = domain, node, a
        t.t0 = time.monotonic()
        t.plans, t.infos = [], []
        t.dds()
        t.matched()
        t.start_w.write(ri.PoseWithCovarianceStamped(header=ri.Header(), pose=ri.PoseWithCovariance(pose=t.pose(start))))
        time.sleep(0.3)
        t.goal_w.write(ri.PoseStamped(header=ri.Header(), pose=t.pose(goal)))
        time.sleep(0.5)  # no map yet: the node keeps the goal
        data = [v for row in grid for v in row]
        for run in range(1, a.runs + 1):
            msg = ri.OccupancyGrid(header=ri.Header(frame_id="map"),
                                   info=ri.MapMetaData(resolution=RES, width=w, height=h),
                                   data=data)
            t0 = time.monotonic()
            t.map_w.write(msg)
            _, info = t.next_plan(run, f"the plan after map {run}")
            dt = time.monotonic() - t0
            ticks = info.get("device_ticks")
            print(f"run {run}: map published -> /plan received {dt:.3f} s; node: upload "
                  f"{info.get('upload_s', 0):.3f} s ({info.get('upload_bytes', 0)} B), plan "
                  f"{info['planning_time_s']:.3f} s, device {ticks} ticks"
                  f"{'' if ticks is None else f' ({ticks / 1000:.1f} M instructions with -icount)'}"
                  f", {info['iterations']} iterations, {info['length_m']:.2f} m, warm {info['warm']}",
                  flush=True)
        return 0
    except ri.Fail as e:
        print(f"FAIL: {e}", file=sys.stderr)
        return 1
    finally:
        node.terminate()
        try:
            _, err = node.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            node.kill()
            _, err = node.communicate()
        if os.environ.get("OHACA_ROS_LOG") == "1":
            print(err, file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
