"""An external harvest node in Python over Eclipse Cyclone DDS: agrisim's own harvest node run
in this process (`agrisim.Node("harvest")`, as a user would wrap a planner), on the far side
of the ROS 2 link. It starts `agrisim bench harvest --ros2 --external harvest` (sharing this
network namespace), learns its fruit from /harvest/task, and at every /clock tick feeds the
node what arrived (raw CDR, not decoded here) and sends back what it published: arm
trajectories, gripper commands, /cmd_vel, the lift set-point and target id (std_msgs/Float64
scalars), its plans and one /harvest/status per tick (lockstep). Prints a JSON report."""

import argparse
import dataclasses
import json
import subprocess
import sys
import time
import types
from pathlib import Path

from cyclonedds._clayer import ddspy_take, ddspy_write
from cyclonedds.core import InstanceState, Policy, Qos, SampleState, ViewState
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import uint8
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

import agrisim

RELIABLE = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepAll)
ANY = SampleState.Any | ViewState.Any | InstanceState.Any

# What the harvest node reads, in the order it is fed each tick.
INPUTS = [
    ("/target_fruit", "geometry_msgs/msg/PoseStamped"),
    ("/localization/pose", "geometry_msgs/msg/PoseStamped"),
    ("/planning_scene", "agrisim_msgs/msg/PlanningScene"),
    ("/left_arm/joint_states", "sensor_msgs/msg/JointState"),
    ("/right_arm/joint_states", "sensor_msgs/msg/JointState"),
    ("/left_arm/trajectory_status", "agrisim_msgs/msg/TrajectoryStatus"),
    ("/right_arm/trajectory_status", "agrisim_msgs/msg/TrajectoryStatus"),
    ("/left_gripper/state", "agrisim_msgs/msg/GripperState"),
    ("/right_gripper/state", "agrisim_msgs/msg/GripperState"),
]
SCALAR_INPUTS = ["/lift/position"]
FLOAT64 = "std_msgs/msg/Float64"


def dds_type(ros_type: str) -> str:
    pkg, _, name = ros_type.split("/")
    return f"{pkg}::msg::dds_::{name}_"


def opaque(ros_type: str):
    """A stand-in IDL type under the ROS 2 type's DDS name: samples go in and out as raw
    CDR, so only the name matters on the wire."""
    cls = types.new_class(ros_type.replace("/", "_"), (IdlStruct,), {"typename": dds_type(ros_type)}, lambda ns: ns.update({"__annotations__": {"x": uint8}, "x": 0}))
    return dataclasses.dataclass(cls)


class Link:
    def __init__(self, domain: int):
        self.dp = DomainParticipant(domain)
        self.types = {}
        self.readers = {}
        self.writers = {}

    def _topic(self, name: str, ros_type: str):
        if ros_type not in self.types:
            self.types[ros_type] = opaque(ros_type)
        return Topic(self.dp, "rt" + name, self.types[ros_type])

    def reader(self, name: str, ros_type: str):
        self.readers[name] = DataReader(self.dp, self._topic(name, ros_type), qos=RELIABLE)

    def take(self, name: str) -> list[bytes]:
        ret = ddspy_take(self.readers[name]._ref, ANY, 1000)
        return [] if isinstance(ret, int) else [bytes(d) for d, info in ret if info.valid_data]

    def write(self, name: str, ros_type: str, cdr: bytes):
        if name not in self.writers:
            self.writers[name] = DataWriter(self.dp, self._topic(name, ros_type), qos=RELIABLE)
        ddspy_write(self.writers[name]._ref, cdr.ljust((len(cdr) + 3) & ~3, b"\0"))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1, help="seed of the node's planners")
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    link = Link(a.domain)
    for name, ty in INPUTS:
        link.reader(name, ty)
    for name in SCALAR_INPUTS + ["/harvest/task"]:
        link.reader(name, FLOAT64)
    link.reader("/clock", "rosgraph_msgs/msg/Clock")
    # Writers first, so the bridge finds them (the status is its lockstep topic).
    waiting = agrisim.encode("agrisim_msgs/msg/HarvestStatus", {"stage": "waiting_for_task", "target_id": -1, "outcome": "running"})
    for name, ty in [("/harvest/status", "agrisim_msgs/msg/HarvestStatus"), ("/harvest/plans", "agrisim_msgs/msg/PlanResult"), ("/cmd_vel", "geometry_msgs/msg/Twist"), ("/left_arm/joint_trajectory", "trajectory_msgs/msg/JointTrajectory"), ("/right_arm/joint_trajectory", "trajectory_msgs/msg/JointTrajectory"), ("/left_gripper/command", "control_msgs/msg/GripperCommand"), ("/right_gripper/command", "control_msgs/msg/GripperCommand")]:
        link.writers[name] = DataWriter(link.dp, link._topic(name, ty), qos=RELIABLE)
    for name in ["/lift/setpoint", "/harvest/target_id"]:
        link.writers[name] = DataWriter(link.dp, link._topic(name, FLOAT64), qos=RELIABLE)
    proc = subprocess.Popen([x for x in a.agrisim if x != "--"])
    node = None
    ticks = sent = 0
    status = waiting
    scalars: dict[str, float] = {}
    try:
        deadline = time.monotonic() + 900
        while proc.poll() is None and time.monotonic() < deadline:
            clocks = link.take("/clock")
            if not clocks:
                time.sleep(0.0002)
                continue
            for task in link.take("/harvest/task"):
                node = agrisim.Node("harvest", fruit_index=int(agrisim.decode(FLOAT64, task)["data"]), seed=a.seed)
            for c in clocks:
                ticks += 1
                clock = agrisim.decode("rosgraph_msgs/msg/Clock", c)["clock"]
                t_ns = clock["sec"] * 1_000_000_000 + clock["nanosec"]
                inbox = [(name, ty, cdr) for name, ty in INPUTS for cdr in link.take(name)]
                for name in SCALAR_INPUTS:
                    for cdr in link.take(name):
                        scalars[name] = agrisim.decode(FLOAT64, cdr)["data"]
                published_status = False
                if node is not None:
                    out, set_scalars = node.step(t_ns, inbox, scalars)
                    for topic, ty, cdr in out:
                        link.write(topic, ty, cdr)
                        sent += 1
                        if topic == "/harvest/status":
                            status, published_status = cdr, True
                    for name, value in set_scalars.items():
                        link.write(name, FLOAT64, agrisim.encode(FLOAT64, {"data": value}))
                if not published_status:
                    link.write("/harvest/status", "agrisim_msgs/msg/HarvestStatus", status)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    print(json.dumps({"ticks": ticks, "sent": sent, "task_received": node is not None, "returncode": proc.returncode}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
