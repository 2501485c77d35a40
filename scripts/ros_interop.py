#!/usr/bin/env python3
"""`ohaca ros` against Eclipse Cyclone DDS (PyPI `cyclonedds`), on the loopback interface only.

Plays the rest of a ROS 2 system with ROS 2's own DDS names, types and QoS (no ROS install):
  1. publishes a map (`rt/map`, `nav_msgs::msg::dds_::OccupancyGrid_`, reliable + transient
     local, as map_server), an initial pose (`rt/initialpose`) and a goal (`rt/goal_pose`);
  2. receives `rt/plan` (`nav_msgs/Path`) and `rt/plan_info`, and checks the path with the
     project's checker (`ohaca check`: starts at the start, ends at the goal, metres in the map
     frame, every segment clear of the inflated map);
  3. moves the robot along the plan, publishes a map update (`rt/map_updates`,
     `map_msgs/OccupancyGridUpdate`) that closes the gap the path goes through, and checks that
     the next plan is warm, valid on the changed map, and that the old one is not;
  4. calls the action `compute_path_to_pose` (`nav2_msgs/action/ComputePathToPose`) with the
     rmw_cyclonedds service mapping (request header in the payload): a goal that succeeds with a
     valid path, and one off the map that is aborted with GOAL_OUTSIDE_MAP (204).

    scripts/ros_interop.py --ohaca target/x86_64-unknown-linux-gnu/host/ohaca --host
    scripts/ros_interop.py --ohaca ... --tcp 127.0.0.1:4444     # a device (QEMU)

Exit status 0 only if every check passed; any failure prints `FAIL: ...` and the node's log.
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

# Cyclone reads its configuration when the first domain is created: loopback, unicast
# discovery to the local participant ports, no multicast.
CYCLONE_LOOPBACK = """<CycloneDDS><Domain id="any">
  <General><Interfaces><NetworkInterface address="127.0.0.1" multicast="false"/></Interfaces>
    <AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>"""
os.environ["CYCLONEDDS_URI"] = CYCLONE_LOOPBACK

try:
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    from cyclonedds.idl.types import array, float32, float64, int8, int32, int64, sequence, uint8, uint16, uint32, uint64
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
except ImportError as e:  # never pass silently
    print(f"FAIL: Python package cyclonedds is missing ({e}): pip install cyclonedds "
          "(scripts/setup.sh does)", file=sys.stderr)
    sys.exit(1)


# --- ROS 2 message types, as rosidl generates them for DDS ---------------------------------

@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = "map"


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose = field(default_factory=Pose)
    covariance: array[float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class PoseWithCovarianceStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovarianceStamped_"):
    header: Header = field(default_factory=Header)
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)


@dataclass
class MapMetaData(IdlStruct, typename="nav_msgs::msg::dds_::MapMetaData_"):
    map_load_time: Time = field(default_factory=Time)
    resolution: float32 = 0.0
    width: uint32 = 0
    height: uint32 = 0
    origin: Pose = field(default_factory=Pose)


@dataclass
class OccupancyGrid(IdlStruct, typename="nav_msgs::msg::dds_::OccupancyGrid_"):
    header: Header = field(default_factory=Header)
    info: MapMetaData = field(default_factory=MapMetaData)
    data: sequence[int8] = field(default_factory=list)


@dataclass
class OccupancyGridUpdate(IdlStruct, typename="map_msgs::msg::dds_::OccupancyGridUpdate_"):
    header: Header = field(default_factory=Header)
    x: int32 = 0
    y: int32 = 0
    width: uint32 = 0
    height: uint32 = 0
    data: sequence[int8] = field(default_factory=list)


@dataclass
class Path(IdlStruct, typename="nav_msgs::msg::dds_::Path_"):
    header: Header = field(default_factory=Header)
    poses: sequence[PoseStamped] = field(default_factory=list)


@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str = ""


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: array[uint8, 16] = field(default_factory=lambda: [0] * 16)


@dataclass
class CPGoal(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_Goal_"):
    goal: PoseStamped = field(default_factory=PoseStamped)
    start: PoseStamped = field(default_factory=PoseStamped)
    planner_id: str = ""
    use_start: bool = False


@dataclass
class CPResult(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_Result_"):
    path: Path = field(default_factory=Path)
    planning_time: Duration = field(default_factory=Duration)
    error_code: uint16 = 0
    error_msg: str = ""


# The action's services with rmw_cyclonedds's mapping: a request header (client guid, sequence
# number) in front of the request and of the reply.
@dataclass
class SendGoalRequest(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Request_"):
    client_guid: uint64 = 0
    seq: int64 = 0
    goal_id: UUID = field(default_factory=UUID)
    goal: CPGoal = field(default_factory=CPGoal)


@dataclass
class SendGoalResponse(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Response_"):
    client_guid: uint64 = 0
    seq: int64 = 0
    accepted: bool = False
    stamp: Time = field(default_factory=Time)


@dataclass
class GetResultRequest(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_GetResult_Request_"):
    client_guid: uint64 = 0
    seq: int64 = 0
    goal_id: UUID = field(default_factory=UUID)


@dataclass
class GetResultResponse(IdlStruct, typename="nav2_msgs::action::dds_::ComputePathToPose_GetResult_Response_"):
    client_guid: uint64 = 0
    seq: int64 = 0
    status: int8 = 0
    result: CPResult = field(default_factory=CPResult)


# --- the map -----------------------------------------------------------------------------------

RES = 0.05
W, H = 120, 80
ORIGIN = (-1.0, -0.5)
INFLATE = 0.1
FREE, OCC, UNK = 0, 100, -1


def base_map():
    """ROS rows (row 0 lowest): two walls with gaps, an unexplored corner."""
    g = [[FREE] * W for _ in range(H)]
    for j in range(0, 60):
        g[j][40] = OCC  # wall 1, open above row 60
    for j in range(0, H):
        if not (j < 20 or j >= 66):
            g[j][80] = OCC  # wall 2: a gap below row 20 and one above row 66
    for j in range(60, H):
        for i in range(100, W):
            g[j][i] = UNK
    return g


# The update closes wall 2's upper gap (ROS cells x 78..82, y 66..79).
UPD = dict(x=78, y=66, width=5, height=14)


def updated(g):
    g = [row[:] for row in g]
    for j in range(UPD["y"], UPD["y"] + UPD["height"]):
        for i in range(UPD["x"], UPD["x"] + UPD["width"]):
            g[j][i] = OCC
    return g


def centre(i, j):
    return (round(ORIGIN[0] + (i + 0.5) * RES, 6), round(ORIGIN[1] + (j + 0.5) * RES, 6))


START = centre(10, 10)
GOAL = centre(110, 40)


def write_map_files(g, folder, name):
    """The grid as a map_server YAML + PGM (image row 0 is the top: ROS row H - 1)."""
    pix = {FREE: 254, OCC: 0, UNK: 205}
    body = bytes(pix[g[H - 1 - r][i]] for r in range(H) for i in range(W))
    with open(os.path.join(folder, name + ".pgm"), "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (W, H) + body)
    yaml = os.path.join(folder, name + ".yaml")
    with open(yaml, "w") as f:
        f.write(f"image: {name}.pgm\nresolution: {RES}\norigin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
                "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return yaml


# --- the test ----------------------------------------------------------------------------------

class Fail(Exception):
    pass


def wait(what, timeout, poll, interval=0.02):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        v = poll()
        if v is not None:
            return v
        time.sleep(interval)
    raise Fail(f"timed out after {timeout:.0f} s waiting for {what}")


def valid_samples(samples):
    return [s for s in samples if isinstance(s, IdlStruct)]


class Test:
    def __init__(self, args):
        self.a = args
        self.tmp = tempfile.mkdtemp(prefix="ohaca-ros-")
        self.domain = args.domain if args.domain is not None else random.randint(100, 200)
        self.grid = base_map()
        self.map_yaml = write_map_files(self.grid, self.tmp, "map")
        self.upd_yaml = write_map_files(updated(self.grid), self.tmp, "map-updated")
        self.log_path = os.path.join(self.tmp, "node.log")
        self.node = None
        self.plans, self.infos = [], []
        self.t0 = time.monotonic()

    def say(self, msg):
        print(f"[{time.monotonic() - self.t0:6.2f} s] {msg}", flush=True)

    def start_node(self):
        cmd = [self.a.ohaca, "ros", "--domain", str(self.domain), "--only-network", "127.0.0.1",
               "--inflate", str(INFLATE), "--service-mapping", "cyclone",
               "--run-for", str(self.a.timeout + 30)]
        cmd += ["--tcp", self.a.tcp] if self.a.tcp else ["--host"]
        if self.a.gif:
            cmd += ["--gif", self.a.gif]
        if self.a.png:
            cmd += ["--png", self.a.png]
        self.say("node: " + " ".join(cmd))
        self.log = open(self.log_path, "w")
        self.node = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=self.log, stderr=self.log)

    def dds(self):
        dp = DomainParticipant(self.domain)
        rel = Policy.Reliability.Reliable(max_blocking_time=1_000_000_000)
        cdr = Policy.DataRepresentation(use_cdrv0_representation=True)
        latched = Qos(rel, Policy.Durability.TransientLocal, Policy.History.KeepLast(1), cdr)
        default = Qos(rel, Policy.Durability.Volatile, Policy.History.KeepLast(10), cdr)
        self.dp = dp

        def topic(name, ty):
            return Topic(dp, name, ty, qos=Qos(cdr))

        self.map_w = DataWriter(dp, topic("rt/map", OccupancyGrid), qos=latched)
        self.upd_w = DataWriter(dp, topic("rt/map_updates", OccupancyGridUpdate), qos=default)
        self.start_w = DataWriter(dp, topic("rt/initialpose", PoseWithCovarianceStamped), qos=default)
        self.goal_w = DataWriter(dp, topic("rt/goal_pose", PoseStamped), qos=default)
        self.plan_r = DataReader(dp, topic("rt/plan", Path), qos=latched)
        self.info_r = DataReader(dp, topic("rt/plan_info", String), qos=latched)
        base = "compute_path_to_pose/_action/"
        self.goal_rq = DataWriter(dp, topic("rq/" + base + "send_goalRequest", SendGoalRequest), qos=default)
        self.goal_rr = DataReader(dp, topic("rr/" + base + "send_goalReply", SendGoalResponse), qos=default)
        self.res_rq = DataWriter(dp, topic("rq/" + base + "get_resultRequest", GetResultRequest), qos=default)
        self.res_rr = DataReader(dp, topic("rr/" + base + "get_resultReply", GetResultResponse), qos=default)

    def matched(self):
        """Wait until the node has discovered every endpoint we talk to."""
        for name, ent, get in [
            ("rt/map", self.map_w, "get_matched_subscriptions"),
            ("rt/map_updates", self.upd_w, "get_matched_subscriptions"),
            ("rt/initialpose", self.start_w, "get_matched_subscriptions"),
            ("rt/goal_pose", self.goal_w, "get_matched_subscriptions"),
            ("rt/plan", self.plan_r, "get_matched_publications"),
            ("rt/plan_info", self.info_r, "get_matched_publications"),
            ("the action's send_goal service", self.goal_rq, "get_matched_subscriptions"),
            ("the action's send_goal replies", self.goal_rr, "get_matched_publications"),
            ("the action's get_result service", self.res_rq, "get_matched_subscriptions"),
            ("the action's get_result replies", self.res_rr, "get_matched_publications"),
        ]:
            wait(f"DDS discovery of `ohaca ros` on {name} (domain {self.domain}, loopback)",
                 self.a.timeout, lambda: (getattr(ent, get)() or None) and True,
                 interval=0.05)
            if self.node.poll() is not None:
                raise Fail(f"the node exited with status {self.node.returncode}")
        self.say("discovered: all 10 endpoints matched")

    def collect(self):
        self.plans += valid_samples(self.plan_r.take(N=100))
        self.infos += [json.loads(s.data) for s in valid_samples(self.info_r.take(N=100))]

    def next_plan(self, n, what):
        def poll():
            self.collect()
            if self.node.poll() is not None:
                raise Fail(f"the node exited with status {self.node.returncode}")
            return True if len(self.plans) >= n and len(self.infos) >= n else None
        wait(f"{what} (plan {n} on rt/plan and rt/plan_info)", self.a.timeout, poll)
        return self.plans[n - 1], self.infos[n - 1]

    def check(self, path, yaml, start, goal, expect_valid=True, name="plan"):
        pts = [[p.pose.position.x, p.pose.position.y] for p in path.poses]
        f = os.path.join(self.tmp, f"{name}.json")
        with open(f, "w") as fh:
            json.dump(pts, fh)
        cmd = [self.a.ohaca, "check", "--map", yaml, "--inflate", str(INFLATE), "--path", f,
               "--start-m", f"{start[0]},{start[1]}", "--goal-m", f"{goal[0]},{goal[1]}"]
        r = subprocess.run(cmd, capture_output=True, text=True)
        ok = r.returncode == 0
        if ok != expect_valid or r.returncode not in (0, 1):
            raise Fail(f"{name}: `ohaca check` said {r.stdout.strip()} {r.stderr.strip()} "
                       f"(exit {r.returncode}), expected {'valid' if expect_valid else 'invalid'}; "
                       f"path {pts}")
        if path.header.frame_id != "map":
            raise Fail(f"{name}: frame `{path.header.frame_id}`, expected `map`")
        return json.loads(r.stdout)

    def pose(self, xy):
        p = Pose(position=Point(x=xy[0], y=xy[1]))
        return p

    def publish_map(self):
        data = [v for row in self.grid for v in row]
        msg = OccupancyGrid(header=Header(frame_id="map"),
                            info=MapMetaData(resolution=RES, width=W, height=H,
                                             origin=Pose(position=Point(x=ORIGIN[0], y=ORIGIN[1]))),
                            data=data)
        self.map_w.write(msg)

    def action_call(self, seq, goal_xy, start_xy):
        gid = UUID(uuid=[random.randint(0, 255) for _ in range(16)])
        guid = random.getrandbits(63)
        req = SendGoalRequest(client_guid=guid, seq=seq, goal_id=gid,
                              goal=CPGoal(goal=PoseStamped(header=Header(), pose=self.pose(goal_xy)),
                                          start=PoseStamped(header=Header(), pose=self.pose(start_xy)),
                                          planner_id="", use_start=True))
        self.goal_rq.write(req)

        def reply(reader, what):
            def poll():
                for s in valid_samples(reader.take(N=10)):
                    if s.client_guid == guid and s.seq == seq:
                        return s
                return None
            return wait(what, self.a.timeout, poll)
        r = reply(self.goal_rr, "the action's send_goal reply")
        if not r.accepted:
            raise Fail("the action refused the goal")
        self.res_rq.write(GetResultRequest(client_guid=guid, seq=seq + 1, goal_id=gid))
        seq += 1
        return reply(self.res_rr, "the action's get_result reply")

    def run(self):
        self.start_node()
        self.dds()
        self.publish_map()
        self.matched()
        # 1. start and goal: the first plan (cold).
        self.start_w.write(PoseWithCovarianceStamped(header=Header(), pose=PoseWithCovariance(pose=self.pose(START))))
        time.sleep(0.3)
        t = time.monotonic()
        self.goal_w.write(PoseStamped(header=Header(), pose=self.pose(GOAL)))
        path1, info1 = self.next_plan(1, "the first plan")
        self.say(f"plan 1: {len(path1.poses)} poses in {time.monotonic() - t:.2f} s "
                 f"(node: {info1['planning_time_s']:.3f} s, warm {info1['warm']}, on {info1['backend']})")
        if info1["warm"] or info1["trigger"] != "goal":
            raise Fail(f"plan 1 should be a cold plan for the goal: {info1}")
        c1 = self.check(path1, self.map_yaml, START, GOAL, name="plan1")
        self.say(f"plan 1 valid: {c1}")
        # 2. the robot moves a third of the way; a map update closes the gap its path uses.
        k = max(1, len(path1.poses) // 3)
        here = (path1.poses[k].pose.position.x, path1.poses[k].pose.position.y)
        if here == GOAL:
            here = (path1.poses[1].pose.position.x, path1.poses[1].pose.position.y)
        self.start_w.write(PoseWithCovarianceStamped(header=Header(), pose=PoseWithCovariance(pose=self.pose(here))))
        time.sleep(0.3)
        data = [OCC] * (UPD["width"] * UPD["height"])
        t = time.monotonic()
        self.upd_w.write(OccupancyGridUpdate(header=Header(), data=data, **UPD))
        path2, info2 = self.next_plan(2, "the replan after the map update")
        self.say(f"plan 2: {len(path2.poses)} poses in {time.monotonic() - t:.2f} s "
                 f"(node: {info2['planning_time_s']:.3f} s, warm {info2['warm']}, trigger {info2['trigger']})")
        self.say(f"plan 2 info: {json.dumps(info2)}")
        if not info2["warm"] or info2["trigger"] != "map_update":
            raise Fail(f"plan 2 should be a warm replan after the update: {info2}")
        self.check(path1, self.upd_yaml, START, GOAL, expect_valid=False, name="plan1-on-updated-map")
        c2 = self.check(path2, self.upd_yaml, here, GOAL, name="plan2")
        self.say(f"plan 2 valid on the updated map (plan 1 is not): {c2}")
        # 3. the action, with rmw_cyclonedds's service mapping.
        t = time.monotonic()
        res = self.action_call(10, GOAL, here)
        if res.status != 4 or res.result.error_code != 0:
            raise Fail(f"the action should succeed: status {res.status}, error {res.result.error_code} "
                       f"{res.result.error_msg!r}")
        pt = res.result.planning_time
        c3 = self.check(res.result.path, self.upd_yaml, here, GOAL, name="action")
        self.say(f"action: SUCCEEDED in {time.monotonic() - t:.2f} s (planning_time "
                 f"{pt.sec + pt.nanosec / 1e9:.3f} s), path valid: {c3}")
        off = (ORIGIN[0] - 1.0, 0.0)
        res = self.action_call(20, off, START)
        if res.status != 6 or res.result.error_code != 204 or "off the map" not in res.result.error_msg:
            raise Fail(f"a goal off the map should abort with GOAL_OUTSIDE_MAP (204): status {res.status}, "
                       f"error {res.result.error_code} {res.result.error_msg!r}")
        self.say(f"action: goal off the map ABORTED, error_code 204: {res.result.error_msg!r}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ohaca", required=True, help="the ohaca binary")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--host", action="store_true", help="plan on the host core")
    g.add_argument("--tcp", help="plan on a device at HOST:PORT (QEMU)")
    ap.add_argument("--domain", type=int, help="DDS domain (default: random in 100..200)")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per wait")
    ap.add_argument("--gif", help="ask the node to draw the replanning drive into this GIF")
    ap.add_argument("--png", help="the same drive as a strip of PNG panels")
    ap.add_argument("--log", action="store_true", help="print the node's log even on success")
    args = ap.parse_args()
    t = Test(args)
    what = f"device {args.tcp}" if args.tcp else "host core"
    rc = 1
    try:
        t.run()
        print(f"PASS: ohaca ros ({what}) with Cyclone DDS: map, poses, plan, warm replan, action "
              f"({time.monotonic() - t.t0:.1f} s)")
        rc = 0
    except Fail as e:
        print(f"FAIL: ohaca ros ({what}) with Cyclone DDS: {e}", file=sys.stderr)
    finally:
        if t.node is not None:
            t.node.terminate()
            try:
                t.node.wait(timeout=5)
            except subprocess.TimeoutExpired:
                t.node.kill()
                t.node.wait()
            t.log.close()
            if rc != 0 or args.log:
                with open(t.log_path) as f:
                    print(f"--- node log ({t.log_path}) ---\n{f.read()}--- end of node log ---",
                          file=sys.stderr)
    return rc


if __name__ == "__main__":
    sys.exit(main())
