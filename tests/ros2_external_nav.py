"""An external navigator on Eclipse Cyclone DDS (the `cyclonedds` package), standing in for a
ROS 2 Nav2 stack: it starts `agrisim bench nav --ros2 --external navigator` (so both share
this process's network namespace), takes /goal_pose, /odom and /clock from it, and answers
every /clock tick with one /cmd_vel and one /navigate/status (lockstep), as Nav2's
controller and navigator would (with `--zenoh ENDPOINT`: the same over `--zenoh`, as an
rmw_zenoh node, tests/zenoh_node.py). Received point clouds are saved (raw CDR) for the test to compare with the
MCAP.

Path: a Manhattan route from the headland start (along the headland to the goal's aisle,
then along the aisle's centre line), followed on wheel odometry with a proportional
controller. Usage: python ros2_external_nav.py AGRISIM_ARGS... (after `--`), options first.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.internal import InvalidSample
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).parent))
from ros2_idl import Clock, Header, NavigationStatus, Odometry, PointCloud2, PoseStamped, Time, Twist, Vector3  # noqa: E402

RELIABLE = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll)
BEST_EFFORT = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(20))


def yaw_of(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Navigator:
    def __init__(self, domain: int, zenoh_node=None):
        if zenoh_node is not None:
            # Over Zenoh as an rmw_zenoh node (tests/zenoh_node.py), the same messages.
            n = zenoh_node
            self.clock = n.reader("/clock", Clock, "rosgraph_msgs/msg/Clock")
            self.odom = n.reader("/odom", Odometry, "nav_msgs/msg/Odometry")
            self.goal_r = n.reader("/goal_pose", PoseStamped, "geometry_msgs/msg/PoseStamped")
            self.points = n.reader("/points", PointCloud2, "sensor_msgs/msg/PointCloud2")
            self.cmd = n.writer("/cmd_vel", "geometry_msgs/msg/Twist")
            self.status = n.writer("/navigate/status", "agrisim_msgs/msg/NavigationStatus")
        else:
            dp = DomainParticipant(domain)
            self.clock = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=RELIABLE)
            self.odom = DataReader(dp, Topic(dp, "rt/odom", Odometry), qos=RELIABLE)
            self.goal_r = DataReader(dp, Topic(dp, "rt/goal_pose", PoseStamped), qos=RELIABLE)
            self.points = DataReader(dp, Topic(dp, "rt/points", PointCloud2), qos=BEST_EFFORT)
            self.cmd = DataWriter(dp, Topic(dp, "rt/cmd_vel", Twist), qos=RELIABLE)
            self.status = DataWriter(dp, Topic(dp, "rt/navigate/status", NavigationStatus), qos=RELIABLE)
        self.pose = None
        self.goal = None
        self.waypoints: list[tuple[float, float]] = []
        self.done = False
        self.ticks = 0
        self.clouds: dict[str, bytes] = {}

    @staticmethod
    def valid(samples):
        """Samples with data (a writer leaving gives an InvalidSample)."""
        return [m for m in samples if not isinstance(m, InvalidSample)]

    def drain(self):
        for m in self.valid(self.odom.take(N=100)):
            p = m.pose.pose
            self.pose = (p.position.x, p.position.y, yaw_of(p.orientation))
        for m in self.valid(self.goal_r.take(N=10)):
            self.goal = m
            self.waypoints = []
        for m in self.valid(self.points.take(N=100)):
            self.clouds[f"{m.header.stamp.sec}.{m.header.stamp.nanosec:09d}"] = m.serialize()

    def answer(self, t: Time):
        """One /cmd_vel for this tick, and the status."""
        vx = vy = 0.0
        state = "idle"
        if self.goal is not None and self.pose is not None and not self.done:
            gx, gy = self.goal.pose.position.x, self.goal.pose.position.y
            if not self.waypoints:
                self.waypoints = [(self.pose[0], gy), (gx, gy)]
            x, y, yaw = self.pose
            wx, wy = self.waypoints[0]
            if math.hypot(wx - x, wy - y) < 0.05:
                self.waypoints.pop(0)
            if not self.waypoints:
                self.done = True
                state = "succeeded"
            else:
                wx, wy = self.waypoints[0]
                dx, dy = wx - x, wy - y
                d = math.hypot(dx, dy)
                speed = min(0.6, 0.8 * d)
                ex, ey = dx / d * speed, dy / d * speed
                c, s = math.cos(yaw), math.sin(yaw)
                vx, vy = c * ex + s * ey, -s * ex + c * ey
                state = "following"
        self.cmd.write(Twist(linear=Vector3(x=vx, y=vy), angular=Vector3()))
        goal = self.goal if self.goal is not None else PoseStamped()
        self.status.write(NavigationStatus(header=Header(stamp=t, frame_id="map"), state=state, detail="", goal=goal))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, default=0)
    ap.add_argument("--clouds", type=Path, required=True, help="where received clouds go (JSON of hex)")
    ap.add_argument("--zenoh", metavar="ENDPOINT", help="talk to the run over Zenoh (--zenoh) at ENDPOINT, not DDS")
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = [x for x in a.agrisim if x != "--"]
    session = None
    if a.zenoh:
        import zenoh_node

        # The run listens first; the navigator connects to it.
        proc = subprocess.Popen(cmd)
        session = zenoh_node.open_session(a.zenoh, proc, timeout=60)
        nav = Navigator(a.domain, zenoh_node.ZenohNode(session, a.domain, "external_navigator"))
    else:
        nav = Navigator(a.domain)
        proc = subprocess.Popen(cmd)
    try:
        deadline = time.monotonic() + 600
        while proc.poll() is None and time.monotonic() < deadline:
            ticks = nav.valid(nav.clock.take(N=100))
            if not ticks:
                time.sleep(0.0002)
                continue
            nav.drain()
            for tick in ticks:
                nav.ticks += 1
                nav.answer(tick.clock)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    nav.drain()
    if session is not None:
        session.close()
    a.clouds.write_text(json.dumps({k: v.hex() for k, v in nav.clouds.items()}))
    print(json.dumps({"ticks": nav.ticks, "clouds": len(nav.clouds), "returncode": proc.returncode}))
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
