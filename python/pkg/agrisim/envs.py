"""gymnasium environments over the simulator.

``agrisim/Navigate-v0``: drive the mobile base to a seeded goal in the greenhouse, the nav
benchmark's task. The policy sees what the robot's algorithm layer may see (a planar scan
made from the LiDAR's point cloud, wheel odometry, the goal in the robot frame from
odometry); the reward and the ends of an episode come from the judge's ground truth (true base
position, the world's collision output), never handed to the policy.

``agrisim/Reach-v0``: one 7-DoF arm moves its gripper to a seeded reachable point; the
policy sees joint states and the target in the arm's base frame, and commands joint
position steps.

Resets restore a snapshot taken once after the first start (no world rebuild), so a seeded
reset is fast and deterministic: the same seed gives the same goal and the same episode.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _agrisim
from .msg import pointcloud_to_array


def register_all() -> None:
    """Registers the environments (done on ``import agrisim``)."""
    for env_id, entry in (("agrisim/Navigate-v0", "agrisim.envs:NavigateEnv"), ("agrisim/Reach-v0", "agrisim.envs:ReachEnv")):
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry, disable_env_checker=False)


def _yaw(q: dict) -> float:
    return math.atan2(2.0 * (q["w"] * q["z"] + q["x"] * q["y"]), 1.0 - 2.0 * (q["y"] ** 2 + q["z"] ** 2))


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def planar_scan(cloud: dict | None, beams: int, max_range: float, z_band: tuple[float, float]) -> np.ndarray:
    """The nearest return per bearing sector (sensor frame) among the points whose height is
    within ``z_band``: the scan a 2D navigation stack makes from a 3D LiDAR. Sectors with no
    return read ``max_range``."""
    scan = np.full(beams, max_range, dtype=np.float32)
    if cloud is None:
        return scan
    p = pointcloud_to_array(cloud)
    z = p["z"]
    band = (z >= z_band[0]) & (z <= z_band[1])
    x, y = p["x"][band], p["y"][band]
    r = np.hypot(x, y)
    ok = (r > 0.05) & np.isfinite(r)
    x, y, r = x[ok], y[ok], r[ok]
    sector = ((np.arctan2(y, x) + np.float32(math.pi)) * np.float32(beams / (2.0 * math.pi))).astype(np.int64) % beams
    np.minimum.at(scan, sector, np.minimum(r, np.float32(max_range)))
    return scan


class NavigateEnv(gym.Env):
    """Drive the 4WS omnidirectional base to a goal (the nav benchmark's targets).

    Observation (dict): ``scan`` (beams,) nearest LiDAR return per bearing [m]; ``odom``
    (x, y, yaw, vx, vy, wz) from wheel odometry; ``goal`` (dx, dy, dyaw) of the goal in the
    robot frame, from odometry. Action: base twist (vx, vy, wz) [m/s, m/s, rad/s], one per
    message period (0.1 s). Reward: progress toward the goal [m] per step, minus 0.01 per
    step; +10 on reaching the goal (within the nav judge's tolerance, true position), -10 on
    a collision. An episode ends on success or collision, and is truncated at ``time_limit``.
    """

    metadata = {"render_modes": []}

    def __init__(self, scenario: str = "default", beams: int = 72, max_range: float = 10.0, time_limit: float = 60.0, max_speed: float = 1.0, max_turn: float = 1.0, parameters: dict | None = None, fmu: dict | None = None):
        self._scenario = scenario
        self._task = _agrisim.NavTask(scenario)
        self._beams, self._max_range, self._time_limit = beams, max_range, time_limit
        self._parameters, self._fmu = parameters, fmu
        self._sim: Any = None
        self._start: Any = None
        # Positions within 1 km of the map origin, speeds within 10 m/s or rad/s.
        pose = np.array([1e3, 1e3, math.pi, 10.0, 10.0, 10.0], np.float32)
        goal = np.array([2e3, 2e3, math.pi], np.float32)
        self.observation_space = spaces.Dict(
            {
                "scan": spaces.Box(0.0, max_range, (beams,), np.float32),
                "odom": spaces.Box(-pose, pose, (6,), np.float32),
                "goal": spaces.Box(-goal, goal, (3,), np.float32),
            }
        )
        self.action_space = spaces.Box(np.array([-max_speed, -max_speed, -max_turn], np.float32), np.array([max_speed, max_speed, max_turn], np.float32), dtype=np.float32)

    # -- simulation ---------------------------------------------------------------------
    def _ensure_sim(self) -> None:
        if self._sim is not None:
            return
        self._sim = _agrisim.Simulation(self._scenario, parameters=self._parameters, fmu=self._fmu)
        self._ticks = max(1, round(self._sim.message_period / self._sim.step_size))
        # One message period standing still: the first scan and odometry exist.
        self._sim.step(self._ticks)
        self._start = self._sim.snapshot()

    def _observe(self) -> dict:
        odom = self._sim.latest("/odom")
        if odom is None:
            pose = np.zeros(6)
        else:
            p, tw = odom["pose"]["pose"], odom["twist"]["twist"]
            pose = np.array([p["position"]["x"], p["position"]["y"], _yaw(p["orientation"]), tw["linear"]["x"], tw["linear"]["y"], tw["angular"]["z"]])
        gx, gy, gyaw = self._goal
        dx, dy = gx - pose[0], gy - pose[1]
        c, s = math.cos(pose[2]), math.sin(pose[2])
        goal = np.array([c * dx + s * dy, -s * dx + c * dy, _wrap(gyaw - pose[2])], np.float32)
        scan = planar_scan(self._sim.latest("/points"), self._beams, self._max_range, (-0.3, 0.6))
        return {"scan": scan, "odom": pose.astype(np.float32), "goal": goal}

    def _judge(self) -> tuple[float, bool]:
        """Ground truth, for the reward only: distance of the true base centre to the goal,
        and the world's collision flag."""
        x, y = self._sim.get("chassis", "x"), self._sim.get("chassis", "y")
        d = math.hypot(x - self._goal[0], y - self._goal[1])
        return d, self._sim.get("world", "collision") != 0

    # -- gymnasium API ------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._ensure_sim()
        self._sim.restore(self._start)
        goal_seed = int(self.np_random.integers(0, 2**63 - 1))
        if options and "goal" in options:
            self._goal = tuple(float(v) for v in options["goal"])
        else:
            self._goal = self._task.goal(goal_seed)
        self._t0 = self._sim.time
        self._dist, _ = self._judge()
        return self._observe(), {"distance": self._dist, "goal_map": self._goal}

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), self.action_space.low, self.action_space.high)
        self._sim.publish("/cmd_vel", {"linear": {"x": float(a[0]), "y": float(a[1])}, "angular": {"z": float(a[2])}})
        self._sim.step(self._ticks)
        d, collision = self._judge()
        success = d <= self._task.goal_tolerance
        reward = (self._dist - d) - 0.01 + (10.0 if success else 0.0) - (10.0 if collision else 0.0)
        self._dist = d
        terminated = bool(success or collision)
        truncated = bool(not terminated and self._sim.time - self._t0 >= self._time_limit - 1e-9)
        info = {"distance": d, "success": bool(success), "collision": bool(collision), "time": self._sim.time - self._t0}
        return self._observe(), float(reward), terminated, truncated, info

    def close(self):
        if self._sim is not None:
            self._sim.close()
            self._sim = None


class ReachEnv(gym.Env):
    """Move one arm's tool centre point to a seeded target (the reaching stage of a harvest).

    The target is the tool centre point of a seeded joint configuration inside the joint
    limits, so it is reachable. Observation (Box, 20): measured joint positions (7) and
    velocities (7) from /arm/joint_states, the target position (3) and the tool centre point
    of the measured joints (3), both in ``base_link`` [m]. Action (Box, 7, in [-1, 1]): a
    joint position step of up to ``max_step`` rad per message period, sent as a one-point
    trajectory_msgs/JointTrajectory. Reward: minus the true distance of the tool centre point
    to the target [m] (from the FMU's joint outputs, not the noisy measurement), +1 on
    reaching it within ``tolerance``; the episode ends there, and is truncated at
    ``time_limit``.
    """

    metadata = {"render_modes": []}

    def __init__(self, scenario: str = "reach", max_step: float = 0.05, tolerance: float = 0.02, time_limit: float = 10.0):
        self._scenario, self._max_step, self._tolerance, self._time_limit = scenario, max_step, tolerance, time_limit
        self._arm = _agrisim.ArmModel("left")
        self._names = self._arm.joint_names
        lo, hi = self._arm.limits
        self._lo, self._hi = np.array(lo), np.array(hi)
        self._sim: Any = None
        self.observation_space = spaces.Box(-10.0, 10.0, (20,), np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (7,), np.float32)

    def _ensure_sim(self) -> None:
        if self._sim is not None:
            return
        self._sim = _agrisim.Simulation(self._scenario)
        self._ticks = max(1, round(self._sim.message_period / self._sim.step_size))
        self._sim.step(self._ticks)
        self._start = self._sim.snapshot()

    def _joints(self) -> tuple[np.ndarray, np.ndarray]:
        js = self._sim.latest("/arm/joint_states")
        index = {n: i for i, n in enumerate(js["name"])}
        k = [index[n] for n in self._names]
        return np.array([js["position"][i] for i in k]), np.array([js["velocity"][i] for i in k])

    def _observe(self) -> np.ndarray:
        q, dq = self._joints()
        tcp, _ = self._arm.fk(list(q))
        return np.concatenate([q, dq, self._target, tcp]).astype(np.float32)

    def _distance(self) -> float:
        """Judge: the tool centre point of the arm's true joint positions."""
        q = [self._sim.get("arm", f"q{i}") for i in range(1, 8)]
        tcp, _ = self._arm.fk(q)
        return float(np.linalg.norm(np.array(tcp) - self._target))

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._ensure_sim()
        self._sim.restore(self._start)
        lo, hi = self._lo, self._hi
        q_goal = lo + (hi - lo) * self.np_random.uniform(0.15, 0.85, size=7)
        self._target = np.array(self._arm.fk(list(q_goal))[0])
        self._command, _ = self._joints()
        self._t0 = self._sim.time
        return self._observe(), {"distance": self._distance()}

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self._command = np.clip(self._command + a * self._max_step, self._lo, self._hi)
        period = self._sim.message_period
        point = {"positions": [float(x) for x in self._command], "time_from_start": {"sec": int(period), "nanosec": int(round((period % 1.0) * 1e9))}}
        self._sim.publish("/arm/joint_trajectory", {"joint_names": self._names, "points": [point]})
        self._sim.step(self._ticks)
        d = self._distance()
        success = d <= self._tolerance
        terminated = bool(success)
        truncated = bool(not terminated and self._sim.time - self._t0 >= self._time_limit - 1e-9)
        return self._observe(), float(-d + (1.0 if success else 0.0)), terminated, truncated, {"distance": d, "success": bool(success)}

    def close(self):
        if self._sim is not None:
            self._sim.close()
            self._sim = None
