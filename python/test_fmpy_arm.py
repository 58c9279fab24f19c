"""The Arm FMU through FMPy's FMI 3 API, with messages encoded and decoded by rosbags (the
ROS 2 Humble type store: an encoder agrisim did not write): two instances (left, right), a
valid JointTrajectory is accepted and tracked, a NaN one is rejected without moving the arm,
the gripper stalls on an object, and JointState / TrajectoryStatus / GripperState decode."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import rosbags.typesys as typesys

from agrisim_fmpy import Slave, fmu_path

REPO = Path(__file__).resolve().parents[1]
READY = [0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4]
H = 0.02


def store():
    st = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    for name in ("GripperState", "TrajectoryStatus"):
        text = (REPO / "models" / "msgs" / "agrisim_msgs" / "msg" / f"{name}.msg").read_text()
        st.register(typesys.get_types_from_msg(text, f"agrisim_msgs/msg/{name}"))
    text = (REPO / "models" / "msgs" / "control_msgs" / "msg" / "GripperCommand.msg").read_text()
    st.register(typesys.get_types_from_msg(text, "control_msgs/msg/GripperCommand"))
    return st


def trajectory(st, side: str, points: list[tuple[list[float], float]]) -> bytes:
    T = st.types
    Header, Time, Duration = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"], T["builtin_interfaces/msg/Duration"]
    Point, Traj = T["trajectory_msgs/msg/JointTrajectoryPoint"], T["trajectory_msgs/msg/JointTrajectory"]
    empty = np.array([], dtype=np.float64)
    pts = []
    for q, t in points:
        sec = int(math.floor(t))
        pts.append(Point(positions=np.array(q, dtype=np.float64), velocities=empty, accelerations=empty, effort=empty,
                         time_from_start=Duration(sec=sec, nanosec=round((t - sec) * 1e9))))
    msg = Traj(header=Header(stamp=Time(sec=0, nanosec=0), frame_id=""),
               joint_names=[f"{side}_joint{i}" for i in range(1, 8)], points=pts)
    return bytes(st.serialize_cdr(msg, "trajectory_msgs/msg/JointTrajectory"))


def arm(side: str) -> Slave:
    s = Slave(fmu_path("Arm"), f"{side}_arm")
    s.slave.setString([s.var("side").valueReference], [side])
    return s


def q_of(s: Slave) -> list[float]:
    return s.get_many([f"q{i}" for i in range(1, 8)])


def test_two_instances_track_reject_and_grip():
    st = store()
    left, right = arm("left"), arm("right")
    try:
        for s in (left, right):
            s.initialize(0.0)
            assert q_of(s) == READY
        goal = [READY[i] + d for i, d in enumerate([0.3, 0.2, -0.2, 0.3, 0.2, -0.2, 0.4])]
        left.set("trajectory", trajectory(st, "left", [(goal, 1.5)]))
        left.set("trajectory_seq", 1)
        bad = list(goal)
        bad[3] = float("nan")
        right.set("trajectory", trajectory(st, "right", [(bad, 1.5)]))
        right.set("trajectory_seq", 1)
        cmd = st.types["control_msgs/msg/GripperCommand"](position=0.0, max_effort=20.0)
        right.set("gripper_command", bytes(st.serialize_cdr(cmd, "control_msgs/msg/GripperCommand")))
        right.set("gripper_command_seq", 1)
        right.set("grasp_width", 0.06)
        t = 0.0
        for _ in range(100):
            left.do_step(t, H)
            right.do_step(t, H)
            t += H
        # Left: accepted, tracked, done.
        ql = q_of(left)
        assert max(abs(a - b) for a, b in zip(ql, goal)) < 6e-3
        ts = st.deserialize_cdr(left.latest("trajectory_status"), "agrisim_msgs/msg/TrajectoryStatus")
        assert (ts.state, ts.trajectory_count, ts.rejected_count) == (2, 1, 0)
        assert 0.0 < ts.rms_tracking_error < 5e-3 and left.get("status") == 0
        js = st.deserialize_cdr(left.latest("joint_states"), "sensor_msgs/msg/JointState")
        assert js.name[:7] == [f"left_joint{i}" for i in range(1, 8)] and len(js.effort) == 9
        assert js.position[:7].tolist() == ql  # published at t = 2 s, the current step end
        # Right: rejected, did not move at all, reason names the joint; gripper stalled.
        assert q_of(right) == READY
        ts = st.deserialize_cdr(right.latest("trajectory_status"), "agrisim_msgs/msg/TrajectoryStatus")
        assert ts.state == 3 and ts.rejected_count == 1 and "right_joint4" in ts.reason and "NaN" in ts.reason
        assert right.get("status") == 2
        gs = st.deserialize_cdr(right.latest("gripper_state"), "agrisim_msgs/msg/GripperState")
        assert (gs.position, gs.effort, gs.stalled, gs.reached_goal) == (0.06, 20.0, True, False)
        assert right.get("finger_width") == 0.06
    finally:
        left.close()
        right.close()
