"""A misbehaving ROS 2 peer on Cyclone DDS for the bridge's bad-input test: it starts the
agrisim command given after `--` (so both share this network namespace) and answers each
/clock tick with one /cmd_vel: valid Twists (0.3 m/s), but at some ticks garbage bytes or a
message of another type under the Twist type name, and once a Twist with a NaN; it also
sends garbage on /left_arm/joint_trajectory. It raises the lift through the scalar input
/lift/setpoint (std_msgs/Float64), later sends it a NaN, and records /lift/position. Prints
what it sent and saw as JSON."""

import argparse
import json
import math
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import sequence, uint8
from cyclonedds.internal import InvalidSample
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).parent))
from ros2_idl import Clock, Float64, Twist, Vector3  # noqa: E402

RELIABLE = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll)


@dataclass
class GarbageTwist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """Raw bytes under the Twist type name: 4 + n bytes, too short for a Twist (48)."""

    junk: sequence[uint8] = field(default_factory=list)


@dataclass
class TextAsTwist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """A std_msgs/String-shaped message under the Twist type name (wrongly typed)."""

    data: str = ""


@dataclass
class GarbageTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectory_"):
    junk: sequence[uint8] = field(default_factory=list)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    dp = DomainParticipant(0)
    clock = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=RELIABLE)
    good = DataWriter(dp, Topic(dp, "rt/cmd_vel", Twist), qos=RELIABLE)
    garbage = DataWriter(dp, Topic(dp, "rt/cmd_vel", GarbageTwist), qos=RELIABLE)
    text = DataWriter(dp, Topic(dp, "rt/cmd_vel", TextAsTwist), qos=RELIABLE)
    traj = DataWriter(dp, Topic(dp, "rt/left_arm/joint_trajectory", GarbageTrajectory), qos=RELIABLE)
    lift = DataWriter(dp, Topic(dp, "rt/lift/setpoint", Float64), qos=RELIABLE)
    lift_position = DataReader(dp, Topic(dp, "rt/lift/position", Float64), qos=RELIABLE)
    positions = []
    proc = subprocess.Popen([x for x in a.agrisim if x != "--"])
    ticks = good_sent = bad_sent = 0
    try:
        deadline = time.monotonic() + 150
        while proc.poll() is None and time.monotonic() < deadline:
            got = [m for m in clock.take(N=100) if not isinstance(m, InvalidSample)]
            if not got:
                time.sleep(0.0002)
                continue
            for _ in got:
                ticks += 1
                if ticks in (10, 20):
                    garbage.write(GarbageTwist(junk=[0xFF, 0x00, 0x13]))
                    bad_sent += 1
                elif ticks == 15:
                    text.write(TextAsTwist(data="drive forward"))
                    bad_sent += 1
                elif ticks == 25:
                    good.write(Twist(linear=Vector3(x=math.nan), angular=Vector3()))
                    good_sent += 1
                else:
                    good.write(Twist(linear=Vector3(x=0.3), angular=Vector3()))
                    good_sent += 1
                if ticks == 12:
                    traj.write(GarbageTrajectory(junk=[1, 2, 3, 4, 5]))
                    bad_sent += 1
                if ticks == 5:
                    lift.write(Float64(data=0.4))  # a scalar input over ROS 2 (the lift starts at 0.2 m)
                elif ticks == 30:
                    lift.write(Float64(data=math.nan))  # refused by the bridge
                    bad_sent += 1
            positions += [m.data for m in lift_position.take(N=100) if not isinstance(m, InvalidSample)]
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    print(json.dumps({"ticks": ticks, "good_sent": good_sent, "bad_sent": bad_sent, "lift_positions": positions, "returncode": proc.returncode}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
